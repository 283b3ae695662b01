"""A z-buffer rasterizer in numba: flat-shaded triangles, and instances drawn by their size on screen.

Conventions shared by the kernels (``camera.Camera`` makes the arrays):

* ``view`` (3, 4) float64 maps world to camera coordinates, ``c = view[:, :3] @ p + view[:, 3]``: x right,
  y up, z forward (away from the eye).
* ``lens`` (4,) float64 is ``(focal, cx, cy, near)``. A perspective camera puts ``c`` at pixel
  ``(cx + focal * x / z, cy - focal * y / z)``, an orthographic one at ``(cx + focal * x, cy - focal * y)``
  (pixel rows grow downwards). Pixel (i, j), column i and row j, is sampled at its centre (i + 0.5, j + 0.5).
  A perspective vertex closer than ``near`` drops its triangle or instance (the fitted camera keeps the whole
  city in front of it, so this only guards the division).
* The depth buffer (h, w) float64 holds nearness, which is affine in screen space and so interpolates
  exactly across a triangle: ``1 / z`` in perspective, ``-z`` orthographic. Larger is nearer. A fragment must
  be strictly nearer to win, so at equal depth the one drawn first stays: the kernels draw in record order,
  which makes the image a function of the record alone.
* ``light`` (5,) float64 is the unit direction towards the sun in camera coordinates, then the ambient and
  diffuse weights. Shading is flat Lambert, ``ambient + diffuse * max(0, n . sun)``, with the triangle's
  normal ``n`` turned towards the eye: two-sided, because facade quads are one-sided and a mirrored instance
  turns its asset's winding inside out.

Instances (``draw_instances``) are sized on screen by the projected bounding box of their unit box's eight
corners, and each is drawn in one of three ways, cheapest first:

1. smaller than ``splat_px`` pixels: a splat, the pixels whose centres its projected box covers (at least
   the one under the box's centre), at the depth of its centre, shaded as the mean of its box's faces that
   face the eye, weighted by their projected areas; nothing if the eye sees no face (a flat quad edge-on).
   A city of 10^6 instances is mostly this at 1600 pixels: a window of 1.5 m is a pixel or two, and its 12
   or 18 triangles would mostly miss every pixel centre;
2. smaller than the asset's ``detail_px``: its box (12 triangles), a proxy for assets of many triangles;
3. otherwise the asset's triangles.

The loops are serial. Drawing is under half of what ``render`` takes (``benchmarks/bench_render.py``;
reading the record and encoding the PNG are the rest), so threads could save little; and they would have
to split the picture into bands, each thread projecting every instance, because a pixel written by two
threads breaks both the depth test and determinism.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def project(points, lens, perspective, out):
    """Pixel coordinates and nearness of camera-space ``points`` (n, 3) float64 into ``out`` (n, 3) float64:
    columns x, y (pixels, continuous) and nearness (larger is nearer). Returns ``out``."""
    focal, cx, cy = lens[0], lens[1], lens[2]
    for k in range(len(points)):
        x, y, z = points[k, 0], points[k, 1], points[k, 2]
        if perspective:
            out[k, 0] = cx + focal * x / z
            out[k, 1] = cy - focal * y / z
            out[k, 2] = 1.0 / z
        else:
            out[k, 0] = cx + focal * x
            out[k, 1] = cy - focal * y
            out[k, 2] = -z
    return out


@njit(cache=True, nogil=True)
def draw_triangles(cam, screen, faces, rgb, near, perspective, light, image, depth):
    """Draw triangles given by their vertices, in order: the mesh table's polygons.

    cam (V, 3) float64 camera-space vertices; screen (V, 3) float64 their ``project``; faces (T, 3) int64
    vertex indices; rgb (T, >=3) uint8 each triangle's colour; near: float; perspective: bool; light (5,)
    float64; image (h, w, 3) uint8 and depth (h, w) float64, updated in place.
    """
    for t in range(len(faces)):
        a, b, c = faces[t, 0], faces[t, 1], faces[t, 2]
        if perspective and min(cam[a, 2], cam[b, 2], cam[c, 2]) < near:
            continue
        _fill(cam, screen, a, b, c, rgb[t, 0], rgb[t, 1], rgb[t, 2], perspective, light, image, depth)


@njit(cache=True, nogil=True)
def draw_instances(xform, rgb, asset, vertex_offsets, face_offsets, vertices, faces, detail_px, splat_px,
                   view, lens, perspective, light, image, depth):
    """Draw every instance, in record order, as a splat, its box or its asset's triangles (module docstring).

    xform (N, 3, 4) float32 unit box to world; rgb (N, >=3) uint8 colours; asset (N,) int32. The asset
    meshes, ragged: asset a's vertices (in its unit box) are ``vertices[vertex_offsets[a]:vertex_offsets[a
    + 1]]`` (v, 3) float64, its triangles ``faces[face_offsets[a]:face_offsets[a + 1]]`` (t, 3) int64 with
    indices local to the asset; the last asset of the table is the unit cube, the box proxy. detail_px (A,)
    float64: each asset's size on screen below which its box is drawn instead (0: never). splat_px: float.
    view (3, 4), lens (4,), light (5,) float64; perspective: bool; image (h, w, 3) uint8 and depth (h, w)
    float64, updated in place.

    Returns (3,) int64: the instances drawn as splats, as boxes, and with their asset's triangles.
    """
    height, width = depth.shape
    near = lens[3]
    box = len(vertex_offsets) - 2
    scratch = int(np.max(np.diff(vertex_offsets)))
    cam = np.empty((scratch, 3))
    screen = np.empty((scratch, 3))
    frame = np.empty((4, 3))  # the instance's three unit-box axes and origin in camera space
    counts = np.zeros(3, np.int64)
    for i in range(len(xform)):
        for j in range(4):
            for r in range(3):
                s = view[r, 3] if j == 3 else 0.0
                for m in range(3):
                    s += view[r, m] * xform[i, m, j]
                frame[j, r] = s
        # The projected bounding box of the unit box's corners, corner k = origin + the axes of k's bits.
        x0 = y0 = np.inf
        x1 = y1 = -np.inf
        behind = False
        for k in range(8):
            px, py, pz = frame[3, 0], frame[3, 1], frame[3, 2]
            for j in range(3):
                if k >> j & 1:
                    px += frame[j, 0]
                    py += frame[j, 1]
                    pz += frame[j, 2]
            if perspective:
                if pz < near:
                    behind = True
                    break
                px, py = lens[1] + lens[0] * px / pz, lens[2] - lens[0] * py / pz
            else:
                px, py = lens[1] + lens[0] * px, lens[2] - lens[0] * py
            x0, x1, y0, y1 = min(x0, px), max(x1, px), min(y0, py), max(y1, py)
        if behind or x1 < 0 or y1 < 0 or x0 > width or y0 > height:
            continue
        size = max(x1 - x0, y1 - y0)
        if size < splat_px:
            _splat(frame, x0, x1, y0, y1, rgb[i, 0], rgb[i, 1], rgb[i, 2], perspective, light, image, depth)
            counts[0] += 1
            continue
        a = asset[i]
        if size < detail_px[a]:
            a = box
            counts[1] += 1
        else:
            counts[2] += 1
        v0 = vertex_offsets[a]
        n = vertex_offsets[a + 1] - v0
        for v in range(n):
            x, y, z = vertices[v0 + v, 0], vertices[v0 + v, 1], vertices[v0 + v, 2]
            for r in range(3):
                cam[v, r] = frame[3, r] + frame[0, r] * x + frame[1, r] * y + frame[2, r] * z
        project(cam[:n], lens, perspective, screen[:n])
        for t in range(face_offsets[a], face_offsets[a + 1]):
            _fill(cam, screen, faces[t, 0], faces[t, 1], faces[t, 2], rgb[i, 0], rgb[i, 1], rgb[i, 2],
                  perspective, light, image, depth)
    return counts


@njit(cache=True, nogil=True)
def _fill(cam, screen, a, b, c, red, green, blue, perspective, light, image, depth):
    """Rasterize triangle (a, b, c), indices into ``cam`` and ``screen`` (see ``draw_triangles``)."""
    height, width = depth.shape
    xa, ya, ka = screen[a, 0], screen[a, 1], screen[a, 2]
    xb, yb, kb = screen[b, 0], screen[b, 1], screen[b, 2]
    xc, yc, kc = screen[c, 0], screen[c, 1], screen[c, 2]
    area = (xb - xa) * (yc - ya) - (yb - ya) * (xc - xa)
    if area == 0.0:
        return
    # Pixels whose centres lie in the triangle's bounding box, clipped to the image.
    i0 = max(0, int(np.ceil(min(xa, xb, xc) - 0.5)))
    i1 = min(width - 1, int(np.floor(max(xa, xb, xc) - 0.5)))
    j0 = max(0, int(np.ceil(min(ya, yb, yc) - 0.5)))
    j1 = min(height - 1, int(np.floor(max(ya, yb, yc) - 0.5)))
    if i0 > i1 or j0 > j1:
        return
    _, shade = _face_light(cam[b, 0] - cam[a, 0], cam[b, 1] - cam[a, 1], cam[b, 2] - cam[a, 2],
                           cam[c, 0] - cam[a, 0], cam[c, 1] - cam[a, 1], cam[c, 2] - cam[a, 2],
                           cam[a, 0], cam[a, 1], cam[a, 2], perspective, light)
    r, g, bl = _shaded(red, shade), _shaded(green, shade), _shaded(blue, shade)
    sign = 1.0 if area > 0 else -1.0
    for j in range(j0, j1 + 1):
        py = j + 0.5
        for i in range(i0, i1 + 1):
            px = i + 0.5
            # Edge functions: each is twice the area of the sub-triangle opposite its vertex, so the three
            # are the barycentric weights times ``area``; all of one sign with ``area`` inside.
            wa = sign * ((xc - xb) * (py - yb) - (yc - yb) * (px - xb))
            wb = sign * ((xa - xc) * (py - yc) - (ya - yc) * (px - xc))
            wc = sign * ((xb - xa) * (py - ya) - (yb - ya) * (px - xa))
            if wa < 0.0 or wb < 0.0 or wc < 0.0:
                continue
            _put(image, depth, j, i, (wa * ka + wb * kb + wc * kc) / (sign * area), r, g, bl)


@njit(cache=True, nogil=True)
def _splat(frame, x0, x1, y0, y1, red, green, blue, perspective, light, image, depth):
    """Fill the pixels whose centres lie in [x0, x1] x [y0, y1], at least the one under its centre, at the
    depth of the box's centre, shaded by its faces that face the eye; none if no face does (module
    docstring)."""
    height, width = depth.shape
    i0, i1 = int(np.ceil(x0 - 0.5)), int(np.floor(x1 - 0.5))
    j0, j1 = int(np.ceil(y0 - 0.5)), int(np.floor(y1 - 0.5))
    if i0 > i1:
        i0 = i1 = int(np.floor(0.5 * (x0 + x1)))
    if j0 > j1:
        j0 = j1 = int(np.floor(0.5 * (y0 + y1)))
    i0, i1, j0, j1 = max(i0, 0), min(i1, width - 1), max(j0, 0), min(j1, height - 1)
    if i0 > i1 or j0 > j1:
        return
    cz = frame[3, 2] + 0.5 * (frame[0, 2] + frame[1, 2] + frame[2, 2])
    key = 1.0 / cz if perspective else -cz
    # Face j of the box spans the other two axes; its normal's length is its area, and the part of the
    # area the eye sees is that normal along the direction to the eye.
    cx = frame[3, 0] + 0.5 * (frame[0, 0] + frame[1, 0] + frame[2, 0])
    cy = frame[3, 1] + 0.5 * (frame[0, 1] + frame[1, 1] + frame[2, 1])
    total = weight = 0.0
    for j in range(3):
        p, q = (j + 1) % 3, (j + 2) % 3
        seen, shade = _face_light(frame[p, 0], frame[p, 1], frame[p, 2], frame[q, 0], frame[q, 1],
                                  frame[q, 2], cx, cy, cz, perspective, light)
        total += seen * shade
        weight += seen
    if weight == 0.0:
        return  # seen edge-on (a facade quad from the top): it covers nothing
    shade = total / weight
    r, g, b = _shaded(red, shade), _shaded(green, shade), _shaded(blue, shade)
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            _put(image, depth, j, i, key, r, g, b)


@njit(cache=True, nogil=True)
def _face_light(ux, uy, uz, vx, vy, vz, px, py, pz, perspective, light):
    """How much of a flat face the eye sees, and its shade: the plane through p spanned by u and v.

    Returns ``|(u x v) . e|``, e the unit direction from p towards the eye (the face's area as seen, when u
    and v are its edges), and its flat Lambert shade with the normal turned towards the eye. Camera space.
    """
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    length = np.sqrt(nx * nx + ny * ny + nz * nz)
    if length == 0.0:
        return 0.0, light[3]
    facing = -nz  # orthographic: the eye looks along +z from infinitely far
    distance = np.sqrt(px * px + py * py + pz * pz)
    if perspective and distance > 0.0:
        facing = -(nx * px + ny * py + nz * pz) / distance
    lit = (nx * light[0] + ny * light[1] + nz * light[2]) / length
    if facing < 0.0:
        lit = -lit
    return abs(facing), light[3] + light[4] * max(lit, 0.0)


@njit(cache=True, nogil=True)
def _put(image, depth, j, i, key, red, green, blue):
    """Write pixel (row j, column i) if ``key`` is strictly nearer than what it holds."""
    if key > depth[j, i]:
        depth[j, i] = key
        image[j, i, 0] = red
        image[j, i, 1] = green
        image[j, i, 2] = blue


@njit(cache=True, nogil=True)
def _shaded(channel, shade):
    """A colour channel (0-255) times ``shade``, rounded and clipped to a byte."""
    return np.uint8(min(255.0, channel * shade + 0.5))
