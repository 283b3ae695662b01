"""geometry/box_distance.py: the least distance between oriented boxes (solids, faces, segments, points)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grammarc.geometry.box_distance import box_distances

AXES = np.eye(3)


def turned(degrees: float) -> np.ndarray:
    """Axes (rows) turned about y."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])


def distance(a, b) -> float:
    """``a`` and ``b`` as (origin, axes, size)."""
    return float(box_distances(*(np.array([x]) for x in (*a, *b)))[0])


@pytest.mark.parametrize(("b_origin", "expected"), [
    ((3, 0, 0), 2.0),                       # face to face along x
    ((3, 4, 0), math.hypot(2, 3)),          # edge to edge
    ((3, 4, 5), math.sqrt(4 + 9 + 16)),     # corner to corner
    ((1, 0, 0), 0.0),                       # touching faces meet
    ((0.5, 0.5, 0.5), 0.0),                 # overlapping
])
def test_unit_boxes_apart_along_the_axes(b_origin, expected):
    assert distance(((0, 0, 0), AXES, (1, 1, 1)), (b_origin, AXES, (1, 1, 1))) == pytest.approx(expected)


def test_a_turned_box_points_a_corner_edge_at_the_cube():
    """A cube turned 45 degrees about y points its vertical edge at x = 3 (its origin's) at the unit cube's
    face x = 1; lifted 2 m, the edge's lower end is nearest the cube's top edge."""
    assert distance(((0, 0, 0), AXES, (1, 1, 1)), ((3, 0, 0.5), turned(45), (1, 1, 1))) == pytest.approx(2)
    assert distance(((0, 0, 0), AXES, (1, 1, 1)), ((3, 2, 0.5), turned(45), (1, 1, 1))) == pytest.approx(math.sqrt(5))


def test_a_rod_through_a_slab_meets_it_though_no_corner_or_edge_does():
    """A thin rod pierces a wide slab through its faces: only the separating axes see that they meet."""
    slab = ((-5, 0, -5), AXES, (10, 0.2, 10))
    rod = ((0, -2, 0), AXES, (0.1, 4, 0.1))
    assert distance(slab, rod) == 0.0
    assert distance(slab, ((0, 1, 0), AXES, (0.1, 4, 0.1))) == pytest.approx(0.8)


def test_flat_scopes_segments_and_points():
    face = ((0, 0, 0), AXES, (4, 0, 2))  # a footprint's rectangle
    assert distance(face, ((1, 3, 1), AXES, (0, 0, 0))) == pytest.approx(3)  # a point above it
    assert distance(face, ((6, 0, 0), AXES, (0, 0, 5))) == pytest.approx(2)  # a segment beside it
    assert distance(face, ((5, 0, 3), AXES, (1, 0, 1))) == pytest.approx(math.sqrt(2))  # a face corner away
    assert distance(face, ((2, 0, 1), AXES, (0, 0, 0))) == 0.0  # a point on it


def test_many_pairs_against_a_minimizer():
    """Random boxes (some flat), turned every way: the distance is the least over both boxes' points."""
    from scipy.optimize import minimize
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(7)
    n = 40
    origin_a, origin_b = rng.uniform(-2, 2, (n, 3)), rng.uniform(-2, 2, (n, 3))
    axes_a, axes_b = Rotation.random(n, random_state=1).as_matrix(), Rotation.random(n, random_state=2).as_matrix()
    size_a, size_b = rng.uniform(0, 2, (n, 3)), rng.uniform(0, 2, (n, 3))
    size_a[rng.random((n, 3)) < 0.2] = 0
    found = box_distances(origin_a, axes_a, size_a, origin_b, axes_b, size_b)
    for i in range(n):
        def gap(x, i=i):
            return np.sum((origin_a[i] + (x[:3] * size_a[i]) @ axes_a[i] - origin_b[i] - (x[3:] * size_b[i]) @ axes_b[i]) ** 2)
        least = min(minimize(gap, rng.random(6), bounds=[(0, 1)] * 6, method="L-BFGS-B",
                             options={"ftol": 1e-15, "gtol": 1e-12}).fun for _ in range(3))
        assert found[i] == pytest.approx(math.sqrt(max(least, 0.0)), abs=1e-4)
