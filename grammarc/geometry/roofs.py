"""Roofs of many polygons in one numba pass: hip, gable, shed and pyramid, as CityEngine builds them.

Input is the ragged polygon store's layout (normalized (u, v) rings, exterior counter-clockwise around
the plane's normal, holes clockwise) with each polygon's size along u and v. Output is one mesh per
polygon, in (a, b, h) coordinates: a and b along the polygon's axes in the polygon's units, h along
its normal. Face 0 of every mesh is the original polygon seen from below (CityEngine's
``roof.bottom``), then come the roof faces:

- ``hip``: one face per edge, from the straight skeleton (``skeleton.py``); the face starts with its
  eave, so a comp(f) scope runs along the eave and up the slope;
- ``gable``: the hip roof, where each triangular hip end whose apex ends a ridge is turned into a
  vertical gable by moving the apex onto the end's eave line; footprints whose skeleton has no ridge
  (a regular polygon's is one point) keep their hips;
- ``shed``: one sloped face rising from edge ``index`` of the exterior ring, and a vertical wall under
  each edge (none where the wall has no height);
- ``pyramid``: the average of the exterior's vertices lifted, and a triangle per exterior edge; holes
  stay in the bottom face only;
- ``mansard`` and ``gambrel`` (the paper's ``Roof`` types): the hip and the gable roof with two slopes,
  every plane cut where the inset reaches ``BREAK_SHARE`` of the skeleton's height: steep below,
  ``angle`` above. A gambrel's gable ends are vertical pentagons;
- ``envelope`` (CityEngine's building envelope): walls ``overhang`` high under every edge, the hip
  roof's planes from their tops, cut flat at height ``cap``: what is left of each plane above the cut
  lies in the flat top. Where the sides differ (a base height and an angle per edge), or a side is
  vertical, the planes are those of a weighted skeleton (``_envelope``);
- ``even`` (hip and gable): every node above the eaves takes their mean height, so the ridges are level
  and the faces by them no longer planar, as CityEngine's ``even`` does.

``roofRidge`` and ``roofGable`` with an edge index, two planes under one ridge in a given direction, are
``ridges.py``'s.

``value`` is the slope angle in degrees, or with ``by_height`` the roof's height (hip and gable: the
highest skeleton node; shed: the highest point; pyramid: the apex). Overhangs (hip and gable) are
measured on the roof plane, as CityEngine's are; with ``by_height`` they are measured horizontally,
because the slope is only known once the skeleton is. Gable ends overhang by the same distance as eaves.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.geometry.skeleton import skeleton_faces
from grammarc.ragged import grow

HIP, GABLE, SHED, PYRAMID, MANSARD, GAMBREL, ENVELOPE = 0, 1, 2, 3, 4, 5, 6
ROOF_KINDS = {"roofHip": HIP, "roofGable": GABLE, "roofShed": SHED, "roofPyramid": PYRAMID, "mansard": MANSARD,
              "gambrel": GAMBREL, "envelope": ENVELOPE}
#: Two-slope roofs (the paper's mansard and gambrel): the lower planes rise to this share of the
#: skeleton's height in inset, at the steeper angle ``90 - (90 - angle) / 3`` (70 degrees for 30).
BREAK_SHARE = 1.0 / 3.0


@njit(cache=True, nogil=True)
def _clean_rings(pts, ring_offsets, eps):
    """Rings without repeated vertices and without vertices between collinear edges; rings left with
    fewer than three vertices are dropped (the exterior too: then nothing is left). Also returns each
    kept vertex's index in ``pts``."""
    out = np.empty_like(pts)
    kept = np.empty(len(pts), np.int64)
    offsets = np.zeros(len(ring_offsets), np.int64)
    n_out = 0
    n_rings = 0
    for r in range(len(ring_offsets) - 1):
        r0, r1 = ring_offsets[r], ring_offsets[r + 1]
        keep = np.ones(r1 - r0, np.bool_)
        for _ in range(r1 - r0):  # each pass may expose a new collinear vertex
            changed = False
            m = r1 - r0
            for j in range(m):
                if not keep[j]:
                    continue
                p = j - 1
                while not keep[p % m]:
                    p -= 1
                q = j + 1
                while not keep[q % m]:
                    q += 1
                p, q = p % m, q % m
                if p == j or q == j:
                    break
                ax, ay = pts[r0 + j, 0] - pts[r0 + p, 0], pts[r0 + j, 1] - pts[r0 + p, 1]
                bx, by = pts[r0 + q, 0] - pts[r0 + j, 0], pts[r0 + q, 1] - pts[r0 + j, 1]
                la, lb = np.sqrt(ax * ax + ay * ay), np.sqrt(bx * bx + by * by)
                if la <= eps or (lb > eps and abs(ax * by - ay * bx) <= eps * (la + lb)
                                 and ax * bx + ay * by > 0):
                    keep[j] = False
                    changed = True
            if not changed:
                break
        count = 0
        for j in range(r1 - r0):
            if keep[j]:
                out[n_out + count] = pts[r0 + j]
                kept[n_out + count] = r0 + j
                count += 1
        if count >= 3:
            n_out += count
            n_rings += 1
            offsets[n_rings] = n_out
        elif r == 0:
            return out[:0], offsets[:1], kept[:0]
    return out[:n_out], offsets[: n_rings + 1], kept[:n_out]


@njit(cache=True, nogil=True)
def _gable_ends(node_xy, faces, face_offsets, xy, succ, eps):
    """Which edges' hip faces become gables: triangles whose apex ends a ridge (no other hip end meets
    there, or only the opposite one)."""
    n = len(face_offsets) - 1
    apex = np.full(n, -1, np.int64)
    for k in range(n):
        if face_offsets[k + 1] - face_offsets[k] == 3:
            apex[k] = faces[face_offsets[k] + 2]
    ends = np.zeros(n, np.bool_)
    for k in range(n):
        if apex[k] < 0:
            continue
        dx, dy = xy[succ[k], 0] - xy[k, 0], xy[succ[k], 1] - xy[k, 1]
        length = np.sqrt(dx * dx + dy * dy)
        dx, dy = dx / length, dy / length
        others = 0
        opposite = True
        for j in range(n):
            if j == k or apex[j] < 0:
                continue
            if (abs(node_xy[apex[j], 0] - node_xy[apex[k], 0]) <= eps
                    and abs(node_xy[apex[j], 1] - node_xy[apex[k], 1]) <= eps):
                others += 1
                ex, ey = xy[succ[j], 0] - xy[j, 0], xy[succ[j], 1] - xy[j, 1]
                if (dx * ex + dy * ey) / np.sqrt(ex * ex + ey * ey) > -0.999:
                    opposite = False
        ends[k] = others <= 1 and opposite
    return ends


@njit(cache=True, nogil=True)
def _move_gable_ends(node_xy, node_t, faces, face_offsets, origin, ends, xy, succ, start_time):
    """Turn the gable ends vertical (in place): every node of a face that came from a gable end's hip
    face, other than its eave, moves along the edge's inward normal back onto the eave line."""
    moves = np.zeros((len(node_xy), 2))
    moved = np.zeros(len(node_xy), np.bool_)
    for f in range(len(face_offsets) - 1):
        k = origin[f]
        if not ends[k]:
            continue
        dx, dy = xy[succ[k], 0] - xy[k, 0], xy[succ[k], 1] - xy[k, 1]
        length = np.sqrt(dx * dx + dy * dy)
        dx, dy = dx / length, dy / length
        for j in range(face_offsets[f], face_offsets[f + 1]):
            q = faces[j]
            if moved[q] or node_t[q] <= start_time:
                continue
            shift = node_t[q] - start_time
            moves[q, 0], moves[q, 1] = dy * shift, -dx * shift
            moved[q] = True
    node_xy += moves


@njit(cache=True, nogil=True)
def _split_at(node_xy, node_t, faces, face_offsets, knees, eave_above, eps):
    """Each face f cut where its inset reaches ``knees[f]``: its part below, then its part above (either
    may be missing), new nodes where face boundaries cross the knee, shared by the faces that meet there
    at the same knee. With ``eave_above`` the part above starts with its cut edge, as the part below
    starts with the face's eave. Returns nodes (xy, t), faces, offsets and each new face's original
    face."""
    n_faces = len(face_offsets) - 1
    m = len(faces)
    xy = np.empty((len(node_xy) + m, 2))
    t = np.empty(len(node_t) + m)
    xy[: len(node_xy)] = node_xy
    t[: len(node_t)] = node_t
    n_nodes = len(node_t)
    break_key = np.empty((m, 2), np.int64)
    n_breaks = 0
    out = np.empty(4 * m + 8, np.int64)
    offsets = np.zeros(2 * n_faces + 1, np.int64)
    origin = np.empty(2 * n_faces, np.int64)
    count = 0
    n_out = 0
    for f in range(n_faces):
        f0, f1 = face_offsets[f], face_offsets[f + 1]
        size = f1 - f0
        knee = knees[f]
        for upper in (False, True):
            start = count
            for j in range(size):
                a = faces[f0 + (j - 1) % size]
                b = faces[f0 + j]
                a_in = (t[a] >= knee - eps) if upper else (t[a] <= knee + eps)
                b_in = (t[b] >= knee - eps) if upper else (t[b] <= knee + eps)
                if a_in != b_in:
                    lo, hi = min(a, b), max(a, b)
                    found = -1
                    for q in range(n_breaks):
                        if break_key[q, 0] == lo and break_key[q, 1] == hi and t[len(node_t) + q] == knee:
                            found = q
                            break
                    if found < 0:
                        f_ = (knee - t[a]) / (t[b] - t[a])
                        xy[n_nodes, 0] = xy[a, 0] + f_ * (xy[b, 0] - xy[a, 0])
                        xy[n_nodes, 1] = xy[a, 1] + f_ * (xy[b, 1] - xy[a, 1])
                        t[n_nodes] = knee
                        break_key[n_breaks, 0], break_key[n_breaks, 1] = lo, hi
                        found = n_breaks
                        n_breaks += 1
                        n_nodes += 1
                    out[count] = len(node_t) + found
                    count += 1
                if b_in:
                    out[count] = b
                    count += 1
            if not upper:  # the part below keeps the eave first
                for j in range(start, count):
                    if out[j] == faces[f0] and j > start:
                        rolled = np.concatenate((out[j:count], out[start:j]))
                        out[start:count] = rolled
                        break
            elif eave_above:  # the part above from the cut node followed by the other cut node
                for j in range(start, count):
                    nxt = start + (j - start + 1) % (count - start)
                    if out[j] >= len(node_t) and out[nxt] >= len(node_t):
                        if j == start:
                            break
                        rolled = np.concatenate((out[j:count], out[start:j]))
                        out[start:count] = rolled
                        break
            if count - start >= 3:
                origin[n_out] = f
                n_out += 1
                offsets[n_out] = count
            else:
                count = start
    return xy[:n_nodes], t[:n_nodes], out[:count], offsets[: n_out + 1], origin[:n_out]


@njit(cache=True, nogil=True)
def _envelope(pts, pring, succ, base, speed, cap, eps):
    """An envelope whose sides differ: walls ``base`` (n,) high under each edge, then each edge's plane
    rising at ``speed`` (n,) (horizontal run per height: 0 is a wall up to the cap), cut flat at ``cap``.

    Heights are the times of a weighted skeleton. Until ``t0``, the highest base of a moving edge, the
    edges' lines are moved in by ``speed * max(h - base, 0)`` and each vertex runs along the meeting of
    its two edges' planes (a corner node where one of them starts to slope); from ``t0`` on every line
    moves linearly, and the weighted skeleton of the outline at ``t0`` gives the rest. Edge k's face
    is its wall and its slope in one ring, then cut at ``base[k]`` into the two, and every face at the
    cap. Returns points (P, 3) as (x, y, h), faces (ragged point ids, each starting with its eave or its
    cut edge) and ok: False where an edge vanished before ``t0`` (bases too far apart for the outline),
    the skeleton did not close, or no edge moves (a prism) and the outline has holes or no cap."""
    n = len(pts)
    pred = np.empty(n, np.int64)
    for k in range(n):
        pred[succ[k]] = k
    moving = speed > 0.0
    if not moving.any():  # walls all round: a prism up to the cap, its top the outline (without holes)
        if len(pring) > 2 or not np.isfinite(cap):
            return np.empty((0, 3)), np.empty(0, np.int64), np.zeros(1, np.int64), False
        point = np.empty((2 * n, 3))
        point[:n, :2], point[n:, :2] = pts, pts
        point[:n, 2], point[n:, 2] = 0.0, cap
        out = np.empty(5 * n, np.int64)
        for k in range(n):
            out[4 * k], out[4 * k + 1], out[4 * k + 2], out[4 * k + 3] = k, succ[k], n + succ[k], n + k
        out[4 * n:] = n + np.arange(n)
        offsets = np.append(4 * np.arange(n + 1), 5 * n)
        return point, out, offsets, True
    t0 = 0.0
    for k in range(n):
        if moving[k]:
            t0 = max(t0, base[k])
    nrm = np.empty((n, 2))
    c = np.empty(n)
    for k in range(n):
        dx, dy = pts[succ[k], 0] - pts[k, 0], pts[succ[k], 1] - pts[k, 1]
        length = np.sqrt(dx * dx + dy * dy)
        nrm[k, 0], nrm[k, 1] = -dy / length, dx / length
        c[k] = nrm[k, 0] * pts[k, 0] + nrm[k, 1] * pts[k, 1]
    # each vertex's path up to t0: its heights (0, the bases of its edges below t0, t0) and points
    path_h = np.empty((n, 4))
    path_xy = np.empty((n, 4, 2))
    path_len = np.zeros(n, np.int64)
    for k in range(n):
        a = pred[k]
        hs = np.array([0.0, base[a] if moving[a] else 0.0, base[k] if moving[k] else 0.0, t0])
        hs.sort()
        for h in hs:
            if path_len[k] > 0 and h <= path_h[k, path_len[k] - 1] + eps:
                continue
            ra = c[a] + speed[a] * max(h - base[a], 0.0)
            rk = c[k] + speed[k] * max(h - base[k], 0.0)
            det = nrm[a, 0] * nrm[k, 1] - nrm[a, 1] * nrm[k, 0]
            path_h[k, path_len[k]] = h
            path_xy[k, path_len[k], 0] = (ra * nrm[k, 1] - nrm[a, 1] * rk) / det
            path_xy[k, path_len[k], 1] = (nrm[a, 0] * rk - ra * nrm[k, 0]) / det
            path_len[k] += 1
    top = np.empty((n, 2))
    for k in range(n):
        top[k] = path_xy[k, path_len[k] - 1]
    for k in range(n):  # every edge keeps its direction up to t0
        if (top[succ[k], 0] - top[k, 0]) * nrm[k, 1] - (top[succ[k], 1] - top[k, 1]) * nrm[k, 0] <= eps:
            return np.empty((0, 3)), np.empty(0, np.int64), np.zeros(1, np.int64), False
    node_xy, node_t, fnodes, foff, done = skeleton_faces(top, pring, 0.0, speed)
    if not done:
        return np.empty((0, 3)), np.empty(0, np.int64), np.zeros(1, np.int64), False
    # nodes: the skeleton's (from t0), then each vertex's path below t0
    first = np.zeros(n + 1, np.int64)
    for k in range(n):
        first[k + 1] = first[k] + path_len[k] - 1
    n_skel = len(node_t)
    all_xy = np.empty((n_skel + first[n], 2))
    all_t = np.empty(n_skel + first[n])
    all_xy[:n_skel] = node_xy
    all_t[:n_skel] = node_t + t0
    for k in range(n):
        for j in range(path_len[k] - 1):
            all_xy[n_skel + first[k] + j] = path_xy[k, j]
            all_t[n_skel + first[k] + j] = path_h[k, j]
    # edge k's face: up the path of succ[k] from its foot, the skeleton's face from succ[k] round to k,
    # then down the path of k to its foot
    out = np.empty(len(fnodes) + 2 * first[n], np.int64)
    offsets = np.zeros(n + 1, np.int64)
    count = 0
    for k in range(n):
        q = succ[k]
        for j in range(path_len[q] - 1):
            out[count] = n_skel + first[q] + j
            count += 1
        f0, f1 = foff[k], foff[k + 1]
        for j in range(f0 + 1, f1):
            out[count] = fnodes[j]
            count += 1
        out[count] = fnodes[f0]
        count += 1
        for j in range(path_len[k] - 2, -1, -1):
            out[count] = n_skel + first[k] + j
            count += 1
        # the eave first: the foot of k, then the foot of succ[k]
        ring = np.concatenate((out[count - 1:count], out[offsets[k]:count - 1]))
        out[offsets[k]:count] = ring
        offsets[k + 1] = count
    knees = np.full(n, np.inf)
    for k in range(n):
        if moving[k] and base[k] > eps:
            knees[k] = base[k]
    all_xy, all_t, out, offsets, _ = _split_at(all_xy, all_t, out, offsets, knees, True, eps)
    if np.isfinite(cap) and cap < all_t.max():
        all_xy, all_t, out, offsets, _ = _split_at(all_xy, all_t, out, offsets, np.full(len(offsets) - 1, cap),
                                                   True, eps)
    point = np.empty((len(all_t), 3))
    point[:, 0] = all_xy[:, 0]
    point[:, 1] = all_xy[:, 1]
    point[:, 2] = np.minimum(all_t, cap)
    return point, out, offsets, True


@njit(cache=True, nogil=True)
def _weighted_sides(edge_base, edge_angle, edges, eps):
    """Whether an envelope's sides ``edges`` (indices into edge_base and edge_angle) differ or one is
    vertical, so that its planes are a weighted skeleton's, and whether their angles are all in (0, 90]
    (valid False refuses the roof). Sides of None (not an envelope) are the same all round."""
    if edge_base is None:
        return False, True
    base, angle = edge_base[edges], edge_angle[edges]
    weighted = base.max() - base.min() > eps or angle.max() - angle.min() > 1e-9 or angle.max() >= 90.0
    if weighted and not (angle.min() > 0.0 and angle.max() <= 90.0):
        return False, False
    return weighted, True


@njit(cache=True, nogil=True)
def _side_envelope(pts, pring, succ, edge_base, edge_angle, edges, cap, eps):
    """``_envelope`` with the sides ``edges`` of edge_base and edge_angle, their angles as speeds (0 for a
    wall). Sides of None never get here; numba prunes the branch, so the roofs other than envelopes
    compile without the weighted skeleton."""
    if edge_base is None:
        return np.empty((0, 3)), np.empty(0, np.int64), np.zeros(1, np.int64), False
    angle = edge_angle[edges]
    speed = np.where(angle >= 90.0, 0.0, 1.0 / np.tan(np.radians(angle)))
    return _envelope(pts, pring, succ, edge_base[edges], speed, cap, eps)


@njit(cache=True, nogil=True)
def roof_meshes(kind, coords, ring_offsets, poly_offsets, plane, size_a, size_b, value, by_height,
                overhang, index, cap, even, edge_base, edge_angle):
    """Roof meshes of k polygons.

    kind : HIP, GABLE, SHED or PYRAMID. coords (V, 2), ring_offsets, poly_offsets : the polygons in the
    store's layout; plane (k,) int8 their plane codes; size_a, size_b (k,) their sizes along u and v;
    value (k,) the angle in degrees or (``by_height``) the height; overhang (k,) for hip and gable;
    index (k,) int64 the shed's edge; cap (k,) the envelope's height (its walls' is ``overhang``); even
    (k,) bool: a hip or gable roof whose ridge nodes all take their mean height (CityEngine's ``even``:
    level ridges, faces no longer planar). edge_base, edge_angle (V,): an envelope's base height and
    angle under the edge from each vertex of ``coords``, used where they differ round a polygon or an
    angle is 90 degrees (``_envelope``; else ``overhang`` and ``value`` serve all round); both None for
    the other roofs, whose specialization numba compiles (and caches) without the weighted envelope and its
    skeleton, so that they load no more code than they run.
    Returns verts (V', 3) as (a, b, h), ring_offsets (R'+1,), face_offsets (F'+1,) into rings,
    mesh_offsets (k+1,) into faces, and ok (k,): False where the roof could not be made.
    """
    k_polys = len(poly_offsets) - 1
    verts = np.empty((max(16, 8 * len(coords)), 3))
    rings = np.zeros(max(16, 4 * len(ring_offsets)), np.int64)
    faces = np.zeros(max(16, 4 * len(ring_offsets)), np.int64)
    mesh_offsets = np.zeros(k_polys + 1, np.int64)
    ok = np.ones(k_polys, np.bool_)
    n_v = 0
    n_r = 0
    n_f = 0
    for g in range(k_polys):
        r_first, r_last = poly_offsets[g], poly_offsets[g + 1]
        v0, v1 = ring_offsets[r_first], ring_offsets[r_last]
        pts = np.empty((v1 - v0, 2))
        pts[:, 0] = coords[v0:v1, 0] * size_a[g]
        pts[:, 1] = coords[v0:v1, 1] * size_b[g]
        area = 0.0
        e0, e1 = ring_offsets[r_first] - v0, ring_offsets[r_first + 1] - v0
        for j in range(e0, e1):
            q = e0 + (j - e0 + 1) % (e1 - e0)
            area += pts[j, 0] * pts[q, 1] - pts[q, 0] * pts[j, 1]
        flip = area < 0.0
        if flip:
            pts[:, 1] = -pts[:, 1]
        scale = max(size_a[g], size_b[g], 1e-300)
        eps = 1e-9 * max(scale, 1.0)
        pts, pring, kept = _clean_rings(pts, ring_offsets[r_first:r_last + 1] - v0, eps)
        angle = np.radians(value[g])
        weighted = False
        if kind == ENVELOPE and len(pring) >= 2:
            weighted, valid = _weighted_sides(edge_base, edge_angle, v0 + kept, eps)
            if not valid:
                angle = np.pi  # refused below
        if len(pring) < 2 or (not by_height and not weighted and not (-np.pi / 2 < angle < np.pi / 2)):
            ok[g] = False
            mesh_offsets[g + 1] = n_f
            continue
        slope = np.tan(angle)
        n = len(pts)
        succ = np.empty(n, np.int64)
        for r in range(len(pring) - 1):
            for j in range(pring[r], pring[r + 1]):
                succ[j] = pring[r] + (j - pring[r] + 1) % (pring[r + 1] - pring[r])
        # ---- the roof's points (x, y, h) and its faces as rings of point ids
        if weighted:
            point, face_ids, face_off, done = _side_envelope(pts, pring, succ, edge_base, edge_angle, v0 + kept,
                                                             cap[g], eps)
            if not done:
                ok[g] = False
                mesh_offsets[g + 1] = n_f
                continue
            lifted = np.empty(0)
        elif kind == HIP or kind == GABLE or kind == MANSARD or kind == GAMBREL or kind == ENVELOPE:
            wall = overhang[g] if kind == ENVELOPE else 0.0
            start_time = 0.0 if kind == ENVELOPE else -overhang[g] * (1.0 if by_height else np.cos(angle))
            node_xy, node_t, fnodes, foff, done = skeleton_faces(pts, pring, start_time, None)
            if not done:
                ok[g] = False
                mesh_offsets[g + 1] = n_f
                continue
            ends = _gable_ends(node_xy, fnodes, foff, pts, succ, eps) if kind == GABLE or kind == GAMBREL \
                else np.zeros(n, np.bool_)
            lower = slope
            knee = np.inf
            if kind == MANSARD or kind == GAMBREL:
                knee = BREAK_SHARE * node_t.max()
                lower = np.tan(np.radians(90.0 - (90.0 - value[g]) / 3.0))
                node_xy, node_t, fnodes, foff, origin = _split_at(node_xy, node_t, fnodes, foff,
                                                                  np.full(n, knee), False, eps)
            elif kind == ENVELOPE and slope > 0 and (cap[g] - wall) / slope < node_t.max():
                knee = max(cap[g] - wall, 0.0) / slope
                node_xy, node_t, fnodes, foff, origin = _split_at(node_xy, node_t, fnodes, foff,
                                                                  np.full(n, knee), False, eps)
            else:
                origin = np.arange(n)
            _move_gable_ends(node_xy, node_t, fnodes, foff, origin, ends, pts, succ, start_time)
            if by_height:
                top = node_t.max()
                slope = value[g] / top if top > eps else 0.0
                lower = slope
            flat_top = slope if kind != ENVELOPE else 0.0  # above the cut an envelope is flat
            point = np.empty((len(node_xy) + (n if kind == ENVELOPE else 0), 3))
            point[: len(node_xy), 0] = node_xy[:, 0]
            point[: len(node_xy), 1] = node_xy[:, 1]
            point[: len(node_xy), 2] = wall + np.where(node_t <= knee, node_t * lower,
                                                       knee * lower + (node_t - knee) * flat_top)
            if even[g] and (kind == HIP or kind == GABLE):
                ridge = node_t > start_time + eps
                if ridge.any():
                    heights = point[: len(node_xy), 2]
                    heights[ridge] = heights[ridge].mean()
            face_ids = fnodes
            face_off = foff
            if kind == ENVELOPE:
                # the walls: under edge k from node k (its start) to node succ[k], up to the roof's eave
                bottom = len(node_xy)
                point[bottom:, :2] = pts
                point[bottom:, 2] = 0.0
                walls = np.empty(4 * n, np.int64)
                for k in range(n):
                    walls[4 * k], walls[4 * k + 1] = bottom + k, bottom + succ[k]
                    walls[4 * k + 2], walls[4 * k + 3] = succ[k], k
                face_ids = np.concatenate((fnodes, walls))
                face_off = np.concatenate((foff, foff[-1] + 4 * np.arange(1, n + 1)))
            lifted = np.empty(0)
        elif kind == SHED:
            ext = pring[1]
            e = index[g] % ext
            q = succ[e]
            dx, dy = pts[q, 0] - pts[e, 0], pts[q, 1] - pts[e, 1]
            length = np.sqrt(dx * dx + dy * dy)
            nx, ny = -dy / length, dx / length
            dist = (pts[:, 0] - pts[e, 0]) * nx + (pts[:, 1] - pts[e, 1]) * ny
            if by_height:
                slope = value[g] / dist.max() if dist.max() > eps else 0.0
            # points: the lifted polygon (the sloped face, appended with the bottom), then the
            # polygon's own vertices for the walls
            point = np.empty((2 * n, 3))
            point[:n, :2] = pts
            point[:n, 2] = dist * slope
            point[n:, :2] = pts
            point[n:, 2] = 0.0
            lifted = point[:n, 2]
            face_ids = np.empty(4 * n, np.int64)
            face_off = np.zeros(n + 1, np.int64)
            count = 0
            n_face = 0
            for j in range(n):
                hj, hq = point[j, 2], point[succ[j], 2]
                if abs(hj) <= eps and abs(hq) <= eps:
                    continue
                face_ids[count], face_ids[count + 1] = n + j, n + succ[j]
                face_ids[count + 2], face_ids[count + 3] = succ[j], j
                count += 4
                n_face += 1
                face_off[n_face] = count
            face_ids = face_ids[:count]
            face_off = face_off[: n_face + 1]
        else:
            ext = pring[1]
            cx, cy = pts[:ext, 0].mean(), pts[:ext, 1].mean()
            height = value[g]
            if not by_height:
                dx, dy = pts[1, 0] - pts[0, 0], pts[1, 1] - pts[0, 1]
                length = np.sqrt(dx * dx + dy * dy)
                height = slope * abs((cx - pts[0, 0]) * -dy + (cy - pts[0, 1]) * dx) / length
            point = np.empty((ext + 1, 3))
            point[:ext, :2] = pts[:ext]
            point[:ext, 2] = 0.0
            point[ext, 0], point[ext, 1], point[ext, 2] = cx, cy, height
            lifted = np.empty(0)
            face_ids = np.empty(3 * ext, np.int64)
            face_off = np.zeros(ext + 1, np.int64)
            for j in range(ext):
                face_ids[3 * j], face_ids[3 * j + 1], face_ids[3 * j + 2] = j, succ[j], ext
                face_off[j + 1] = 3 * j + 3
        # ---- append: the bottom (seen from below), the shed's sloped face, then the roof faces
        # without repeated points
        n_rings_new = 2 * (len(pring) - 1) + len(face_off) - 1
        verts = grow(verts, n_v + 2 * n + len(face_ids))
        rings = grow(rings, n_r + n_rings_new + 1)
        faces = grow(faces, n_f + len(face_off) + 2)
        reverse = flip != (plane[g] == 1)
        mesh_start = n_v
        for layer in range(1 + (len(lifted) > 0)):
            for r in range(len(pring) - 1):
                for j in range(pring[r], pring[r + 1]):
                    # the bottom runs backwards unless the output is reversed anyway
                    at = j if (layer == 1) != reverse else pring[r + 1] - 1 - (j - pring[r])
                    verts[n_v, 0], verts[n_v, 1] = pts[at, 0], pts[at, 1]
                    verts[n_v, 2] = lifted[at] if layer == 1 else 0.0
                    n_v += 1
                rings[n_r + 1] = n_v
                n_r += 1
            n_f += 1
            faces[n_f] = n_r
        for f in range(len(face_off) - 1):
            start = n_v
            for j in range(face_off[f], face_off[f + 1]):
                p = point[face_ids[j]]
                if n_v > start and (abs(p[0] - verts[n_v - 1, 0]) <= eps and abs(p[1] - verts[n_v - 1, 1])
                                    <= eps and abs(p[2] - verts[n_v - 1, 2]) <= eps):
                    continue
                verts[n_v] = p
                n_v += 1
            while n_v - start > 1 and (abs(verts[start, 0] - verts[n_v - 1, 0]) <= eps
                                       and abs(verts[start, 1] - verts[n_v - 1, 1]) <= eps
                                       and abs(verts[start, 2] - verts[n_v - 1, 2]) <= eps):
                n_v -= 1
            if n_v - start < 3:
                n_v = start  # a face that shrank to an edge or a point
                continue
            if reverse:
                _reverse_keeping_first_edge(verts, start, n_v)
            rings[n_r + 1] = n_v
            n_r += 1
            n_f += 1
            faces[n_f] = n_r
        if flip:
            verts[mesh_start:n_v, 1] = -verts[mesh_start:n_v, 1]
        mesh_offsets[g + 1] = n_f
    return verts[:n_v], rings[: n_r + 1], faces[: n_f + 1], mesh_offsets, ok


@njit(cache=True, nogil=True)
def _reverse_keeping_first_edge(verts, start, end):
    """Reverse a ring so that its first edge stays first (reversed): [0, 1, 2, 3] -> [1, 0, 3, 2]."""
    ring = verts[start:end].copy()
    m = end - start
    verts[start] = ring[1]
    verts[start + 1] = ring[0]
    for j in range(2, m):
        verts[start + j] = ring[m + 1 - j]
