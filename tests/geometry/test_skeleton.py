"""Straight skeletons: the faces of hip roofs, on shapes with known skeletons and on random polygons."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.geometry.skeleton import skeleton_faces

RECT = [[(0, 0), (10, 0), (10, 4), (0, 4)]]
L_SHAPE = [[(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)]]
U_SHAPE = [[(0, 0), (40, 0), (40, 30), (30, 30), (30, 10), (10, 10), (10, 30), (0, 30)]]
#: The kit's U (arms as wide as the base is deep is not this one): its arms' ridges end where the notch's
#: corners reach them, at the same time as the arms close, a tie of three events.
KIT_U = [[(0, 0), (0, -30), (10, -30), (10, -15), (30, -15), (30, -30), (40, -30), (40, 0)]]
COURTYARD = [[(0, 0), (40, 0), (40, 40), (0, 40)], [(10, 10), (10, 30), (30, 30), (30, 10)]]
OCTAGON = [[(10 * np.cos(a), 10 * np.sin(a)) for a in np.arange(8) * np.pi / 4]]


def skeleton(rings, start_time=0.0, speed=None):
    xy = np.concatenate([np.asarray(r, dtype=float) for r in rings])
    ring_offsets = np.cumsum([0] + [len(r) for r in rings]).astype(np.int64)
    speed = None if speed is None else np.asarray(speed, float)
    node_xy, node_t, nodes, offsets, ok = skeleton_faces(xy, ring_offsets, start_time, speed)
    faces = [nodes[offsets[k]:offsets[k + 1]] for k in range(len(xy))]
    return xy, node_xy, node_t, faces, ok


def check_faces(rings, start_time=0.0):
    """Each face: its edge first, every node at the distance from the edge's line that its time says
    (the face is planar under a unit slope), and the faces tile the polygon moved out by -start_time."""
    xy, node_xy, node_t, faces, ok = skeleton(rings, start_time)
    assert ok
    ends = np.concatenate([np.roll(np.arange(len(r)), -1) + s for r, s in
                           zip(rings, np.cumsum([0] + [len(r) for r in rings]))])
    for k, face in enumerate(faces):
        assert list(face[:2]) == [k, ends[k]]
        d = xy[ends[k]] - xy[k]
        inward = np.array([-d[1], d[0]]) / np.linalg.norm(d)
        np.testing.assert_allclose(node_xy[face] @ inward - inward @ xy[k], node_t[face], atol=1e-7)
    polygon = shapely.Polygon(rings[0], rings[1:])
    # no point is reached later than its distance to the boundary
    reach = shapely.distance(shapely.points(node_xy), polygon.boundary)
    assert (node_t - start_time <= reach + 1e-7).all() or start_time
    if start_time:
        polygon = polygon.buffer(-start_time, join_style="mitre", mitre_limit=100)
    area = sum(shapely.Polygon(node_xy[f]).area for f in faces if len(f) >= 3)
    assert area == pytest.approx(polygon.area, rel=1e-9)
    return node_xy, node_t, faces


def test_rectangle_ridge_runs_along_the_middle_at_half_the_width():
    node_xy, node_t, faces = check_faces(RECT)
    assert [len(f) for f in faces] == [4, 3, 4, 3]  # trapezoids on the long sides, hip ends on the short
    ridge = node_xy[faces[0][2:]]
    np.testing.assert_allclose(sorted(map(tuple, ridge)), [(2, 2), (8, 2)])
    assert node_t.max() == pytest.approx(2.0)


@pytest.mark.parametrize("rings, top", [(L_SHAPE, 5.0), (U_SHAPE, 5.0), (KIT_U, 7.5), (COURTYARD, 5.0),
                                        (OCTAGON, 10 * np.cos(np.pi / 8))])
def test_known_shapes_rise_to_half_their_narrowest_wing(rings, top):
    _, node_t, _ = check_faces(rings)
    assert node_t.max() == pytest.approx(top)


def test_an_overhang_starts_the_wavefront_outside():
    node_xy, node_t, faces = check_faces(RECT, start_time=-1.0)
    assert node_t.min() == pytest.approx(-1.0)
    np.testing.assert_allclose(node_xy[faces[0][:2]], [(-1, -1), (11, -1)])


def random_polygon(seed, hole):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(5, 30))
    angles = np.sort(rng.uniform(0, 2 * np.pi, k))
    angles += (np.arange(k) * 2 * np.pi / k - angles) * 0.5
    radius = rng.uniform(6, 12, k)
    outer = np.stack([np.cos(angles), np.sin(angles)], axis=1) * radius[:, None]
    rings = [outer]
    inner = np.stack([np.cos(-np.arange(7) * 0.9), np.sin(-np.arange(7) * 0.9)], axis=1) * 2.0
    if hole and shapely.Polygon(outer).contains(shapely.Polygon(inner).buffer(0.5)):
        rings.append(inner)
    return rings


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_random_concave_polygons_with_holes_are_tiled_by_planar_faces(seed, hole):
    check_faces(random_polygon(seed, hole))


def test_weighted_skeleton_moves_each_edge_at_its_speed():
    """The rectangle's long edges at speed 1 and its short ends at 0 (an envelope's vertical gable walls):
    the ridge runs the whole length at half the width; at speed 1 everywhere the same input is the plain
    skeleton, node for node."""
    _, node_xy, node_t, faces, ok = skeleton(RECT, speed=[1.0, 0.0, 1.0, 0.0])
    assert ok
    ridge = {tuple(np.round(p, 9)) for p, t in zip(node_xy, node_t) if t > 0}
    assert ridge == {(0.0, 2.0), (10.0, 2.0)} and np.allclose(node_t[node_t > 0], 2.0)
    assert [len(f) for f in faces] == [4, 3, 4, 3]
    plain, weighted = skeleton(L_SHAPE), skeleton(L_SHAPE, speed=np.ones(6))
    assert all(np.array_equal(a, b) for a, b in zip(plain[1:3], weighted[1:3]))
