"""geometry/edge_cuts.py: rings divided by a segment between two of their edges."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.edge_cuts import cut_rings

SQUARE = np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float)


def _pieces(xy, offsets):
    return [xy[offsets[i]:offsets[i + 1]].tolist() for i in range(len(offsets) - 1)]


def _area(ring):
    x, y = np.asarray(ring).T
    return 0.5 * (x @ np.roll(y, -1) - y @ np.roll(x, -1))


def test_opposite_edges_give_two_quadrilaterals_adjacent_ones_a_triangle_and_a_pentagon():
    xy, offsets = np.concatenate([SQUARE, SQUARE]), np.array([0, 4, 8])
    first, first_offsets, second, second_offsets, bad = cut_rings(
        xy, offsets, np.array([0, 0]), np.array([0.5, 0.5]), np.array([2, 1]), np.array([0.5, 0.5]))
    assert not bad.any()
    assert _pieces(first, first_offsets) == [[[2, 0], [4, 0], [4, 4], [2, 4]], [[2, 0], [4, 0], [4, 2]]]
    assert _pieces(second, second_offsets) == [[[2, 4], [0, 4], [0, 0], [2, 0]],
                                               [[4, 2], [4, 4], [0, 4], [0, 0], [2, 0]]]
    # both pieces keep the ring's winding and share its area
    for a, b in zip(_pieces(first, first_offsets), _pieces(second, second_offsets)):
        assert _area(a) > 0 and _area(b) > 0 and _area(a) + _area(b) == pytest.approx(16)


def test_edges_count_modulo_the_ring_and_fractions_at_an_end_are_the_vertex():
    # edge 4 is edge 0, its end vertex 1; edge -1 is edge 3, its start vertex 3: the diagonal
    first, first_offsets, second, second_offsets, bad = cut_rings(
        SQUARE, np.array([0, 4]), np.array([4]), np.array([1.0]), np.array([-1]), np.array([0.0]))
    assert not bad.any()
    assert _pieces(first, first_offsets) == [[[4, 0], [4, 4], [0, 4]]]
    assert _pieces(second, second_offsets) == [[[0, 4], [0, 0], [4, 0]]]


@pytest.mark.parametrize("e1, t1, e2, t2", [(1, 0.5, 1, 0.2), (0, 1.0, 1, 0.0), (0, 0.0, 0, 1.0)])
def test_a_cut_that_leaves_no_two_polygons_is_bad(e1, t1, e2, t2):
    _, first_offsets, _, second_offsets, bad = cut_rings(
        np.concatenate([SQUARE, SQUARE]), np.array([0, 4, 8]), np.array([e1, 0]), np.array([t1, 0.5]),
        np.array([e2, 2]), np.array([t2, 0.5]))
    assert bad.tolist() == [True, False]
    assert first_offsets.tolist() == [0, 0, 4] and second_offsets.tolist() == [0, 0, 4]
