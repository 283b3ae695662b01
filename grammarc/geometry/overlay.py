"""Overlays of arrays of shapely geometries as the setbacks and insets need them: unions by group, and the
regions an overlay makes cleaned of what rounding leaves (lines where areas touch, zero-wide spikes,
nanometre steps and slivers, vertices where two strips meet on a straight line), on a nanometre grid.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.ragged import offsets_from_counts, rank_within

#: The grid (scope units, metres) that setback regions are snapped to, collapsing zero-width spikes.
SNAP = 1e-9
#: How far off the line through its neighbours a seam may lie (scope units, metres): ten snaps.
_SEAM = 1e-8


def polygonal(geometries: np.ndarray) -> np.ndarray:
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


def without_flat_parts(geometries: np.ndarray) -> np.ndarray:
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


def without_seams(regions: np.ndarray, polygons: np.ndarray) -> np.ndarray:
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


def without_spikes(geometries: np.ndarray) -> np.ndarray:
    """Regions snapped to a nanometre grid. A strip whose side runs along an unmoved edge leaves the
    difference a spike out along that edge, zero wide but for rounding (massing's half octagon): the
    snap collapses it, moving the other vertices by half a nanometre at most. Two strips' lines that
    should be one (moved copies of collinear edges) but for rounding may snap to neighbouring grid lines,
    leaving a step of a nanometre: a vertex within ``_SEAM`` of the one before it goes (massing's
    holes.62285 moved 90 km away, whose rounding put a step in a shapeU strip's line: 130 faces for 126)."""
    return _without_slivers(shapely.remove_repeated_points(shapely.set_precision(geometries, SNAP), _SEAM))


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


def union_by_group(geometries: np.ndarray, group: np.ndarray, n_groups: int) -> np.ndarray:
    """The union of the geometries of each group (n_groups,), empty where a group has none."""
    rank = rank_within(group)
    grid = np.full((n_groups, int(rank.max(initial=0)) + 1), None, dtype=object)
    grid[group, rank] = geometries
    united = shapely.union_all(grid, axis=1)
    return np.where(shapely.is_empty(united), shapely.Polygon(), united)
