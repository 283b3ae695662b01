"""Convex parts of polygons with holes (CityEngine's ``convexify``), all polygons of a batch at once.

Holes are opened first (``_opened``): from each of a hole's reflex corners a cut runs along the line of
one of its edges and stops at the boundary, as PRT's do; the faces they enclose are cut as follows.
Each round cuts every piece that still has a reflex vertex along a line through one of them: the line
of one of the two edges that meet there, the one that runs a shorter way into the piece from the vertex
(on one side the vertex becomes straight, on the other its angle drops below 180 degrees). The vertex
whose cut is the shortest goes first (of cuts as long as it but for rounding, the first in the ring).
A reflex corner that turns by less than a degree (``NEARLY_STRAIGHT``) is not cut at all: PRT's candler
lays a ventilation on a strip across a block's end whose side bends in by 0.007 to 0.99 degrees, and
none from 1.02 degrees on (the bend's cut ends on the strip's edge and gives it a fifth corner); its
roof accesses stand on roofs dented by under a degree as on whole ones (candler.yverdon.10,
concave.11029). A cut never makes a reflex vertex, so the reflex vertices of a lineage strictly decrease.
Rectilinear footprints come out as rectangles (an L in two, a U in three) whose corners where a cut
ends on an edge stay: PRT's pieces keep them, and ``geometry.isRectangular`` tells such a piece from a
rectangle (candler's roofs). Each piece starts where its boundary leaves the last cut: at the corner
cut, or where the cut ends on the boundary (``_cut_vertices``). A cut runs from the corner to where it
first comes to the boundary, as PRT's cuts of holes do, and ends at a corner of the piece that it passes
within 0.8 mm of (``SNAP``: a bump whose side stands half a millimetre off the line of the block's side
is cut off whole), never at the corner's own neighbour. The pieces come out as one mesh's faces, as
PRT's do: a cut that ends on an earlier cut gives the piece beyond that a corner there too
(``_conforming``).

A corner whose cut would only shave off a sliver (below the area floor) is passed over: the piece's next
corner is cut instead, and a piece whose corners are all passed over stays as it is (such a corner was
cut across the boundary, which PRT does not: candler.seoul.12's roof, whose side bends back by a
thousandth of a degree 16 cm before its end, got two rectangles and ventilations PRT does not lay).

``max_length`` (CityEngine's ``convexify(maxLength)``): a reflex vertex is only cut where the cut's
chord through the piece, from boundary to boundary through the vertex, is shorter; a piece whose reflex
vertices all have longer chords stays concave.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from grammarc.constants import TOL
from grammarc.ragged import offsets_from_counts, rank_within, segment_of

#: Cutting rounds at most (each removes at least one reflex vertex from every piece it cuts).
MAX_ROUNDS = 256
#: A reflex corner that turns less than this (radians: one degree) is left as it is.
NEARLY_STRAIGHT = np.radians(1.0)
#: Cuts whose lengths differ by less than this fraction are tied (rounding): the first in the ring goes first.
TIED = 1e-9
#: A corner's cut that passes a corner of its piece this close (metres) ends there. PRT's candler on a
#: block whose side steps sideways by e at a bump on it: from 0.3 to 0.7 mm the bump's feet are cut along
#: one line, from 0.9 mm on (0.8 mm at twice the size) each foot is cut on its own (ventilations on other
#: pieces), the same at half and twice the size.
SNAP = 0.0008


def convex_parts(polygons: np.ndarray, max_length: np.ndarray | None = None,
                 mirrored: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Convex pieces of shapely polygons (m,): (pieces (k,), source (k,)), each source's pieces together
    in cutting order. ``max_length`` (m,): longest chord to cut along, per polygon (None: no limit).
    ``mirrored`` (m,) bool: the polygons given in a left-handed pair of axes (a scope's x-z plane), whose
    boundary runs forward (counter-clockwise about the face's normal) clockwise; a piece's start depends on
    which way its boundary runs forward from the cut (None: all right-handed)."""
    polygons = np.asarray(polygons, dtype=object)
    flip = np.zeros(len(polygons), dtype=bool) if mirrored is None else np.asarray(mirrored, dtype=bool)
    if flip.any():
        polygons = polygons.copy()
        polygons[flip] = _mirrored(polygons[flip])
    pieces, source = _convex_parts(polygons, max_length)
    if flip.any():
        back = flip[source]
        pieces[back] = _mirrored(pieces[back])
    return pieces, source


def _mirrored(polygons: np.ndarray) -> np.ndarray:
    """Polygons (k,) with their x negated: the same rings in the other handedness."""
    return shapely.transform(polygons, lambda xy: xy * np.array([-1.0, 1.0]))


def _convex_parts(polygons: np.ndarray, max_length: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """``convex_parts`` of polygons in a right-handed pair of axes."""
    pieces = shapely.orient_polygons(polygons, exterior_cw=False)
    pieces, source = _opened(pieces)
    passed = np.zeros(len(pieces), dtype=np.int64)  # corners passed over: their cuts only shaved slivers off
    done_pieces, done_source = [], []
    for _ in range(MAX_ROUNDS):
        if not len(pieces):
            break
        pieces = _without_spikes(pieces)
        limit = None if max_length is None else max_length[source]
        vertex, direction, starts, end = _cut_vertices(pieces, limit, passed)
        finished = np.isnan(vertex[:, 0])
        done_pieces.append(pieces[finished])
        done_source.append(source[finished])
        pieces, source, vertex, direction, starts, end, passed = (
            pieces[~finished], source[~finished], vertex[~finished], direction[~finished], starts[~finished],
            end[~finished], passed[~finished])
        if not len(pieces):
            break
        parts, index = _cut(pieces, vertex, direction, end)
        keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) & (shapely.area(parts) > TOL.area_floor)
        parent = np.concatenate([np.arange(len(pieces))] * 2)[index[keep]]
        parts = parts.copy()
        parts[keep] = _keeping_vertex(parts[keep], vertex[parent], _reach(pieces)[parent])
        side = (index[keep] >= len(pieces)).astype(np.int64)  # 0: on the cut's left, 1: on its right
        # a cut that only shaves off a sliver (an edge's line running close to another edge) passes its
        # corner over: the piece goes again, to be cut at its next corner
        stuck = np.bincount(parent, minlength=len(pieces)) < 2
        retry = np.flatnonzero(stuck)
        parts, parent, side = parts[keep][~stuck[parent]], parent[~stuck[parent]], side[~stuck[parent]]
        parts = _starting_at(parts, _kept_start(parts, _first_vertices(pieces)[parent], starts[parent, side]))
        order = np.argsort(np.concatenate([parent, retry]), kind="stable")
        pieces = shapely.orient_polygons(np.concatenate([parts, pieces[retry]])[order], exterior_cw=False)
        passed = np.concatenate([np.zeros(len(parts), dtype=np.int64), passed[retry] + 1])[order]
        source = source[np.concatenate([parent, retry])[order]]
    else:
        done_pieces.append(pieces)
        done_source.append(source)
    pieces, source = np.concatenate(done_pieces), np.concatenate(done_source)
    order = np.argsort(source, kind="stable")
    return _conforming(pieces[order], source[order]), source[order]


def _conforming(pieces: np.ndarray, source: np.ndarray) -> np.ndarray:
    """Pieces (k,) (each source's together) with every corner of another piece of their source that lies
    inside one of their edges inserted there. PRT cuts the polygon as one mesh: a cut that ends on an
    edge that two pieces share (an earlier cut) splits the edge in both, and the piece on the edge's far
    side gets a fifth corner too (PRT's candler roofs: of a strip along a block's side and a strip across
    its end that meet at a corner, only the one whose cut goes last comes out a rectangle and carries a
    ventilation, candler.seoul.35). A cut's end is a corner of the pieces beside the cut; a vertex where a
    piece's boundary runs on within a degree (``NEARLY_STRAIGHT``) is none: the overlay leaves such
    vertices where a cut runs a hair off an edge's line."""
    if len(pieces) < 2:
        return pieces
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(pieces)
    coords = np.asarray(coords)[:, :2]
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    part_offsets = np.asarray(part_offsets, dtype=np.int64)
    group = np.r_[0, np.flatnonzero(source[1:] != source[:-1]) + 1, len(source)]
    d_in, d_out, cross, _ = _corners(coords, ring_offsets)
    corner = np.abs(cross) > np.sin(NEARLY_STRAIGHT) * np.hypot(*d_in.T) * np.hypot(*d_out.T)
    corner[ring_offsets[1:] - 1] = False  # a ring's closing point repeats its first
    counts, new_coords = _edges_split(coords, ring_offsets, part_offsets, group, corner, 1e-9 * _reach(pieces))
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, new_coords,
                                     (offsets_from_counts(counts), part_offsets))


@njit(cache=True, nogil=True)
def _edges_split(coords, ring_offsets, part_offsets, group, corner, tolerance):
    """``_conforming`` on ragged closed rings: each ring's new vertex count (closing point included) and
    the new coordinates. A ``corner`` of another piece of the same group (pieces ``group[g]:group[g + 1]``)
    lies inside an edge where it is within the piece's ``tolerance`` of it and farther than that from
    the edge's ends; it goes in as it is, in order along the edge, several at one point once."""
    counts = np.empty(len(ring_offsets) - 1, np.int64)
    out = np.empty((len(coords), 2))
    at = 0
    for g in range(len(group) - 1):
        v_first, v_last = ring_offsets[part_offsets[group[g]]], ring_offsets[part_offsets[group[g + 1]]]
        along, vertex = np.empty(v_last - v_first), np.empty(v_last - v_first, np.int64)
        for p in range(group[g], group[g + 1]):
            tol = tolerance[p]
            own_first, own_last = ring_offsets[part_offsets[p]], ring_offsets[part_offsets[p + 1]]
            for r in range(part_offsets[p], part_offsets[p + 1]):
                first = at
                for j in range(ring_offsets[r], ring_offsets[r + 1] - 1):
                    dx, dy = coords[j + 1, 0] - coords[j, 0], coords[j + 1, 1] - coords[j, 1]
                    length = np.sqrt(dx * dx + dy * dy)
                    n = 0
                    for v in range(v_first, v_last):
                        if not corner[v] or own_first <= v < own_last or length <= 2 * tol:
                            continue
                        rx, ry = coords[v, 0] - coords[j, 0], coords[v, 1] - coords[j, 1]
                        t = (rx * dx + ry * dy) / length
                        if tol < t < length - tol and abs(dx * ry - dy * rx) <= tol * length:
                            along[n], vertex[n] = t, v
                            n += 1
                    if at + n + 2 > len(out):
                        grown = np.empty((2 * len(out) + n + 2, 2))
                        grown[:at] = out[:at]
                        out = grown
                    out[at] = coords[j]
                    at += 1
                    last = 0.0
                    for k in np.argsort(along[:n]):
                        if along[k] - last > tol:
                            out[at] = coords[vertex[k]]
                            at += 1
                            last = along[k]
                out[at] = out[first]
                at += 1
                counts[r] = at - first
    return counts, out[:at].copy()


def _opened(pieces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Polygons (m,) with their holes opened: (pieces (k,), source (k,)). From each reflex corner of a hole
    a cut runs along the line of one of its edges (the one whose run into the polygon is shorter) and stops
    where it comes to the boundary; the polygon falls into the faces these cuts and its rings enclose.
    PRT's roof accesses on candler's courtyards lie on such faces (courtyard.32354: two faces over 200
    m^2, where cuts along whole lines left four under it)."""
    holed = np.flatnonzero(shapely.get_num_interior_rings(pieces) > 0)
    if not len(holed):
        return pieces, np.arange(len(pieces))
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(pieces[holed])
    coords = np.asarray(coords)[:, :2]
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    part_offsets = np.asarray(part_offsets, dtype=np.int64)
    ring = segment_of(ring_offsets)
    inner = np.ones(len(ring_offsets) - 1, dtype=bool)
    inner[part_offsets[:-1]] = False
    owner = segment_of(part_offsets)[ring]
    d_in, d_out, _, reflex = _corners(coords, ring_offsets)
    corner = np.flatnonzero(reflex & inner[ring])
    a = d_in[corner] / np.hypot(*d_in[corner].T)[:, None]
    b = d_out[corner] / np.hypot(*d_out[corner].T)[:, None]
    polygons = pieces[holed]
    _, direction, run = _edge_cuts(polygons, owner[corner], coords[corner], a, b)
    faces, index = _cut_faces(polygons, owner[corner], coords[corner], coords[corner] + direction * run[:, None])
    # a face starts at the first hole corner its cuts leave, in the hole's order
    first = np.full((len(faces), 2), np.nan)
    ray_start = coords[corner]
    # each face against the cuts of its own polygon (corners are in their polygon's order)
    per_owner = np.bincount(owner[corner], minlength=len(polygons))
    first_corner = np.r_[0, np.cumsum(per_owner)[:-1]]
    n = per_owner[index]
    pair_face = np.repeat(np.arange(len(faces)), n)
    pair_corner = first_corner[index][pair_face] + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    on = shapely.dwithin(faces[pair_face], shapely.points(ray_start[pair_corner]),
                         1e-9 * (1.0 + np.abs(ray_start[pair_corner]).max(axis=1)))
    pairs_face, pairs_corner = pair_face[on], pair_corner[on]
    taken = np.r_[True, pairs_face[1:] != pairs_face[:-1]] if len(pairs_face) else np.zeros(0, bool)
    first[pairs_face[taken]] = ray_start[pairs_corner[taken]]
    faces = _starting_at(faces, np.where(np.isnan(first), _first_vertices(faces), first))
    whole = np.ones(len(pieces), dtype=bool)
    whole[holed] = False
    kept = np.flatnonzero(whole)
    source = np.concatenate([kept, holed[index]])
    order = np.argsort(source, kind="stable")
    return np.concatenate([pieces[kept], faces])[order], source[order]


def _cut_faces(polygons: np.ndarray, owner: np.ndarray, start: np.ndarray, end: np.ndarray):
    """The faces (k,) that ``polygons`` (m,) fall into when each is cut along its segments from ``start`` to
    ``end`` (n, 2) (segment i cuts ``polygons[owner[i]]``), and the polygon each face is of (k,): each
    polygon's rings and its cuts, noded together, then the faces they enclose. A cut is carried a hair past
    its end (a run ends just inside the boundary), so that noding ends it on the boundary, unless it ends at
    a corner (where the hair would add a vertex to an edge running on from there)."""
    if not len(polygons):
        return np.empty(0, dtype=object), np.zeros(0, dtype=np.int64)
    direction = end - start
    direction /= np.maximum(np.hypot(direction[:, 0], direction[:, 1]), 1e-300)[:, None]
    reach = _reach(polygons)[owner]
    at_corner = shapely.distance(shapely.points(end), shapely.extract_unique_points(polygons[owner])) <= 1e-9 * reach
    far = end + direction * np.where(at_corner, 0.0, 1e-7 * reach)[:, None]
    rays = shapely.linestrings(np.stack([start, far], axis=1))
    rings = shapely.get_rings(polygons)
    ring_owner = np.repeat(np.arange(len(polygons)), shapely.get_num_interior_rings(polygons) + 1)
    lines = np.concatenate([rings, rays])
    line_owner = np.concatenate([ring_owner, owner])
    order = np.argsort(line_owner, kind="stable")
    lines, line_owner = lines[order], line_owner[order]
    width = np.bincount(line_owner, minlength=len(polygons))
    table = np.full((len(polygons), width.max()), None, dtype=object)
    table[line_owner, rank_within(line_owner)] = lines
    faces, index = shapely.get_parts(shapely.polygonize(shapely.union_all(table, axis=1)[:, None], axis=1),
                                     return_index=True)
    inside = shapely.contains_properly(polygons[index], shapely.point_on_surface(faces))
    return shapely.orient_polygons(faces[inside], exterior_cw=False), index[inside]


def _cut_vertices(pieces: np.ndarray, limit: np.ndarray | None, passed: np.ndarray):
    """Per piece, the reflex vertex that is cut first (k, 2: the shortest cut, ``TIED``; after the piece's
    first ``passed`` (k,) corners in that order), the cut's direction (k, 2): along the line of one of
    the edges that meet there, and where the parts on its left and on its right start (k, 2) each; NaN
    where there is none (the piece is convex, every cut is too long, or every corner is passed over).

    The ring of the piece cut off along an edge's line runs from the vertex on along the boundary to the
    cut's far end and back along the cut; the other part's ring runs from that far end on to the vertex:
    the one part starts at the vertex, the other where the cut ends on the boundary (PRT's pieces: the
    scope of a Z's arm lies along its long side, from the cut's end, not along the cut)."""
    vertex, chosen = np.full((len(pieces), 2), np.nan), np.full((len(pieces), 2), np.nan)
    starts, ends = np.full((len(pieces), 2, 2), np.nan), np.full((len(pieces), 2), np.nan)
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(pieces)
    coords = np.asarray(coords)[:, :2]
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    ring = segment_of(ring_offsets)
    d_in, d_out, cross, reflex = _corners(coords, ring_offsets)
    piece = segment_of(np.asarray(part_offsets, dtype=np.int64))[ring]
    # a corner that is nearly straight (under a degree) is none: a bump of 1 cm in an L's bar does not
    # take the bar off whole before the L's corner is cut across it (candler.near_degenerate.31488: PRT's
    # parts of the bar are too small for a roof access)
    turn = np.arctan2(cross, d_in[:, 0] * d_out[:, 0] + d_in[:, 1] * d_out[:, 1])
    candidates = np.flatnonzero(reflex & (turn <= -NEARLY_STRAIGHT))
    if not len(candidates):
        return vertex, chosen, starts, ends
    a = d_in[candidates] / np.hypot(d_in[candidates, 0], d_in[candidates, 1])[:, None]
    b = d_out[candidates] / np.hypot(d_out[candidates, 0], d_out[candidates, 1])[:, None]
    # a corner is cut along the line of one of its edges, the one whose run into the piece from the
    # corner is shorter (PRT's candler roofs: an H's bar, a Z's middle and a U's arms come out as
    # rectangles, the rest keeping the cut's ends); the incoming edge's on a tie (the kit's L into its
    # two 10 m arms, the boundary running forward about the roof's normal)
    point = coords[candidates]
    shorter, into, run = _edge_cuts(pieces, piece[candidates], point, a, b)
    # the cut ends at a corner of the piece that it passes within SNAP of, and stops where it comes to the
    # boundary (``_cut``)
    first, last = ring_offsets[:-1][ring[candidates]], ring_offsets[1:][ring[candidates]] - 1
    neighbours = np.stack([coords[np.where(candidates > first, candidates - 1, last - 1)], coords[candidates + 1]],
                          axis=1)
    into, run, end = _snapped(coords, piece, piece[candidates], point, into, run, neighbours)
    direction = np.where(shorter[:, None], into, -into)
    # the far end: on the right of the outgoing edge's line (the incoming edge's side), on the left of the
    # incoming edge's line
    left = np.where(shorter[:, None], end, point)
    right = np.where(shorter[:, None], point, end)
    # the shortest cut goes first, the first in the ring of cuts as long but for rounding (TIED): PRT's
    # candler roofs take a small bump off before the long cut at a corner earlier in the ring
    # (candler.tartu.17: the ventilation stands on the bump's outer strip; candler.seoul.42: a jog between
    # two bars leaves no rectangle), and cut a block across at a corner 11 m from its far side before a
    # cut 3.5 mm longer across it, whatever the ring's start (a ventilation on the block)
    shortest = np.full(len(pieces), np.inf)
    np.minimum.at(shortest, piece[candidates], run)
    # then the others by length (a piece's corners passed over give way to the next)
    key = np.where(run > shortest[piece[candidates]] * (1.0 + TIED), run, 0.0)
    order = np.lexsort((candidates, key, piece[candidates]))
    candidates, direction, left, right, end, point = (candidates[order], direction[order], left[order],
                                                      right[order], end[order], point[order])
    if limit is not None:
        chord = _chords(pieces[piece[candidates]], point, direction)
        keep = chord < limit[piece[candidates]]
        candidates, direction, left, right, end = (candidates[keep], direction[keep], left[keep], right[keep],
                                                   end[keep])
    # each piece's candidate after the ones passed over (candidates in the order they go)
    at = piece[candidates]
    first = rank_within(at) == passed[at]
    vertex[at[first]] = coords[candidates[first]]
    chosen[at[first]] = direction[first]
    starts[at[first], 0] = left[first]
    starts[at[first], 1] = right[first]
    ends[at[first]] = end[first]
    return vertex, chosen, starts, ends


def _cut(pieces: np.ndarray, vertex: np.ndarray, direction: np.ndarray, end: np.ndarray):
    """Each piece cut through its ``vertex`` (k, 2) along ``direction`` (k, 2) to ``end`` (k, 2), where the cut
    comes to the boundary (PRT's cuts stop there, as they do on holes): the parts (j,) and where each comes
    from (j,): i for piece i's parts on the cut's left, k + i for those on its right."""
    faces, owner = _cut_faces(pieces, np.arange(len(pieces)), vertex, end)
    # a face is on the cut's left where it holds a point a hair left of the cut's middle
    normal = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    beside = (vertex + end) / 2 + normal * (1e-7 * _reach(pieces))[:, None]
    on_left = shapely.contains(faces, shapely.points(beside[owner]))
    index = owner + np.where(on_left, 0, len(pieces))
    order = np.argsort(index, kind="stable")
    return faces[order], index[order]


def _snapped(coords: np.ndarray, vertex_piece: np.ndarray, owner: np.ndarray, point: np.ndarray,
             into: np.ndarray, run: np.ndarray, neighbours: np.ndarray):
    """Cuts from ``point`` (k, 2) along ``into`` (k, 2) for ``run`` (k,) into ``pieces[owner]`` (whose
    vertices are ``coords``, of pieces ``vertex_piece``), ended at the first vertex of the piece that lies
    within SNAP of them: (direction, run, end) (k, 2), (k,), (k, 2). A cut along an edge's line that passes
    half a millimetre beside a corner of the piece ends there (candler.tartu.12: the line of the roof's
    side beside a bump, 0.5 mm off the bump's other corner, cuts the bump off, a rectangle, where it ran
    on along the side and left slivers); but never at one of the cut corner's own ``neighbours`` (k, 2, 2):
    ended there, it would run along their edge and cut nothing off (a corner 16 cm before the end of a
    side that bends back by 1.5 degrees; PRT's candler lays no ventilation on either side of it)."""
    first_vertex = np.searchsorted(vertex_piece, owner, side="left")
    n = np.searchsorted(vertex_piece, owner, side="right") - first_vertex
    pair = np.repeat(np.arange(len(owner)), n)
    v = first_vertex[pair] + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    rel = coords[v] - point[pair]
    along = rel[:, 0] * into[pair, 0] + rel[:, 1] * into[pair, 1]
    off = np.abs(into[pair, 0] * rel[:, 1] - into[pair, 1] * rel[:, 0])
    own = (coords[v] == neighbours[pair, 0]).all(axis=1) | (coords[v] == neighbours[pair, 1]).all(axis=1)
    near = (along > SNAP) & (along < run[pair] + SNAP) & (off <= SNAP) & ~own
    nearest = np.full(len(owner), np.inf)
    np.minimum.at(nearest, pair[near], along[near])
    end = point + into * run[:, None]
    hit = near & (along == nearest[pair])
    end[pair[hit]] = coords[v[hit]]
    direction = end - point
    length = np.hypot(direction[:, 0], direction[:, 1])
    return direction / np.maximum(length, 1e-300)[:, None], length, end


def _corners(coords: np.ndarray, ring_offsets: np.ndarray):
    """Each vertex's incoming and outgoing edge (n, 2) each, their cross product (n,), and whether it is a
    reflex corner (n,) bool (turning right, the boundary running counter-clockwise; never a ring's closing
    point). Closed rings: vertex j of a ring (its last point repeats its first) has neighbours j - 1 and
    j + 1, the previous of its first being the one before its closing point."""
    ring = segment_of(ring_offsets)
    start, end = ring_offsets[:-1][ring], ring_offsets[1:][ring] - 1
    at = np.arange(len(coords))
    prev = np.where(at > start, at - 1, end - 1)
    d_in = coords - coords[prev]
    d_out = coords[np.minimum(at + 1, len(coords) - 1)] - coords
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    scale = np.hypot(d_in[:, 0], d_in[:, 1]) * np.hypot(d_out[:, 0], d_out[:, 1])
    return d_in, d_out, cross, (at < end) & (cross < -1e-9 * np.maximum(scale, TOL.zero))


def _edge_cuts(pieces: np.ndarray, owner: np.ndarray, point: np.ndarray, a: np.ndarray, b: np.ndarray):
    """Of the two edges meeting at each corner ``point`` (k, 2) of ``pieces[owner]``, incoming ``a`` and
    outgoing ``b`` (unit, (k, 2) each), the one whose line runs the shorter way into the piece from the
    corner (the incoming one on a tie): whether it is the incoming one (k,), the cut's direction (k, 2)
    and its length to the boundary (k,)."""
    run_in, run_out = np.split(_runs(pieces, np.r_[owner, owner], np.r_[point, point], np.r_[a, -b]), 2)
    shorter = run_in <= run_out * (1.0 + 1e-9)
    return shorter, np.where(shorter[:, None], a, -b), np.where(shorter, run_in, run_out)


def _runs(pieces: np.ndarray, owner: np.ndarray, point: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """How far the half-line from each ``point`` (k, 2) on the boundary of ``pieces[owner]`` along
    ``direction`` (k, 2) runs inside before it comes to the boundary again (0 where it does not run
    inside): the length of a cut from there. The pieces are taken shrunk by a hair, so that a line
    through one of their corners (an H's bar, cut along its arms' inner edges) ends there and does not
    run on along the edge beyond."""
    used = np.unique(owner)
    reach = np.zeros(len(pieces))
    reach[used] = _reach(pieces[used])
    shrunk = np.empty(len(pieces), dtype=object)
    shrunk[used] = shapely.buffer(pieces[used], -1e-9 * reach[used], join_style="mitre")
    ray = shapely.linestrings(np.stack([point, point + direction * reach[owner][:, None]], axis=1))
    parts, index = shapely.get_parts(shapely.intersection(ray, shrunk[owner]), return_index=True)
    line = (shapely.get_type_id(parts) == shapely.GeometryType.LINESTRING) & ~shapely.is_empty(parts)
    parts, index = parts[line], index[line]
    length = np.full(len(owner), np.inf)
    np.minimum.at(length, index, shapely.distance(shapely.points(point[index]), parts) + shapely.length(parts))
    return np.where(np.isfinite(length), length, 0.0)


def _chords(pieces: np.ndarray, point: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Length of the part of each piece's cut line that runs through ``point``: the split line."""
    reach = _reach(pieces)
    lines = shapely.linestrings(np.stack([point - direction * reach[:, None], point + direction * reach[:, None]],
                                         axis=1))
    parts, index = shapely.get_parts(shapely.intersection(lines, pieces), return_index=True)
    through = shapely.distance(parts, shapely.points(point[index])) <= 1e-9 * (reach[index] + 1.0)
    length = np.full(len(pieces), np.inf)
    np.minimum.at(length, index[through], shapely.length(parts[through]))
    return length


def _without_spikes(pieces: np.ndarray) -> np.ndarray:
    """Pieces without repeated vertices and the vertices where the boundary turns straight back (a cut
    along a line nearly collinear with an edge leaves such zero-width spikes). A vertex where it runs
    straight on stays: where a cut ends on an edge, PRT's piece keeps the point as a corner (candler's
    ``geometry.isRectangular`` is false for an arm whose side the cut of a bar ends on)."""
    if not len(pieces):
        return pieces
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(pieces)
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    # open rings: drop each ring's closing point
    closing = ring_offsets[1:] - 1
    keep = np.ones(len(coords), dtype=bool)
    keep[closing] = False
    coords = np.asarray(coords)[keep, :2]
    ring = segment_of(ring_offsets)[keep]
    n_rings = len(ring_offsets) - 1
    for _ in range(64):  # removing a spike's tip makes its base straight; one of two neighbours a pass
        counts = np.bincount(ring, minlength=n_rings)
        offsets = np.r_[0, np.cumsum(counts)]
        at = np.arange(len(coords))
        start, stop = offsets[:-1][ring], offsets[1:][ring]
        prev = np.where(at > start, at - 1, stop - 1)
        nxt = np.where(at + 1 < stop, at + 1, start)
        d_in, d_out = coords - coords[prev], coords[nxt] - coords
        out_length = np.hypot(d_out[:, 0], d_out[:, 1])
        cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
        repeated = out_length <= 1e-9 * (1.0 + np.abs(coords).max(axis=1))
        back = (np.abs(cross) <= 1e-9 * np.hypot(d_in[:, 0], d_in[:, 1]) * out_length) & (
            d_in[:, 0] * d_out[:, 0] + d_in[:, 1] * d_out[:, 1] <= 0.0)
        spike = repeated | back
        # never below a triangle; of two neighbours both spikes, the first goes this time
        drop = spike & (counts[ring] > 3) & ~(spike[prev] & (prev != at) & (at > start))
        if not drop.any():
            break
        coords, ring = coords[~drop], ring[~drop]
    counts = np.bincount(ring, minlength=n_rings)
    offsets = np.r_[0, np.cumsum(counts)]
    # closed again: each ring's first vertex after its last
    order = np.concatenate([np.arange(len(coords)), offsets[:-1]])
    order = order[np.argsort(np.concatenate([ring, np.arange(n_rings)]), kind="stable")]
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords[order],
                                     (np.r_[0, np.cumsum(counts + 1)], part_offsets))


def _keeping_vertex(parts: np.ndarray, vertex: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """Parts (k,) with the corner they were cut at (k, 2) on their boundary as a vertex. Where the cut runs on
    along an edge from that corner, GEOS's overlay may take the cut's line for the edge and leave the
    corner out, depending on the last bits of the coordinates (a lot 8 km from the origin lost it where
    the same lot at the origin kept it); PRT's pieces keep it."""
    return shapely.snap(parts, shapely.points(vertex), 1e-9 * reach)


def _first_vertices(pieces: np.ndarray) -> np.ndarray:
    """The first vertex of each piece's outer ring (k, 2)."""
    return shapely.get_coordinates(shapely.get_point(shapely.get_exterior_ring(pieces), 0))


def _kept_start(parts: np.ndarray, first: np.ndarray, cut: np.ndarray) -> np.ndarray:
    """Where each part's ring starts (k, 2): at its parent's first vertex ``first`` where the part keeps it,
    else at its end of the cut ``cut``. A part is a run of its parent's ring closed by the cut, kept in
    the parent's order: the run that goes round the parent's start begins there (PRT's pieces: of an H's
    four arms, the one whose run holds the roof's first corner has its scope along the cut, and candler's
    ventilator on it lies across the arm)."""
    if not len(parts):
        return cut
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(parts)
    ring = segment_of(np.asarray(ring_offsets, dtype=np.int64))
    outer_rings = np.asarray(part_offsets, dtype=np.int64)[:-1]
    which = np.full(len(ring_offsets) - 1, -1)
    which[outer_rings] = np.arange(len(parts))
    which = which[ring]
    at = np.flatnonzero(which >= 0)
    which = which[at]
    coords = np.asarray(coords)[:, :2]
    scale = 1e-9 * (1.0 + np.abs(first).max(axis=1))
    kept = np.zeros(len(parts), dtype=bool)
    np.logical_or.at(kept, which, np.hypot(*(coords[at] - first[which]).T) <= scale[which])
    return np.where(kept[:, None], first, cut)


def _starting_at(pieces: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Pieces (k,) whose outer rings start at their vertex nearest ``point`` (k, 2), the corner they
    were cut at: PRT's pieces start there (the scope of candler's roof parts lies along the edge that
    leaves the cut corner)."""
    if not len(pieces):
        return pieces
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(pieces)
    coords = np.asarray(coords)[:, :2].copy()
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    outer = np.asarray(part_offsets, dtype=np.int64)[:-1]
    start, stop = ring_offsets[outer], ring_offsets[outer + 1] - 1  # open rings: without the closing point
    length = stop - start
    open_offsets = np.r_[0, np.cumsum(length)]
    ring = segment_of(open_offsets)
    at = np.arange(open_offsets[-1]) + (start - open_offsets[:-1])[ring]
    distance = np.hypot(*(coords[at] - point[ring]).T)
    order = np.lexsort((distance, ring))
    shift = at[order][open_offsets[:-1]] - start
    coords[at] = coords[start[ring] + (at - start[ring] + shift[ring]) % length[ring]]
    coords[stop] = coords[start]
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords, (ring_offsets, part_offsets))


def _reach(pieces: np.ndarray) -> np.ndarray:
    """A length past which a line through a point of the piece has left it: twice its box's diagonal."""
    bounds = shapely.bounds(pieces).reshape(-1, 4)
    return 2.0 * np.hypot(bounds[:, 2] - bounds[:, 0], bounds[:, 3] - bounds[:, 1]) + 1.0
