"""Short edges of lot rings collapsed as PRT collapses them: order, counts and owners."""

import numpy as np

from grammarc.geometry.short_edges import collapse_short_edges


def xz(points):
    return np.array([[x, 0.0, z] for x, z in points])


def test_the_end_that_changes_the_ring_less_goes_and_its_edge_goes_to_the_one_before():
    square = [(0, 0), (10, 0), (10, 10), (0, 10)]
    spiked = [(0, 0), (10, 0), (10, 10), (10 + 5e-4, 10 + 1e-4), (0, 10)]  # the spike goes
    vertices = xz(square + spiked)
    order, counts, owner = collapse_short_edges(vertices, np.array([0, 4, 9]), 8e-4)
    assert counts.tolist() == [4, 4]
    assert order.tolist() == [0, 1, 2, 3, 4, 5, 6, 8]
    assert owner.tolist() == [0, 1, 2, 3, 4, 5, 6, 6, 7]  # the spike's edge joins its predecessor's


def test_a_first_vertex_that_goes_hands_the_start_to_the_vertex_it_went_into():
    ring = xz([(0, 0), (10, 0), (10, 10), (0, 10), (-5e-4, 0)])  # the first vertex lies on a line
    order, counts, owner = collapse_short_edges(ring, np.array([0, 5]), 8e-4)
    assert counts.tolist() == [4] and order.tolist() == [4, 1, 2, 3]
    assert owner.tolist() == [0, 1, 2, 3, 0]  # the first vertex's edge joins the new first one's


def test_exact_duplicates_keep_the_first_and_too_few_vertices_are_left_as_they_are():
    closed = xz([(0, 0), (10, 0), (10, 10), (0, 0)])  # closed by repeating the first vertex
    order, counts, _ = collapse_short_edges(closed, np.array([0, 4]), 8e-4)
    assert order.tolist() == [0, 1, 2] and counts.tolist() == [3]
    flat = xz([(0, 0), (1, 0), (1, 0), (0, 0)])
    _, counts, _ = collapse_short_edges(flat, np.array([0, 4]), 8e-4)
    assert counts.tolist() == [2]  # fewer than 3 distinct vertices: the caller's to report


def test_vertices_that_went_into_vertices_that_went_later_are_owned_by_the_one_that_stays():
    """A ring after another, whose vertices go in a chain (10 into 9 into 8): each is owned by the vertex
    that stays, at its position in ``order``; positions of the first vertices were followed as vertices,
    and the walk went round for ever."""
    pentagon = [(31.39, -46.35), (48.19, -3.71), (0.0, -40.52), (-34.39, -20.0), (-30.98, -28.57), (31.39, -46.35)]
    sliver = [(5e5, -5e6), (5e5 + 1e-9, -5e6), (5e5 + 1e-9, -5000010.0), (5e5, -5000010.0), (5e5, -5e6)]
    order, counts, owner = collapse_short_edges(xz(pentagon + sliver), np.array([0, 6, 11]), 8e-4)
    assert counts.tolist() == [5, 2] and order.tolist() == [0, 1, 2, 3, 4, 7, 8]
    assert owner.tolist() == [0, 1, 2, 3, 4, 4, 6, 5, 6, 6, 6]
