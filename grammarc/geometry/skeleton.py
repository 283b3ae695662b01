"""Straight skeletons of many polygons with holes, in one numba pass: the faces of hip roofs.

Every edge line moves inward at its own speed (``n . x = c + w t``, n the inward normal; ``w`` is 1 for
roofs of one slope, and an envelope's sides of other slopes or vertical walls move at other speeds, down
to 0: a weighted skeleton), and the wavefront polygon is the set of the moved lines between its vertices. Its vertices live in a circular doubly
linked list (``prev``/``next``) over all rings at once, so a split event that joins a hole to the outer
ring and one that cuts a ring in two are the same relinking. Events, the earliest first:

- edge event: an edge of the wavefront shrinks to nothing where its line and its neighbours' lines
  meet; its two vertices become one;
- split event: a reflex vertex reaches the line of another wavefront edge between that edge's
  vertices; the ring is cut there (or two rings join).

Event points are found by solving for the point and time at which three moving lines meet, never by
moving vertices, so collinear-opposite edges (the ridge of a rectangle) need no special velocity.
Each vertex's path, from the node where it was made to the node where it ended, is an arc between the
faces of its two edges; the face of an input edge is the cycle of arcs that have that edge on one
side. A ring that shrinks to two vertices has become a ridge segment: one arc closes it.

Edge events are cached per vertex until its edge changes; a reflex vertex's split candidates (the time
it meets each line) are solved once when it is made and sorted, and each step checks them in time order
against the wavefront's current edges, stopping at the earliest event so far. Cost is O(n) per event
in practice, O(n^2) at worst, for O(n) events per polygon: cubic at worst in the vertices of one
polygon but linear in the number of polygons; real footprints have tens of vertices. A polygon whose skeleton cannot be
completed (degenerate input that the events do not resolve) is flagged, and its shape is reported.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Relative tolerance of event times and positions (times are distances, in the polygon's units).
_EPS = 1e-9


@njit(cache=True, nogil=True)
def _solve3(a0, a1, a2, aw, b0, b1, b2, bw, c0, c1, c2, cw):
    """The point (x, y) and time t where three moving lines (nx, ny, c, w: n . x = c + w t) meet; ok False
    when they never meet in one point (two of them parallel and apart, or all concurrent always)."""
    det = a0 * (b1 * -cw - (-bw) * c1) - a1 * (b0 * -cw - (-bw) * c0) + (-aw) * (b0 * c1 - b1 * c0)
    if abs(det) < 1e-12:
        return 0.0, 0.0, 0.0, False
    # Cramer's rule on [[a0, a1, -aw], [b0, b1, -bw], [c0, c1, -cw]] (x, y, t) = (a2, b2, c2)
    dx = a2 * (b1 * -cw - (-bw) * c1) - a1 * (b2 * -cw - (-bw) * c2) + (-aw) * (b2 * c1 - b1 * c2)
    dy = a0 * (b2 * -cw - (-bw) * c2) - a2 * (b0 * -cw - (-bw) * c0) + (-aw) * (b0 * c2 - b2 * c0)
    dt = a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0)
    return dx / det, dy / det, dt / det, True


@njit(cache=True, nogil=True)
def _speed(speed, e):
    """Edge e's speed: 1 where ``speed`` is None (numba prunes the branch in that specialization)."""
    if speed is None:
        return 1.0
    return speed[e]


@njit(cache=True, nogil=True)
def _vertex_at(nrm, c, w, e0, e1, t):
    """Where the lines of edges e0 and e1 cross at time t; ok False when they are parallel."""
    a0, a1, b0, b1 = nrm[e0, 0], nrm[e0, 1], nrm[e1, 0], nrm[e1, 1]
    det = a0 * b1 - a1 * b0
    if abs(det) < 1e-12:
        return 0.0, 0.0, False
    r0, r1 = c[e0] + _speed(w, e0) * t, c[e1] + _speed(w, e1) * t
    return (r0 * b1 - a1 * r1) / det, (a0 * r1 - r0 * b0) / det, True


@njit(cache=True, nogil=True)
def _position(nrm, c, w, node_xy, node_t, start, e0, e1, v, t, eps):
    """Where vertex v (between edges e0 and e1) is at time t; a spike tip, whose lines are parallel,
    is only anywhere at the time it was made."""
    x, y, ok = _vertex_at(nrm, c, w, e0, e1, t)
    if not ok and abs(t - node_t[start[v]]) <= eps:
        return node_xy[start[v], 0], node_xy[start[v], 1], True
    return x, y, ok


@njit(cache=True, nogil=True)
def skeleton_faces(xy, ring_offsets, start_time, speed):
    """Faces of the straight skeleton of one polygon with holes.

    xy : (n, 2) float64, the polygon's vertices, exterior counter-clockwise then holes clockwise (ring
    ``r`` is ``ring_offsets[r]:ring_offsets[r+1]``), without repeated or collinear consecutive vertices.
    start_time : <= 0; the wavefront starts from the edges moved out by -start_time (an overhang).
    speed : (n,) float64 >= 0, how fast each edge's line moves in, or None: 1 everywhere, the plain
    skeleton (numba compiles it apart, without the speeds).
    Returns node_xy (N, 2), node_t (N,), face_nodes (ragged node ids of each edge's face, starting with
    the edge's two ends), face_offsets (n+1,) and ok.
    """
    n = len(xy)
    cap = 6 * n + 16
    # edge lines: edge k runs from vertex k to the next vertex of its ring
    succ = np.empty(n, np.int64)
    pred = np.empty(n, np.int64)
    for r in range(len(ring_offsets) - 1):
        r0, r1 = ring_offsets[r], ring_offsets[r + 1]
        for k in range(r0, r1):
            succ[k] = r0 + (k - r0 + 1) % (r1 - r0)
            pred[k] = r0 + (k - r0 - 1) % (r1 - r0)
    nrm = np.empty((n, 2))
    c = np.empty(n)
    direction = np.empty((n, 2))
    scale = 0.0
    for k in range(n):
        dx, dy = xy[succ[k], 0] - xy[k, 0], xy[succ[k], 1] - xy[k, 1]
        length = np.sqrt(dx * dx + dy * dy)
        scale = max(scale, abs(xy[k, 0]), abs(xy[k, 1]), length)
        if length == 0.0:
            length = 1.0
        direction[k, 0], direction[k, 1] = dx / length, dy / length
        nrm[k, 0], nrm[k, 1] = -dy / length, dx / length
        c[k] = nrm[k, 0] * xy[k, 0] + nrm[k, 1] * xy[k, 1]
    eps = _EPS * max(scale, 1.0)

    node_xy = np.empty((cap, 2))
    node_t = np.empty(cap)
    in_edge = np.empty(cap, np.int64)
    out_edge = np.empty(cap, np.int64)
    prev = np.empty(cap, np.int64)
    nxt = np.empty(cap, np.int64)
    alive = np.zeros(cap, np.bool_)
    start = np.empty(cap, np.int64)
    # arcs: (from node, to node, in edge, out edge); the in edge's face runs along it, the out edge's
    # face against it
    arcs = np.empty((cap, 4), np.int64)
    n_arcs = 0
    dirty = np.ones(cap, np.bool_)
    edge_t = np.full(cap, np.inf)
    edge_x = np.zeros(cap)
    edge_y = np.zeros(cap)
    cand_t = np.empty((cap, n))
    cand_x = np.empty((cap, n))
    cand_y = np.empty((cap, n))
    cand_e = np.empty((cap, n), np.int64)
    n_cand = np.zeros(cap, np.int64)
    cand_first = np.zeros(cap, np.int64)
    for k in range(n):
        in_edge[k], out_edge[k], prev[k], nxt[k] = pred[k], k, pred[k], succ[k]
        alive[k] = True
        start[k] = k
        if start_time == 0.0:
            node_xy[k, 0], node_xy[k, 1] = xy[k, 0], xy[k, 1]
        else:
            px, py, ok = _vertex_at(nrm, c, speed, pred[k], k, start_time)
            if not ok:
                px, py = xy[k, 0] - nrm[k, 0] * start_time, xy[k, 1] - nrm[k, 1] * start_time
            node_xy[k, 0], node_xy[k, 1] = px, py
        node_t[k] = start_time
    n_nodes = n
    n_verts = n
    for k in range(n):
        _split_candidates(k, nrm, c, speed, direction, node_xy, node_t, start, in_edge, out_edge, alive, n, eps,
                          cand_t, cand_x, cand_y, cand_e, n_cand, cand_first)
    now = start_time
    ok = True
    alive_count = n
    for _ in range(cap):
        if alive_count == 0:
            break
        # ---- the earliest event: edge events (cached per vertex until its edge changes), then split
        # events (each reflex vertex's candidates against the lines, sorted by time once, checked
        # against the wavefront's current edges in time order)
        best_t = np.inf
        best_kind = -1
        best_v = -1
        best_u = -1
        best_x = 0.0
        best_y = 0.0
        for v in range(n_verts):
            if not alive[v]:
                continue
            if dirty[v]:
                dirty[v] = False
                edge_t[v] = np.inf
                w = nxt[v]
                a, e, b = in_edge[v], out_edge[v], out_edge[w]
                if not (_spike(direction, v, in_edge, out_edge) or _spike(direction, w, in_edge, out_edge)):
                    x, y, t, solved = _solve3(nrm[a, 0], nrm[a, 1], c[a], _speed(speed, a), nrm[e, 0],
                                              nrm[e, 1], c[e], _speed(speed, e), nrm[b, 0], nrm[b, 1], c[b],
                                              _speed(speed, b))
                    if solved:
                        edge_t[v], edge_x[v], edge_y[v] = t, x, y
            t = edge_t[v]
            if t >= now - eps and t < best_t - eps:
                best_t, best_kind, best_v, best_x, best_y = t, 0, v, edge_x[v], edge_y[v]
        for v in range(n_verts):
            if not alive[v] or n_cand[v] == 0:
                continue
            a, b = in_edge[v], out_edge[v]
            found = False
            for j in range(cand_first[v], n_cand[v]):
                t = cand_t[v, j]
                if t < now - eps:
                    cand_first[v] = j + 1  # in the past for good
                    continue
                if t >= best_t - eps:
                    break
                e = cand_e[v, j]
                x, y = cand_x[v, j], cand_y[v, j]
                for u in range(n_verts):
                    if not alive[u] or out_edge[u] != e or u == v or nxt[u] == v:
                        continue
                    w = nxt[u]
                    ux, uy, ok_u = _position(nrm, c, speed, node_xy, node_t, start, in_edge[u], e, u, t, eps)
                    wx, wy, ok_w = _position(nrm, c, speed, node_xy, node_t, start, e, out_edge[w], w, t, eps)
                    if not (ok_u and ok_w):
                        continue
                    along = (x - ux) * direction[e, 0] + (y - uy) * direction[e, 1]
                    length = (wx - ux) * direction[e, 0] + (wy - uy) * direction[e, 1]
                    if along < -eps or along > length + eps:
                        continue
                    best_t, best_kind, best_v, best_u, best_x, best_y = t, 1, v, u, x, y
                    found = True
                    break
                if found:
                    break
        if best_kind < 0 or n_verts + 2 > cap or n_nodes + 1 > cap or n_arcs + 4 > cap:
            ok = False
            break
        now = max(best_t, now)
        node = n_nodes
        node_xy[node, 0], node_xy[node, 1] = best_x, best_y
        node_t[node] = now
        n_nodes += 1
        v = best_v
        if best_kind == 0:
            # ---- edge event: v and its successor w become z
            w = nxt[v]
            for q in (v, w):
                arcs[n_arcs, 0], arcs[n_arcs, 1] = start[q], node
                arcs[n_arcs, 2], arcs[n_arcs, 3] = in_edge[q], out_edge[q]
                n_arcs += 1
                alive[q] = False
            alive_count -= 2
            if prev[v] == w:  # a ring of two: both ended here
                continue
            z = n_verts
            n_verts += 1
            in_edge[z], out_edge[z] = in_edge[v], out_edge[w]
            prev[z], nxt[z] = prev[v], nxt[w]
            nxt[prev[v]] = z
            prev[nxt[w]] = z
            start[z] = node
            alive[z] = True
            alive_count += 1
            dirty[prev[z]] = True
            n_arcs, alive_count = _close_pair(z, nxt, in_edge, out_edge, start, alive, arcs, n_arcs,
                                              alive_count)
            if alive[z]:
                _split_candidates(z, nrm, c, speed, direction, node_xy, node_t, start, in_edge, out_edge, alive,
                                  n_verts, eps, cand_t, cand_x, cand_y, cand_e, n_cand, cand_first)
        else:
            # ---- split event: v reaches edge u -> w; X ends the ring before v, Y starts the one after
            u = best_u
            w = nxt[u]
            arcs[n_arcs, 0], arcs[n_arcs, 1] = start[v], node
            arcs[n_arcs, 2], arcs[n_arcs, 3] = in_edge[v], out_edge[v]
            n_arcs += 1
            alive[v] = False
            e = out_edge[u]
            x_v, y_v = n_verts, n_verts + 1
            n_verts += 2
            in_edge[x_v], out_edge[x_v], prev[x_v], nxt[x_v] = in_edge[v], e, prev[v], w
            in_edge[y_v], out_edge[y_v], prev[y_v], nxt[y_v] = e, out_edge[v], u, nxt[v]
            nxt[prev[v]] = x_v
            prev[w] = x_v
            nxt[u] = y_v
            prev[nxt[v]] = y_v
            for q in (x_v, y_v):
                start[q] = node
                alive[q] = True
            alive_count += 1
            dirty[prev[x_v]] = True
            dirty[u] = True
            for q in (x_v, y_v):
                if alive[q]:
                    n_arcs, alive_count = _close_pair(q, nxt, in_edge, out_edge, start, alive, arcs,
                                                      n_arcs, alive_count)
            for q in (x_v, y_v):
                if alive[q]:
                    _split_candidates(q, nrm, c, speed, direction, node_xy, node_t, start, in_edge, out_edge,
                                      alive, n_verts, eps, cand_t, cand_x, cand_y, cand_e, n_cand, cand_first)
    if alive_count != 0:
        ok = False
    # the wavefront reaches every point no later than the boundary's offset at the slowest speed does:
    # a node later than its distance to the (moved-out) boundary over that speed is a wrong event order
    slowest = 1.0 if speed is None else speed.min()
    for q in range(n_nodes if slowest > 0.0 else 0):
        reach = np.inf
        for k in range(n):
            ax, ay = node_xy[k, 0], node_xy[k, 1]
            bx, by = node_xy[succ[k], 0] - ax, node_xy[succ[k], 1] - ay
            px, py = node_xy[q, 0] - ax, node_xy[q, 1] - ay
            f = min(max((px * bx + py * by) / max(bx * bx + by * by, 1e-300), 0.0), 1.0)
            reach = min(reach, np.sqrt((px - f * bx) ** 2 + (py - f * by) ** 2))
        if node_t[q] - start_time > reach / slowest + 1e3 * eps:
            ok = False
    face_nodes, face_offsets, faces_ok = _faces(arcs[:n_arcs], n, succ)
    return node_xy[:n_nodes], node_t[:n_nodes], face_nodes, face_offsets, ok and faces_ok


@njit(cache=True, nogil=True)
def _spike(direction, v, in_edge, out_edge):
    """Whether v's two edges run back on each other: the tip of a wavefront that folded onto itself
    (two edges whose lines met all along). Its edges do not shrink linearly, so they have no edge
    events; the spike ends by the split event of the vertex that reaches it, or by closing its ring."""
    a, b = in_edge[v], out_edge[v]
    return direction[a, 0] * direction[b, 0] + direction[a, 1] * direction[b, 1] < -1.0 + 1e-9


@njit(cache=True, nogil=True)
def _split_candidates(v, nrm, c, speed, direction, node_xy, node_t, start, in_edge, out_edge, alive, n_verts, eps,
                      cand_t, cand_x, cand_y, cand_e, n_cand, cand_first):
    """Where and when a reflex vertex v, from where it was made, would meet each line of the wavefront's
    edges that it moves towards: its split event candidates, in time order (row v of the cand_*
    arrays). Lines are fixed, so these never change; whether the edge still spans the point at that
    time is checked when the event is looked for."""
    a, b = in_edge[v], out_edge[v]
    n_cand[v] = 0
    cand_first[v] = 0
    if direction[a, 0] * direction[b, 1] - direction[a, 1] * direction[b, 0] > -1e-12:
        return  # not reflex
    t0 = node_t[start[v]]
    px, py = node_xy[start[v], 0], node_xy[start[v], 1]
    present = np.zeros(len(c), np.bool_)
    for u in range(n_verts):
        if alive[u]:
            present[out_edge[u]] = True
    count = 0
    for e in range(len(c)):
        if not present[e] or e == a or e == b:
            continue
        if nrm[e, 0] * px + nrm[e, 1] * py - c[e] - _speed(speed, e) * t0 < -eps:
            continue  # behind the line: moving away from it
        x, y, t, solved = _solve3(nrm[a, 0], nrm[a, 1], c[a], _speed(speed, a), nrm[b, 0], nrm[b, 1], c[b],
                                  _speed(speed, b), nrm[e, 0], nrm[e, 1], c[e], _speed(speed, e))
        if not solved or t < t0 - eps:
            continue
        cand_t[v, count], cand_x[v, count], cand_y[v, count], cand_e[v, count] = t, x, y, e
        count += 1
    order = np.argsort(cand_t[v, :count], kind="mergesort")
    cand_t[v, :count] = cand_t[v, :count][order]
    cand_x[v, :count] = cand_x[v, :count][order]
    cand_y[v, :count] = cand_y[v, :count][order]
    cand_e[v, :count] = cand_e[v, :count][order]
    n_cand[v] = count


@njit(cache=True, nogil=True)
def _close_pair(z, nxt, in_edge, out_edge, start, alive, arcs, n_arcs, alive_count):
    """A ring of two vertices (the new ``z`` and an older one) has no area left: the older vertex's
    path runs to z's node, and the ring is done. Rings of one vertex (a degenerate collapse) end too."""
    other = nxt[z]
    if other == z:
        alive[z] = False
        return n_arcs, alive_count - 1
    if nxt[other] != z:
        return n_arcs, alive_count
    arcs[n_arcs, 0], arcs[n_arcs, 1] = start[other], start[z]
    arcs[n_arcs, 2], arcs[n_arcs, 3] = in_edge[other], out_edge[other]
    n_arcs += 1
    alive[z] = False
    alive[other] = False
    return n_arcs, alive_count - 2


@njit(cache=True, nogil=True)
def _faces(arcs, n, succ):
    """The face of each input edge as a cycle of nodes: the edge from node k to node succ[k], then the
    arcs that have k on one side, each followed from the node the last one reached."""
    m = len(arcs)
    # directed segments per face: the in edge's face along the arc, the out edge's against it
    seg_face = np.empty(2 * m, np.int64)
    seg_from = np.empty(2 * m, np.int64)
    seg_to = np.empty(2 * m, np.int64)
    for i in range(m):
        seg_face[2 * i], seg_from[2 * i], seg_to[2 * i] = arcs[i, 2], arcs[i, 0], arcs[i, 1]
        seg_face[2 * i + 1], seg_from[2 * i + 1], seg_to[2 * i + 1] = arcs[i, 3], arcs[i, 1], arcs[i, 0]
    order = np.argsort(seg_face, kind="mergesort")
    first = np.zeros(n + 1, np.int64)
    for i in range(2 * m):
        first[seg_face[i] + 1] += 1
    for k in range(n):
        first[k + 1] += first[k]
    used = np.zeros(2 * m, np.bool_)
    out = np.empty(2 * m + 2 * n, np.int64)
    offsets = np.zeros(n + 1, np.int64)
    count = 0
    ok = True
    for k in range(n):
        out[count] = k
        out[count + 1] = succ[k]
        count += 2
        here = succ[k]
        steps = 0
        while here != k:
            found = -1
            for j in range(first[k], first[k + 1]):
                s = order[j]
                if not used[s] and seg_from[s] == here:
                    found = s
                    break
            if found < 0 or steps > first[k + 1] - first[k]:
                ok = False
                break
            used[found] = True
            here = seg_to[found]
            steps += 1
            if here != k:
                out[count] = here
                count += 1
        offsets[k + 1] = count
    return out[:count], offsets, ok
