"""Scatter: CityEngine's ``scatter(surface|volume|scope, n, uniform|gaussian[, mean, stddev]) { ... }``, point
shapes drawn on the surface, in the volume or in the scope box of each shape, for the operations in braces.

The points of all shapes are one ragged fan-out (``ragged.fan_out`` of the per-shape counts): point k of a
shape gets the key of child k at the operation's site, and its draws come from that key alone
(``backend.random``), so a lot's points do not depend on the lots around it. A point is a shape with a
zero-size scope at the point (geometry: the scope, a point); on a surface its scope's y is the surface's
normal (its x the parent's x laid into the surface, or its z where x stands along the normal), elsewhere it
keeps the parent's axes, as the reference says.

- ``surface``: the shape's faces (``geometry.queries.shape_faces``: a box its six rectangles, a polygon its
  face with its holes, a prism its bottom, sides and top, a roof or mesh its faces) are triangulated
  (``geometry.triangulation``) and a triangle is drawn by area, then a point in it. A shape without area
  (a line or a point) draws in its scope.
- ``volume``: a solid box (or an inserted asset, taken as its box, as ``geometry.volume`` has it) draws in
  its scope; a prism draws a point of its base polygon and a height. A flat face has no volume and falls
  back to ``surface``, as the reference says of an open mesh; so, for now, do roofs and other meshes, which
  grammarc does not fill.
- ``scope``: in the scope box.
- ``gaussian``: each scope axis draws around ``mean`` (``center``, or the middle of the scope's face
  ``front`` (z = sz), ``back``, ``left`` (x = 0), ``right``, ``top`` (y = sy), ``bottom``) with the standard
  deviation ``stddev``, in metres or times the scope's size on that axis (``'0.16`` by default). The
  reference does not say what becomes of a draw outside the domain; grammarc draws again (up to
  ``_TRIES`` times) while it falls outside the scope box, or is not straight above (along the face's
  normal) a point of the surface, so that the distribution is the gaussian cut to the shape rather than
  piled on its border; the last draw takes the nearest point of the domain. A point inside a solid goes
  to the nearest face.

``n`` is evaluated per shape and truncated (CityEngine's rule files floor it themselves); a negative
count makes no point, a NaN one fails the lot. Reads: the scope, ``geom``, ``key``, and what ``n`` reads;
the points inherit ``lot``, ``depth``, ``params`` and ``dynamic``. Writes: no column of the cursor (the
shape goes on after its points, as in CityEngine, whose rule files end a scatter with ``NIL``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.random import child_keys, mix, mix1, uniform
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry.meshes import is_polygon
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.triangulation import triangulate_polygons
from grammarc.ir import nodes as ir
from grammarc.ragged import fan_out, offsets_from_counts

#: Salt of the points' draw keys, so that their draws do not repeat the ``rand`` sites their bodies use.
_DRAW_SALT = 0x5CA77E
#: The gaussian's mean in the scope, as fractions of its size.
_MEANS = {"center": (0.5, 0.5, 0.5), "front": (0.5, 0.5, 1.0), "back": (0.5, 0.5, 0.0),
          "left": (0.0, 0.5, 0.5), "right": (1.0, 0.5, 0.5), "top": (0.5, 1.0, 0.5), "bottom": (0.5, 0.0, 0.5)}


@operation(ir.Scatter, meshes=True)
def scatter(ctx: Context, cursor: Shapes, op: ir.Scatter) -> Parts:
    env = ctx.env(cursor)
    count = np.broadcast_to(evaluate_array(op.count, env), (len(cursor),))
    bad = np.isnan(count)
    if bad.any():
        ctx.fail(cursor, bad, "`scatter` needs a number of points, got NaN", op.span)
    counts = np.clip(count, 0, 2.0**62).astype(np.int64)  # truncated; too many is --max-shapes' error
    ctx.check_fan_out(cursor, counts, op.span)
    parent, index = fan_out(counts)
    key = child_keys(cursor.key[parent], op.site, index)
    draw_key = mix(key, _DRAW_SALT)
    u = np.stack([uniform(draw_key, d) for d in range(4)], axis=1)  # (m, 4)
    size = cursor.size[parent]
    mean, sigma = _spread(op, env, size, parent)

    kind = _domains(ctx, cursor, op.domain)[parent]
    local = np.empty((len(parent), 3))
    normal = np.full((len(parent), 3), np.nan)  # the surface's normal in the scope, where the point has one
    for domain in (_SURFACE, _PRISM):
        rows = np.flatnonzero(kind == domain)
        if not len(rows):
            continue
        axis = (ctx.chunk.polygons.plane[cursor.geom[parent[rows]]].astype(np.int64) if domain == _PRISM
                else np.full(len(rows), -1, dtype=np.int64))
        local[rows], normal[rows], found = _on_faces(ctx, cursor, parent[rows], axis, draw_key[rows], u[rows],
                                                     mean[rows], sigma[rows], op.gaussian)
        kind[rows[~found]] = _SCOPE  # no area: the scope it is
    rows = np.flatnonzero(kind == _SCOPE)
    if len(rows):
        local[rows] = (_in_box(draw_key[rows], mean[rows], sigma[rows], size[rows], TOL.zero) if op.gaussian
                       else u[rows, :3] * size[rows])

    frames = ctx.chunk.frames
    axes = frames[cursor.frame[parent]]
    origin = cursor.origin[parent] + np.einsum("ni,nij->nj", local, axes)
    frame = cursor.frame[parent].copy()
    turned = np.flatnonzero((kind == _SURFACE) & ~(np.abs(normal[:, 1] - 1.0) <= TOL.zero))
    if len(turned):
        # points on one face share its turned frame
        frame[turned] = frames.turned(_surface_axes(normal[turned]), frame[turned])[0]
    made = Shapes(origin, np.zeros((len(parent), 3)), frame.astype(np.int32),
                  np.full(len(parent), -1, dtype=np.int32), cursor.lot[parent], key, cursor.depth[parent],
                  tuple(p[parent] for p in cursor.params), tuple(d[parent] for d in cursor.dynamic))
    ctx.count(made, op.span)
    return Parts(op.parts, made, np.array([0, len(made)], dtype=np.int64))


#: Where a shape's points are drawn.
_SCOPE, _SURFACE, _PRISM = 0, 1, 2
#: Draws of a gaussian point before it takes the nearest point of its domain.
_TRIES = 64


def _domains(ctx: Context, cursor: Shapes, domain: str) -> np.ndarray:
    """Per shape (n,) int64, what its points are drawn on: the scope, the surface, or a prism's base
    and height (module docstring)."""
    if domain == "scope":
        return np.full(len(cursor), _SCOPE, dtype=np.int64)
    kind = np.full(len(cursor), _SURFACE, dtype=np.int64)
    if domain == "volume":
        solid = (cursor.size > TOL.zero).all(axis=1)
        kind[solid & (cursor.geom < 0)] = _SCOPE  # a box, or an inserted asset taken as its box
        rows = np.flatnonzero(is_polygon(cursor.geom))
        if len(rows):
            axis = ctx.chunk.polygons.plane[cursor.geom[rows]].astype(np.int64)
            kind[rows[cursor.size[rows, axis] > TOL.zero]] = _PRISM
    return kind


def _spread(op: ir.Scatter, env, size: np.ndarray, parent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The gaussian's mean and standard deviation per point and scope axis, (m, 3) each (zeros when
    the points are uniform)."""
    if not op.gaussian:
        return np.zeros_like(size), np.zeros_like(size)
    stddev = np.broadcast_to(evaluate_array(op.stddev, env), (len(env.shapes),))[parent][:, None]
    sigma = stddev * size if op.relative else np.repeat(stddev, 3, axis=1)
    return np.asarray(_MEANS[op.mean]) * size, np.ascontiguousarray(sigma)


def _on_faces(ctx: Context, cursor: Shapes, parent: np.ndarray, axis: np.ndarray, key: np.ndarray,
              u: np.ndarray, mean: np.ndarray, sigma: np.ndarray, gaussian: bool):
    """Points (m, 3) on the faces of shapes ``parent`` (m,) of ``cursor`` (in their scopes), the faces'
    normals (m, 3), and whether the shape had area (m,) bool. Where ``axis`` (m,) is not -1 the shape
    is a prism across that axis: the point is drawn on its polygon and lifted by a height. Uniform by
    area from the draws ``u`` (m, 4), or gaussian (``_points``)."""
    shapes, back = np.unique(parent, return_inverse=True)
    size = cursor.size[shapes]
    prism = np.zeros(len(shapes), dtype=bool)
    prism[back[axis >= 0]] = True
    rows = np.flatnonzero(prism)
    height = cursor.size[parent, np.maximum(axis, 0)]
    if len(rows):
        size = size.copy()
        size[rows, ctx.chunk.polygons.plane[cursor.geom[shapes[rows]]]] = 0.0  # the prism's polygon
    faces = shape_faces(size, cursor.geom[shapes], ctx.chunk.polygons, ctx.chunk.meshes)
    triangles = triangulate_polygons(faces.verts, faces.ring_offsets, faces.face_offsets)
    owner = faces.vertex_shape()[triangles[:, 0]]
    order = np.argsort(owner, kind="stable")
    triangles = faces.verts[triangles[order]]  # (T, 3 corners, 3)
    offsets = offsets_from_counts(np.bincount(owner, minlength=len(shapes)))
    return _points(np.ascontiguousarray(triangles), offsets, back.astype(np.int64), axis, height,
                   np.ascontiguousarray(key), np.ascontiguousarray(u), mean, sigma, gaussian, TOL.zero)


def _surface_axes(normal: np.ndarray) -> np.ndarray:
    """Scope axes (m, 3, 3) (rows) in the parent's scope with y along ``normal`` (m, 3): x is the parent's
    x laid into the surface, or its z where x stands along the normal."""
    x = np.eye(3)[np.where(np.abs(normal[:, 0]) < 1.0 - 1e-6, 0, 2)]
    x = x - np.einsum("ni,ni->n", x, normal)[:, None] * normal
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    return np.stack([x, normal, np.cross(x, normal)], axis=1)


@njit(cache=True, nogil=True)
def _points(triangles, offsets, shape, axis, height, key, u, mean, sigma, gaussian, tol):
    """Per point, on the triangles ``offsets[s]:offsets[s+1]`` (T, 3, 3) of its shape ``s``, lifted
    along ``axis`` (-1: not) within ``height``. Uniform: draw u[:, 0] picks a triangle by area,
    u[:, 1:3] the point in it, u[:, 3] the height. Gaussian (``_gauss``): drawn again while the draw
    is not over the surface (its nearest point is not straight below it) or not within the height,
    then the nearest point of the last draw. Returns points (m, 3), the triangles' unit normals (m, 3),
    and whether the shape had area (m,) bool."""
    n_tri = triangles.shape[0]
    cumulative = np.empty(n_tri)
    unit = np.empty((n_tri, 3))
    for s in range(len(offsets) - 1):  # each shape's areas summed from its own first triangle
        total = 0.0
        for t in range(offsets[s], offsets[s + 1]):
            n = np.cross(triangles[t, 1] - triangles[t, 0], triangles[t, 2] - triangles[t, 0])
            length = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
            unit[t] = n / max(length, 1e-300)
            total += 0.5 * length
            cumulative[t] = total
    m = len(shape)
    points = np.zeros((m, 3))
    normals = np.zeros((m, 3))
    found = np.zeros(m, dtype=np.bool_)
    for i in range(m):
        lo, hi = offsets[shape[i]], offsets[shape[i] + 1]
        if hi == lo or cumulative[hi - 1] <= 0.0:
            continue
        found[i] = True
        a = axis[i]
        pick = lo
        if gaussian:
            for attempt in range(_TRIES):
                g = _gauss(key[i], attempt, mean[i], sigma[i])
                best = np.inf
                for t in range(lo, hi):
                    q = _closest(g[0], g[1], g[2], triangles[t])
                    d = (q[0] - g[0]) ** 2 + (q[1] - g[1]) ** 2 + (q[2] - g[2]) ** 2
                    if d < best:
                        best, pick, near = d, t, q
                n = unit[pick]
                off = (g[0] - near[0], g[1] - near[1], g[2] - near[2])
                along = off[0] * n[0] + off[1] * n[1] + off[2] * n[2]
                side = (off[0] - along * n[0]) ** 2 + (off[1] - along * n[1]) ** 2 + (off[2] - along * n[2]) ** 2
                if side <= tol * tol and (a < 0 or 0.0 <= g[a] <= height[i]):
                    break
            points[i, 0], points[i, 1], points[i, 2] = near
            if a >= 0:
                points[i, a] = min(max(g[a], 0.0), height[i])
        else:
            pick = min(lo + np.searchsorted(cumulative[lo:hi], u[i, 0] * cumulative[hi - 1], side="right"), hi - 1)
            r = np.sqrt(u[i, 1])
            points[i] = ((1.0 - r) * triangles[pick, 0] + r * (1.0 - u[i, 2]) * triangles[pick, 1]
                         + r * u[i, 2] * triangles[pick, 2])
            if a >= 0:
                points[i, a] = u[i, 3] * height[i]
        normals[i] = unit[pick]
    return points, normals, found


@njit(cache=True, nogil=True)
def _in_box(key, mean, sigma, size, tol):
    """Gaussian points (m, 3) in the scope boxes ``size`` (m, 3): drawn again while outside the box on
    an axis where it has extent, then clamped into it."""
    out = np.empty((len(key), 3))
    for i in range(len(key)):
        for attempt in range(_TRIES):
            g = _gauss(key[i], attempt, mean[i], sigma[i])
            inside = True
            for j in range(3):
                if size[i, j] > tol and not 0.0 <= g[j] <= size[i, j]:
                    inside = False
            if inside:
                break
        for j in range(3):
            out[i, j] = min(max(g[j], 0.0), size[i, j])
    return out


@njit(cache=True, nogil=True, inline="always")
def _gauss(key, attempt, mean, sigma):
    """Draw ``attempt`` of a point's gaussian: ``mean`` (3,) plus ``sigma`` (3,) times normal draws
    (Box-Muller of four uniform draws of the point's key, 53 bits each as ``random.uniform``'s)."""
    k = mix1(key, attempt)
    scale = 1.0 / 9007199254740992.0
    u0, u1 = (mix1(k, 0) >> np.uint64(11)) * scale, (mix1(k, 1) >> np.uint64(11)) * scale
    u2, u3 = (mix1(k, 2) >> np.uint64(11)) * scale, (mix1(k, 3) >> np.uint64(11)) * scale
    r0, r1 = np.sqrt(-2.0 * np.log1p(-u0)), np.sqrt(-2.0 * np.log1p(-u2))
    return (mean[0] + sigma[0] * r0 * np.cos(2.0 * np.pi * u1), mean[1] + sigma[1] * r0 * np.sin(2.0 * np.pi * u1),
            mean[2] + sigma[2] * r1 * np.cos(2.0 * np.pi * u3))


@njit(cache=True, nogil=True, inline="always")
def _closest(px, py, pz, tri):
    """The point of triangle ``tri`` (3, 3) nearest to (px, py, pz), as a tuple (Ericson, Real-Time
    Collision Detection 5.1.5), in scalars: it runs per draw and triangle."""
    ax, ay, az = tri[0, 0], tri[0, 1], tri[0, 2]
    bx, by, bz = tri[1, 0], tri[1, 1], tri[1, 2]
    cx, cy, cz = tri[2, 0], tri[2, 1], tri[2, 2]
    abx, aby, abz, acx, acy, acz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
    d1 = abx * (px - ax) + aby * (py - ay) + abz * (pz - az)
    d2 = acx * (px - ax) + acy * (py - ay) + acz * (pz - az)
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az
    d3 = abx * (px - bx) + aby * (py - by) + abz * (pz - bz)
    d4 = acx * (px - bx) + acy * (py - by) + acz * (pz - bz)
    if d3 >= 0.0 and d4 <= d3:
        return bx, by, bz
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return ax + v * abx, ay + v * aby, az + v * abz
    d5 = abx * (px - cx) + aby * (py - cy) + abz * (pz - cz)
    d6 = acx * (px - cx) + acy * (py - cy) + acz * (pz - cz)
    if d6 >= 0.0 and d5 <= d6:
        return cx, cy, cz
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return ax + w * acx, ay + w * acy, az + w * acz
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return bx + w * (cx - bx), by + w * (cy - by), bz + w * (cz - bz)
    denominator = 1.0 / (va + vb + vc)
    v, w = vb * denominator, vc * denominator
    return ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w
