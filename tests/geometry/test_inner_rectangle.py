"""Largest inner rectangles: exact on rectilinear and rotated shapes, always inside, on random polygons."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from grammarc.geometry.inner_rectangle import largest_rectangles

L_SHAPE = shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)])
COURTYARD = shapely.Polygon([(0, 0), (40, 0), (40, 40), (0, 40)], [[(10, 10), (10, 30), (30, 30), (30, 10)]])
ROTATED = shapely.affinity.rotate(shapely.box(0, 0, 25, 15), 30)
TRIANGLE = shapely.Polygon([(0, 0), (20, 0), (0, 15)])


@pytest.mark.parametrize("polygon, scope, edge", [
    (L_SHAPE, 300.0, 300.0),       # the 30 x 10 arm
    (COURTYARD, 400.0, 400.0),     # one 40 x 10 side of the ring
    (ROTATED, None, 375.0),        # the whole rotated rectangle, found along its edges
    (TRIANGLE, 75.0, 75.0),        # half the right triangle, with the corner at the right angle
])
def test_known_largest_rectangles(polygon, scope, edge):
    by_scope, by_edge = (largest_rectangles(np.array([polygon]), a)[0] for a in ("scope", "edge"))
    if scope is not None:
        assert by_scope.area == pytest.approx(scope, rel=1e-9)
    assert by_edge.area == pytest.approx(edge, rel=1e-9)
    for rectangle in (by_scope, by_edge):
        assert shapely.oriented_envelope(rectangle).area == pytest.approx(rectangle.area)  # a rectangle
        assert rectangle.within(polygon.buffer(1e-7))


def test_scope_rectangles_have_sides_along_x_and_y():
    [rectangle] = largest_rectangles(np.array([ROTATED]), "scope")
    x, y = np.asarray(rectangle.exterior.coords).T
    assert len(set(np.round(x, 9))) == 2 and len(set(np.round(y, 9))) == 2


def star(seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(5, 30))
    angles = np.sort(rng.uniform(0, 2 * np.pi, k))
    radius = rng.uniform(4, 12, k)
    polygon = shapely.Polygon(np.stack([np.cos(angles), np.sin(angles)], axis=1) * radius[:, None]).buffer(0)
    return polygon if isinstance(polygon, shapely.Polygon) else max(polygon.geoms, key=lambda g: g.area)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["scope", "edge"]))
@example(1001, "scope")  # a reflex spike whose wedge crosses a cell between the band's two samples
def test_rectangles_lie_inside_random_polygons(seed, align):
    polygon = star(seed)
    [rectangle] = largest_rectangles(np.array([polygon]), align)
    assert rectangle.within(polygon.buffer(1e-7)) and rectangle.area > 0
    assert shapely.oriented_envelope(rectangle).area == pytest.approx(rectangle.area)
