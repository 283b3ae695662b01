"""geometry/ridges.py: roofs of two planes under one ridge along a given direction (roofRidge, roofGable
with an edge index)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from grammarc.geometry.ridges import ridge_roofs

TAN30 = np.tan(np.radians(30))


def faces(result):
    """Each face's outer ring (m, 3) of a one-polygon result."""
    verts, rings, face_offsets, _, _ = result
    return [verts[rings[face_offsets[f]]:rings[face_offsets[f] + 1]] for f in range(len(face_offsets) - 1)]


def area(ring):
    return np.linalg.norm(np.cross(ring, np.roll(ring, -1, axis=0)).sum(axis=0)) / 2


def roof(polygon, direction, value=30.0, by_height=False, overhang=(0.0, 0.0)):
    return ridge_roofs(np.array([polygon]), np.array([2]), np.array([direction], float), np.array([value]),
                       by_height, np.array([overhang[0]]), np.array([overhang[1]]), 1e-9)


def test_a_rectangle_gets_a_gable_along_the_direction():
    """10 x 6, ridge along u: two planes of 10 x 3/cos30, two gable triangles, the bottom."""
    result = roof(shapely.box(0, 0, 10, 6), (1, 0))
    assert result[4].all()
    got = faces(result)
    assert len(got) == 5
    assert area(got[0]) == pytest.approx(60)
    assert sorted(area(f) for f in got[1:3]) == [pytest.approx(10 * 3 / np.cos(np.radians(30)))] * 2
    assert sorted(area(f) for f in got[3:]) == [pytest.approx(3 * 3 * TAN30)] * 2
    assert max(f[:, 2].max() for f in got) == pytest.approx(3 * TAN30)
    # the bottom faces down, the roof planes up, the walls outwards
    normals = [np.cross(f[1] - f[0], f[2] - f[0]) for f in got]
    assert normals[0][2] < 0 and normals[1][2] > 0 and normals[2][2] > 0
    assert sorted(np.sign(n[0]) for n in normals[3:]) == [-1, 1]


def test_across_the_other_way_and_by_height():
    result = roof(shapely.box(0, 0, 10, 6), (0, 1), value=2.0, by_height=True)
    got = faces(result)
    assert max(f[:, 2].max() for f in got) == pytest.approx(2)
    assert sorted(area(f) for f in got[3:]) == [pytest.approx(10 * 2 / 2)] * 2


def test_overhangs_grow_the_roof_across_and_along_the_ridge():
    """overhangX 1 on the roof: 0.866 out and 0.5 down at the eaves; overhangY 0.5 out at the gables."""
    got = faces(roof(shapely.box(0, 0, 10, 6), (1, 0), overhang=(1.0, 0.5)))
    top = np.concatenate(got[1:3])
    np.testing.assert_allclose(top.min(axis=0), [-0.5, -np.cos(np.radians(30)), -0.5], atol=1e-9)
    np.testing.assert_allclose(top.max(axis=0), [10.5, 6 + np.cos(np.radians(30)), 3 * TAN30], atol=1e-9)
    assert area(got[0]) == pytest.approx(60)  # the bottom and the walls stay on the outline


def test_an_l_becomes_part_of_two_planes_with_walls_under_its_edges():
    """The L's extent across the ridge is 20: the ridge at 10, the inner corner's edges get walls."""
    lot = shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)])
    got = faces(roof(lot, (1, 0), value=2.0, by_height=True))
    assert area(got[0]) == pytest.approx(400)
    roof_area = sum(area(f) for f in got if np.ptp(f[:, 2]) > 0 and np.ptp(f[:, 0]) > 1 and np.ptp(f[:, 1]) > 1)
    assert roof_area == pytest.approx(400 * np.hypot(1, 0.2))
    walls = [f for f in got[1:] if abs(np.cross(f[1] - f[0], f[2] - f[0])[2]) < 1e-9]
    # the edge at v = 10 (x 10..30) stands under the ridge: a wall 20 long and 2 high
    assert max(area(w) for w in walls) == pytest.approx(40)


def test_a_polygon_without_extent_across_the_ridge_fails():
    assert not roof(shapely.box(0, 0, 10, 0), (1, 0))[4].any()
