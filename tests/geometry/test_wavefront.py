"""The setback strips of folding outlines swept as a wavefront: edge events, parallel lines, split events."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
import shapely

from grammarc.geometry.setback import _mitres, polygon_edges
from grammarc.geometry.wavefront import swept_strips


def sweep(ring, d):
    """The strips (shapely, per edge; None where an edge does not move), whether nothing is left, whether
    the sweep followed the wavefront to the end, and its vertices at the end, of one outline."""
    edges = polygon_edges(np.array([shapely.Polygon(ring)]))
    d = np.asarray(d, float)
    corner, ends, _ = _mitres(edges, d)
    coords, offsets, collapsed, trusted, left, _ = swept_strips(
        edges.start, edges.end, edges.inward, d, corner, ends, np.array([0, len(d)]))
    strips = [shapely.make_valid(shapely.Polygon(coords[a:b])) if b > a else None
              for a, b in pairwise(offsets)]
    return strips, collapsed[0], trusted[0], left


def test_a_short_end_vanishes_and_the_front_runs_on_past_the_kept_edge_parallel_to_it():
    """The 3 m end of a 9 x 5 m L, moved 4 m, vanishes at (6, 3) (t = 3/4); the front's line then meets the
    kept edge beside it (parallel, slower: it goes) and sweeps on to the arm's side at x = 5.4."""
    ring = [(0, 0), (9, 0), (9, 3), (5.4, 3), (5.4, 5), (0, 5)]
    strips, collapsed, trusted, left = sweep(ring, [4, 4, 0, 0, 0, 0])
    assert trusted and not collapsed
    assert strips[1].area == pytest.approx(3 * 3 / 2)  # the end's triangle up to (6, 3)
    np.testing.assert_allclose(sorted(set(map(tuple, np.round(left, 9)))),
                               [(0, 4), (0, 5), (5.4, 4), (5.4, 5)], atol=1e-9)
    covered = shapely.union_all([s for s in strips if s is not None])
    assert shapely.Polygon(ring).difference(covered).area == pytest.approx(5.4)


def test_edges_on_one_line_that_move_alike_sweep_as_one_line():
    """A 1 x 20 m face whose right side is three edges on one line (an inset's side past holes' closed
    channels, massing's holes.33739): sides moved 0.7 m, the top 15 m. The three sweep as one line, and
    the strips cover the face, as the strips of a side of one edge do."""
    one_edge = ([(0, 0), (0, 20), (1, 20), (1, 0)], [0.7, 15, 0.7, 0])
    three_edges = ([(0, 0), (0, 20), (1, 20), (1, 13), (1, 6), (1, 0)], [0.7, 15, 0.7, 0.7, 0.7, 0])
    for ring, d in (one_edge, three_edges):
        strips, _, trusted, _ = sweep(ring, d)
        covered = shapely.union_all([s for s in strips if s is not None])
        assert trusted and shapely.Polygon(ring).difference(covered).area == pytest.approx(0, abs=1e-9)


def test_a_face_swept_whole_leaves_nothing():
    """A 3-4-5 triangle (inradius 1) whose edges move 2 m: its edges vanish at t = 1/2, nothing is left,
    and the strips are the skeleton's three faces."""
    strips, collapsed, trusted, left = sweep([(0, 0), (4, 0), (0, 3)], [2, 2, 2])
    assert collapsed and trusted and len(left) == 0
    assert sum(s.area for s in strips) == pytest.approx(6)
    assert [s.area for s in strips] == pytest.approx([2, 2.5, 1.5])


def test_facing_lines_that_meet_apart_are_a_split_event_the_sweep_does_not_follow():
    """A U whose left arm closes (its sides moved 4 m, 3.2 m apart): its bottom's line and the kept edge
    above it are parallel but apart when they become neighbours, where the wavefront parts."""
    ring = [(0, 0), (21, 0), (21, 10), (18, 10), (18, 1.6), (3.2, 1.6), (3.2, 10), (0, 10)]
    _, _, trusted, _ = sweep(ring, [4, 4, 3, 3, 0, 0, 4, 3])
    assert not trusted
