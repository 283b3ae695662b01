"""The setback strips of outlines whose strips fold: the moved edges as a wavefront, its edge events in
time order.

``setback`` moves each edge of a face in by its own distance. Where no strip folds, each strip is the quad
between the edge and its moved copy, ended at the neighbours' mitre points (``geometry.setback_strips``). Where
one does (a short edge moved further than its neighbours' lines allow, a strip of massing's tiers whose
end lines cross before its moved line), PRT lets that edge vanish where its end lines cross and its
neighbours' moved lines meet from there on, as in a weighted straight skeleton whose edges move at their
own distances: its remainder runs along the neighbours' moved lines, where the folded quads would leave
a notch (measured through PyPRT on massing's harness lot convex.15000, four real lots, and a 9 x 5 m L
whose 3 m end moves 4 m: PRT's remainder is the 5.4 x 1 m rectangle past the moved front).

The wavefront is a ring of lines ``n . x = c + w t`` (n the inward normal, w the distance, t from 0 to 1).
Where ``geometry.setback_strips`` steps between two edges (a turn of less than 15 degrees between different
distances) or cuts a mitre too long, the two strips end apart; the segment between their ends is a line
of its own here (through the vertex, along the step, moving so that its ends stay on the two strips'
lines), so the steps stay PRT's. An edge event (an edge's segment shrinks to nothing) removes the edge;
its neighbours then meet, and a step beside it goes with it; neighbours moved by different distances
that turn by less than 15 degrees step from where they met instead, as at a vertex of the outline (PRT's
moved line past a kept edge's far end, where the next kept edge turns little from it). Neighbours whose lines are parallel meet only
where they coincide: facing ones (two edges passing each other) annihilate where their segments overlap,
the shorter going and the rest of the longer sweeping on, as PRT's front strip runs on past the kept end
of an L's arm and a T's bar top past where its bottom met it; of two with the same normal the slower
goes; a kept edge between parallel neighbours does not vanish (PRT's strip ends at its line:
massing.H.15118). Split events (an arm that closes parts the wavefront) are not followed: where two
parallel lines apart become neighbours, or the wavefront ends outside its face (but for one turned inside
out; one that ends crossing itself inside its face has its strips clipped to the face, ``geometry.setback``),
the caller keeps the folded quads' strips. A ring that falls below three lines has nothing left.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Lengths (scope units) below this are zero: parallel lines, a vanished segment.
_EPS = 1e-9


@njit(cache=True, nogil=True)
def _meet(nx, ny, c, w, a, b, t):
    """Where lines a and b meet at time t (x, y), and whether they do (not parallel)."""
    det = nx[a] * ny[b] - ny[a] * nx[b]
    if abs(det) <= _EPS:
        return 0.0, 0.0, False
    ca, cb = c[a] + w[a] * t, c[b] + w[b] * t
    return (ca * ny[b] - cb * ny[a]) / det, (nx[a] * cb - nx[b] * ca) / det, True


@njit(cache=True, nogil=True)
def _length(nx, ny, c, w, ux, uy, prv, nxt, e, t):
    """The length of line e's segment at time t along its direction, and whether both its ends exist."""
    x0, y0, ok0 = _meet(nx, ny, c, w, prv[e], e, t)
    x1, y1, ok1 = _meet(nx, ny, c, w, e, nxt[e], t)
    return (x1 - x0) * ux[e] + (y1 - y0) * uy[e], ok0 and ok1


@njit(cache=True, nogil=True)
def _retire(alive, final, pool, s_head, e, x, y):
    """Line e (a step) goes with the edge that vanished at (x, y); returns where its segment started."""
    alive[e] = False
    final[e, 0, 0], final[e, 0, 1], final[e, 1, 0], final[e, 1, 1] = x, y, x, y
    k = s_head[e]
    return pool[k, 0], pool[k, 1]


@njit(cache=True, nogil=True)
def _past_step(nx, ny, c, w, ux, uy, pool, s_head, step, a, b, t, sign):
    """Whether lines a and b, the neighbours a step (a line, ``step``) lies between once an edge beside it
    vanished, meet at time t on the far line's side of the step's vertex (where the step's path starts):
    past it along b (``sign`` 1, b the line beyond the step) or before it along a (``sign`` -1). Lines
    that do not meet, and a far line that moves, count as meeting there (only steps to kept edges were
    measured staying: those between moved edges go with the edge, as before)."""
    far = b if sign > 0 else a
    x, y, ok = _meet(nx, ny, c, w, a, b, t)
    if not ok or w[far] > _EPS:
        return True
    k = s_head[step]
    return sign * ((x - pool[k, 0]) * ux[far] + (y - pool[k, 1]) * uy[far]) >= -_EPS


@njit(cache=True, nogil=True)
def _push(pool, link, used, head, tail, e, x, y):
    """Append (x, y) to line e's path (a linked list in ``pool``); returns the pool's new size."""
    pool[used, 0], pool[used, 1] = x, y
    link[used] = -1
    if tail[e] >= 0:
        link[tail[e]] = used
    else:
        head[e] = used
    tail[e] = used
    return used + 1


@njit(cache=True, nogil=True)
def _ring_strips(start, end, inward, d, corner, ends, out, out_n, left, step_cos):
    """The swept strip of each edge of one ring (n edges), written one after another to ``out`` with its
    vertex count in ``out_n`` (n,) (0 for an edge that does not move), and the wavefront's vertices at
    the end to ``left`` (2 n, 2), two per line (its segment's ends); returns whether the wavefront fell
    below three lines (nothing is left), how many vertices it ended with, whether it met no split event
    (two parallel lines apart becoming neighbours), and whether a moved line overtook a kept one (a kept
    edge went where a moved line with its normal reached it)."""
    n = len(d)
    m_cap = 6 * n + 4  # the edges, a step at each vertex, and one at each of at most 2 m events
    nx, ny, c, w = np.empty(m_cap), np.empty(m_cap), np.empty(m_cap), np.empty(m_cap)
    ux, uy = np.empty(m_cap), np.empty(m_cap)
    real = np.full(m_cap, -1, np.int64)
    # each line's start path (where its strip starts, from its start vertex on) and end path, as linked
    # lists in one pool: two points per line, and at most eight per event
    pool = np.empty((10 * m_cap + 8, 2))
    link = np.empty(10 * m_cap + 8, np.int64)
    s_head, s_tail = np.full(m_cap, -1, np.int64), np.full(m_cap, -1, np.int64)
    e_head, e_tail = np.full(m_cap, -1, np.int64), np.full(m_cap, -1, np.int64)
    used = 0
    m = 0
    for k in range(n):
        gx, gy = corner[k, 0] - ends[k, 0], corner[k, 1] - ends[k, 1]
        gap = np.sqrt(gx * gx + gy * gy)
        if gap > _EPS:
            # the step between edge k-1's end and edge k's start: a line through the vertex along it
            ux[m], uy[m] = gx / gap, gy / gap
            nx[m], ny[m] = -uy[m], ux[m]
            c[m] = nx[m] * start[k, 0] + ny[m] * start[k, 1]
            w[m] = nx[m] * corner[k, 0] + ny[m] * corner[k, 1]
            used = _push(pool, link, used, s_head, s_tail, m, start[k, 0], start[k, 1])
            used = _push(pool, link, used, e_head, e_tail, m, start[k, 0], start[k, 1])
            m += 1
        if (m > 0 and gap <= _EPS and real[m - 1] >= 0 and abs(w[m - 1] - d[k]) <= _EPS
                and abs(nx[m - 1] - inward[k, 0]) <= _EPS and abs(ny[m - 1] - inward[k, 1]) <= _EPS
                and abs(nx[m - 1] * start[k, 0] + ny[m - 1] * start[k, 1] - c[m - 1]) <= _EPS * (1.0 + abs(c[m - 1]))):
            # edge k runs on along edge k-1's line and moves as far: one line, whose strip covers both (a
            # vertex on a straight run, as an inset leaves where a hole's channel closed, is no corner)
            pool[e_tail[m - 1], 0], pool[e_tail[m - 1], 1] = end[k, 0], end[k, 1]
            continue
        ex, ey = end[k, 0] - start[k, 0], end[k, 1] - start[k, 1]
        length = np.sqrt(ex * ex + ey * ey)
        ux[m], uy[m] = ex / length, ey / length
        nx[m], ny[m] = inward[k, 0], inward[k, 1]
        c[m] = nx[m] * start[k, 0] + ny[m] * start[k, 1]
        w[m] = d[k]
        real[m] = k
        used = _push(pool, link, used, s_head, s_tail, m, start[k, 0], start[k, 1])
        used = _push(pool, link, used, e_head, e_tail, m, end[k, 0], end[k, 1])
        m += 1
    prv, nxt = np.empty(m_cap, np.int64), np.empty(m_cap, np.int64)
    for i in range(m):
        prv[i], nxt[i] = (i - 1) % m, (i + 1) % m
    alive = np.zeros(m_cap, np.bool_)
    alive[:m] = True
    count = m
    final = np.empty((m_cap, 2, 2))
    now = 0.0
    collapsed = False
    trusted = True
    overtook = False
    for _ in range(2 * m):
        best, best_t = -1, np.inf
        for e in range(m):
            if not alive[e]:
                continue
            if w[e] <= _EPS and abs(nx[prv[e]] * ny[nxt[e]] - ny[prv[e]] * nx[nxt[e]]) <= _EPS:
                continue  # a kept edge between parallel lines stays: the strips end at its line
            l0, ok0 = _length(nx, ny, c, w, ux, uy, prv, nxt, e, now)
            l1, ok1 = _length(nx, ny, c, w, ux, uy, prv, nxt, e, 1.0)
            if not (ok0 and ok1) or l1 >= -_EPS or l0 <= l1:
                continue
            t = now + (1.0 - now) * max(l0, 0.0) / (l0 - l1)
            if t < best_t:
                best, best_t = e, t
        if best < 0:
            break
        now = best_t
        p, q = prv[best], nxt[best]
        x, y, _ = _meet(nx, ny, c, w, p, best, now)
        final[best, 0, 0], final[best, 0, 1], final[best, 1, 0], final[best, 1, 1] = x, y, x, y
        alive[best] = False
        count -= 1
        used = _push(pool, link, used, e_head, e_tail, p, x, y)
        used = _push(pool, link, used, s_head, s_tail, q, x, y)
        if real[best] >= 0:
            # the steps at a vanished edge's ends go with it: its neighbours meet as they would have without
            # it, their strips reaching across its step's vertex (PRT's on massing.far.33391, where a short
            # edge moved 4 m between a moved and a kept edge turned by 13 degrees), where they meet on the
            # far side's line past the step's vertex; where they would meet behind it (the kept edge beyond
            # the step runs on along the vanished edge's line, or turns from it by up to 8 degrees either
            # way), the step stays and the neighbour meets it (PRT's tiers on a lot whose edge set back 4 m
            # vanishes beside such a kept edge, after it and, mirrored, before it:
            # massing.near_degenerate.43838's second tier); nor where its other neighbour stays too, which
            # would meet the edge beyond the step out of the face (PRT's first tier on massing.concave.43589
            # keeps the step its moved edge left past a kept edge's far end, that edge's front then running
            # out on the kept edge beyond)
            if real[q] < 0 and count > 3 and w[p] > _EPS and _past_step(nx, ny, c, w, ux, uy, pool, s_head, q, p,
                                                                         nxt[q], now, 1.0):
                sx, sy = _retire(alive, final, pool, s_head, q, x, y)
                count -= 1
                used = _push(pool, link, used, e_head, e_tail, p, sx, sy)
                q = nxt[q]
            if real[p] < 0 and count > 3 and w[q] > _EPS and _past_step(nx, ny, c, w, ux, uy, pool, s_head, p,
                                                                         prv[p], q, now, -1.0):
                sx, sy = _retire(alive, final, pool, s_head, p, x, y)
                count -= 1
                used = _push(pool, link, used, s_head, s_tail, q, sx, sy)
                p = prv[p]
        nxt[p], prv[q] = q, p
        hx, hy = x, y  # where p's segment and q's meet
        while count >= 3:
            det = nx[p] * ny[q] - ny[p] * nx[q]
            if abs(det) > _EPS:
                jx, jy, _ = _meet(nx, ny, c, w, p, q, now)
                used = _push(pool, link, used, e_head, e_tail, p, jx, jy)
                used = _push(pool, link, used, s_head, s_tail, q, jx, jy)
                if (real[p] >= 0 and real[q] >= 0 and abs(w[p] - w[q]) > _EPS
                        and nx[p] * nx[q] + ny[p] * ny[q] > step_cos):
                    # neighbours moved by different distances that turn little step from where they met, as
                    # at a vertex of the outline (``geometry.setback_strips.mitres``): a line through the point
                    # along their normals' bisector, which their moved lines cross at their own distances
                    # (PRT's tiers: a moved edge that runs past a kept edge's far end, where the next kept
                    # edge turns from it by 15 degrees or less, steps there)
                    bx, by = nx[p] + nx[q], ny[p] + ny[q]
                    size = np.sqrt(bx * bx + by * by)
                    sign = 1.0 if w[q] > w[p] else -1.0
                    ux[m], uy[m] = sign * bx / size, sign * by / size
                    nx[m], ny[m] = -uy[m], ux[m]
                    c[m] = nx[m] * jx + ny[m] * jy
                    w[m] = 0.0  # (it stays where it is)
                    real[m] = -1
                    alive[m] = True
                    used = _push(pool, link, used, s_head, s_tail, m, jx, jy)
                    used = _push(pool, link, used, e_head, e_tail, m, jx, jy)
                    nxt[p], prv[m], nxt[m], prv[q] = m, p, q, m
                    m += 1
                    count += 1
                break
            # parallel neighbours meet where they coincide; apart, the ring parts there (a split event): the
            # strips are not to be trusted. Lines with the same normal: the slower goes (both where equally
            # fast); facing lines annihilate where their segments overlap: the shorter goes (both where
            # equally long) and the rest of the longer sweeps on, as PRT's front strip runs on past the kept
            # end of an L's arm, and a T's bar top (moved 3 m) on past where its bottom (4 m) met it
            # (massing.T.34179)
            same = nx[p] * nx[q] + ny[p] * ny[q] > 0.0
            at_p, at_q = c[p] + w[p] * now, c[q] + w[q] * now
            if abs(at_p - at_q if same else at_p + at_q) > _EPS * (1.0 + abs(at_p)):
                trusted = False
                break
            if same:
                gone_p, gone_q = w[p] <= w[q] + _EPS, w[q] <= w[p] + _EPS
                overtook |= (w[p] <= _EPS) != (w[q] <= _EPS)
            else:
                ax, ay, oka = _meet(nx, ny, c, w, prv[p], p, now)
                bx, by, okb = _meet(nx, ny, c, w, q, nxt[q], now)
                long_p = np.hypot(hx - ax, hy - ay) if oka else np.inf
                long_q = np.hypot(bx - hx, by - hy) if okb else np.inf
                gone_p, gone_q = long_p <= long_q + _EPS, long_q <= long_p + _EPS
            for r in (p, q):
                if (r == p and gone_p) or (r == q and gone_q):
                    a, b = prv[r], nxt[r]
                    sx, sy, oks = _meet(nx, ny, c, w, a, r, now)
                    fx, fy, okf = _meet(nx, ny, c, w, r, b, now)
                    final[r, 0, 0], final[r, 0, 1] = (sx, sy) if oks else (x, y)
                    final[r, 1, 0], final[r, 1, 1] = (fx, fy) if okf else (x, y)
                    alive[r] = False
                    count -= 1
                    nxt[a], prv[b] = b, a
            if gone_p and gone_q:
                p, q = prv[p], nxt[q]
            elif gone_p:
                hx, hy = final[p, 0, 0], final[p, 0, 1]
                p = prv[p]
            else:
                hx, hy = final[q, 1, 0], final[q, 1, 1]
                q = nxt[q]
        if not trusted:
            break
        if count < 3:
            collapsed = True
            break
    t_end = now if collapsed else 1.0
    for e in range(m):
        if alive[e]:
            sx, sy, oks = _meet(nx, ny, c, w, prv[e], e, t_end)
            fx, fy, okf = _meet(nx, ny, c, w, e, nxt[e], t_end)
            final[e, 0, 0], final[e, 0, 1] = (sx, sy) if oks else (pool[s_tail[e], 0], pool[s_tail[e], 1])
            final[e, 1, 0], final[e, 1, 1] = (fx, fy) if okf else (pool[e_tail[e], 0], pool[e_tail[e], 1])
    n_left = 0
    if not collapsed:
        first = 0
        while first < m and not alive[first]:
            first += 1
        e = first
        while first < m:  # (in the ring's order: a step made at an event comes after the lines before it)
            left[n_left], left[n_left + 1] = final[e, 0], final[e, 1]
            n_left += 2
            e = nxt[e]
            if e == first:
                break
    j = 0
    back = np.empty(used, np.int64)
    for e in range(m):
        k = real[e]
        if k < 0:
            continue
        out_n[k] = 0
        if d[k] <= _EPS:
            continue
        first = j
        # the edge, its end's path, its moved segment (or the point where it vanished), its start's path back
        i = s_head[e]
        out[j] = pool[i]
        j += 1
        i = e_head[e]
        while i >= 0:
            out[j] = pool[i]
            j += 1
            i = link[i]
        out[j], out[j + 1] = final[e, 1], final[e, 0]
        j += 2
        n_back = 0
        i = link[s_head[e]]
        while i >= 0:
            back[n_back] = i
            n_back += 1
            i = link[i]
        for b in range(n_back - 1, -1, -1):
            out[j] = pool[back[b]]
            j += 1
        out_n[k] = j - first
    return collapsed, n_left, trusted, overtook


@njit(cache=True, nogil=True)
def swept_strips(start, end, inward, d, corner, ends, ring_offsets, step_cos):
    """The strips of the edges of rings (outer rings of faces), each the region its edge sweeps.

    start, end, inward (E, 2) float64: the edges, ring after ring (``ring_offsets`` (R+1,)), and their
    inward unit normals; d (E,): how far each moves in; corner (E, 2): where edge k's strip starts,
    relative to its start vertex, and ends (E, 2) where edge k-1's strip ends, relative to the same
    vertex (``geometry.setback_strips.mitres``); step_cos: the cosine of the turn under which neighbours moved
    by different distances that meet after an event step there. Returns the strips as ragged rings:
    coords (V, 2) and offsets (E+1,) (an edge that does not move has none); (R,) bool whether nothing is left of the
    ring's face; (R,) bool whether its wavefront met no split event it cannot follow; (R,) bool whether a
    moved line overtook a kept one (``_ring_strips``); and the
    wavefront's vertices at the end (W, 2), two per line, with their ring (W,) (where they lie outside
    the face, a split event was missed: the strips are not to be trusted either).
    """
    n_edges = len(d)
    n_rings = len(ring_offsets) - 1
    coords = np.empty((24 * n_edges + 8 * n_rings, 2))
    counts = np.zeros(n_edges, np.int64)
    collapsed = np.zeros(n_rings, np.bool_)
    trusted = np.zeros(n_rings, np.bool_)
    overtook = np.zeros(n_rings, np.bool_)
    left = np.empty((4 * n_edges, 2))
    left_ring = np.empty(4 * n_edges, np.int64)
    n_left = 0
    used = 0
    for r in range(n_rings):
        a, b = ring_offsets[r], ring_offsets[r + 1]
        collapsed[r], k, trusted[r], overtook[r] = _ring_strips(start[a:b], end[a:b], inward[a:b], d[a:b], corner[a:b],
                                                   ends[a:b], coords[used:], counts[a:b], left[n_left:],
                                                   step_cos)
        left_ring[n_left:n_left + k] = r
        n_left += k
        used += counts[a:b].sum()
    offsets = np.zeros(n_edges + 1, np.int64)
    for k in range(n_edges):
        offsets[k + 1] = offsets[k] + counts[k]
    return coords[:used], offsets, collapsed, trusted, overtook, left[:n_left], left_ring[:n_left]
