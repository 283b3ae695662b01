"""Random footprints by class, for the differential harness: the lots real cities have and tidy kits lack.

Each class is a function of a numpy ``Generator`` that returns a valid shapely polygon in metres, exterior
counter-clockwise and holes clockwise (GeoJSON's orientation), centred near the origin. ``footprint`` then
turns it by a random angle and starts its exterior at a random vertex (PRT and grammarc align a lot's scope
with its first edge, so the start matters), and the class ``far`` moves it to national-grid coordinates.
A footprint is a pure function of (class, seed): a case file names both, and regenerating it gives the
same coordinates bit for bit.

Seeded generators rather than hypothesis strategies: the harness runs for hours against an external
oracle, one PRT call per batch of lots, which hypothesis's example-at-a-time search and shrinking do not
fit; what it keeps of hypothesis's way is the classes of inputs that break geometry code.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import shapely
from shapely.geometry import Polygon, box
from shapely.geometry.polygon import orient

__all__ = ["CLASSES", "footprint"]


def _convex(rng: np.random.Generator) -> Polygon:
    """The convex hull of 5-12 points in an ellipse of 5-30 m."""
    n = int(rng.integers(5, 13))
    radius = rng.uniform(5, 30)
    angle = rng.uniform(0, 2 * math.pi, n)
    r = radius * np.sqrt(rng.uniform(0.3, 1, n))
    points = np.column_stack([r * np.cos(angle), rng.uniform(0.4, 1) * r * np.sin(angle)])
    return shapely.convex_hull(shapely.multipoints(points))


def _concave(rng: np.random.Generator) -> Polygon:
    """A star polygon of 6-14 corners whose radii vary 0.4-1: reflex corners at random places."""
    n = int(rng.integers(6, 15))
    angle = np.sort(rng.uniform(0, 2 * math.pi, n))
    r = rng.uniform(8, 30) * rng.uniform(0.4, 1, n)
    return Polygon(np.column_stack([r * np.cos(angle), r * np.sin(angle)]))


def _letter(parts: Callable[[np.random.Generator, float, float, float, float], list]) -> Callable:
    """A class of orthogonal shapes: the union of the rectangles ``parts(rng, w, h, t1, t2)`` gives."""

    def make(rng: np.random.Generator) -> Polygon:
        w, h = rng.uniform(12, 45, 2)
        t1, t2 = rng.uniform(4, 0.4 * w), rng.uniform(4, 0.4 * h)
        return shapely.union_all([box(*b) for b in parts(rng, w, h, t1, t2)]).simplify(0)

    return make


_L = _letter(lambda rng, w, h, t1, t2: [(0, 0, w, t2), (0, 0, t1, h)])
_T = _letter(lambda rng, w, h, t1, t2: [(0, h - t2, w, h), ((w - t1) / 2, 0, (w + t1) / 2, h)])
_U = _letter(lambda rng, w, h, t1, t2: [(0, 0, w, t2), (0, 0, t1, h), (w - t1, 0, w, h)])
_H = _letter(lambda rng, w, h, t1, t2: [(0, 0, t1, h), (w - t1, 0, w, h), (0, (h - t2) / 2, w, (h + t2) / 2)])
_Z = _letter(lambda rng, w, h, t1, t2: [(0, h - t2, 0.6 * w, h), (0.4 * w, 0, w, t2),
                                       (0.4 * w, 0, 0.6 * w, h)])


def _acute(rng: np.random.Generator) -> Polygon:
    """A triangle or a quadrilateral with a corner of 10-35 degrees."""
    theta = math.radians(rng.uniform(10, 35))
    a = rng.uniform(15, 50)
    b = a * rng.uniform(0.8, 1.2)  # the other corners stay wide
    corners = [(0, 0), (a, 0), (b * math.cos(theta), b * math.sin(theta))]
    if rng.random() < 0.5:  # cut the far corners: a wedge-shaped lot
        corners.insert(2, (a, rng.uniform(1, 0.5 * b * math.sin(theta))))
    return Polygon(corners).buffer(0)


def _thin(rng: np.random.Generator) -> Polygon:
    """A long narrow lot, 30-120 m by 1.5-5 m, its short sides square or slanted."""
    length, width = rng.uniform(30, 120), rng.uniform(1.5, 5)
    skew = rng.uniform(-1, 1) * width if rng.random() < 0.5 else 0.0
    return Polygon([(0, 0), (length, 0), (length + skew, width), (skew, width)])


def _tiny(rng: np.random.Generator) -> Polygon:
    """A lot of 2-10 m^2: a small rectangle or a small convex polygon."""
    if rng.random() < 0.5:
        w = rng.uniform(1, 3.5)
        return box(0, 0, w, rng.uniform(2, 10) / w)
    polygon = _convex(rng)
    return shapely.affinity.scale(polygon, *(2 * [math.sqrt(rng.uniform(2, 10) / polygon.area)]))


def _courtyard(rng: np.random.Generator) -> Polygon:
    """A rectangle of 20-60 m with one hole, a rectangle turned by up to 30 degrees, 3 m or more inside."""
    w, h = rng.uniform(20, 60, 2)
    hole = box(0, 0, rng.uniform(0.2, 0.5) * w, rng.uniform(0.2, 0.5) * h)
    hole = shapely.affinity.rotate(hole, rng.uniform(-30, 30))
    hole = shapely.affinity.translate(hole, w / 2 - hole.centroid.x, h / 2 - hole.centroid.y)
    return box(0, 0, w, h).difference(hole)


def _holes(rng: np.random.Generator) -> Polygon:
    """A rectangle of 30-70 m with 2-4 rectangular holes on a grid."""
    w, h = rng.uniform(30, 70, 2)
    n = int(rng.integers(2, 5))
    cell = w / n
    holes = [box(i * cell + 0.25 * cell, 0.25 * h, i * cell + rng.uniform(0.5, 0.75) * cell,
                 rng.uniform(0.5, 0.75) * h) for i in range(n)]
    return box(0, 0, w, h).difference(shapely.union_all(holes))


def _near_degenerate(rng: np.random.Generator) -> Polygon:
    """A convex or L lot with near-collinear vertices (0.1 mm-1 cm off an edge) and near-duplicates."""
    base = _convex(rng) if rng.random() < 0.5 else _L(rng)
    ring = np.asarray(base.exterior.coords)[:-1]
    out = []
    for i, p in enumerate(ring):
        out.append(p)
        q = ring[(i + 1) % len(ring)]
        u = rng.random()
        if u < 0.35:  # a vertex just off the edge's middle
            edge = q - p
            normal = np.array([-edge[1], edge[0]]) / np.hypot(*edge)
            out.append(p + edge * rng.uniform(0.2, 0.8) + normal * rng.choice([-1, 1]) * 10 ** rng.uniform(-4, -2))
        elif u < 0.55:  # a vertex a hundredth of a millimetre to a millimetre after this one
            out.append(p + (q - p) / np.hypot(*(q - p)) * 10 ** rng.uniform(-5, -3))
    return Polygon(out)


CLASSES: dict[str, Callable[[np.random.Generator], Polygon]] = {
    "convex": _convex, "concave": _concave, "L": _L, "T": _T, "U": _U, "Z": _Z, "H": _H, "acute": _acute,
    "thin": _thin, "tiny": _tiny, "courtyard": _courtyard, "holes": _holes,
    "near_degenerate": _near_degenerate, "far": _convex,
}


def footprint(kind: str, seed: int) -> Polygon:
    """The footprint of class ``kind`` made from ``seed``: turned, started at a random vertex, oriented.

    Raises
    ------
    KeyError
        If ``kind`` is not one of ``CLASSES``.
    """
    rng = np.random.default_rng([seed, sorted(CLASSES).index(kind)])
    polygon = CLASSES[kind](rng)
    while not (polygon.is_valid and polygon.geom_type == "Polygon"):  # a star whose corners met: draw again
        polygon = CLASSES[kind](rng)
    polygon = orient(polygon, 1.0)
    centroid = polygon.centroid
    polygon = shapely.affinity.rotate(polygon, rng.uniform(0, 360), origin=centroid)
    polygon = shapely.affinity.translate(polygon, -centroid.x, -centroid.y)
    if kind == "far":  # where UTM and national grids put European towns
        polygon = shapely.affinity.translate(polygon, rng.uniform(3e5, 7e5), rng.uniform(4e6, 6.5e6))
    ring = np.asarray(polygon.exterior.coords)[:-1]
    ring = np.roll(ring, -int(rng.integers(len(ring))), axis=0)
    return Polygon(ring, [np.asarray(h.coords) for h in polygon.interiors])
