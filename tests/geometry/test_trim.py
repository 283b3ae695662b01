"""Trim planes: bisectors at the corners where a component split's side faces meet, and triangles cut by
them."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.trim import plane_coordinates, shallow_edge_planes, side_face_planes, trim_triangles
from grammarc.model.assets import builtin_mesh

UP = np.tile([0.0, 1.0, 0.0], (4, 1))  # the split solid's scope y: world up


def box_sides(width=10.0, depth=6.0, height=3.0):
    """The four side faces of a width x depth box, counter-clockwise seen from above (x east, y up):
    axes rows (edge direction, up, outward normal), origin at each face's start corner."""
    corners = np.array([[0, 0, 0], [width, 0, 0], [width, 0, -depth], [0, 0, -depth]], float)
    axes, origin, size = [], [], []
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        x = (b - a) / np.linalg.norm(b - a)
        y = np.array([0.0, 1.0, 0.0])
        axes.append([x, y, np.cross(x, y)])
        origin.append(a)
        size.append([np.linalg.norm(b - a), height, 0.0])
    return np.array(axes), np.array(origin), np.array(size)


def test_side_faces_of_a_box_meet_in_45_degree_planes():
    axes, origin, size = box_sides()
    planes = side_face_planes(axes, origin, size, np.zeros(4, dtype=np.int64), UP)
    assert not np.isnan(planes).any()
    # face 0 runs east along z = 0; its start plane bisects the corner with face 3 (running south to
    # north along x = 0): points of face 0 are kept, points of face 3 beyond the corner are not
    start, end = planes[0, :4], planes[0, 4:]
    np.testing.assert_allclose(np.abs(start[:3]), [np.sqrt(0.5), 0, np.sqrt(0.5)], atol=1e-12)
    assert start[:3] @ [5, 1, 0] + start[3] > 0 and start[:3] @ [-1, 1, 0.5] + start[3] < 0
    assert end[:3] @ [5, 1, 0] + end[3] > 0 and end[:3] @ [11, 1, 0.5] + end[3] < 0


def test_faces_without_a_steep_neighbour_have_no_planes():
    axes, origin, size = box_sides()
    lying = axes.copy()
    lying[:, 1] = [0, 0, 1]  # "up" along the ground: the shared edges are horizontal
    planes = side_face_planes(lying, origin, size, np.zeros(4, dtype=np.int64), UP)
    assert np.isnan(planes).all()
    planes = side_face_planes(axes[:2], origin[:2], size[:2], np.zeros(2, dtype=np.int64), UP[:2])
    assert np.isnan(planes[0, :4]).all() and not np.isnan(planes[0, 4:]).any()  # only 0 -> 1 meet


def test_steepness_is_measured_from_the_split_shapes_scope():
    """A box extruded sideways (its scope y along world x, as candler's pipes off a wall): the edges
    along that y are its side faces' vertical edges, and they get planes."""
    axes, origin, size = box_sides()
    sideways = axes.copy()
    sideways[:, 1] = [0, 0, 1]
    planes = side_face_planes(sideways, origin, size, np.zeros(4, dtype=np.int64), np.tile([0.0, 0, 1], (4, 1)))
    assert not np.isnan(planes).any()


def test_a_ledge_past_the_corner_is_cut_along_the_mitre():
    """A 12 m ledge centred on a 10 m facade, 1 m deep: cut at both 45-degree corner planes its top is a
    trapezoid of 10 and 12 m sides (the 1 m it sticks out beyond the facade is mitred)."""
    axes, origin, size = box_sides()
    planes = side_face_planes(axes, origin, size, np.zeros(4, dtype=np.int64), UP)[:1]
    cube = builtin_mesh("builtin:cube")
    xform = np.array([[[12.0, 0, 0, -1.0], [0, 0.5, 0, 2.0], [0, 0, 1.0, 0.0]]])  # x -1..11, z 0..1
    vertices, rings, owner = trim_triangles(cube.vertices, cube.faces, xform, planes, 1e-12)
    top = [vertices[rings[f]:rings[f + 1]] for f in range(len(rings) - 1)]
    top = [ring for ring in top if np.allclose(ring[:, 1], 2.5)]
    area = sum(np.linalg.norm(np.cross(r, np.roll(r, -1, axis=0)).sum(axis=0)) / 2 for r in top)
    assert area == pytest.approx((10 + 12) / 2 * 1.0)
    assert (owner == 0).all()


def test_plane_coordinates_are_right_handed_frames_on_the_normal():
    normal = np.array([[1.0, 0, 0], [0, 0, -1.0], [np.sqrt(0.5), np.sqrt(0.5), 0]])
    frames = plane_coordinates(normal)
    assert frames[:, 0] == pytest.approx(normal)
    assert np.einsum("nij,nkj->nik", frames, frames) == pytest.approx(np.broadcast_to(np.eye(3), (3, 3, 3)))
    assert np.linalg.det(frames) == pytest.approx(np.ones(3))


def test_shallow_edge_planes_of_a_box_bisect_its_horizontal_edges():
    """A 2 x 1.5 x 0.5 box's six faces (outlines counter-clockwise seen from outside): the top and bottom
    faces get a plane at each of their four edges, the sides one at their top and bottom edges; at the edge
    between the top (y = 1.5) and the front (z = 0.5) both planes are the bisector, each keeping the points
    of its own face and not the other's."""
    x0, x1, y0, y1, z0, z1 = 0.0, 2.0, 0.0, 1.5, 0.0, 0.5
    faces = [[(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)], [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],
             [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],
             [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)], [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)]]
    verts = np.array([p for f in faces for p in f])
    planes = shallow_edge_planes(verts, np.arange(0, 25, 4), np.arange(7), np.zeros(6, np.int64), UP[:1].repeat(6, 0))
    counts = (~np.isnan(planes[:, 0::4])).sum(axis=1)
    assert counts.tolist() == [2, 2, 4, 4, 2, 2]
    front, top = planes[1], planes[3]
    edge_point = np.array([1.0, y1, z1])
    on_front, on_top = np.array([1.0, 1.0, z1]), np.array([1.0, y1, 0.25])
    for plane, mine, theirs in ((front, on_front, on_top), (top, on_top, on_front)):
        (k,) = [k for k in range(4) if abs(plane[4 * k:4 * k + 3] @ edge_point + plane[4 * k + 3]) < 1e-9]
        normal, offset = plane[4 * k:4 * k + 3], plane[4 * k + 3]
        assert np.abs(normal) @ np.ones(3) == pytest.approx(np.sqrt(2))
        assert normal @ mine + offset > 0 > normal @ theirs + offset


def test_corners_far_from_the_origin_are_matched_as_at_the_origin():
    """The side faces of a 0.64 x 11 m box (complexpatterns' top floor on a lot of Uummannaq) 7,842 km
    north in UTM get the planes they get at the origin, moved with them. Corners matched on a grid of
    the coordinates' magnitude (0.78 m there) made the box's two corners 0.64 m apart one, and the faces
    at its ends lost their neighbours."""
    axes, origin, size = box_sides(width=0.64, depth=11.1)
    far = np.array([457596.4, 0.0, -7842088.517217704])
    here = side_face_planes(axes, origin, size, np.zeros(4, dtype=np.int64), UP)
    there = side_face_planes(axes, origin + far, size, np.zeros(4, dtype=np.int64), UP)
    assert not np.isnan(there).any()
    np.testing.assert_allclose(there[:, [0, 1, 2, 4, 5, 6]], here[:, [0, 1, 2, 4, 5, 6]], atol=1e-12)
    moved = here[:, [3, 7]] - np.stack([here[:, 0:3] @ far, here[:, 4:7] @ far], axis=1)
    np.testing.assert_allclose(there[:, [3, 7]], moved, atol=1e-6)


def test_faces_of_boxes_in_any_order_find_their_neighbours_in_their_own_parent():
    """Two boxes' side faces interleaved and shuffled (and a third box at the same place, another parent):
    each face gets the planes it gets with its box alone."""
    axes, origin, size = box_sides()
    alone = side_face_planes(axes, origin, size, np.zeros(4, dtype=np.int64), UP)
    rng = np.random.default_rng(2)
    parent = np.repeat([0, 1, 2], 4)
    order = rng.permutation(12)
    planes = side_face_planes(np.tile(axes, (3, 1, 1))[order], np.tile(origin, (3, 1))[order],
                              np.tile(size, (3, 1))[order], parent[order], np.tile(UP, (3, 1)))
    np.testing.assert_array_equal(planes, np.tile(alone, (3, 1))[order])


def test_corner_cells_round_and_cast_as_numpy():
    from grammarc.geometry.trim import _corner_cells

    rng = np.random.default_rng(8)
    parent = rng.integers(0, 5, 400)
    start = np.round(rng.normal(size=(400, 3)) * 1e7) / 2  # halves of the grid: rounded to even
    end = rng.normal(size=(400, 3)) * 1e3
    end[::37] = np.nan  # a cell of no number: int64's least, as numpy's cast gives it
    (first, last), scale = _corner_cells(parent, start, end)
    lows = np.full((5, 3), np.inf)
    highs = np.full((5, 3), -np.inf)
    for p in (start, end):
        np.minimum.at(lows, parent, p)
        np.maximum.at(highs, parent, p)
    want_scale = (np.maximum((highs - lows).max(axis=1), 1.0) * 1e-7)[parent][:, None]
    np.testing.assert_array_equal(scale, want_scale)
    with np.errstate(invalid="ignore"):
        for got, p in ((first, start), (last, end)):
            np.testing.assert_array_equal(got, np.round((p - lows[parent]) / want_scale).astype(np.int64))
