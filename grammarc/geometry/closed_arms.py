"""Where an offset that closes an arm leaves its vertex: on the arm's skeleton, as PRT's insets have it.

An arm narrower than twice an inward offset vanishes from the inset. Its two neighbouring edges, when they
lie on one line (a T's bar on either side of its stem), leave a vertex between their moved parts, on a
straight run. GEOS's mitred buffer puts that vertex where one of the arm's moved sides crosses the run;
PRT (a wavefront: the arm's sides meet along their bisector, the two reflex corners at the arm's root merge
there and the merged vertex moves straight on) puts it where the bisector of the arm's two side lines
crosses the run: on a straight stem's centre line (measured through PyPRT on massing's T lots: T.18003,
T.19073, T.19129, 0.5 to 1.6 m from GEOS's vertex). The vertex's place decides where the run's two edges
meet, so which part of it a per-edge setback moves by which edge's distance.

A run is taken whole: the parent edges whose moved copies lie on it, in their order along it, give its
vertices (one per arm closed between two of them), whatever GEOS left there, none included (an H's leg
whose bar closed: massing's H.57370 59 km away). GEOS's vertices on such a run depend on the rounding of
the coordinates (a lot moved 2 km away had others), the run's do not.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from grammarc.geometry.clip import open_rings, polygons_from_rings
from grammarc.ragged import grow, offsets_from_counts

#: How far (scope units, metres) a vertex may lie off its run, or an edge off its moved line.
TOLERANCE = 1e-6


@njit(cache=True, nogil=True)
def _ring_at(edge, g, parent_rings, parent_offsets):
    """The first vertex and the length of the ring of polygon g that holds the vertex (edge) ``edge``."""
    for q in range(parent_offsets[g], parent_offsets[g + 1]):
        if parent_rings[q] <= edge < parent_rings[q + 1]:
            return parent_rings[q], parent_rings[q + 1] - parent_rings[q]
    return edge, 1


@njit(cache=True, nogil=True)
def _along(edge, step, g, parent_rings, parent_offsets):
    """The edge ``step`` edges on from ``edge`` (indices into the parents' vertices) along its ring."""
    q0, n = _ring_at(edge, g, parent_rings, parent_offsets)
    return q0 + (edge - q0 + step) % n


@njit(cache=True, nogil=True)
def _bisector_point(ax, ay, ux, uy, side_a, side_b, g, parent_coords, parent_rings, parent_offsets):
    """The parameter s of the point a + s u equidistant from the lines of the parents' edges ``side_a``
    and ``side_b`` of polygon g (distances to their left), NaN where no such point is."""
    terms = np.empty(4)
    for k, e in enumerate((side_a, side_b)):
        px, py = parent_coords[e, 0], parent_coords[e, 1]
        nxt = _along(e, 1, g, parent_rings, parent_offsets)
        ex = parent_coords[nxt, 0] - px
        ey = parent_coords[nxt, 1] - py
        span = np.hypot(ex, ey)
        terms[2 * k] = (ex * (ay - py) - ey * (ax - px)) / span
        terms[2 * k + 1] = (ex * uy - ey * ux) / span
    slope = terms[1] - terms[3]
    if abs(slope) < 1e-12:
        return np.nan
    return (terms[2] - terms[0]) / slope


@njit(cache=True, nogil=True)
def _unit(parent_coords, a, b):
    """The unit direction from parent vertex a to b, and the length between them."""
    ex, ey = parent_coords[b, 0] - parent_coords[a, 0], parent_coords[b, 1] - parent_coords[a, 1]
    span = np.hypot(ex, ey)
    if span <= 0.0:
        return 0.0, 0.0, 0.0
    return ex / span, ey / span, span


@njit(cache=True, nogil=True)
def _run_vertices(ax, ay, ux, uy, length, g, parent_coords, parent_rings, parent_offsets, distance, tolerance):
    """Where (parameters s along a + s u, ascending, 0 < s < length) the straight run from a moved in by
    ``distance`` keeps vertices: between each two parent edges of polygon g that it runs along (those
    whose moved, mitred copies lie on it), taken in their order along it, the point where the arm between
    them closed (on the bisector of its side lines), or the moved vertex they share. None where no parent
    edge lies on the run's line (the run is not a moved edge's)."""
    first, last = parent_rings[parent_offsets[g]], parent_rings[parent_offsets[g + 1]]
    edges = np.empty(last - first, np.int64)
    starts = np.empty(last - first)
    k = 0
    for q in range(parent_offsets[g], parent_offsets[g + 1]):
        q0, n = parent_rings[q], parent_rings[q + 1] - parent_rings[q]
        for e in range(n):
            here, after, before = q0 + e, q0 + (e + 1) % n, q0 + (e - 1) % n
            tx, ty, span = _unit(parent_coords, here, after)
            if span <= tolerance or tx * ux + ty * uy < 1.0 - 1e-9:  # not parallel, or against the run
                continue
            px, py = parent_coords[here, 0], parent_coords[here, 1]
            if abs(tx * (ay - py) - ty * (ax - px) - distance) > tolerance:  # the run is not its moved line
                continue
            s0 = (px - ax) * ux + (py - ay) * uy
            # the moved copy's ends, where its neighbours' moved lines meet it (reflex corners reach further)
            reach = np.empty(2)
            for end, (a, b) in enumerate(((before, here), (after, (e + 2) % n + q0))):
                nx, ny, nspan = _unit(parent_coords, a, b)
                cosine = nx * tx + ny * ty
                sine = ny * ux - nx * uy if end == 0 else nx * uy - ny * ux  # the neighbour's normal along u
                reach[end] = distance * sine / (1.0 + cosine) if nspan > 0.0 and 1.0 + cosine > 1e-9 else 0.0
            if min(s0 + span + reach[1], length) - max(s0 - reach[0], 0.0) <= tolerance:
                continue
            edges[k], starts[k] = here, s0
            k += 1
    if k == 0:
        return None
    order = np.argsort(starts[:k], kind="mergesort")
    out = np.empty(max(k - 1, 0))
    n_out = 0
    for i in range(k - 1):
        a, b = edges[order[i]], edges[order[i + 1]]
        if _along(a, 1, g, parent_rings, parent_offsets) == b:  # one ring's edges on one line: their vertex
            s = (parent_coords[b, 0] - ax) * ux + (parent_coords[b, 1] - ay) * uy
        else:
            s = _bisector_point(ax, ay, ux, uy, _along(a, 1, g, parent_rings, parent_offsets),
                                _along(b, -1, g, parent_rings, parent_offsets), g, parent_coords, parent_rings,
                                parent_offsets)
        if tolerance < s < length - tolerance and (n_out == 0 or s > out[n_out - 1] + tolerance):
            out[n_out] = s
            n_out += 1
    return out[:n_out]


@njit(cache=True, nogil=True)
def _straight(coords, r0, m, k, tolerance):
    """Whether vertex k of the ring at r0 (m vertices) lies on the segment between its neighbours."""
    p, v, w = r0 + (k - 1) % m, r0 + k, r0 + (k + 1) % m
    cx, cy = coords[w, 0] - coords[p, 0], coords[w, 1] - coords[p, 1]
    chord = np.hypot(cx, cy)
    if chord <= tolerance:
        return False
    vx, vy = coords[v, 0] - coords[p, 0], coords[v, 1] - coords[p, 1]
    along = (vx * cx + vy * cy) / chord
    return abs(cx * vy - cy * vx) / chord <= tolerance and -tolerance <= along <= chord + tolerance


@njit(cache=True, nogil=True)
def _push(out, n, x, y):
    """``out`` with (x, y) at row n, grown where full (``ragged.grow``)."""
    out = grow(out, n + 1)
    out[n, 0], out[n, 1] = x, y
    return out


@njit(cache=True, nogil=True)
def place_closed_arm_vertices(coords, ring_offsets, ring_poly, parent_coords, parent_rings, parent_offsets,
                              distance, tolerance):
    """The inset rings' coords (V', 2) and their counts (R,), the straight runs of the outer rings (their
    polygons ``ring_poly`` (R,), -1 for holes, which stay) along moved parent edges given the vertices a
    wavefront leaves there (``_run_vertices``) in place of GEOS's (V, 2) (which leaves one where each
    moved side of a closed arm crossed the run, where grown holes' corners cross it, repeats some, or
    leaves none: vertices that depend on rounding, and on where the lot lies); and whether any ring
    changed.
    ``distance`` (G,) each polygon's inset distance, the parents' outer rings counter-clockwise, their
    holes clockwise. The parent edges along a run may lie on holes (or a hole and the outline): a channel
    between them closed as an arm does (PRT's inset of massing's holes.33739, whose holes' ends lie on one
    line)."""
    out = np.empty((len(coords) + 8, 2))
    counts = np.zeros(len(ring_offsets) - 1, np.int64)
    n = 0
    changed = False
    for r in range(len(ring_offsets) - 1):
        r0, m, g = ring_offsets[r], ring_offsets[r + 1] - ring_offsets[r], ring_poly[r]
        straight = np.zeros(m, np.bool_)
        if g >= 0 and m >= 4:
            for k in range(m):
                straight[k] = _straight(coords, r0, m, k, tolerance)
        if g < 0 or m < 4 or straight.all():
            for k in range(m):
                out = _push(out, n, coords[r0 + k, 0], coords[r0 + k, 1])
                n += 1
            counts[r] = m
            continue
        k0 = np.flatnonzero(~straight)[0]
        begun = n
        t = 0
        while t < m:
            k = (k0 + t) % m
            if not straight[k]:
                out = _push(out, n, coords[r0 + k, 0], coords[r0 + k, 1])
                n += 1
                t += 1
                w = (k0 + t) % m
                if not straight[w]:  # a run of one edge, where GEOS left no vertex of a closed arm
                    ax, ay = coords[r0 + k, 0], coords[r0 + k, 1]
                    length = np.hypot(coords[r0 + w, 0] - ax, coords[r0 + w, 1] - ay)
                    if length > tolerance:
                        ux, uy = (coords[r0 + w, 0] - ax) / length, (coords[r0 + w, 1] - ay) / length
                        kept = _run_vertices(ax, ay, ux, uy, length, g, parent_coords, parent_rings,
                                             parent_offsets, distance[g], tolerance)
                        if kept is not None and len(kept):
                            changed = True
                            for s in kept:
                                out = _push(out, n, ax + s * ux, ay + s * uy)
                                n += 1
                continue
            t_end = t
            while straight[(k0 + t_end) % m]:
                t_end += 1
            p, w = r0 + (k0 + t - 1) % m, r0 + (k0 + t_end) % m
            ax, ay = coords[p, 0], coords[p, 1]
            dx, dy = coords[w, 0] - ax, coords[w, 1] - ay
            length = np.hypot(dx, dy)
            ux, uy = dx / length, dy / length
            on_line = True
            for i in range(t, t_end):
                v = r0 + (k0 + i) % m
                on_line &= abs(ux * (coords[v, 1] - ay) - uy * (coords[v, 0] - ax)) <= tolerance
            kept = _run_vertices(ax, ay, ux, uy, length, g, parent_coords, parent_rings, parent_offsets,
                                 distance[g], tolerance) if on_line else None
            if kept is None:
                for i in range(t, t_end):
                    v = r0 + (k0 + i) % m
                    out = _push(out, n, coords[v, 0], coords[v, 1])
                    n += 1
            else:
                changed = True
                for s in kept:
                    out = _push(out, n, ax + s * ux, ay + s * uy)
                    n += 1
            t = t_end
        counts[r] = n - begun
    return out[:n], counts, changed


def closed_arm_insets(insets: np.ndarray, polygons: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """The insets (k,) (shapely polygons or multipolygons) of ``polygons`` (k,) moved in by ``distance`` (k,)
    (positive inward), with the vertices that closed arms leave on straight runs where PRT leaves them."""
    rows = np.flatnonzero((distance > 0) & ~shapely.is_empty(insets))
    if not len(rows):
        return insets
    parts, part_row = shapely.get_parts(insets[rows], return_index=True)
    parts = shapely.orient_polygons(parts, exterior_cw=False)
    parents = shapely.orient_polygons(polygons[rows], exterior_cw=False)
    _, flat, (closed_rings, part_offsets) = shapely.to_ragged_array(parts)
    # a face offset as its valid parts is a multipolygon (``offsets._offset_regions``): its rings are
    # those of all its parts
    _, parent_flat, (parent_closed, *parent_parts) = shapely.to_ragged_array(parents)
    parent_offsets = parent_parts[0] if len(parent_parts) == 1 else parent_parts[0][parent_parts[1]]
    coords, ring_offsets = open_rings(np.asarray(flat)[:, :2], np.asarray(closed_rings, dtype=np.int64))
    parent_coords, parent_rings = open_rings(np.asarray(parent_flat)[:, :2],
                                             np.asarray(parent_closed, dtype=np.int64))
    part_offsets = np.asarray(part_offsets, dtype=np.int64)
    ring_poly = np.full(len(ring_offsets) - 1, -1, dtype=np.int64)
    ring_poly[part_offsets[:-1]] = part_row  # outer rings only: a hole's vertices stay
    parent_offsets = np.asarray(parent_offsets, dtype=np.int64)
    placed, counts, changed = place_closed_arm_vertices(coords, ring_offsets, ring_poly, parent_coords,
                                                        parent_rings, parent_offsets, distance[rows], TOLERANCE)
    if not changed:
        return insets
    rebuilt = polygons_from_rings(placed, offsets_from_counts(counts), part_offsets)
    out = insets.copy()
    out[rows] = shapely.multipolygons(rebuilt, indices=part_row) if len(parts) != len(rows) or (
        shapely.get_type_id(insets[rows]) != shapely.GeometryType.POLYGON).any() else rebuilt
    return out
