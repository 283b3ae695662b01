"""Split of polygons across their plane: each child is its parent's polygon clipped to its slab.

A split along an in-plane axis of a concave or holed polygon (a footprint, its prism, a gable face) gives
each part the piece of the polygon inside the part's slab, with GEOS (shapely) clipping all the children
of a batch in one vectorized call. A part the polygon does not reach is dropped (CityEngine drops empty
parts); a slab that cuts the polygon into several pieces gives one child per piece. A child's scope is
the bounding box of its piece (the parent's axes), and a piece that fills its box takes the box fast path.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import shapely
from numba import njit

from grammarc.constants import TOL
from grammarc.geometry.components import DOWN, UP
from grammarc.geometry.polygons import PLANE_U as _A
from grammarc.geometry.polygons import PLANE_V as _B
from grammarc.geometry.polygons import PolygonStore
from grammarc.geometry.ring_starts import material_sides, places, ring_starts
from grammarc.ragged import next_in_segment, offsets_from_counts, ragged_take, segment_of, segment_reduce


@dataclass(frozen=True)
class Clipped:
    """The pieces of clipped children.

    ``source`` (k,) int64: the child (index into the split's children) each piece comes from (a child
    may give none or several); ``low``, ``extent`` (k, 3) float64: each piece's box in its parent's scope
    coordinates (along the plane's normal: 0 and the parent's size); ``is_rect`` (k,) bool; the pieces'
    normalized polygons (``coords`` (V, 2), ``ring_offsets``, ``poly_offsets`` (k+1,)), ``plane`` (k,) and
    where the side face over each edge starts its ring (``turn`` (V,) int8, ``cap_turns``).
    """

    source: np.ndarray
    low: np.ndarray
    extent: np.ndarray
    is_rect: np.ndarray
    coords: np.ndarray
    ring_offsets: np.ndarray
    poly_offsets: np.ndarray
    plane: np.ndarray
    turn: np.ndarray

    def take(self, index: np.ndarray) -> Clipped:
        """The pieces at ``index`` (a boolean mask or indices), with their polygons."""
        index = np.flatnonzero(index) if np.asarray(index).dtype == bool else np.asarray(index, np.int64)
        rings, poly_offsets = ragged_take(self.poly_offsets, index)
        vertices, ring_offsets = ragged_take(self.ring_offsets, rings)
        return Clipped(self.source[index], self.low[index], self.extent[index], self.is_rect[index],
                       self.coords[vertices], ring_offsets, poly_offsets, self.plane[index], self.turn[vertices])


def scope_polygons(store: PolygonStore, geom: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Shapely polygons (m,) of store polygons ``geom`` in their scopes' units (u, v scaled by size)."""
    plane = store.plane[geom]
    rows = np.arange(len(geom))
    coords, ring_offsets, poly_offsets = store.gather(geom)
    vertex_poly = segment_of(poly_offsets)[segment_of(ring_offsets)]
    scale = np.stack([size[rows, _A[plane]], size[rows, _B[plane]]], axis=1)
    return polygons_from_rings(coords * scale[vertex_poly], ring_offsets, poly_offsets)


def clip_to_slabs(store: PolygonStore, geom: np.ndarray, size: np.ndarray, axis: int, pos: np.ndarray,
                  length: np.ndarray, turn_cuts: bool = False) -> Clipped:
    """Clip the polygons ``geom`` (m,) of the children's parents to the children's slabs.

    size (m, 3): the parents' scope sizes; the slab of child i runs from pos[i] to pos[i] + length[i]
    along scope axis ``axis``, which must lie in each polygon's plane. With ``turn_cuts`` (CityEngine's
    ``split``), the faces of a solid's cut through a hole turn as PRT's do (``cap_turns``); the paper's
    ``Subdiv`` and ``Repeat`` keep every side face's x along its edge.
    """
    plane = store.plane[geom]
    a, b = _A[plane], _B[plane]
    rows = np.arange(len(geom))
    sa, sb = size[rows, a], size[rows, b]
    polygons = scope_polygons(store, geom, size)
    along_a = axis == a
    big = np.maximum(sa, sb) + 1.0
    xmin = np.where(along_a, pos, -big)
    xmax = np.where(along_a, pos + length, big)
    ymin = np.where(along_a, -big, pos)
    ymax = np.where(along_a, big, pos + length)
    pieces = shapely.intersection(polygons, shapely.box(xmin, ymin, xmax, ymax))
    # the slabs that hold the parent's vertex 0 or 1 (their pieces start differently, ``ring_starts``)
    slack = TOL.zero * np.maximum(np.maximum(sa, sb), 1.0)
    with_start = np.zeros(len(geom), dtype=bool)
    for vertex in (0, 1):
        point = shapely.get_coordinates(shapely.get_point(shapely.get_exterior_ring(polygons), vertex))
        at = np.where(along_a, point[:, 0], point[:, 1])
        with_start |= (at >= pos - slack) & (at <= pos + length + slack)
    clipped = fit_pieces(pieces, plane, size, polygons, cut_sides=with_start)
    if not turn_cuts:
        return clipped
    # the slab's sides that cut a solid (NaN: the polygon's own extent ends there, or it is flat: a cut
    # face has no faces of its own, and a solid extruded from its pieces has side faces like any other)
    far = np.where(along_a, sa, sb)
    solid = size[rows, plane] > TOL.zero
    lo = np.where(solid & (pos > slack), pos, np.nan)
    hi = np.where(solid & (pos + length < far - slack), pos + length, np.nan)
    turn = cap_turns(clipped, polygons, along_a, lo, hi, slack)
    # a rectangle with turned faces keeps its polygon: a box's faces are never turned
    turned = np.zeros(len(clipped.source), dtype=bool)
    turned[segment_of(clipped.poly_offsets)[segment_of(clipped.ring_offsets)][turn != 0]] = True
    return replace(clipped, turn=turn, is_rect=clipped.is_rect & ~turned)


def cap_turns(clipped: Clipped, parents: np.ndarray, along_a: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              slack: np.ndarray) -> np.ndarray:
    """Where the side faces over the pieces' cut edges start their rings (V,) int8 (``components.UP``,
    ``DOWN``; ``ALONG`` elsewhere), as PRT's split of a holed solid starts them.

    PRT splits a solid as a mesh and closes each piece with the faces where the cut crosses it, each face's
    ring starting with the segment of the first face of the solid that crosses the plane there: the bottom
    (its scope's x along the cut, as grammarc's side faces are), but where the cut runs through a hole of the
    polygon the bottom and the top come after every side face, and the ring starts with the segment on the
    side face of the polygon's edge that comes first (the outer ring's edges from edge 0, then the holes'):
    at the top of the cut edge's start, x down, where that is the edge before it, at the bottom of its end,
    x up, where it is the edge after it (measured through PyPRT on complexpatterns' top floors, whose
    front is that face, on courtyard lots a split crosses through the courtyard: the x of each part of the
    face runs down or up as this says, in nine parts of five lots). Pieces without an edge of a hole in
    their outline (the cut misses the holes, or they have none) keep ``ALONG``, and so do the pieces of a
    flat polygon: its cut makes no faces, and a solid extruded from a piece has side faces like any
    other's (massing on the kit's courtyard lot, whose inset it splits through the courtyard: its facades'
    floors, split along y, are 114 faces with the faces turned, 118 without, 122 in PRT).

    ``parents`` (m,): the polygons cut, in scope units; ``along_a`` (m,): whether the cut's axis is their
    plane's first; ``lo``, ``hi`` (m,): the slab's cutting sides on that axis (NaN where it does not cut,
    or the polygon is flat); ``slack`` (m,): lengths within it count as nought."""
    parent_flat, parent_rings, parent_offsets = _open_polygons(parents)
    vertex_piece = segment_of(clipped.poly_offsets)[segment_of(clipped.ring_offsets)]
    piece = np.arange(len(clipped.source))
    a, b = _A[clipped.plane], _B[clipped.plane]
    low = np.stack([clipped.low[piece, a], clipped.low[piece, b]], axis=1)
    extent = np.stack([clipped.extent[piece, a], clipped.extent[piece, b]], axis=1)
    flat = low[vertex_piece] + clipped.coords * extent[vertex_piece]
    return _cap_turns(flat, clipped.ring_offsets, clipped.poly_offsets, clipped.source, along_a, lo, hi, slack,
                      parent_flat, parent_rings, parent_offsets)


@njit(cache=True, nogil=True)
def _cap_turns(coords, ring_offsets, part_offsets, part_source, along_a, lo, hi, slack, parent_coords,
               parent_rings, parent_offsets):
    """``cap_turns`` on the pieces' rings in scope units."""
    turn = np.zeros(len(coords), np.int8)
    material = material_sides(parent_coords, parent_rings, parent_offsets)
    no_moves = np.zeros(0)
    for p in range(len(part_offsets) - 1):
        g = part_source[p]
        if (np.isnan(lo[g]) and np.isnan(hi[g])) or parent_offsets[g + 1] - parent_offsets[g] < 2:
            continue  # no cut of a solid, or no hole for it to run through
        outer = parent_rings[parent_offsets[g] + 1] - parent_rings[parent_offsets[g]]
        r0, r1 = ring_offsets[part_offsets[p]], ring_offsets[part_offsets[p] + 1]
        n = r1 - r0
        keys = np.empty(n)
        for j in range(n):
            k = r0 + (j + 1) % n
            keys[j] = places(coords[r0 + j, 0], coords[r0 + j, 1], coords[k, 0], coords[k, 1], g, parent_coords,
                              parent_rings, parent_offsets, material, no_moves)[1]
        if not (keys >= outer).any():
            continue  # no edge of a hole in the outline: the cut misses the holes
        axis = 0 if along_a[g] else 1
        for j in range(n):
            k = (j + 1) % n
            on_cut = False
            for side in (lo[g], hi[g]):
                if abs(coords[r0 + j, axis] - side) <= slack[g] and abs(coords[r0 + k, axis] - side) <= slack[g]:
                    on_cut = True
            if on_cut:
                before, after = np.floor(keys[(j - 1) % n]), np.floor(keys[k])
                turn[r0 + j] = DOWN if before < after else UP
    return turn


def oriented_rings(parts: np.ndarray, part_plane: np.ndarray):
    """Shapely polygons (k,) in their planes, turned so that exteriors wind counter-clockwise around
    the plane's normal (clockwise in (u, v) for plane 1, whose (x, z) axes make a left-handed pair with
    y), and their open rings: (parts, coords (V, 2), ring_offsets (R+1,), part_offsets (k+1,))."""
    parts = parts.copy()
    for flip in (True, False):
        sel = (part_plane == 1) == flip
        if sel.any():
            parts[sel] = shapely.orient_polygons(parts[sel], exterior_cw=flip)
    if not len(parts):
        return parts, np.zeros((0, 2)), np.zeros(1, np.int64), np.zeros(1, np.int64)
    _, flat, (closed_rings, part_offsets) = shapely.to_ragged_array(parts)
    flat, ring_offsets = open_rings(np.asarray(flat)[:, :2], np.asarray(closed_rings, dtype=np.int64))
    return parts, flat, ring_offsets, np.asarray(part_offsets, dtype=np.int64)


def fit_pieces(geometries: np.ndarray, plane: np.ndarray, size: np.ndarray,
               parents: np.ndarray | None = None, cut_sides: np.ndarray | None = None,
               start_edges: np.ndarray | None = None, insets: np.ndarray | None = None,
               moves: np.ndarray | None = None) -> Clipped:
    """Polygons (or multipolygons) in scope units, one per source row, as pieces with fitted boxes.

    ``parents`` (one polygon per source row, the polygons the pieces were cut or moved in from): each
    piece's rings then start where CityEngine's do (``ring_starts``), so that edge numbers
    (``comp.index`` of ``comp(fe)``) follow the parent's. ``cut_sides`` (one bool per source row) when the
    pieces were cut from their parents (a split): whether the row's pieces lie on a side of the cut that
    holds the parent's vertex 0 or 1; None when they were moved in from them (an offset, a setback).
    ``start_edges`` (one bool per vertex of the parents' open rings, all rings one after the other): the
    parent edges (from that vertex) where pieces moved in start when they run along one (a setback's
    strips start at the first edge they set back). ``insets`` (one bool per source row, None for none):
    the rows whose pieces are an offset's insets, which start otherwise than a setback's remainder where
    the offset took edges (``ring_starts``). ``moves`` (one float per vertex of the parents' open
    rings, as ``start_edges``; None where not known): how far each parent edge was moved in, so that a
    piece's edge is told to come from the edge at that distance (``ring_starts``)."""
    parts, source = shapely.get_parts(geometries, return_index=True)
    keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) & (
        shapely.area(parts) > TOL.area_floor)
    parts, source = parts[keep], source[keep]
    a, b = _A[plane], _B[plane]
    part_plane = plane[source]
    parts, flat, ring_offsets, part_offsets = oriented_rings(parts, part_plane)
    bounds = shapely.bounds(parts).reshape(-1, 4)
    if parents is not None and len(parts):
        parent_flat, parent_rings, parent_offsets = _open_polygons(parents)
        cut = cut_sides is not None
        side = cut_sides if cut else np.ones(len(geometries), dtype=np.bool_)
        allowed = np.zeros(0, dtype=np.bool_) if start_edges is None else start_edges
        inset = np.zeros(len(geometries), dtype=np.bool_) if insets is None else insets
        moved = np.zeros(0) if moves is None else np.asarray(moves, dtype=np.float64)
        flat = ring_starts(flat, ring_offsets, part_offsets, source, side[source], cut, inset[source],
                           allowed, moved, parent_flat, parent_rings, parent_offsets)
    vertex_part = segment_of(part_offsets)[segment_of(ring_offsets)]
    low2 = bounds[:, :2]
    extent2 = bounds[:, 2:] - bounds[:, :2]
    safe = np.where(extent2 > TOL.zero, extent2, 1.0)
    normalized = (flat - low2[vertex_part]) / safe[vertex_part]
    low = np.zeros((len(parts), 3))
    extent = np.zeros((len(parts), 3))
    k = np.arange(len(parts))
    pa, pb = a[source], b[source]
    low[k, pa], low[k, pb] = low2[:, 0], low2[:, 1]
    extent[k, pa], extent[k, pb] = extent2[:, 0], extent2[:, 1]
    extent[k, part_plane] = size[source, part_plane]
    area = np.abs(segment_reduce(np.add, _cross(normalized, ring_offsets), ring_offsets[part_offsets],
                                 0.0)) / 2
    is_rect = (np.diff(part_offsets) == 1) & (np.diff(ring_offsets[part_offsets]) == 4) & (
        np.abs(area - 1.0) <= TOL.rect)
    return Clipped(source, low, extent, is_rect, normalized, ring_offsets, part_offsets,
                   part_plane.astype(np.int8), np.zeros(len(normalized), dtype=np.int8))


def _open_polygons(polygons: np.ndarray):
    """Shapely polygons (m,) as open rings: coords (V, 2), ring_offsets (R+1,), polygon offsets (m+1,)."""
    _, flat, (closed, offsets) = shapely.to_ragged_array(polygons)
    flat, rings = open_rings(np.asarray(flat)[:, :2], np.asarray(closed, dtype=np.int64))
    return flat, rings, np.asarray(offsets, dtype=np.int64)


def polygons_from_rings(coords: np.ndarray, ring_offsets: np.ndarray, poly_offsets: np.ndarray) -> np.ndarray:
    """Shapely polygons from open ragged rings (shapely wants each ring closed)."""
    counts = np.diff(ring_offsets)
    closed_counts = counts + 1
    closed_offsets = offsets_from_counts(closed_counts)
    index = np.arange(closed_offsets[-1]) - np.repeat(closed_offsets[:-1], closed_counts)
    source = np.repeat(ring_offsets[:-1], closed_counts) + np.mod(index, np.repeat(counts, closed_counts))
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords[source],
                                     (closed_offsets, poly_offsets))


def open_rings(coords: np.ndarray, closed_offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop each ring's closing vertex (the repeat of its first)."""
    counts = np.diff(closed_offsets) - 1
    keep = np.ones(len(coords), dtype=bool)
    keep[closed_offsets[1:] - 1] = False
    return coords[keep], offsets_from_counts(counts)


def _cross(coords: np.ndarray, ring_offsets: np.ndarray) -> np.ndarray:
    """Shoelace terms u_i v_{i+1} - u_{i+1} v_i of open rings."""
    nxt = next_in_segment(ring_offsets)
    return coords[:, 0] * coords[nxt, 1] - coords[nxt, 0] * coords[:, 1]
