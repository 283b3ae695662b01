"""Where an offset that closes an arm leaves its vertex: on the arm's skeleton, as PRT's insets have it.

An arm narrower than twice an inward offset vanishes from the inset. Its two neighbouring edges, when they
lie on one line (a T's bar on either side of its stem), leave a vertex between their moved parts, on a
straight run. GEOS's mitred buffer puts that vertex where one of the arm's moved sides crosses the run;
PRT (a wavefront: the arm's sides meet along their bisector, the two reflex corners at the arm's root merge
there and the merged vertex moves straight on) puts it where the bisector of the arm's two side lines
crosses the run: on a straight stem's centre line (measured through PyPRT on massing's T lots: T.18003,
T.19073, T.19129, 0.5 to 1.6 m from GEOS's vertex). The vertex's place decides where the run's two edges
meet, so which part of it a per-edge setback moves by which edge's distance.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from grammarc.geometry.clip import open_rings, polygons_from_rings
from grammarc.ragged import offsets_from_counts

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
def _edge_of(ax, ay, bx, by, g, parent_coords, parent_rings, parent_offsets, distance, tolerance):
    """The edge of polygon g (its index among the parents' vertices: the outer ring's or a hole's) that the
    inset edge a -> b was moved in from (parallel, in its direction, ``distance`` inside it), the one whose
    span it overlaps most; -1 for none (an edge of no length, or one whose span it does not overlap)."""
    dx, dy = bx - ax, by - ay
    length = np.hypot(dx, dy)
    best, overlap = -1, tolerance
    if length <= tolerance:
        return best
    for q in range(parent_offsets[g], parent_offsets[g + 1]):
        q0, q1 = parent_rings[q], parent_rings[q + 1]
        n = q1 - q0
        for e in range(n):
            px, py = parent_coords[q0 + e, 0], parent_coords[q0 + e, 1]
            qx, qy = parent_coords[q0 + (e + 1) % n, 0], parent_coords[q0 + (e + 1) % n, 1]
            ex, ey = qx - px, qy - py
            span = np.hypot(ex, ey)
            if span <= tolerance:
                continue
            ux, uy = ex / span, ey / span
            if (dx * ux + dy * uy) < length * (1.0 - 1e-9):  # not parallel, or against it
                continue
            inside = ux * (ay - py) - uy * (ax - px)  # to the left of the edge: the polygon's side
            if abs(inside - distance) > tolerance:
                continue
            s0, s1 = (ax - px) * ux + (ay - py) * uy, (bx - px) * ux + (by - py) * uy
            shared = min(s1, span) - max(s0, 0.0)
            if shared > overlap:
                best, overlap = q0 + e, shared
    return best


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
def place_closed_arm_vertices(coords, ring_offsets, ring_poly, parent_coords, parent_rings, parent_offsets,
                              distance, tolerance):
    """The inset rings' coords (V, 2) (counter-clockwise outer rings, ``ring_poly`` (R,) their polygons, -1
    for holes) with the vertices between the moved parts of two edges on one line, an arm closed between
    them, made one vertex on the bisector of the arm's side lines (see the module), and which vertices
    stay (V,) bool (GEOS leaves a vertex where each moved side crossed the line, and repeats some);
    ``distance`` (G,) each polygon's inset distance, the parents' outer rings counter-clockwise, their
    holes clockwise. The two edges may lie on two holes (or a hole and the outline): the arm is then the
    channel between them, its sides the edges that follow the first and precede the second along their
    rings (PRT's inset of massing's holes.33739, whose holes' ends lie on one line)."""
    out = coords.copy()
    keep = np.ones(len(coords), np.bool_)
    for r in range(len(ring_offsets) - 1):
        g = ring_poly[r]
        if g < 0:
            continue
        r0, r1 = ring_offsets[r], ring_offsets[r + 1]
        m = r1 - r0
        source = np.empty(m, np.int64)  # the parent edge each inset edge was moved in from, -1 for none
        for k in range(m):
            a, b = r0 + k, r0 + (k + 1) % m
            source[k] = _edge_of(coords[a, 0], coords[a, 1], coords[b, 0], coords[b, 1], g, parent_coords,
                                 parent_rings, parent_offsets, distance[g], tolerance)
        for j in range(m):
            before = source[(j - 1) % m]
            if before < 0:
                continue
            # the run from vertex j over edges from no parent edge to the first from any one
            last = j
            while source[last % m] < 0 and last - j < m - 1:
                last += 1
            after = source[last % m]
            if after < 0:
                continue
            q0, n = _ring_at(before, g, parent_rings, parent_offsets)
            if after != before and q0 <= after < q0 + n and (after - before) % n < 3:
                continue  # no arm between the two (an arm has two sides and an end)
            p, w = r0 + (j - 1) % m, r0 + (last + 1) % m
            ax, ay = coords[p, 0], coords[p, 1]
            dx, dy = coords[w, 0] - ax, coords[w, 1] - ay
            length = np.hypot(dx, dy)
            if length <= tolerance:
                continue
            ux, uy = dx / length, dy / length
            straight = True
            for k in range(j, last + 1):
                v = r0 + k % m
                straight &= abs(ux * (coords[v, 1] - ay) - uy * (coords[v, 0] - ax)) <= tolerance
            if not straight:
                continue
            if after == before:
                # one moved edge that GEOS broke where grown holes' corners crossed it: one edge, as a
                # wavefront's front is
                for k in range(j, last + 1):
                    keep[r0 + k % m] = False
                continue
            s = _bisector_point(ax, ay, ux, uy, _along(before, 1, g, parent_rings, parent_offsets),
                                _along(after, -1, g, parent_rings, parent_offsets), g, parent_coords,
                                parent_rings, parent_offsets)
            if tolerance < s < length - tolerance:
                out[r0 + j, 0], out[r0 + j, 1] = ax + s * ux, ay + s * uy
                for k in range(j + 1, last + 1):
                    keep[r0 + k % m] = False
    return out, keep


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
    _, parent_flat, (parent_closed, parent_offsets) = shapely.to_ragged_array(parents)
    coords, ring_offsets = open_rings(np.asarray(flat)[:, :2], np.asarray(closed_rings, dtype=np.int64))
    parent_coords, parent_rings = open_rings(np.asarray(parent_flat)[:, :2],
                                             np.asarray(parent_closed, dtype=np.int64))
    part_offsets = np.asarray(part_offsets, dtype=np.int64)
    ring_poly = np.full(len(ring_offsets) - 1, -1, dtype=np.int64)
    ring_poly[part_offsets[:-1]] = part_row  # outer rings only: a hole's vertices stay
    parent_offsets = np.asarray(parent_offsets, dtype=np.int64)
    moved, keep = place_closed_arm_vertices(coords, ring_offsets, ring_poly, parent_coords, parent_rings,
                                            parent_offsets, distance[rows], TOLERANCE)
    if keep.all() and np.array_equal(moved, coords):
        return insets
    counts = np.add.reduceat(keep.astype(np.int64), ring_offsets[:-1]) if len(keep) else np.zeros(0, np.int64)
    rebuilt = polygons_from_rings(moved[keep], offsets_from_counts(counts), part_offsets)
    out = insets.copy()
    out[rows] = shapely.multipolygons(rebuilt, indices=part_row) if len(parts) != len(rows) or (
        shapely.get_type_id(insets[rows]) != shapely.GeometryType.POLYGON).any() else rebuilt
    return out
