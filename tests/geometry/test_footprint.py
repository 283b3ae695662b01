"""Lot scopes and footprint polygons (grammarc.geometry.footprint) on the zoo, rotated and shifted.

Conventions (README, "The record"): world x = map x, world z = -map y; scope x along the lot's first edge, y up,
z = x cross y; origin where the footprint's box starts, so the footprint lies in the positive quadrant.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.geometry.footprint import footprint_polygons, lot_scopes
from grammarc.io.lots import lots_from_polygons
from grammarc.ragged import segment_of

ZOO = tuple(LOT_ZOO)
RECTS = {"square", "rect_12x8", "sliver"}


def rotated(polygon, degrees, shift=(0.0, 0.0)):
    t = np.radians(degrees)
    rot = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
    return [ring @ rot.T + shift for ring in polygon]


def zoo_lots(degrees=0.0, shift=(0.0, 0.0)):
    return lots_from_polygons([rotated(LOT_ZOO[k], degrees, shift) for k in ZOO], ids=list(ZOO))


ANGLES = [0.0, 30.0, -75.0, 180.0]


def vertex_lot(lots):
    return segment_of(lots.lot_offsets)[segment_of(lots.ring_offsets)]


@pytest.mark.parametrize("degrees", ANGLES)
def test_axes_orthonormal_right_handed_y_up(degrees):
    lots = zoo_lots(degrees, (250.0, -40.0))
    _, axes, _, _ = lot_scopes(lots)
    for a in axes:
        np.testing.assert_allclose(a @ a.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(a) == pytest.approx(1.0)
        np.testing.assert_allclose(np.cross(a[0], a[1]), a[2], atol=1e-12)
        np.testing.assert_allclose(a[1], [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize("degrees", ANGLES)
def test_x_along_first_edge_in_world(degrees):
    """The first map edge of every zoo lot runs along map +x; rotated by t it is world (cos t, 0, -sin t)."""
    _, axes, _, _ = lot_scopes(zoo_lots(degrees))
    t = np.radians(degrees)
    for a in axes:
        np.testing.assert_allclose(a[0], [np.cos(t), 0.0, -np.sin(t)], atol=1e-12)


def test_unrotated_square_scope():
    lots = lots_from_polygons([LOT_ZOO["square"]])
    origin, axes, size, local = lot_scopes(lots)
    np.testing.assert_allclose(axes[0], np.eye(3), atol=1e-15)
    np.testing.assert_allclose(origin[0], [0, 0, -10])  # map (0, 10) is the corner nearest -z
    np.testing.assert_allclose(size[0], [10, 0, 10])
    np.testing.assert_allclose(local, [[0, 0, 10], [10, 0, 10], [10, 0, 0], [0, 0, 0]], atol=1e-12)


@pytest.mark.parametrize("degrees", ANGLES)
def test_local_vertices_fill_the_scope(degrees):
    lots = zoo_lots(degrees, (1000.0, 2000.0))
    origin, axes, size, local = lot_scopes(lots)
    vl = vertex_lot(lots)
    assert local.shape == (len(lots.vertices), 3)
    assert np.all(size[:, 1] == 0.0)
    # y = 0, inside [0, size] on x and z, touching both ends (the box is tight)
    np.testing.assert_allclose(local[:, 1], 0.0, atol=1e-9)
    for k in (0, 2):
        assert np.all(local[:, k] >= -1e-9)
        assert np.all(local[:, k] <= size[vl, k] + 1e-9)
        for lot in range(len(lots)):
            np.testing.assert_allclose(local[vl == lot, k].min(), 0.0, atol=1e-9)
            np.testing.assert_allclose(local[vl == lot, k].max(), size[lot, k], atol=1e-9)
    # local coordinates map back to the world vertices
    world = origin[vl] + np.einsum("vi,vij->vj", local, axes[vl])
    np.testing.assert_allclose(world, lots.vertices, atol=1e-9)


@pytest.mark.parametrize("degrees", ANGLES)
def test_sizes_of_the_zoo(degrees):
    _, _, size, _ = lot_scopes(zoo_lots(degrees, (3.0, 4.0)))
    want = {"square": (10, 10), "rect_12x8": (12, 8), "concave_L": (30, 20), "courtyard": (40, 40),
            "sliver": (50, 0.05)}
    np.testing.assert_allclose(size[:, [0, 2]], [want[k] for k in ZOO], rtol=1e-9)


@pytest.mark.parametrize("degrees", ANGLES)
def test_is_rect_and_normalized_polygons(degrees):
    lots = zoo_lots(degrees, (-30.0, 12.5))
    _, _, size, local = lot_scopes(lots)
    is_rect, coords, ring_offsets, poly_offsets = footprint_polygons(lots, size, local)
    assert is_rect.tolist() == [k in RECTS for k in ZOO]
    assert np.all((coords >= -1e-9) & (coords <= 1 + 1e-9))
    assert ring_offsets[0] == 0 and poly_offsets[0] == 0
    assert ring_offsets[-1] == len(coords)
    assert poly_offsets[-1] == len(ring_offsets) - 1
    # the L has one ring of 6 vertices, the courtyard two of 4
    assert np.diff(poly_offsets).tolist() == [1, 2]
    assert np.diff(ring_offsets).tolist() == [6, 4, 4]
    # normalized coords times the scope size are the local vertices, ring by ring
    vl = vertex_lot(lots)
    poly_lots = np.flatnonzero(~is_rect)
    want = np.concatenate([local[vl == lot][:, [0, 2]] / size[lot, [0, 2]] for lot in poly_lots])
    np.testing.assert_allclose(coords, want, atol=1e-9)


def test_courtyard_hole_in_normalized_coords():
    lots = lots_from_polygons([LOT_ZOO["courtyard"]])
    _, _, size, local = lot_scopes(lots)
    _, coords, ring_offsets, _ = footprint_polygons(lots, size, local)
    hole = coords[ring_offsets[1]:ring_offsets[2]]
    np.testing.assert_allclose(np.sort(np.unique(hole)), [0.25, 0.75])


@pytest.mark.parametrize("ring", [
    [[0, 0], [10, 0], [8, 5], [2, 5]],       # trapezoid
    [[0, 0], [10, 0], [12, 5], [2, 5]],      # parallelogram
    [[0, 0], [10, 0], [10, 5], [5, 2]],      # concave quad
], ids=["trapezoid", "parallelogram", "dart"])
@pytest.mark.parametrize("degrees", [0.0, 30.0])
def test_four_vertices_but_not_a_rectangle(ring, degrees):
    lots = lots_from_polygons([rotated([np.array(ring, float)], degrees)])
    assert not lots.bad
    _, _, size, local = lot_scopes(lots)
    is_rect, coords, _, _ = footprint_polygons(lots, size, local)
    assert is_rect.tolist() == [False]
    assert len(coords) == 4


@pytest.mark.parametrize("degrees", [30.0, 45.0, 123.0])
def test_rotated_rectangles_are_rects(degrees):
    polygons = [rotated([np.array([[0, 0], [w, 0], [w, h], [0, h]], float)], degrees, (7.0, -3.0))
                for w, h in ((10, 10), (12, 8), (3.5, 40), (50, 0.05))]
    lots = lots_from_polygons(polygons)
    _, _, size, local = lot_scopes(lots)
    is_rect, coords, ring_offsets, poly_offsets = footprint_polygons(lots, size, local)
    assert is_rect.all()
    assert len(coords) == 0 and ring_offsets.tolist() == [0] and poly_offsets.tolist() == [0]


def test_clockwise_ring_starting_at_concave_corner():
    """A clockwise L is reversed keeping v0, so it gets the scope of the same L wound counter-clockwise."""
    ccw = np.array([[10, 10], [10, 20], [0, 20], [0, 0], [30, 0], [30, 10]], float)
    cw = np.concatenate([ccw[:1], ccw[:0:-1]])
    lots = lots_from_polygons([[ccw], [cw]])
    origin, axes, size, local = lot_scopes(lots)
    np.testing.assert_allclose(origin[0], origin[1])
    np.testing.assert_allclose(axes[0], axes[1])
    # the first edge runs map +y = world -z; the extent along it is the L's 20
    np.testing.assert_allclose(axes[0], [[0, 0, -1], [0, 1, 0], [1, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(size, [[20, 0, 30]] * 2, atol=1e-9)
    np.testing.assert_allclose(local[0, 2], local[1, 2], atol=1e-12)  # v0 -> v1 along x
    assert local[:6, 0].min() == pytest.approx(0.0, abs=1e-12)
    assert local[:6, 2].min() == pytest.approx(0.0, abs=1e-12)


def test_no_lots():
    lots = lots_from_polygons([])
    origin, axes, size, local = lot_scopes(lots)
    assert origin.shape == (0, 3) and axes.shape == (0, 3, 3) and size.shape == (0, 3)
    assert local.shape == (0, 3)
    is_rect, coords, ring_offsets, poly_offsets = footprint_polygons(lots, size, local)
    assert is_rect.shape == (0,) and coords.shape == (0, 2)
    assert ring_offsets.tolist() == [0] and poly_offsets.tolist() == [0]


@pytest.mark.parametrize("name", ZOO)
def test_one_lot(name):
    """A lot alone has the scope it has among others."""
    together = lot_scopes(zoo_lots(30.0))
    alone = lot_scopes(lots_from_polygons([rotated(LOT_ZOO[name], 30.0)]))
    i = ZOO.index(name)
    for a, b in zip(alone[:3], together[:3]):
        np.testing.assert_allclose(a[0], b[i], atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(w=st.floats(0.5, 200), h=st.floats(0.5, 200), degrees=st.floats(-180, 180),
       sx=st.floats(-1e5, 1e5), sy=st.floats(-1e5, 1e5))
def test_any_rotated_rectangle_is_a_rect_of_its_size(w, h, degrees, sx, sy):
    ring = np.array([[0, 0], [w, 0], [w, h], [0, h]], float)
    lots = lots_from_polygons([rotated([ring], degrees, (sx, sy))])
    _, axes, size, local = lot_scopes(lots)
    # rounding of coordinates near 1e5 m (ulp ~1.5e-11), times the lever arm of a 0.5 x 200 lot
    np.testing.assert_allclose(size[0], [w, 0, h], rtol=1e-9, atol=1e-8)
    np.testing.assert_allclose(axes[0] @ axes[0].T, np.eye(3), atol=1e-12)
    assert np.linalg.det(axes[0]) == pytest.approx(1.0)
    assert footprint_polygons(lots, size, local)[0].tolist() == [True]
    assert np.all(local[:, [0, 2]] >= -1e-9 * max(w, h))
