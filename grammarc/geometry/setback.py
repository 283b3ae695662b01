"""Setbacks of polygon edges: CityEngine's ``setback``, ``shapeL``, ``shapeU`` and ``shapeO``.

Each edge moves into the polygon by its own distance (0 keeps it). The strip it sweeps is the quad
between the edge and its moved copy, whose ends are the mitre points where the moved lines of
neighbouring edges meet: a strip stops at an unmoved neighbour's line, and two moved neighbours share their
corner, as in CityEngine; where the boundary turns by less than 15 degrees between edges moved by
different distances (one of them 0, or not), each strip ends at its own distance's mitre point instead
and the remainder steps across at the vertex. An edge whose quad folds over itself (a distance longer than
the edge allows) between two parallel neighbours, one moved and one kept, does not move (``setback_strips.unfolded``);
another folded quad is cut to the triangle of its edge and its end lines, as a straight skeleton's face
ends; the folded edge then vanishes and its neighbours' moved lines meet, the edges of the face's outline
swept as a wavefront (``geometry.wavefront``; a hole stays, the strips are clipped to it). The strips of each owner (a
selector of the operation) are united and clipped to the polygon; an edge belongs to the first owner that
claims it, and the remainder is what no strip covers. All of it runs on whole batches: numpy over the
ragged edges, GEOS over arrays of quads.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.geometry.meshes import ring_vector_areas
from grammarc.geometry.overlay import (
    SNAP,
    polygonal,
    union_by_group,
    without_flat_parts,
    without_seams,
    without_spikes,
)
from grammarc.geometry.polygon_edges import Edges, cosines
from grammarc.geometry.setback_strips import (
    STEP_TURN,
    chosen_quads,
    mitred_quads,
    mitres,
    quad_strips,
    reflex_strips,
    short_of_reflex_ends,
    unfolded,
)
from grammarc.geometry.wavefront import swept_strips
from grammarc.ragged import offsets_from_counts

#: The turn (degrees) past a kept edge under which a moved line that passes its far end sweeps on
#: (``setback_regions``): measured between 20 (sweeps on) and 90 (stops). Past a convex far end the moved
#: line sweeps on also where the edge beyond turns from the moved edge by more than ``Tol.parallel`` and at
#: most this (a jog's 5 to 40 degrees sweep on; 65 degrees stops).
_RUN_ON_TURN = 45.0
#: The most steps ``distances_to_area`` takes for one polygon.
_AREA_STEPS = 64


def setback_regions(polygons: np.ndarray, edges: Edges, distance: np.ndarray, owner: np.ndarray,
                    n_owners: int) -> tuple[list[np.ndarray], np.ndarray]:
    """The regions (n_owners lists of (m,) geometries) the edges' strips cover, and the remainder (m,).

    distance (E,): how far each edge moves in; owner (E,): the owner of its strip (n_owners for none).
    """
    m = len(polygons)
    # a distance that is not a number (``float("")`` of a missing list item) moves nothing
    d = unfolded(edges, np.where((owner < n_owners) & np.isfinite(distance), np.maximum(distance, 0.0), 0.0))
    # the strips mitred at reflex vertices (``quads``) and stepped there too (``stepped``), as PRT's are
    corner, _, end_corner, idx, quads = mitred_quads(edges, d, reflex_steps=False)
    stepped_corner, stepped_ends, _, _, stepped = mitred_quads(edges, d)
    moved = d > TOL.zero
    strips, folded = quad_strips(quads)
    stepped_strips, stepped_folded = quad_strips(stepped)
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
    turn = np.abs(cosines(tangent[other], tangent[mover]))
    across = (turn < np.cos(np.radians(TOL.parallel))) & (turn >= np.cos(np.radians(_RUN_ON_TURN)))
    turned_over = ~moved & ~edges.hole & (moved[edges.prev] != moved[edges.next]) & (
        span < -TOL.zero * np.einsum("ij,ij->i", tangent, tangent)) & (
        reflex_end | (~far_reflex & across) | (cosines(tangent, tangent[other]) > np.cos(np.radians(_RUN_ON_TURN))))
    passed = np.zeros(m, dtype=bool)
    passed[edges.poly[turned_over]] = True
    swept |= passed
    strips = reflex_strips(edges, swept, strips, idx, quads, stepped, stepped_strips)
    strips = short_of_reflex_ends(edges, d, strips, idx, chosen_quads(edges, swept, idx, quads, stepped))
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
        _, convex_ends, _ = mitres(edges, d, reflex_steps=False)
        strips, group = _swept(polygons, edges, d, np.where(keep, corner, stepped_corner),
                               np.where(keep, convex_ends, stepped_ends), owner, swept, strips, group, idx)
    united = polygonal(union_by_group(strips, group, n_owners * m)).reshape(n_owners, m)
    regions, covered = [], np.full(m, shapely.Polygon(), dtype=object)
    # overlaid on the regions' grid (snap rounding): in floating point GEOS cuts off a face's vertex that
    # rounding left 1e-14 m outside the strip along its edge (a lot moved 2 km away, massing's holes.43809:
    # its tier numbered the face's edges otherwise, 316 faces for 346)
    for k in range(n_owners):
        inside = polygonal(shapely.intersection(polygons, united[k], grid_size=SNAP))
        # (the first owner's region is all it covers: two overlays fewer for the most common setbacks)
        region = inside if k == 0 else polygonal(shapely.difference(inside, covered, grid_size=SNAP))
        regions.append(without_seams(without_spikes(region), polygons))
        covered = region if k == 0 else shapely.union(covered, region, grid_size=SNAP)
    return regions, without_spikes(shapely.difference(polygons, covered, grid_size=SNAP))


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
        np.cos(np.radians(STEP_TURN)))
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
    made = without_flat_parts(shapely.make_valid(shapely.polygons(shapely.linearrings(
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
