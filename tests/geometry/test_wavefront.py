"""The setback strips of folding outlines swept as a wavefront: edge events, parallel lines, split events."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
import shapely

from grammarc.geometry.polygon_edges import polygon_edges
from grammarc.geometry.setback import setback_regions
from grammarc.geometry.setback_strips import STEP_TURN, mitres
from grammarc.geometry.wavefront import swept_strips


def sweep(ring, d):
    """The strips (shapely, per edge; None where an edge does not move), whether nothing is left, whether
    the sweep followed the wavefront to the end, and its vertices at the end, of one outline."""
    edges = polygon_edges(np.array([shapely.Polygon(ring)]))
    d = np.asarray(d, float)
    corner, ends, _ = mitres(edges, d)
    coords, offsets, collapsed, trusted, _, left, _ = swept_strips(
        edges.start, edges.end, edges.inward, d, corner, ends, np.array([0, len(d)]),
        np.cos(np.radians(STEP_TURN)))
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


def test_lines_that_become_neighbours_apart_are_a_split_event_the_sweep_does_not_follow():
    """An outline (``random_polygon(1395)`` of the setback tests) whose edges 1-3 run nearly collinear; moved
    by 0;4;0;0;0;0;0;3 its wavefront parts where two parallel lines apart become neighbours. (Moved by
    3;8;0;4;8;4;0;3 it parted so too, until neighbours moved by different distances that turn little stepped
    where they meet after an event: it now sweeps to nothing, as PRT's setback of it, measured through PyPRT.)"""
    ring = [(-2.741298957897467, -1.8729945287653271), (-2.7677734989337943, -1.971798861019968),
            (-2.7345322386164876, -2.09585693343178), (-2.286436292788719, -16.853930360413194),
            (-6.468099005249695, -11.517845132766984), (-6.8529512539598585, -6.28356906748052),
            (-16.24326538759794, -10.687517687190201), (-3.1990815156498873, 13.204108185076974)]
    _, _, trusted, _ = sweep(ring, [0, 4, 0, 0, 0, 0, 0, 3])
    assert not trusted


def test_the_step_beside_a_vanished_edge_goes_with_it():
    """massing.far.33391's first tier: edge 3 (2.8 m, moved 4 m) turns by 13 degrees into the kept edge 4, a
    step; it vanishes, and PRT's remainder then runs along edge 2's moved line up to edge 4 (measured through
    PyPRT: 300.245 m^2, its corner at (30.247, 9.223)), where keeping the step left a notch (303.48 m^2)."""
    ring = [(0.0, 3.524), (0.0, 0.0), (24.4042, 0.0), (31.3414, 5.0686), (30.8369, 7.8597), (27.8887, 14.6713),
            (19.6308, 18.3044)]
    strips, collapsed, trusted, _ = sweep(ring, [4, 0, 4, 4, 0, 0, 0])
    assert trusted and not collapsed
    covered = shapely.union_all([s for s in strips if s is not None])
    remainder = shapely.Polygon(ring).difference(covered)
    assert remainder.area == pytest.approx(300.245, abs=0.02)
    assert min(np.hypot(*(np.asarray(remainder.exterior.coords) - (30.247, 9.223)).T)) < 2e-3


def test_moving_lines_that_meet_face_to_face_annihilate_where_they_overlap():
    """massing.T.34179's second tier: the bar's left end (moved 4 m) vanishes as its bottom (4 m) and top (3 m)
    meet; the bottom's segment, the shorter, goes and the top runs on over the bar's right half (PRT's
    remainder: 25.999 m^2, that half 3 m below the top, from the stem's side moved 3 m to the end moved 4 m;
    the top went, as the slower, before)."""
    ring = [(0.0, 30.19), (0.0, 25.214), (18.238, 25.214), (18.238, 0.0), (20.155, 0.0), (20.155, 25.214),
            (38.393, 25.214), (38.393, 30.19)]
    d = [4, 4, 3, 3, 0, 0, 4, 3]
    _, collapsed, trusted, _ = sweep(ring, d)
    assert trusted and not collapsed
    face = np.array([shapely.Polygon(ring)])
    _, rest = setback_regions(face, polygon_edges(face), np.array(d, float), np.zeros(8, np.int64), 1)
    assert shapely.area(rest[0]) == pytest.approx((38.393 - 4 - 21.238) * (30.19 - 3 - 25.214), rel=1e-9)
