"""Largest rectangles inside polygons with holes (CityEngine's ``innerRectangle``), many at once.

For one direction, the polygon is turned so that the direction is x, and cut by a grid whose lines are
the vertices' coordinates plus ``subdivisions`` even steps across its extent. No vertex lies inside a
band between two horizontal lines, so in a band the polygon's boundary crossings move linearly: a cell
is inside when it lies inside the polygon just above the band's bottom and just below its top. The
largest union of whole cells that is a rectangle is the largest rectangle under one of the rows'
histograms (how far up each column stays inside), found with a stack in one pass per row and weighted
by the cells' real sizes. Rectilinear polygons come out exact; slanted edges to within one grid step (the extent over
``subdivisions``).

``scope`` alignment uses the scope's x; ``edge`` tries the direction of every edge at least a quarter as
long as the polygon's longest (CityEngine's rule) and keeps the largest rectangle.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from grammarc.ragged import offsets_from_counts, row_groups, segment_of

#: Even grid steps across the polygon's extent, besides its vertices' coordinates.
SUBDIVISIONS = {"scope": 64, "edge": 32}


def largest_rectangles(polygons: np.ndarray, align: str) -> np.ndarray:
    """The largest rectangle inside each shapely polygon (m,), sides along the x axis (``scope``) or
    along one of its long edges (``edge``); an empty polygon where none has area."""
    if not len(polygons):
        return np.empty(0, dtype=object)
    _, coords, (ring_offsets, poly_offsets) = shapely.to_ragged_array(polygons)
    coords = np.ascontiguousarray(np.asarray(coords)[:, :2], dtype=np.float64)
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    poly_offsets = np.asarray(poly_offsets, dtype=np.int64)
    if align == "scope":
        angle = np.zeros(len(polygons))
        angle_offsets = np.arange(len(polygons) + 1, dtype=np.int64)
    else:
        angle, angle_offsets = _edge_directions(coords, ring_offsets, poly_offsets)
    corners = _rectangles(coords, ring_offsets, poly_offsets, angle, angle_offsets, SUBDIVISIONS[align])
    found = np.isfinite(corners[:, 0, 0])
    out = np.full(len(polygons), shapely.Polygon(), dtype=object)
    out[found] = shapely.polygons(corners[found])
    return out


def _edge_directions(coords, ring_offsets, poly_offsets):
    """Per polygon, the directions (radians) of its edges at least a quarter as long as its longest
    (closed rings: each ring's last point repeats its first), as ragged (angles, offsets)."""
    ring = segment_of(ring_offsets)
    last = np.r_[ring[1:] != ring[:-1], True]
    start = np.flatnonzero(~last)
    step = coords[start + 1] - coords[start]
    length = np.hypot(step[:, 0], step[:, 1])
    poly = segment_of(poly_offsets)[ring[start]]
    longest = np.zeros(len(poly_offsets) - 1)
    np.maximum.at(longest, poly, length)
    keep = (length >= longest[poly] / 4) & (length > 0)
    angle = np.arctan2(step[keep, 1], step[keep, 0]) % (np.pi / 2)  # a rectangle repeats every 90 degrees
    poly = poly[keep]
    # one per distinct direction of a polygon
    key = np.round(angle, 9)
    first = np.sort(row_groups(np.column_stack([poly, key]))[1])
    return angle[first], offsets_from_counts(np.bincount(poly[first], minlength=len(poly_offsets) - 1))


@njit(cache=True, nogil=True)
def _rectangles(coords, ring_offsets, poly_offsets, angle, angle_offsets, subdivisions):
    """(m, 5, 2) closed corner rings of each polygon's best rectangle over its candidate angles; NaN
    where none was found."""
    m = len(poly_offsets) - 1
    out = np.full((m, 5, 2), np.nan)
    for g in range(m):
        v0 = ring_offsets[poly_offsets[g]]
        v1 = ring_offsets[poly_offsets[g + 1]]
        rings = ring_offsets[poly_offsets[g]:poly_offsets[g + 1] + 1] - v0
        best = 0.0
        for k in range(angle_offsets[g], angle_offsets[g + 1]):
            c, s = np.cos(angle[k]), np.sin(angle[k])
            pts = np.empty((v1 - v0, 2))
            for j in range(v1 - v0):
                x, y = coords[v0 + j, 0], coords[v0 + j, 1]
                pts[j, 0], pts[j, 1] = x * c + y * s, -x * s + y * c
            area, x0, y0, x1, y1 = _axis_rectangle(pts, rings, subdivisions)
            if area > best:
                best = area
                for q, (u, w) in enumerate(((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0))):
                    out[g, q, 0], out[g, q, 1] = u * c - w * s, u * s + w * c
    return out


@njit(cache=True, nogil=True)
def _grid(values, subdivisions):
    lo, hi = values.min(), values.max()
    steps = np.linspace(lo, hi, subdivisions + 1)
    grid = np.unique(np.concatenate((values, steps)))
    # lines closer than rounding are one line
    keep = np.ones(len(grid), np.bool_)
    for i in range(1, len(grid)):
        if grid[i] - grid[i - 1] <= 1e-9 * max(hi - lo, 1.0):
            keep[i] = False
    return grid[keep]


@njit(cache=True, nogil=True)
def _axis_rectangle(pts, rings, subdivisions):
    """The largest axis-aligned rectangle of whole grid cells inside the polygon (closed rings ``rings``
    into ``pts``): area, x0, y0, x1, y1."""
    xs = _grid(pts[:, 0], subdivisions)
    ys = _grid(pts[:, 1], subdivisions)
    nx, ny = len(xs) - 1, len(ys) - 1
    inside = np.zeros((ny, nx), np.bool_)
    crossings = np.empty(len(pts))
    which = np.empty((2, nx), np.int64)  # the inside interval holding each cell, per sample (-1: none)
    tol = 1e-9 * (xs[-1] - xs[0] + 1.0)
    for j in range(ny):
        pad = (ys[j + 1] - ys[j]) * 1e-6
        for sample in range(2):
            y = ys[j] + pad if sample == 0 else ys[j + 1] - pad
            count = 0
            for r in range(len(rings) - 1):
                for q in range(rings[r], rings[r + 1] - 1):  # closed rings: q -> q + 1
                    ay, by = pts[q, 1], pts[q + 1, 1]
                    if (ay > y) != (by > y):
                        f = (y - ay) / (by - ay)
                        crossings[count] = pts[q, 0] + f * (pts[q + 1, 0] - pts[q, 0])
                        count += 1
            cut = np.sort(crossings[:count])
            p = 0  # both sorted: one sweep over the cells and the inside intervals [cut[p], cut[p + 1]]
            for i in range(nx):
                while p + 1 < count and cut[p + 1] + tol < xs[i + 1]:
                    p += 2
                which[sample, i] = p if p + 1 < count and cut[p] <= xs[i] + tol else -1
        # no vertex lies inside the band, so its crossings keep their order: a cell in the same interval
        # at the bottom and at the top of the band stays in it all the way (an interval's ends move
        # linearly), while one in different intervals has the boundary pass through it
        for i in range(nx):
            inside[j, i] = which[0, i] >= 0 and which[0, i] == which[1, i]
    # largest rectangle under each row's histogram of inside heights (bars of the cells' widths)
    best, bx0, by0, bx1, by1 = 0.0, 0.0, 0.0, 0.0, 0.0
    height = np.zeros(nx + 1)
    stack_start = np.empty(nx + 1, np.int64)
    stack_height = np.empty(nx + 1)
    for j in range(ny):
        for i in range(nx):
            height[i] = height[i] + (ys[j + 1] - ys[j]) if inside[j, i] else 0.0
        top = 0
        for i in range(nx + 1):  # height[nx] stays 0: it empties the stack
            start = i
            while top > 0 and stack_height[top - 1] >= height[i]:
                top -= 1
                h = stack_height[top]
                area = h * (xs[i] - xs[stack_start[top]])
                if area > best:
                    best, bx0, by0, bx1, by1 = area, xs[stack_start[top]], ys[j + 1] - h, xs[i], ys[j + 1]
                start = stack_start[top]
            stack_start[top], stack_height[top] = start, height[i]
            top += 1
    return best, bx0, by0, bx1, by1
