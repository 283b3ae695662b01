"""Splitting polygons across their plane: pieces clipped to slabs, area conserved, empty parts dropped."""

from __future__ import annotations

import numpy as np
import shapely
from conftest import make_lots
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.build import derive
from grammarc.compiler import compile_grammar
from grammarc.geometry.clip import clip_to_slabs
from grammarc.geometry.polygons import PolygonStore
from grammarc.io.lots import lots_from_polygons


def store_of(rings, plane=1):
    """A store holding one normalized polygon (rings in [0, 1]^2)."""
    store = PolygonStore()
    coords = np.concatenate(rings)
    ring_offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64)
    store.add(coords, ring_offsets, np.array([0, len(rings)], np.int64), np.array([plane], np.int8))
    return store


def test_l_shape_cut_in_three():
    # an L in (u, v): the square minus its top-right quarter, clockwise in (u, v) as plane 1 wants
    ring = np.array([[0, 0], [0, 1], [0.5, 1], [0.5, 0.5], [1, 0.5], [1, 0]], float)
    store = store_of([ring])
    size = np.array([[30.0, 0.0, 20.0]] * 3)
    pos, length = np.array([0.0, 10.0, 20.0]), np.array([10.0, 10.0, 10.0])
    clipped = clip_to_slabs(store, np.zeros(3, np.int32), size, 0, pos, length)
    assert list(clipped.source) == [0, 1, 2]
    np.testing.assert_allclose(clipped.extent[:, [0, 2]], [[10, 20], [10, 20], [10, 10]])
    np.testing.assert_allclose(clipped.low[:, [0, 2]], [[0, 0], [10, 0], [20, 0]])
    # the middle slab holds the inner corner of the L: a polygon; the others are rectangles
    assert list(clipped.is_rect) == [True, False, True]


def test_slab_beyond_the_polygon_is_dropped_and_a_cut_gives_two_pieces():
    # a U: the slab across its two arms gives two pieces, one outside the polygon none
    u = np.array([[0, 0], [0, 1], [1, 1], [1, 0], [0.7, 0], [0.7, 0.6], [0.3, 0.6], [0.3, 0]], float)
    store = store_of([u[::-1]])
    size = np.array([[10.0, 0.0, 10.0]] * 2)
    clipped = clip_to_slabs(store, np.zeros(2, np.int32), size, 2, np.array([0.0, 20.0]),
                            np.array([5.0, 5.0]))
    assert list(clipped.source) == [0, 0]
    np.testing.assert_allclose(sorted(clipped.extent[:, 0]), [3, 3])


@settings(max_examples=30, deadline=None)
@given(st.integers(3, 9), st.floats(0.1, 0.9), st.integers(0, 2**31 - 1))
def test_a_split_conserves_area(n_parts, hole, seed):
    """Random concave lots with a hole, split in n parts along x: the parts' areas add up."""
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 9))
    radius = rng.uniform(10, 20, 9)
    outer = np.stack([np.cos(angles) * radius, np.sin(angles) * radius], axis=1) + 25
    polygon = shapely.Polygon(outer).buffer(0)
    inner = shapely.Point(25, 25).buffer(3 * hole, quad_segs=4)
    if not polygon.is_valid or polygon.geom_type != "Polygon" or not polygon.contains(inner):
        return
    polygon = shapely.Polygon(polygon.exterior.coords[:-1], [inner.exterior.coords[:-1][::-1]])
    polygon = shapely.orient_polygons(polygon)
    rings = [np.asarray(polygon.exterior.coords[:-1]), np.asarray(polygon.interiors[0].coords[:-1])]
    lots = lots_from_polygons([rings])
    if not len(lots):
        return
    grammar = compile_grammar("g.cga", text=f'lot ~> S(1r, 2, 1r) Repeat("X", {50 / n_parts}){{ a }}\n')
    record = derive(grammar, lots)
    mesh = record["mesh"]
    # each piece's top face has the area of its slab of the footprint; boxes are rectangles
    tops = 0.0
    for face in range(len(mesh.lot)):
        rings_of = range(mesh.face_offsets[face], mesh.face_offsets[face + 1])
        vertices = [mesh.vertices[mesh.ring_offsets[r]:mesh.ring_offsets[r + 1]] for r in rings_of]
        if np.allclose(vertices[0][:, 1], 2.0, atol=1e-4):
            poly = shapely.Polygon(vertices[0][:, [0, 2]], [v[:, [0, 2]] for v in vertices[1:]])
            tops += poly.area
    boxes = record["xform"][record["asset"] == 0]
    tops += np.abs(boxes[:, 0, 0] * boxes[:, 2, 2] - boxes[:, 0, 2] * boxes[:, 2, 0]).sum()
    assert abs(tops - polygon.area) <= 1e-3 * polygon.area


def test_paper_notation_splits_a_concave_lot(write):
    grammar = compile_grammar(write("g.cga", 'lot ~> S(1r, 6, 1r) Subdiv("X", 1r, 1r, 1r){ a | b | c }\n'))
    record = derive(grammar, make_lots("concave_L"))
    assert not record["bad"]
    names = set(record["symbols"][record["symbol"]]) | set(record["symbols"][record["mesh"].symbol])
    assert names == {"a", "b", "c"}


def test_cut_edges_of_a_piece_the_cut_takes_through_a_hole_turn_their_faces():
    """A courtyard prism (plane 1, 30 x 20) cut at v = 0.5 through its hole: each piece's two cut edges
    turn their side faces (``cap_turns``: DOWN after the outer edge 3, UP before the outer edge 1, as the
    hole's edges come after the outline's); the piece the cut does not take through the hole keeps ALONG
    everywhere, and so do edges that are not cut."""
    from grammarc.geometry.components import ALONG, DOWN, UP

    outer = np.array([[0, 0], [0, 1], [1, 1], [1, 0]], float)  # clockwise in (u, v), as plane 1 wants
    hole = np.array([[1 / 3, 0.25], [2 / 3, 0.25], [2 / 3, 0.75], [1 / 3, 0.75]])
    store = store_of([outer, hole])
    size = np.array([[30.0, 5.0, 20.0]] * 2)  # a prism 5 m high
    halves = np.array([0.0, 10.0]), np.array([10.0, 10.0])
    through = clip_to_slabs(store, np.zeros(2, np.int32), size, 2, *halves, turn_cuts=True)
    assert sorted(through.turn[through.turn != ALONG].tolist()) == sorted([UP, DOWN, UP, DOWN])
    assert not through.is_rect.any()
    missed = clip_to_slabs(store, np.zeros(2, np.int32), size, 2, np.array([0.0, 2.0]), np.array([2.0, 18.0]),
                           turn_cuts=True)
    assert (missed.turn == ALONG).all()
    # a face's cut makes no faces; the paper's Subdiv (no ``turn_cuts``) keeps x along every edge
    flat = clip_to_slabs(store, np.zeros(2, np.int32), size * [1, 0, 1], 2, *halves, turn_cuts=True)
    paper = clip_to_slabs(store, np.zeros(2, np.int32), size, 2, *halves)
    assert (flat.turn == ALONG).all() and (paper.turn == ALONG).all()
