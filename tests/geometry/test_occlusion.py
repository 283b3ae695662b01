"""Occlusion relations of query boxes and faces against prism occluders (``geometry.occlusion``)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from grammarc.geometry.occlusion import BOX_CORNERS, BOX_EDGES, QUAD_CORNERS, QUAD_EDGES, prisms, relations

L_SHAPE = shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)])


def prism(polygon, height, n=1):
    """An upright prism (x-z plane, extruded along y) at the world origin, n copies."""
    return prisms(np.zeros((n, 3)), np.tile(np.eye(3), (n, 1, 1)), np.ones(n, dtype=np.int64),
                  np.full(n, float(height)), np.full(n, polygon, dtype=object))


def box(low, size):
    return np.asarray(low, float) + BOX_CORNERS * np.asarray(size, float)


def quad(origin, x, y):
    origin, x, y = (np.asarray(a, float) for a in (origin, x, y))
    return origin + QUAD_CORNERS[:, :1] * x + QUAD_CORNERS[:, 1:2] * y


@pytest.mark.parametrize("low, size, expected", [
    ([2, 1, 2], [3, 3, 3], (True, True, True)),        # in the L's first arm
    ([8, 1, 8], [4, 3, 4], (False, True, True)),       # across the inner corner, partly in the notch
    ([12, 1, 12], [4, 3, 4], (False, False, False)),   # in the notch: the hull of the L would say inside
    ([30, 1, 2], [4, 3, 4], (False, False, True)),     # against the end wall x = 30
    ([2, 10, 2], [4, 3, 4], (False, False, True)),     # standing on the roof (height 10)
    ([30, 10, 2], [4, 3, 4], (False, False, False)),   # only an edge in common
    ([40, 1, 2], [4, 3, 4], (False, False, False)),    # away
])
def test_boxes_against_a_concave_prism(low, size, expected):
    inside, overlaps, touches = relations(box(low, size)[None], BOX_EDGES, prism(L_SHAPE, 10)).values()
    assert (bool(inside[0]), bool(overlaps[0]), bool(touches[0])) == expected


@pytest.mark.parametrize("face, expected", [
    (quad([30, 0, 2], [0, 0, 4], [0, 3, 0]), (True, False, True)),     # a window in the end wall's plane
    (quad([30, 0, 12], [0, 0, 4], [0, 3, 0]), (False, False, False)),  # in that plane, but past the wall
    (quad([25, 0, 2], [0, 0, 4], [0, 3, 0]), (True, True, True)),      # through the solid
    (quad([5, 4, 5], [2, 0, 0], [0, 0, 2]), (True, True, True)),       # a floor inside
    (quad([5, 10, 5], [2, 0, 0], [0, 0, 2]), (True, False, True)),     # on the roof
    (quad([5, 12, 5], [2, 0, 0], [0, 0, 2]), (False, False, False)),   # above it
])
def test_faces_against_a_concave_prism(face, expected):
    inside, overlaps, touches = relations(face[None], QUAD_EDGES, prism(L_SHAPE, 10)).values()
    assert (bool(inside[0]), bool(overlaps[0]), bool(touches[0])) == expected


def test_pairs_are_independent_and_the_prism_may_turn():
    turned = prisms(np.array([[0.0, 0, 0]] * 2), np.array([[[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]] * 2),
                    np.array([1, 1]), np.array([10.0, 10.0]), np.array([shapely.box(0, 0, 5, 5)] * 2, dtype=object))
    # the scope's x runs along world z, its z along world -x: the box covers world x -5..0, z 0..5
    corners = np.stack([box([-4, 1, 1], [2, 2, 2]), box([1, 1, 1], [2, 2, 2])])
    found = relations(corners, BOX_EDGES, turned)
    assert found["inside"].tolist() == [True, False] and found["overlaps"].tolist() == [True, False]
    assert found["touches"].tolist() == [True, False]
    assert set(relations(corners, BOX_EDGES, turned, ("inside",))) == {"inside"}


@pytest.mark.parametrize("seed", range(3))
def test_separating_axes_on_boxes_agree_with_the_planar_test(seed):
    """Box occluders take the numba path (separating axes); the same pairs through the GEOS path (the
    polygon of a prism of any outline) give the same answers, for boxes and faces placed on a grid of
    positions that makes many of them touch, overlap or lie inside exactly."""
    from dataclasses import replace

    from grammarc.geometry.occlusion import EPS, _boxes, _prisms

    rng = np.random.default_rng(seed)
    n = 400
    occluders = prism(shapely.box(0, 0, 4, 4), 3, n)
    # the GEOS path's outlines, which prisms() does not make for boxes
    as_any = replace(occluders, outer=shapely.buffer(occluders.polygon, EPS, join_style="mitre"),
                     inner=shapely.buffer(occluders.polygon, -EPS, join_style="mitre"),
                     boundary=shapely.boundary(occluders.polygon))
    for corners_of, edges in ((lambda lo, size, _: box(lo, size), BOX_EDGES),
                              (lambda lo, size, k: [quad(lo, [size[0], 0, 0], [0, size[1], 0]),
                                                    quad(lo, [size[0], 0, 0], [0, 0, size[2]]),
                                                    quad(lo, [0, size[1], 0], [0, 0, size[2]])][k], QUAD_EDGES)):
        low = rng.integers(-2, 5, (n, 3)).astype(float)
        size = rng.integers(1, 4, (n, 3)).astype(float)
        corners = np.stack([corners_of(low[i], size[i], i % 3) for i in range(n)])
        fast = _boxes(corners, edges, occluders)
        slow = _prisms(corners, edges, as_any, ("inside", "overlaps", "touches"))
        for k, kind in enumerate(("inside", "overlaps", "touches")):
            np.testing.assert_array_equal(fast[:, k], slow[kind], err_msg=kind)
