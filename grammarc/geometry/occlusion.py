"""Occlusion tests between query shapes and closed occluders, many pairs at once (CityEngine's ``inside``,
``overlaps`` and ``touches``).

An occluder is a prism: a polygon in one plane of its scope (a box's is its x-z rectangle) extruded
``height`` along that plane's normal. A query is a convex polytope given by its corners and edges: a box
(8 corners) or a face (4). In the occluder's frame the prism is the product P x [0, h], so for a convex
query Q, with w its coordinate along the normal and Q's projection onto the plane:

- ``inside``: every corner has w in [0, h] and P covers Q's projection (exact: the projection of a
  convex Q is the hull of its projected corners);
- ``overlaps``: Q meets the prism's interior: the part of Q strictly inside the slab 0 < w < h (its
  corners there and its edges' crossings of the two planes) projects into P's interior;
- ``touches``: it overlaps, or Q lies against the prism's surface over an area: against a top or bottom
  (the part of Q in the closed slab projects onto P with positive area) or against a side (that part
  runs along P's boundary for a positive length and over a positive height).

Everything runs on arrays of pairs: a box occluder (the common case: masses, cubes) by separating axes
in numba (``box_relations``), any other prism with numpy for the frames and slab clipping and shapely's
vectorized predicates for the planar part. ``EPS`` (metres) absorbs rounding, so faces that meet exactly
touch.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import shapely
from numba import njit

from grammarc.geometry.polygons import PLANE_U, PLANE_V

#: Metres within which geometry counts as meeting.
EPS = 1e-4

#: Corners of the unit box and of the unit square (z = 0), and their edges.
BOX_CORNERS = np.array([[i & 1, i >> 1 & 1, i >> 2 & 1] for i in range(8)], dtype=np.float64)
BOX_EDGES = np.array([[a, b] for a in range(8) for b in range(a + 1, 8) if (a ^ b).bit_count() == 1])
QUAD_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
QUAD_EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])


@dataclass(frozen=True)
class Prisms:
    """Occluders: ``origin`` (k, 3) and ``axes`` (k, 3, 3) (rows) of their scopes, ``plane`` (k,) the scope
    axis along which each extrudes, ``height`` (k,), ``polygon`` (k,) shapely polygons in the plane's
    (u, v) = (axis PLANE_U, axis PLANE_V) coordinates, in metres from the origin; ``outer`` and
    ``inner`` (k,) the polygons grown and shrunk by ``EPS``, ``boundary`` (k,) their outlines (None for
    boxes), ``bounds`` (k, 4) and ``rect`` (k,) whether the polygon is its bounding rectangle (a box:
    tested by separating axes in numba, ``box_relations``), all made once by ``prisms``, not per query."""

    origin: np.ndarray
    axes: np.ndarray
    plane: np.ndarray
    height: np.ndarray
    polygon: np.ndarray
    outer: np.ndarray
    inner: np.ndarray
    boundary: np.ndarray
    bounds: np.ndarray
    rect: np.ndarray

    def take(self, rows) -> Prisms:
        return Prisms(*(getattr(self, f.name)[rows] for f in fields(self)))

    @staticmethod
    def concat(parts: list[Prisms]) -> Prisms:
        return Prisms(*(np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Prisms)))


def prisms(origin, axes, plane, height, polygon) -> Prisms:
    """Prisms with their bounds and, for those that are not boxes (the GEOS path), their grown and shrunk
    polygons and outlines (None for boxes: they are never asked)."""
    bounds = shapely.bounds(polygon).reshape(-1, 4)
    box_area = (bounds[:, 2] - bounds[:, 0]) * (bounds[:, 3] - bounds[:, 1])
    rect = (shapely.get_num_coordinates(polygon) == 5) & (np.abs(shapely.area(polygon) - box_area) <= 1e-9 * box_area)
    outer, inner, boundary = (np.full(len(polygon), None, dtype=object) for _ in range(3))
    other = ~rect
    if other.any():
        outer[other] = shapely.buffer(polygon[other], EPS, join_style="mitre")
        inner[other] = shapely.buffer(polygon[other], -EPS, join_style="mitre")
        boundary[other] = shapely.boundary(polygon[other])
    return Prisms(origin, axes, plane, height, polygon, outer, inner, boundary, bounds, rect)


def relations(corners: np.ndarray, edges: np.ndarray, prisms: Prisms,
              kinds=("inside", "overlaps", "touches")) -> dict[str, np.ndarray]:
    """The ``kinds`` of p pairs, each (p,) bool: query corners (p, c, 3) in world coordinates with the
    corner pairs ``edges`` (e, 2) of their polytope, against the pairs' prisms."""
    p = len(corners)
    local = np.matmul(corners - prisms.origin[:, None], np.transpose(prisms.axes, (0, 2, 1)))
    out = {kind: np.zeros(p, dtype=bool) for kind in kinds}
    fast = np.flatnonzero(prisms.rect)
    if len(fast):
        found = _boxes(local[fast], edges, prisms.take(fast))
        for kind in kinds:
            out[kind][fast] = found[:, ("inside", "overlaps", "touches").index(kind)]
    slow = np.flatnonzero(~prisms.rect)
    if len(slow):
        found = _prisms(local[slow], edges, prisms.take(slow), kinds)
        for kind in kinds:
            out[kind][slow] = found[kind]
    return out


def _boxes(local: np.ndarray, edges: np.ndarray, prisms: Prisms) -> np.ndarray:
    """``box_relations`` of queries (local corners (p, c, 3) in their boxes' frames) against boxes."""
    p, c = local.shape[:2]
    rows = np.arange(p)
    low, high = np.zeros((p, 3)), np.zeros((p, 3))
    u, v = PLANE_U[prisms.plane], PLANE_V[prisms.plane]
    low[rows, u], low[rows, v] = prisms.bounds[:, 0], prisms.bounds[:, 1]
    high[rows, u], high[rows, v], high[rows, prisms.plane] = prisms.bounds[:, 2], prisms.bounds[:, 3], prisms.height
    if c == 8:  # a box: its edge directions are its faces' normals
        dirs = np.stack([local[:, 1] - local[:, 0], local[:, 2] - local[:, 0], local[:, 4] - local[:, 0]], axis=1)
        normals = dirs
    elif c == 2:  # a segment: one direction, no face
        dirs = (local[:, 1] - local[:, 0])[:, None]
        normals = np.zeros((p, 0, 3))
    else:  # a face: two edge directions and its normal
        dirs = np.stack([local[:, 1] - local[:, 0], local[:, 3] - local[:, 0]], axis=1)
        normals = np.cross(dirs[:, 0], dirs[:, 1])[:, None]
    return box_relations(np.ascontiguousarray(local), low, high, np.ascontiguousarray(dirs),
                         np.ascontiguousarray(normals), EPS)


def _prisms(local: np.ndarray, edges: np.ndarray, prisms: Prisms, kinds) -> dict[str, np.ndarray]:
    """``relations`` against prisms of any polygon, in the plane with GEOS."""
    p, c = local.shape[:2]
    rows, cols = np.arange(p)[:, None], np.arange(c)[None]
    uv = np.stack([local[rows, cols, PLANE_U[prisms.plane][:, None]],
                   local[rows, cols, PLANE_V[prisms.plane][:, None]]], axis=2)
    w = local[rows, cols, prisms.plane[:, None]]
    out = {}
    if "inside" in kinds:
        within = (w >= -EPS).all(axis=1) & (w <= prisms.height[:, None] + EPS).all(axis=1)
        out["inside"] = within
        if within.any():
            out["inside"][within] = shapely.covers(prisms.outer[within],
                                                   _hulls(uv[within], np.ones(w[within].shape, dtype=bool)))
    if "overlaps" in kinds or "touches" in kinds:
        open_part, _ = _slab_part(uv, w, edges, EPS, prisms.height - EPS)
        out["overlaps"] = shapely.intersects(open_part, prisms.inner)
    if "touches" in kinds:
        touches = out["overlaps"].copy()
        rest = np.flatnonzero(~touches)
        if len(rest):
            part, w_extent = _slab_part(uv[rest], w[rest], edges, -EPS, prisms.height[rest] + EPS)
            near = np.flatnonzero(shapely.intersects(part, prisms.polygon[rest]))  # cheap before the exact
            part, w_extent, rest = part[near], w_extent[near], rest[near]
            met = shapely.area(shapely.intersection(part, prisms.polygon[rest])) > EPS * EPS
            along = shapely.length(shapely.intersection(part, prisms.boundary[rest])) > EPS
            touches[rest] = met | (along & (w_extent > 2 * EPS))  # more than the slab's margins
        out["touches"] = touches
    return out


def _slab_part(uv: np.ndarray, w: np.ndarray, edges: np.ndarray, low, high) -> tuple[np.ndarray, np.ndarray]:
    """The projection (p,) of each query's part in the slab low < w < high (its corners there and its
    edges' crossings of the two planes), and that part's extent along w (p,)."""
    low = np.broadcast_to(np.asarray(low, dtype=np.float64), (len(w),))[:, None]
    high = np.broadcast_to(np.asarray(high, dtype=np.float64), (len(w),))[:, None]
    keep = (w > low) & (w < high)
    points, where, kept_w = [uv], [keep], [w]
    a, b = edges[:, 0], edges[:, 1]
    for level in (low, high):
        wa, wb = w[:, a], w[:, b]
        crosses = (wa - level) * (wb - level) < 0
        t = np.where(crosses, (level - wa) / np.where(crosses, wb - wa, 1.0), 0.0)
        points.append(uv[:, a] + t[..., None] * (uv[:, b] - uv[:, a]))
        where.append(crosses)
        kept_w.append(np.broadcast_to(level, crosses.shape))
    points, where, kept_w = np.concatenate(points, 1), np.concatenate(where, 1), np.concatenate(kept_w, 1)
    extent = np.where(where, kept_w, -np.inf).max(axis=1) - np.where(where, kept_w, np.inf).min(axis=1)
    return _hulls(points, where), np.where(where.any(axis=1), extent, 0.0)


def _hulls(points: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Convex hulls (p,) of the kept points (p, k, 2) of each row (empty geometries where none)."""
    counts = keep.sum(axis=1)
    hulls = np.full(len(points), shapely.GeometryCollection(), dtype=object)
    some = counts > 0
    if some.any():
        offsets = np.concatenate([[0], np.cumsum(counts[some])])
        multi = shapely.from_ragged_array(shapely.GeometryType.MULTIPOINT, points[keep], (offsets,))
        hulls[some] = shapely.convex_hull(multi)
    return hulls


@njit(cache=True, nogil=True)
def box_relations(local, low, high, dirs, normals, eps):
    """``relations`` of convex queries against boxes, exactly, by separating axes (numba): corners
    ``local`` (p, c, 3) in the box's frame, the box ``low``..``high`` (p, 3), the query's edge
    directions ``dirs`` (p, d, 3) and face normals ``normals`` (p, f, 3). The candidate axes are the box's
    three, the query's normals and the cross products of its edge directions with the box's axes.
    Overlaps: every axis shows an overlap longer than eps. Touches: it overlaps, or no axis shows a gap
    and the axes that show no overlap all lie along one direction, across one of the box's faces and one
    of the query's (a plane the two share over an area, not an edge or a point). Inside: every corner in the box. Returns (p, 3) bool: inside, overlaps, touches."""
    p, c = local.shape[0], local.shape[1]
    out = np.zeros((p, 3), np.bool_)
    axes = np.empty((3 + normals.shape[1] + 3 * dirs.shape[1], 3))
    for k in range(p):
        inside = True
        for j in range(c):
            for a in range(3):
                if local[k, j, a] < low[k, a] - eps or local[k, j, a] > high[k, a] + eps:
                    inside = False
        n_axes = 0
        for a in range(3):
            axes[n_axes] = 0.0
            axes[n_axes, a] = 1.0
            n_axes += 1
        for f in range(normals.shape[1]):
            axes[n_axes] = normals[k, f]
            n_axes += 1
        for d in range(dirs.shape[1]):
            for a in range(3):
                e = dirs[k, d]
                axes[n_axes, 0] = e[1] * (a == 2) - e[2] * (a == 1)
                axes[n_axes, 1] = e[2] * (a == 0) - e[0] * (a == 2)
                axes[n_axes, 2] = e[0] * (a == 1) - e[1] * (a == 0)
                n_axes += 1
        overlaps = True
        gap = False
        flat_dir = np.zeros(3)
        n_flat = 0
        same_dir = True
        for i in range(n_axes):
            ax = axes[i]
            norm = np.sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2])
            if norm < 1e-9:
                continue
            ax = ax / norm
            q_min, q_max = np.inf, -np.inf
            for j in range(c):
                t = local[k, j, 0] * ax[0] + local[k, j, 1] * ax[1] + local[k, j, 2] * ax[2]
                q_min, q_max = min(q_min, t), max(q_max, t)
            b_min, b_max = 0.0, 0.0
            for a in range(3):
                lo_t, hi_t = low[k, a] * ax[a], high[k, a] * ax[a]
                b_min += min(lo_t, hi_t)
                b_max += max(lo_t, hi_t)
            if q_max - q_min <= eps:  # a flat query across this axis: how deep in the box it lies
                length = min(q_max - b_min, b_max - q_min)
            else:
                length = min(q_max, b_max) - max(q_min, b_min)
            if length < -eps:
                gap = True
            if length <= eps:
                overlaps = False
                if n_flat == 0:
                    flat_dir[:] = ax
                elif abs(flat_dir[0] * ax[0] + flat_dir[1] * ax[1] + flat_dir[2] * ax[2]) < 1 - 1e-9:
                    same_dir = False
                n_flat += 1
        # a shared plane: across one of the box's axes and one of the query's face normals
        planar = False
        if not overlaps and not gap and same_dir and n_flat > 0:
            box_face = max(abs(flat_dir[0]), abs(flat_dir[1]), abs(flat_dir[2])) > 1 - 1e-9
            for f in range(normals.shape[1]):
                nf = normals[k, f]
                norm = np.sqrt(nf[0] * nf[0] + nf[1] * nf[1] + nf[2] * nf[2])
                if box_face and norm > 1e-9 and abs(nf[0] * flat_dir[0] + nf[1] * flat_dir[1]
                                                    + nf[2] * flat_dir[2]) > (1 - 1e-9) * norm:
                    planar = True
        out[k, 0] = inside
        out[k, 1] = overlaps
        out[k, 2] = overlaps or planar
    return out
