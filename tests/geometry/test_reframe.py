"""A new scope around unchanged polygons: the box the polygon fills in the new axes, and its coordinates."""

from __future__ import annotations

import numpy as np

from grammarc.geometry.reframe import NORMAL_UP, reframe
from grammarc.ragged import segment_reduce

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def one_face(coords, ring_counts=None, size=(4.0, 2.0, 0.0), new_axes=NORMAL_UP[2]):
    """reframe's arguments for one polygon in the x-y plane (plane 2) of a world-aligned scope at (1, 2, 3)."""
    ring_counts = [len(coords)] if ring_counts is None else ring_counts
    ring_offsets = np.r_[0, np.cumsum(ring_counts)].astype(np.int64)
    return (np.array([[1.0, 2.0, 3.0]]), np.array([size]), np.eye(3)[None], np.asarray(coords, dtype=float),
            ring_offsets, np.array([0, len(ring_counts)], dtype=np.int64), np.array([2], dtype=np.int8),
            np.asarray(new_axes, dtype=float)[None])


def test_a_face_turned_to_y_up_keeps_its_box():
    ok, plane, origin, size, is_rect, coords = reframe(*one_face(SQUARE))
    # new axes (x, z, -y): the face's normal, old z, is the new y; old y runs along the new -z
    assert ok.tolist() == [True] and plane.tolist() == [1] and is_rect.tolist() == [True]
    np.testing.assert_array_equal(size, [[4.0, 0.0, 2.0]])
    np.testing.assert_array_equal(origin, [[1.0, 4.0, 3.0]])  # the new box starts at the old top edge
    np.testing.assert_array_equal(coords, [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]])


def test_a_triangle_is_no_rectangle_and_a_tilted_scope_is_refused():
    triangle = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    ok, _, _, _, is_rect, coords = reframe(*one_face(triangle))
    assert ok.tolist() == [True] and is_rect.tolist() == [False]
    np.testing.assert_array_equal(coords, [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]])
    turn = np.radians(30.0)
    tilted = [[1.0, 0.0, 0.0], [0.0, np.cos(turn), np.sin(turn)], [0.0, -np.sin(turn), np.cos(turn)]]
    assert reframe(*one_face(SQUARE, new_axes=tilted))[0].tolist() == [False]


def test_no_shapes_and_a_shape_without_vertices():
    _, _, _, size, is_rect, coords = reframe(*one_face(np.zeros((0, 2)), ring_counts=[]))
    assert coords.shape == (0, 2) and is_rect.tolist() == [False]
    np.testing.assert_array_equal(size, [[0.0, 0.0, 0.0]])  # bounds of nothing are 0, and so is its height
    offsets = np.zeros(1, dtype=np.int64)
    none = reframe(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 2)), offsets, offsets,
                   np.zeros(0, dtype=np.int8), np.zeros((0, 3, 3)))
    assert [x.shape for x in none] == [(0,), (0,), (0, 3), (0, 3), (0,), (0, 2)]


def test_bounds_over_signed_zeros_are_numpys():
    """A polygon whose lowest u is 0.0 at some vertices and -0.0 at others: which one bounds it, and so the
    sign of the zeros in its new coordinates, is as numpy's reductions give it, for a ring of any length."""
    for count in (4, 9, 17, 40, 100):
        at = np.arange(count)
        coords = np.column_stack([np.where(at % 3 == 0, -0.0, 0.0), np.where(at % 2 == 0, -0.0, 0.0)])
        coords[count // 2, 0] = coords[count // 3, 1] = 1.0
        _, _, _, _, _, new = reframe(*one_face(coords, new_axes=np.eye(3)))
        # the same axes: a vertex lies at u (4, 0, 0) + v (0, 2, 0), as einsum gives the axes
        local = coords[:, :1] * [4.0, 0.0, 0.0] + coords[:, 1:] * [0.0, 2.0, 0.0]
        offsets = np.array([0, count])
        low, high = (segment_reduce(f, local[:, :2], offsets, 0.0)[0] for f in (np.minimum, np.maximum))
        assert new.tobytes() == ((local[:, :2] - low) / (high - low)).tobytes(), count
