"""Setbacks of polygon edges: CityEngine's ``setback``, ``shapeL``, ``shapeU`` and ``shapeO``.

Each edge moves into the polygon by its own distance (0 keeps it). The strip it sweeps is the quad
between the edge and its moved copy, whose ends are the mitre points where the moved lines of
neighbouring edges meet: a strip stops at an unmoved neighbour's line, and two moved neighbours share their
corner, as in CityEngine; where the boundary turns by less than 15 degrees between edges moved by
different distances (one of them 0, or not), each strip ends at its own distance's mitre point instead
and the remainder steps across at the vertex. An edge whose quad folds over itself (a distance longer than
the edge allows) between two parallel neighbours, one moved and one kept, does not move (``_unfolded``);
another folded quad is cut to the triangle of its edge and its end lines, as a straight skeleton's face
ends; the folded edge then vanishes and its neighbours' moved lines meet, the edges of the face's outline
swept as a wavefront (``geometry.wavefront``; a hole stays, the strips are clipped to it). The strips of each owner (a
selector of the operation) are united and clipped to the polygon; an edge belongs to the first owner that
claims it, and the remainder is what no strip covers. All of it runs on whole batches: numpy over the
ragged edges, GEOS over arrays of quads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.geometry.meshes import ring_vector_areas
from grammarc.geometry.wavefront import swept_strips
from grammarc.ragged import offsets_from_counts, rank_within

#: A mitre longer than this many setback distances (a near-reversal of the boundary) is cut to the
#: edge's rectangle.
_MITRE_LIMIT = 10.0
#: The turn (degrees) of the boundary below which edges moved by different distances step (``_mitres``)
#: at a convex vertex, and at a reflex one: measured through PyPRT, 14.99 steps and 15.01 meets at a convex
#: vertex; 44.5 and 45 step and 45.5 meets at a reflex one, whatever the distances (2, 4 and 8 m).
_STEP_TURN = 15.0
_REFLEX_STEP_TURN = 45.0
#: The turn (degrees) from a kept edge's line past its reflex end under which the bisector ray there cuts no
#: strip short (``_short_of_reflex_ends``): measured through PyPRT, 0.249 cuts nothing and 0.2505 cuts,
#: beside parallel edges and beside edges turned 14 degrees from each other alike.
_RAY_TURN = 0.25
#: The turn (degrees) past a kept edge under which a moved line that passes its far end sweeps on
#: (``setback_regions``): measured between 20 (sweeps on) and 90 (stops). Past a convex far end the moved
#: line sweeps on also where the edge beyond turns from the moved edge by more than ``Tol.parallel`` and at
#: most this (a jog's 5 to 40 degrees sweep on; 65 degrees stops).
_RUN_ON_TURN = 45.0
#: The grid (scope units, metres) that setback regions are snapped to, collapsing zero-width spikes.
_SNAP = 1e-9
#: The most steps ``distances_to_area`` takes for one polygon.
_AREA_STEPS = 64


@dataclass(frozen=True)
class Edges:
    """The boundary edges of m polygons: ``start``, ``end`` (E, 2); ``inward`` (E, 2) unit normals
    pointing into the polygon; ``poly`` (E,) the polygon of each edge; ``prev``, ``next`` (E,) the
    neighbouring edges along the same ring; ``vertex`` (E,) each one's start among the vertices of the
    polygons' open rings, all rings one after the other (as ``shapely.to_ragged_array`` lists them);
    ``hole`` (E,) whether the edge lies on a hole."""

    start: np.ndarray
    end: np.ndarray
    inward: np.ndarray
    poly: np.ndarray
    prev: np.ndarray
    next: np.ndarray
    vertex: np.ndarray
    hole: np.ndarray


def polygon_edges(polygons: np.ndarray) -> Edges:
    """The edges of shapely polygons (m,), exterior rings and holes, zero-length edges dropped."""
    rings, ring_poly = shapely.get_rings(polygons, return_index=True)
    hole = np.r_[False, ring_poly[1:] == ring_poly[:-1]] if len(rings) else np.zeros(0, dtype=bool)
    points, point_ring = shapely.get_coordinates(rings, return_index=True)
    last = np.r_[point_ring[1:] != point_ring[:-1], True] if len(points) else np.zeros(0, dtype=bool)
    first = np.flatnonzero(~last)
    step = points[first + 1] - points[first]
    length = np.hypot(step[:, 0], step[:, 1])
    first = first[length > TOL.zero]
    start, end, ring = points[first], points[first + 1], point_ring[first]
    step = end - start
    tangent = step / np.hypot(step[:, 0], step[:, 1])[:, None]
    signed_area = np.bincount(ring, weights=start[:, 0] * end[:, 1] - end[:, 0] * start[:, 1],
                              minlength=len(rings))
    left = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
    # the interior lies left of a counter-clockwise exterior ring and right of a counter-clockwise hole
    inward = np.where(((signed_area[ring] > 0) != hole[ring])[:, None], left, -left)
    counts = np.bincount(ring, minlength=len(rings))
    offsets = offsets_from_counts(counts)
    local = np.arange(len(ring)) - offsets[ring]
    size = np.maximum(counts[ring], 1)
    return Edges(start, end, inward, ring_poly[ring], offsets[ring] + (local - 1) % size,
                 offsets[ring] + (local + 1) % size, first - ring, hole[ring])


def setback_regions(polygons: np.ndarray, edges: Edges, distance: np.ndarray, owner: np.ndarray,
                    n_owners: int) -> tuple[list[np.ndarray], np.ndarray]:
    """The regions (n_owners lists of (m,) geometries) the edges' strips cover, and the remainder (m,).

    distance (E,): how far each edge moves in; owner (E,): the owner of its strip (n_owners for none).
    """
    m = len(polygons)
    # a distance that is not a number (``float("")`` of a missing list item) moves nothing
    d = _unfolded(edges, np.where((owner < n_owners) & np.isfinite(distance), np.maximum(distance, 0.0), 0.0))
    # the strips mitred at reflex vertices (``quads``) and stepped there too (``stepped``), as PRT's are
    corner, _, end_corner, idx, quads = _quads(edges, d, reflex_steps=False)
    stepped_corner, stepped_ends, _, _, stepped = _quads(edges, d)
    moved = d > TOL.zero
    strips, folded = _strips(quads)
    stepped_strips, stepped_folded = _strips(stepped)
    group = owner[idx] * m + edges.poly[idx]
    # a face whose stepped strips fold, or where a moved edge's line passes a kept neighbour's far end (the
    # kept edge's segment turns over: PRT's tiers on massing's near_degenerate.34258 and 34006 run on past a
    # short kept edge): its strips swept by its outline's edges as a wavefront (holes do not move). (A strip
    # that folds mitred but not stepped does not fold: PRT's terrace on lots whose edge, 2 to 4 m long and
    # set back 3 or 4 m, runs from an acute corner's kept edge to a reflex vertex of 25 or 40 degrees is the
    # stepped quad, measured through PyPRT; massing.concave.44289's and 50043's first tiers.)
    swept = np.zeros(m, dtype=bool)
    swept[edges.poly[idx[stepped_folded]]] = True
    tangent = edges.end - edges.start
    span = np.einsum("ij,ij->i", tangent + end_corner - corner, tangent)
    # (where the boundary runs on past it turned by less than ``_RUN_ON_TURN``: 1 degree on 34258, 20 on
    # concave.46141, or turns away from the face, at a reflex vertex, and runs on back the way the moved line
    # goes: PRT's tier on a block whose kept 1.1 m foot of a bump the bump's side set back 2 or 4 m passes,
    # measured through PyPRT, and on massing.concave.50953, not on far.51343, whose boundary runs away; past
    # a convex corner too, but for one whose edge beyond runs parallel to the moved edge, where the moved
    # line stops at the kept edge's line, as PRT's tier on the real lot massing.hiroshima.111, whose shapeL
    # arm it keeps: 4.71 m^2; a 1.3 m kept jog whose edge beyond turns 5 to 40 degrees from the moved edge,
    # 50 to 85 past the jog, is swept in PRT: concave.43589's first tier; nor does a kept edge between two
    # moved ones start it, whose moved lines cross its line the other way round: massing.concave.50323's
    # first tier, PRT's terrace the union of the strips)
    other = np.where(moved[edges.prev], edges.next, edges.prev)
    mover = np.where(moved[edges.prev], edges.prev, edges.next)
    beyond = np.where(moved[edges.prev][:, None], tangent[edges.next], -tangent[edges.prev])  # (from that end)
    far_reflex = np.where(moved[edges.prev], np.einsum("ij,ij->i", tangent[edges.next], edges.inward),
                          np.einsum("ij,ij->i", tangent, edges.inward[edges.prev])) < 0
    reflex_end = far_reflex & (np.einsum("ij,ij->i", beyond, edges.inward[mover]) > 0)
    # (the edge beyond turned from the moved edge by more than ``Tol.parallel`` and at most
    # ``_RUN_ON_TURN``: the jog's 5 to 40 degrees sweep; a 6 m kept edge whose edge beyond turns 65 degrees
    # from the moved one does not, PRT's terrace being the stepped quad there, 33.610 m^2, measured through
    # PyPRT)
    turn = np.abs(_cosines(tangent[other], tangent[mover]))
    across = (turn < np.cos(np.radians(TOL.parallel))) & (turn >= np.cos(np.radians(_RUN_ON_TURN)))
    turned_over = ~moved & ~edges.hole & (moved[edges.prev] != moved[edges.next]) & (
        span < -TOL.zero * np.einsum("ij,ij->i", tangent, tangent)) & (
        reflex_end | (~far_reflex & across) | (_cosines(tangent, tangent[other]) > np.cos(np.radians(_RUN_ON_TURN))))
    passed = np.zeros(m, dtype=bool)
    passed[edges.poly[turned_over]] = True
    swept |= passed
    strips = _reflex_strips(edges, swept, strips, idx, quads, stepped, stepped_strips)
    strips = _short_of_reflex_ends(edges, d, strips, idx, _chosen_quads(edges, swept, idx, quads, stepped))
    if swept.any():
        # a swept face's wavefront steps at reflex vertices too, but for those of an edge whose strip folds
        # mitred and not stepped in a face that a moved line passes a kept edge of (it vanishes there: a
        # replay lot's first tier, whose folded edge set back 4 m turns by 40 degrees at a reflex vertex;
        # PRT's front runs on past it as the mitres'); a face swept only because a strip folds steps there
        # (massing.convex.43938's second tier, 15 degrees; concave.50953's first, 25: PRT's fronts step as
        # the edge's lone strip); one whose stepped strip folds too vanishes on the stepped lines (PRT's
        # terrace on a 2 m edge set back 3 m from an acute corner's kept edge to a 25-degree reflex vertex:
        # the triangle of its stepped lines, measured through PyPRT)
        folding = np.zeros(len(d), dtype=bool)
        folding[idx[folded & ~stepped_folded]] = True
        keep = ((folding | folding[edges.prev]) & passed[edges.poly])[:, None]
        _, convex_ends, _ = _mitres(edges, d, reflex_steps=False)
        strips, group = _swept(polygons, edges, d, np.where(keep, corner, stepped_corner),
                               np.where(keep, convex_ends, stepped_ends), owner, swept, strips, group, idx)
    united = _polygonal(union_by_group(strips, group, n_owners * m)).reshape(n_owners, m)
    regions, covered = [], np.full(m, shapely.Polygon(), dtype=object)
    # overlaid on the regions' grid (snap rounding): in floating point GEOS cuts off a face's vertex that
    # rounding left 1e-14 m outside the strip along its edge (a lot moved 2 km away, massing's holes.43809:
    # its tier numbered the face's edges otherwise, 316 faces for 346)
    for k in range(n_owners):
        inside = _polygonal(shapely.intersection(polygons, united[k], grid_size=_SNAP))
        # (the first owner's region is all it covers: two overlays fewer for the most common setbacks)
        region = inside if k == 0 else _polygonal(shapely.difference(inside, covered, grid_size=_SNAP))
        regions.append(_without_seams(_without_spikes(region), polygons))
        covered = region if k == 0 else shapely.union(covered, region, grid_size=_SNAP)
    return regions, _without_spikes(shapely.difference(polygons, covered, grid_size=_SNAP))


def _polygonal(geometries: np.ndarray) -> np.ndarray:
    """Geometries (k,) without the lines and points an overlay leaves where areas touch: GEOS's snap rounding
    takes no input of mixed dimension (it raised on a strip region that touched its face along a line)."""
    parts, row = shapely.get_parts(geometries, return_index=True)
    areal = shapely.get_type_id(parts) == shapely.GeometryType.POLYGON
    if areal.all():
        return geometries
    out = geometries.copy()
    touched = np.unique(row[~areal])
    out[touched] = shapely.Polygon()
    mine = areal & np.isin(row, touched)
    kept = np.unique(row[mine])
    out[kept] = shapely.multipolygons(parts[mine], indices=np.searchsorted(kept, row[mine]))
    return out


def _strips(quads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The strips (k,) of quads (k, 4, 2): each quad, or where it folds over itself (k,) its triangle
    (``_folded_strips``)."""
    strips = shapely.polygons(quads) if len(quads) else np.empty(0, dtype=object)
    folded = ~shapely.is_valid(strips)
    if folded.any():
        strips[folded] = _folded_strips(quads[folded])
    return strips, folded


def _reflex_strips(edges: Edges, swept: np.ndarray, strips: np.ndarray, idx: np.ndarray, quads: np.ndarray,
                   stepped: np.ndarray, stepped_strips: np.ndarray) -> np.ndarray:
    """The strips (k,) of the moved edges ``idx`` (k,), those of the faces not ``swept`` (m,) the
    ``stepped_strips`` (k,) of the quads ``stepped`` (k, 4, 2) that step at reflex vertices too
    (``_stepping``) where they differ from ``quads`` (k, 4, 2), which step at convex ones alone."""
    changed = ~swept[edges.poly[idx]] & np.any(stepped != quads, axis=(1, 2))
    return np.where(changed, stepped_strips, strips)


def _chosen_quads(edges: Edges, swept: np.ndarray, idx: np.ndarray, quads: np.ndarray,
                  stepped: np.ndarray) -> np.ndarray:
    """The quads (k, 4, 2) of the strips ``_reflex_strips`` chose: ``stepped`` but in the faces ``swept``."""
    return np.where(swept[edges.poly[idx]][:, None, None], quads, stepped)


def _short_of_reflex_ends(edges: Edges, d: np.ndarray, strips: np.ndarray, idx: np.ndarray,
                          quads: np.ndarray) -> np.ndarray:
    """The strips (k,) of the moved edges ``idx`` (k,), their quads (k, 4, 2), each cut short where its side
    along a kept neighbour's line runs past that neighbour's far end, a reflex vertex whose other edge moves:
    there the strip stops at the ray from that vertex along the bisector of its own edge and the edge beyond
    (the sum of their inward normals, whatever their distances), and the triangle between the ray and the
    kept edge's line is the remainder's, reaching the outline at the vertex: the two strips, which touched
    along the kept edge's line, are two faces. Measured through PyPRT on massing's tiers and shapeL: an edge
    set back 7.5 m whose kept neighbour's line, turned 79 degrees at the reflex vertex, it passes by 2.5 m
    loses that triangle, 0.625 m^2 beside an edge parallel to it, and its ray turns 7 degrees with an edge
    beyond turned 14 from it, set back 5 or 7.5 m; a ray turned from the line by ``_RAY_TURN`` or less (or
    to the other side, at a turn of 90 degrees or more) cuts nothing, whatever the distances (6 to 14 m).
    Only where the two edges, met at one vertex, would turn from each other by under ``_STEP_TURN`` into the
    face, as two edges step there (``_mitres``; 14.98 degrees cuts and 15.04 does not, whether the strip's
    edge is parallel to the kept edge's neighbour or turned 14 degrees from it), or turn away from it (15
    to 57 degrees cut, measured likewise).
    Real lots: massing.brno.44's shapeU, a 1.3 m kept edge between two arms set back 1.5 m, whose ray
    turns 1.4 degrees from it: PRT's faces of 27.43 and 8.69 m^2; kunming.47's shapeL, three faces."""
    moved = d > TOL.zero
    tangent = edges.end - edges.start
    unit = tangent / np.maximum(np.hypot(tangent[:, 0], tangent[:, 1]), TOL.zero)[:, None]
    slack = TOL.zero * np.maximum(np.abs(edges.start).max(axis=1, initial=0.0), 1.0)
    out = strips
    # the strip's start side, along its previous edge (``kept``), whose start is the vertex; its end side,
    # along its next edge, whose end is the vertex
    for kept, corner, ahead in ((edges.prev[idx], quads[:, 3], False), (edges.next[idx], quads[:, 2], True)):
        beyond = edges.next[kept] if ahead else edges.prev[kept]
        vertex = edges.end[kept] if ahead else edges.start[kept]
        reflex = np.einsum("ij,ij->i", unit[beyond] if ahead else unit[kept],
                           edges.inward[kept] if ahead else edges.inward[beyond]) < 0
        along = np.einsum("ij,ij->i", corner - vertex, unit[kept])
        past = along > slack[kept] if ahead else along < -slack[kept]
        ray = edges.inward[idx] + edges.inward[beyond]
        reach = np.hypot(ray[:, 0], ray[:, 1])
        into = np.einsum("ij,ij->i", ray, edges.inward[kept]) > np.sin(np.radians(_RAY_TURN)) * reach
        # where the ray meets the strip's moved line: (vertex + s ray - start) . inward = d
        toward = np.einsum("ij,ij->i", ray, edges.inward[idx])
        s = (d[idx] - np.einsum("ij,ij->i", vertex - edges.start[idx], edges.inward[idx])) / np.where(
            toward > 0, toward, 1.0)
        # (the edge beyond turned from the strip's edge by under ``_STEP_TURN`` where, met at one vertex, the
        # two would make a convex corner, by any angle where a reflex one)
        away = np.einsum("ij,ij->i", tangent[beyond] if ahead else tangent[idx],
                         edges.inward[idx] if ahead else edges.inward[beyond]) < 0
        stepping = away | (_cosines(tangent[idx], tangent[beyond]) > np.cos(np.radians(_STEP_TURN)))
        rows = np.flatnonzero(~moved[kept] & ~edges.hole[kept] & moved[beyond] & (beyond != idx) & reflex
                              & past & into & stepping & (toward > 0) & (s > 0))
        if len(rows):
            triangles = shapely.polygons(np.stack([vertex[rows], corner[rows],
                                                   vertex[rows] + s[rows, None] * ray[rows]], axis=1))
            out = out.copy() if out is strips else out
            out[rows] = shapely.difference(out[rows], triangles)
    return out


def _swept(polygons: np.ndarray, edges: Edges, d, corner, ends, owner, swept, strips, group, idx):
    """The strips (k,) of the moved edges ``idx`` (k,) and their groups (owner * m + polygon), those of the
    polygons ``swept`` (m,) bool replaced by the regions their edges sweep as a wavefront
    (``geometry.wavefront``: their outer rings; holes stay); a polygon of which nothing is left goes whole
    to the owner of its furthest-moved edge (what no strip reaches of it is no remainder either). A
    wavefront that ends outside its outline or crossing itself, but for one turned inside out, missed a
    split event (an arm that closed parts it): that polygon keeps its strips."""
    m = len(polygons)
    faces = np.flatnonzero(swept)
    rows = np.flatnonzero(swept[edges.poly] & ~edges.hole)  # (their outer rings, one after the other)
    ring_offsets = offsets_from_counts(np.bincount(edges.poly[rows], minlength=m)[faces])
    coords, offsets, collapsed, followed, overtook, left, left_ring = swept_strips(
        edges.start[rows], edges.end[rows], edges.inward[rows], d[rows], corner[rows], ends[rows], ring_offsets,
        np.cos(np.radians(_STEP_TURN)))
    scale = max(float(np.abs(edges.start[rows]).max(initial=1.0)), 1.0)
    outlines = shapely.get_exterior_ring(polygons[faces])
    outside = shapely.distance(shapely.points(left), shapely.polygons(outlines)[left_ring]) > 1e-9 * scale
    # a wavefront that ends wound against its outline (or flat), simple or passed out of its face, turned
    # inside out past an event it did not see, the face closing between two edge events: its strips cover
    # the face (but for slivers: PRT's terraces on massing's convex.33448 and acute.33595, and a third tier
    # on concave.33925's 1.5e-5 m^2), where the folded quads left up to 2.4 m^2; one that ends outside its
    # face otherwise, or crosses itself inside it, missed a split event
    n = len(faces)
    out, crossed, has_front = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    out[left_ring[outside]] = True
    ends_as, dense = np.unique(left_ring, return_inverse=True)
    front = shapely.linearrings(left, indices=dense)
    has_front[ends_as] = True
    crossed[ends_as] = ~shapely.is_simple(front)
    # twice the signed area of each front: its winding, positive counter-clockwise (not GEOS's ``is_ccw``,
    # which looks at one vertex of a ring that may cross itself)
    fronts = offsets_from_counts(np.bincount(left_ring, minlength=n))
    winding = 2 * ring_vector_areas(np.column_stack([left, np.zeros(len(left))]), fronts)[:, 2]
    turned = np.zeros(n, dtype=bool)
    turned[ends_as] = (winding[ends_as] > 0) != shapely.is_ccw(outlines[ends_as])
    turned |= np.abs(winding) <= 1e-12 * scale * scale
    turned &= (~crossed | out) & has_front
    # a front that crosses itself inside its face is followed, its strips clipped to the face making the
    # pieces: where a moved line passed kept ones (a reflex corner of kept edges, where the moved line parts
    # the face: a split event), as PRT's tier on massing's concave.43897 (an edge set back 4 m past a
    # reflex corner of kept edges, 2.8 m beyond it: PRT keeps the two pieces beyond the moved line), and
    # where moved lines cross each other, as on a face narrower than its distances (PRT's terrace on
    # massing's concave.44289, a 0.5 m wide shapeO ring whose outer edges are set back 3 m: 13.731 m^2,
    # measured through PyPRT; concave.30589 and 57225's tiers); not one where a moved line overtook a kept
    # edge with its normal and swept on past it (the wall of massing's H.43552, a 0.77 m stem that PRT's
    # second tier keeps)
    passed = crossed & ~out & ~overtook
    trusted = np.zeros(m, dtype=bool)
    trusted[faces] = turned | (followed & ~out & (~crossed | passed))
    swept = swept & trusted
    has = (np.diff(offsets) > 0) & swept[edges.poly[rows]]
    counts = np.diff(offsets)
    vertex_edge = np.repeat(np.arange(len(rows)), counts)
    mine = has[vertex_edge]
    made = _without_flat_parts(shapely.make_valid(shapely.polygons(shapely.linearrings(
        coords[mine], indices=np.cumsum(has)[vertex_edge[mine]] - 1))))
    made_group = owner[rows[has]] * m + edges.poly[rows[has]]
    gone = faces[collapsed & swept[faces]]
    if len(gone):
        sub = rows[np.isin(edges.poly[rows], gone)]
        order = np.lexsort((-d[sub], edges.poly[sub]))
        furthest = sub[order][np.r_[True, np.diff(edges.poly[sub][order]) != 0]]
        made = np.concatenate([made, polygons[gone]])
        made_group = np.concatenate([made_group, owner[furthest] * m + gone])
    kept = ~swept[edges.poly[idx]] | edges.hole[idx]  # (a moved hole edge keeps its strip)
    return np.concatenate([strips[kept], made]), np.concatenate([group[kept], made_group])


def _without_flat_parts(geometries: np.ndarray) -> np.ndarray:
    """Swept strips (k,) without the parts of no area that ``make_valid`` keeps of a path passing one point
    more than once (an event's point): GEOS's union of the strips then dropped a whole neighbouring strip
    (massing's far.43727: a 102.7 m^2 strip lost beside a part of 7.9e-31 m^2, and a remainder left where
    PRT's shapeU covers its face)."""
    parts, row = shapely.get_parts(geometries, return_index=True)
    flat = shapely.area(parts) <= TOL.zero * TOL.zero
    if not flat.any():
        return geometries
    rows, dense = np.unique(row, return_inverse=True)
    touched = np.zeros(len(rows), dtype=bool)
    touched[dense[flat]] = True
    keep = ~flat & touched[dense]
    out = geometries.copy()
    out[rows[touched]] = union_by_group(parts[keep], np.searchsorted(rows[touched], row[keep]),
                                        int(touched.sum()))
    return out


def _unfolded(edges: Edges, d: np.ndarray) -> np.ndarray:
    """The distances (E,) with that of one edge of each face whose quad folds between two parallel
    neighbours (turned by under ``Tol.parallel`` from each other, facing or not), one moved and one kept, set
    to 0 where then no strip of the face folds: such an edge (a short end moved further than its length)
    does not move in PRT, and its neighbours' strips end at its line (measured through PyPRT on massing's
    tiers over real lots: tartu.0, a 2 m edge moved 4 m between a kept edge and a moved one parallel to
    it, where PRT's front runs on past the kept edge's line and ends at the short edge's line, and the swept
    wavefront left 62.6 m^2 of that terrace out; seoul.31; hiroshima.111, whose second tier, a 1.8 x 2.6 m face with sides moved 3 and 4 m,
    keeps the 1.8 m side and the other's strip covers the face; the random lots' narrow arms,
    massing.H.15118 and an L's 3 m end moved 4 m, as the wavefront had them). A face whose strips would
    still fold is swept as it is (``_swept``), the edge moving (massing.L.46072's 0.07 m wide shapeU frame,
    bergen.44's 0.5 m wide one: PRT's terraces), and so is one whose folded edges lie between neighbours
    that are not parallel, or both moved (a channel's end that closes: holes.33921's second tier), or whose
    moved neighbour steps from the edge beyond it (nearly collinear, moved by another distance: a part of a
    kept edge's line that moves, as near_degenerate.44048's 0.67 m step, where PRT's terrace runs on along
    the bar as the wavefront's; a moved line that runs on, as hiroshima.136's, is a side). Of two such
    edges (an arm's end and a jog beside it, both moved 4 m), the jog, whose neighbours run the same way,
    stays, whichever is shorter, and then the shortest (measured through PyPRT on fifteen designed lots,
    the jog 3.1 to 3.95 m long after the end or 3.5 m before it, the end 2.5 to 3.8 m: PRT's strip beside
    the jog runs on past the kept edge to the jog's line; massing.utrecht.8's first tier, whose 3.03 m end
    stayed and left 1.7 m^2 of that terrace out). A jog between neighbours moved by different distances (3
    and 4 m, massing's shapeR second tier) stays too, even where a strip still folds beside it (PRT's second
    tier on utrecht.8, a 0.57 m jog, and on seventeen designed lots whose jogs run 0.05 to 0.9 m: the
    strips end at its line; moved, it let the 3 m strip run past it under the 4 m one)."""
    tangent = edges.end - edges.start
    length = np.hypot(tangent[:, 0], tangent[:, 1])
    moved = d > TOL.zero
    parallel = np.abs(_cosines(tangent[edges.prev], tangent[edges.next])) > np.cos(np.radians(TOL.parallel))
    # the moved neighbour (``side``) and the edge beyond it step as in ``_mitres``
    side = np.where(moved[edges.prev], edges.prev, edges.next)
    beyond = np.where(moved[edges.prev], edges.prev[side], edges.next[side])
    steps = (_cosines(tangent[side], tangent[beyond]) > np.cos(np.radians(_STEP_TURN))) & (
        np.abs(d[side] - d[beyond]) > TOL.zero)
    facing = np.einsum("ij,ij->i", tangent[edges.prev], tangent[edges.next]) < 0
    apart = moved[edges.prev] & moved[edges.next] & (np.abs(d[edges.prev] - d[edges.next]) > TOL.zero) & ~facing
    between = parallel & ((moved[edges.prev] != moved[edges.next]) | apart) & ~steps
    if not (between & moved).any():  # no edge to keep (most faces): the quads need no test of their own
        return d
    folded = _folds(edges, d)
    folded = folded[between[folded]]
    if not len(folded):
        return d
    # (a jog first, whose neighbours run the same way, then the shortest)
    order = np.lexsort((length[folded], facing[folded], edges.poly[folded]))
    first = folded[order][np.r_[True, np.diff(edges.poly[folded][order]) != 0]]
    unfolded = d.copy()
    unfolded[first] = 0.0
    # a face where strips still fold is swept as it was (massing.L.46072: its end stays moved)
    folding = np.zeros(int(edges.poly.max(initial=-1)) + 1, dtype=bool)
    folding[edges.poly[_folds(edges, unfolded)]] = True
    folding[edges.poly[first[apart[first]]]] = False  # (a jog between distances stays even so: utrecht.8)
    return np.where(folding[edges.poly], d, unfolded)


def _quads(edges: Edges, d: np.ndarray, reflex_steps: bool = True):
    """The quads of the edges moved by ``d`` (E,): (E, 2) where each edge's strip starts and where its
    previous edge's ends (``_mitres``, stepping at reflex vertices too or not), and (E, 2) where its own
    strip ends, relative to its vertices; the moved edges (k,) and their quads (k, 4, 2): start, end, moved
    end, moved start."""
    corner, ends, mitred = _mitres(edges, d, reflex_steps)
    # a strip ends at its next edge's mitre (its own, where the two step); where the two do not meet in
    # one (a straight vertex, as between the collinear edges a setback leaves, or a spike), at its own
    # moved end
    end_corner = np.where(mitred[edges.next][:, None], ends[edges.next], edges.inward * d[:, None])
    idx = np.flatnonzero(d > TOL.zero)
    quads = np.stack([edges.start[idx], edges.end[idx], edges.end[idx] + end_corner[idx],
                      edges.start[idx] + corner[idx]], axis=1)
    return corner, ends, end_corner, idx, quads


def _folds(edges: Edges, d: np.ndarray) -> np.ndarray:
    """The moved edges (indices) whose quads fold over themselves (a distance longer than the edge allows)."""
    _, _, _, idx, quads = _quads(edges, d, reflex_steps=False)
    return idx[~shapely.is_valid(shapely.polygons(quads))] if len(idx) else idx


def _cosines(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The cosines (k,) of the angles between the vectors a and b (k, 2)."""
    norms = np.hypot(a[:, 0], a[:, 1]) * np.hypot(b[:, 0], b[:, 1])
    return np.einsum("ij,ij->i", a, b) / np.where(norms > 0, norms, 1.0)


def _folded_strips(quads: np.ndarray) -> np.ndarray:
    """The strips (k,) of edges whose quads (k, 4, 2) (start, end, moved end, moved start) fold over
    themselves: their end lines cross before the moved line (a distance longer than the edge allows). The
    strip is then the triangle of the edge and that crossing, where its neighbours' strips take over,
    as a straight skeleton's face of the edge ends (PRT's terraces on massing's narrow shapeL arms: the
    end's strip reaches the kept edge beside it)."""
    start, end, moved_end, moved_start = quads.transpose(1, 0, 2)
    a, b = moved_start - start, moved_end - end
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    gap = end - start
    t = (gap[:, 0] * b[:, 1] - gap[:, 1] * b[:, 0]) / np.where(np.abs(det) > 1e-300, det, 1.0)
    return shapely.polygons(np.stack([start, end, start + t[:, None] * a], axis=1))


def distances_to_area(polygons: np.ndarray, edges: Edges, minimum: np.ndarray, maximum: np.ndarray,
                      moving: np.ndarray, area: np.ndarray) -> np.ndarray:
    """The distances (E,) of CityEngine's ``setbackToArea``: each ``moving`` edge (E,) bool at its
    ``minimum`` (E,) plus an offset common to its polygon, capped at its ``maximum`` (E,), the offset
    chosen so that the remainder of ``setback_regions`` has ``area`` (m,) (the others stay).

    The remainder's area falls as the offset grows, so the offset is bracketed between 0 and the
    polygon's diagonal past its largest minimum (where nothing is left) and found by regula falsi with the
    Illinois step, to a billionth of the area. Where no offset reaches the area the nearest end is taken:
    0 when the polygon is smaller (or its minimums leave less), the bracket's end when the maximums leave
    more. Each polygon iterates on its own, so its distances do not depend on the others of the batch.
    """
    m, poly = len(polygons), edges.poly
    if not m:
        return np.zeros(0)
    low, high = shapely.bounds(polygons).reshape(m, 2, 2).transpose(1, 0, 2)
    top = np.hypot(*(high - low).T)
    np.maximum.at(top, poly, top[poly] + np.where(moving, np.abs(minimum), 0.0))
    owner = np.where(moving, 0, 1)
    tolerance = 1e-9 * np.maximum(area, 1.0)

    def excess(offset, rows):
        """The remainder's area over the target (k,) of the polygons ``rows`` (k,) at ``offset`` (k,)."""
        chosen = np.zeros(m, dtype=bool)
        chosen[rows] = True
        sub, sub_edges = _edges_of(edges, chosen)
        d = np.minimum(minimum[sub] + offset[sub_edges.poly], maximum[sub])
        _, remainder = setback_regions(polygons[rows], sub_edges, d, owner[sub], 1)
        return shapely.area(remainder) - area[rows]

    everything = np.arange(m)
    lo, hi = np.zeros(m), top.copy()
    f_lo, f_hi = excess(lo, everything), excess(hi, everything)
    offset = np.where(f_lo <= tolerance, 0.0, hi)
    active = (f_lo > tolerance) & (f_hi < -tolerance)
    side = np.zeros(m, dtype=np.int64)  # which end the last step replaced: -1 low, 1 high
    for _ in range(_AREA_STEPS):
        rows = np.flatnonzero(active)
        if not len(rows):
            break
        a, b, fa, fb = lo[rows], hi[rows], f_lo[rows], f_hi[rows]
        c = (a * fb - b * fa) / (fb - fa)
        c = np.where((c > a) & (c < b), c, 0.5 * (a + b))
        fc = excess(c, rows)
        offset[rows] = c
        below = fc > 0  # too much left: the offset goes up
        lo[rows] = np.where(below, c, a)
        f_lo[rows] = np.where(below, fc, fa * np.where(~below & (side[rows] == 1), 0.5, 1.0))
        hi[rows] = np.where(below, b, c)
        f_hi[rows] = np.where(below, fb * np.where(side[rows] == -1, 0.5, 1.0), fc)
        side[rows] = np.where(below, -1, 1)
        active[rows] = (np.abs(fc) > tolerance[rows]) & (hi[rows] - lo[rows] > 1e-12 * top[rows])
    return np.where(moving, np.minimum(minimum + offset[poly], maximum), 0.0)


def _edges_of(edges: Edges, chosen: np.ndarray) -> tuple[np.ndarray, Edges]:
    """The edges (k,) of the polygons ``chosen`` (m,) bool, and they as ``Edges`` of those polygons alone."""
    keep = np.flatnonzero(chosen[edges.poly])
    renumber = np.full(len(edges.poly), -1, dtype=np.int64)
    renumber[keep] = np.arange(len(keep))
    polygon = np.cumsum(chosen) - 1
    return keep, Edges(edges.start[keep], edges.end[keep], edges.inward[keep], polygon[edges.poly[keep]],
                       renumber[edges.prev[keep]], renumber[edges.next[keep]], edges.vertex[keep],
                       edges.hole[keep])


#: How far off the line through its neighbours a seam may lie (scope units, metres): ten snaps.
_SEAM = 1e-8


def _without_seams(regions: np.ndarray, polygons: np.ndarray) -> np.ndarray:
    """Regions (m,) without the vertices where two strips of their owner meet on a straight line: a
    vertex between two collinear edges of a region that is not a vertex of its polygon (m,) goes (a region
    it changes keeps its polygons only: lines and points would go with its pieces anyway). PRT's
    shapeO whose strips cover the whole face is the face itself, its edges numbered as the face's."""
    parts, part_of = shapely.get_parts(regions, return_index=True)
    polygon = shapely.get_type_id(parts) == shapely.GeometryType.POLYGON  # (not a collapsed sliver's line)
    parts, part_of = parts[polygon], part_of[polygon]
    if not len(parts):
        return regions
    kind, coords, (ring_offsets, poly_offsets) = shapely.to_ragged_array(parts)
    coords, ring_offsets = np.asarray(coords)[:, :2], np.asarray(ring_offsets, dtype=np.int64)
    ring = np.repeat(np.arange(len(ring_offsets) - 1), np.diff(ring_offsets))
    index = np.arange(len(coords))
    first, last = ring_offsets[:-1][ring], ring_offsets[1:][ring] - 2  # rings repeat their first vertex
    a = coords - coords[np.where(index == first, last, index - 1)]
    b = coords[np.where(index >= last, first, index + 1)] - coords  # (the closing repeats are left alone)
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    # within a few snaps of the chord past it (the snap moves a seam off its line by up to half a nanometre,
    # a turn of 2e-9 between a 5 m and a 0.25 m edge on convex.18196, 8e-9 on concave.19099)
    straight = (np.abs(cross) <= _SEAM * np.hypot(*(a + b).T)) & (np.einsum("ij,ij->i", a, b) > 0)
    straight &= (index <= last) & (last - first >= 3)
    rows = np.flatnonzero(straight)
    if not len(rows):
        return regions
    corners, owner = shapely.get_coordinates(polygons, return_index=True)
    corners = shapely.multipoints(corners, indices=owner)
    part = np.searchsorted(np.asarray(poly_offsets), ring[rows], side="right") - 1
    seam = shapely.distance(shapely.points(coords[rows]), corners[part_of[part]]) > 1e-9
    if not seam.any():
        return regions
    keep = np.ones(len(coords), dtype=bool)
    keep[rows[seam]] = False
    keep[ring_offsets[1:] - 1] = keep[ring_offsets[:-1]]  # the closing repeat goes with the first
    counts = np.add.reduceat(keep.astype(np.int64), ring_offsets[:-1])
    # a ring of no area, all its vertices on one line, keeps them (it would lose all but two, no ring; a
    # tier's strips on a 0.4 m wide arm of massing.seoul.47's, numbered from another vertex)
    flat = counts < 4
    keep |= np.repeat(flat, np.diff(ring_offsets))
    counts = np.where(flat, np.diff(ring_offsets), counts)
    rebuilt = shapely.from_ragged_array(kind, coords[keep], (offsets_from_counts(counts),
                                                             np.asarray(poly_offsets)))
    out = regions.copy()
    touched = np.unique(part_of[part[seam]])
    mine = np.isin(part_of, touched)
    out[touched] = shapely.multipolygons(rebuilt[mine], indices=np.searchsorted(touched, part_of[mine]))
    return out


def _without_spikes(geometries: np.ndarray) -> np.ndarray:
    """Regions snapped to a nanometre grid. A strip whose side runs along an unmoved edge leaves the
    difference a spike out along that edge, zero wide but for rounding (massing's half octagon): the
    snap collapses it, moving the other vertices by half a nanometre at most. Two strips' lines that
    should be one (moved copies of collinear edges) but for rounding may snap to neighbouring grid lines,
    leaving a step of a nanometre: a vertex within ``_SEAM`` of the one before it goes (massing's
    holes.62285 moved 90 km away, whose rounding put a step in a shapeU strip's line: 130 faces for 126)."""
    return _without_slivers(shapely.remove_repeated_points(shapely.set_precision(geometries, _SNAP), _SEAM))


def _without_slivers(geometries: np.ndarray) -> np.ndarray:
    """Geometries (k,) without the rings narrower than ``_SEAM`` on average (a polygon goes with its outer
    ring): where two strips should meet on one line (folded strips of an arm's two sides, on its centre
    line) but for rounding lie a nanometre apart, the snapped overlay leaves a sliver there, a hole in
    the strips and a piece of the remainder of no area (massing's holes.62033 moved 56 km away: 192 faces
    for 191)."""
    parts, row = shapely.get_parts(geometries, return_index=True)
    areal = np.flatnonzero(shapely.get_type_id(parts) == shapely.GeometryType.POLYGON)
    rings, ring_part = shapely.get_rings(parts[areal], return_index=True)
    points, point_ring = shapely.get_coordinates(rings, return_index=True)
    if not len(points):
        return geometries
    following = np.r_[points[1:], points[:1]]
    inside = np.r_[point_ring[1:] == point_ring[:-1], False]  # (each ring repeats its first point last)
    cross = np.where(inside, points[:, 0] * following[:, 1] - following[:, 0] * points[:, 1], 0.0)
    step = np.where(inside, np.hypot(*(following - points).T), 0.0)
    area = np.abs(np.bincount(point_ring, cross, len(rings))) / 2
    thin = area <= _SEAM * np.bincount(point_ring, step, len(rings))
    if not thin.any():
        return geometries
    exterior = np.r_[True, ring_part[1:] != ring_part[:-1]]
    kept_part = np.zeros(len(areal), dtype=bool)
    kept_part[ring_part[exterior & ~thin]] = True
    touched = np.unique(row[areal[ring_part[thin]]])
    mine = kept_part & np.isin(row[areal], touched)
    kept = ~thin & mine[ring_part]  # (each part's outer ring first, then its holes)
    rebuilt = shapely.polygons(rings[kept], indices=(np.cumsum(mine) - 1)[ring_part[kept]])
    out = geometries.copy()
    out[touched] = shapely.Polygon()
    rows = row[areal[mine]]
    kept_rows = np.unique(rows)
    out[kept_rows] = shapely.multipolygons(rebuilt, indices=np.searchsorted(kept_rows, rows))
    return out


def _mitres(edges: Edges, d: np.ndarray, reflex_steps: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(E, 2) twice: where the strip of each edge starts and where its previous edge's strip ends, relative
    to the vertex they share: where their moved lines meet (the edge's own move where they do not meet
    near it); and (E,) whether they do.

    Where the two distances differ (one edge stays, or both move by different distances) and the
    boundary turns there by less than ``_STEP_TURN`` (at a convex vertex; ``_REFLEX_STEP_TURN`` at a reflex
    one, ``_stepping``), PRT steps instead of running the moved lines out to where they meet: each strip
    ends at the mitre point of its own distance on both edges, and the remainder steps across between them
    (measured through PyPRT on massing's tiers: a kept edge then a moved one, turned by 14.99 degrees
    steps, by 15.01 meets; edges set back 4 and 3 m turned by 7 degrees step by 1 m on convex.11084; at a
    reflex vertex, a kept edge then one moved 2, 4 or 8 m, or edges moved 4 and 3 or 4 and 1 m, turned by
    5 to 45 degrees step, by 45.5 to 89 meet: massing.concave.43421's first tier, 30 degrees)."""
    a, b = edges.inward[edges.prev], edges.inward
    da, db = d[edges.prev], d
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    safe = np.where(np.abs(det) > 1e-9, det, 1.0)
    corner = np.stack([(da * b[:, 1] - db * a[:, 1]) / safe, (a[:, 0] * db - b[:, 0] * da) / safe], axis=1)
    straight = b * db[:, None]
    reach = np.hypot(corner[:, 0], corner[:, 1])
    far = np.maximum(da, db)
    cosine = np.einsum("ij,ij->i", a, b)
    step = (np.abs(da - db) > TOL.zero) & (_stepping(edges.end - edges.start, a, cosine) if reflex_steps else
                                            cosine > np.cos(np.radians(_STEP_TURN)))
    too_far = ~step & ((np.abs(det) <= 1e-9) | (reach > _MITRE_LIMIT * np.maximum(far, TOL.zero)))
    corner = np.where(too_far[:, None], straight, corner)
    ends = corner.copy()
    bisector = (a[step] + b[step]) / (1.0 + cosine[step])[:, None]
    corner[step], ends[step] = bisector * db[step, None], bisector * da[step, None]
    return corner, ends, ~too_far


def _stepping(tangent: np.ndarray, previous_inward: np.ndarray, cosine: np.ndarray) -> np.ndarray:
    """(k,) whether the boundary turns by little enough at the vertices where edges (their ``tangent`` (k, 2))
    leave their previous edges (``previous_inward`` (k, 2) normals; ``cosine`` (k,) of the turn) that
    edges moved by different distances step there: under ``_STEP_TURN`` where the edge turns into the
    polygon (a convex vertex), up to ``_REFLEX_STEP_TURN`` where it turns away (a reflex one)."""
    reflex = np.einsum("ij,ij->i", tangent, previous_inward) < 0
    return np.where(reflex, cosine >= np.cos(np.radians(_REFLEX_STEP_TURN)) - 1e-12,
                    cosine > np.cos(np.radians(_STEP_TURN)))


def union_by_group(geometries: np.ndarray, group: np.ndarray, n_groups: int) -> np.ndarray:
    """The union of the geometries of each group (n_groups,), empty where a group has none."""
    rank = rank_within(group)
    grid = np.full((n_groups, int(rank.max(initial=0)) + 1), None, dtype=object)
    grid[group, rank] = geometries
    united = shapely.union_all(grid, axis=1)
    return np.where(shapely.is_empty(united), shapely.Polygon(), united)
