"""geometry/align.py: the face and edge alignScopeToGeometry picks per shape, and the axes they give."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.align import EDGE_MODES, FACE_MODES, aligned_axes, bbox_turns, pick_edges

# Shape 0: a 2 x 2 square on the ground (area 4, facing up) and a 3 x 1 upright quad between y = 1 and 2
# (area 3, facing +z); shape 1 has no faces.
VERTS = np.array([[0, 0, 0], [0, 0, -2], [2, 0, -2], [2, 0, 0],
                  [0, 1, 0], [3, 1, 0], [3, 2, 0], [0, 2, 0]], float)
RINGS = np.array([0, 4, 8])
FACES = np.array([0, 1, 2])
SHAPES = np.array([0, 2, 2])
AREA = np.array([4.0, 3.0])


def pick(face, edge, face_index=0, edge_index=0):
    return pick_edges(VERTS, RINGS, FACES, SHAPES, AREA, FACE_MODES[face], np.full(2, face_index),
                      EDGE_MODES[edge], np.full(2, edge_index))


@pytest.mark.parametrize("face, edge, face_index, edge_index, want", [
    ("index", "index", 0, 0, (0, 0, 1)),
    ("index", "index", -1, -1, (1, 7, 4)),  # negative indices count from the end
    ("index", "index", 3, 6, (1, 6, 7)),  # and wrap around
    ("largest", "longest", 0, 0, (0, 0, 1)),  # the square; its edges tie: the first
    ("world.lowest", "index", 0, 2, (0, 2, 3)),
    ("index", "longest", 1, 0, (1, 4, 5)),
    ("index", "world.lowest", 1, 0, (1, 4, 5)),
    ("any", "longest", 0, 0, (1, 4, 5)),  # the 3 long edge, on the second face
    ("any", "world.lowest", 0, 0, (0, 0, 1)),  # the square's first edge, at y = 0
    ("any", "index", 0, 1, (0, 1, 2)),  # any with an index: the first face
])
def test_pick_edges(face, edge, face_index, edge_index, want):
    faces, start, end = pick(face, edge, face_index, edge_index)
    assert (faces[0], start[0], end[0]) == want
    assert (faces[1], start[1], end[1]) == (-1, -1, -1)  # no faces, nothing picked


def test_aligned_axes_y_up_and_z_up():
    edge = np.array([[3.0, 0, 0], [0, 0, 0]])
    normal = np.array([[1e-12, 0, 1], [0, 0, 1]])
    frame = np.broadcast_to(np.eye(3), (2, 3, 3))
    axes, ok = aligned_axes(edge, normal, frame, "yUp")
    assert ok.tolist() == [True, False]  # a zero-length edge gives no x
    # the normal within 1e-9 of the scope's z is z exactly
    np.testing.assert_array_equal(axes[0], [[1, 0, 0], [0, 0, 1], [0, -1, 0]])
    axes, ok = aligned_axes(edge, normal, frame, "zUp")
    np.testing.assert_array_equal(axes[0], np.eye(3))


def test_aligned_axes_make_x_orthogonal_to_the_normal():
    """An edge not quite in the face's plane (a non-planar face) still gives an orthonormal frame."""
    axes, ok = aligned_axes(np.array([[1.0, 0.2, 0]]), np.array([[0, 0.6, 0.8]]), np.eye(3)[None], "yUp")
    assert ok.all()
    np.testing.assert_allclose(axes[0] @ axes[0].T, np.eye(3), atol=1e-12)
    assert np.linalg.det(axes[0]) == pytest.approx(1)


def test_bbox_turns_onto_the_longer_side_of_the_smallest_rectangle():
    """A 10 x 4 rectangle turned by 30 degrees, its points in any order: the first axis turns by 30 (not
    by -150: the nearer sense); a line of points gives its line; one point none."""
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    box = np.array([[0, 0], [10, 0], [10, 4], [0, 4], [5, 2]], float) @ np.array([[c, s], [-s, c]])
    points = np.concatenate([box[::-1], [[0, 0], [0, 3], [0, 1]], [[7, 7]]])
    turn, ok = bbox_turns(points, np.array([0] * 5 + [1] * 3 + [2]), 3)
    np.testing.assert_allclose(turn[:2], [[c, s], [0, 1]], atol=1e-9)
    assert ok.tolist() == [True, True, False]
