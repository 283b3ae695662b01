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

Everything runs on arrays of pairs: numpy for the frames and slab clipping, shapely's vectorized
predicates for the planar part. ``EPS`` (metres) absorbs rounding, so faces that meet exactly touch.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import shapely

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
    ``inner`` (k,) the polygons grown and shrunk by ``EPS``, ``boundary`` (k,) their outlines (made
    once by ``prisms``, not per query)."""

    origin: np.ndarray
    axes: np.ndarray
    plane: np.ndarray
    height: np.ndarray
    polygon: np.ndarray
    outer: np.ndarray
    inner: np.ndarray
    boundary: np.ndarray

    def take(self, rows) -> Prisms:
        return Prisms(*(getattr(self, f.name)[rows] for f in fields(self)))

    @staticmethod
    def concat(parts: list[Prisms]) -> Prisms:
        return Prisms(*(np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Prisms)))


def prisms(origin, axes, plane, height, polygon) -> Prisms:
    """Prisms with their grown and shrunk polygons and outlines."""
    return Prisms(origin, axes, plane, height, polygon, shapely.buffer(polygon, EPS, join_style="mitre"),
                  shapely.buffer(polygon, -EPS, join_style="mitre"), shapely.boundary(polygon))


def relations(corners: np.ndarray, edges: np.ndarray, prisms: Prisms,
              kinds=("inside", "overlaps", "touches")) -> dict[str, np.ndarray]:
    """The ``kinds`` of p pairs, each (p,) bool: query corners (p, c, 3) in world coordinates with the
    corner pairs ``edges`` (e, 2) of their polytope, against the pairs' prisms."""
    p, c = corners.shape[:2]
    local = np.matmul(corners - prisms.origin[:, None], np.transpose(prisms.axes, (0, 2, 1)))
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
            touches[rest] = met | (along & (w_extent > EPS))
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
