"""PolygonStore (grammarc.geometry.polygons): add then gather gives the polygons back, in any order;
plane_to_scope places in-plane coordinates on the scope axes."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.polygons import PolygonStore, plane_to_scope


def random_polygons(rng, k):
    """k polygons as a list of lists of rings ((m, 2) arrays), 1 to 3 rings of 3 to 6 vertices."""
    return [[rng.random((rng.integers(3, 7), 2)) for _ in range(rng.integers(1, 4))] for _ in range(k)]


def ragged(polygons):
    """The store's input layout of a list of polygons: coords, ring_offsets, poly_offsets."""
    rings = [r for p in polygons for r in p]
    coords = np.concatenate(rings) if rings else np.zeros((0, 2))
    ring_offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64)
    poly_offsets = np.concatenate([[0], np.cumsum([len(p) for p in polygons])]).astype(np.int64)
    return coords, ring_offsets, poly_offsets


def unpack(coords, ring_offsets, poly_offsets):
    """The inverse of ``ragged``."""
    return [[coords[ring_offsets[r]:ring_offsets[r + 1]] for r in range(poly_offsets[g], poly_offsets[g + 1])]
            for g in range(len(poly_offsets) - 1)]


def assert_same(got, want):
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert len(g) == len(w)
        for a, b in zip(g, w):
            np.testing.assert_array_equal(a, b)


def check_layout(coords, ring_offsets, poly_offsets):
    assert ring_offsets.dtype == np.int64 and poly_offsets.dtype == np.int64
    assert ring_offsets[0] == 0 and poly_offsets[0] == 0
    assert ring_offsets[-1] == len(coords) and poly_offsets[-1] == len(ring_offsets) - 1
    assert np.all(np.diff(ring_offsets) >= 0) and np.all(np.diff(poly_offsets) >= 0)


def test_empty_store():
    store = PolygonStore()
    assert len(store) == 0
    coords, ring_offsets, poly_offsets = store.gather(np.zeros(0, np.int64))
    assert coords.shape == (0, 2) and ring_offsets.tolist() == [0] and poly_offsets.tolist() == [0]


@pytest.mark.parametrize("batches", [[0], [1], [3], [0, 2, 0, 1, 5], [1, 1, 1]])
def test_add_gather_round_trip(batches):
    rng = np.random.default_rng(sum(batches) * 7 + len(batches))
    store = PolygonStore()
    everything, planes = [], []
    for k in batches:
        polygons = random_polygons(rng, k)
        plane = rng.integers(0, 3, k).astype(np.int8)
        ids = store.add(*ragged(polygons), plane)
        assert ids.dtype == np.int32
        assert ids.tolist() == list(range(len(everything), len(everything) + k))
        everything += polygons
        planes += plane.tolist()
    n = len(everything)
    assert len(store) == n
    assert store.plane.tolist() == planes
    check_layout(store.coords, store.ring_offsets, store.poly_offsets)
    assert_same(unpack(store.coords, store.ring_offsets, store.poly_offsets), everything)

    for ids in (np.arange(n), rng.permutation(n), rng.integers(0, max(n, 1), 2 * n) if n else np.arange(0),
                np.arange(min(n, 1)), np.zeros(0, np.int64)):
        out = store.gather(ids)
        check_layout(*out)
        assert len(out[2]) == len(ids) + 1
        assert_same(unpack(*out), [everything[i] for i in ids])


def test_gathered_polygons_can_be_added_back():
    rng = np.random.default_rng(5)
    store = PolygonStore()
    polygons = random_polygons(rng, 4)
    store.add(*ragged(polygons), np.ones(4, np.int8))
    ids = store.add(*store.gather(np.array([3, 1])), np.full(2, 2, np.int8))
    assert ids.tolist() == [4, 5]
    assert_same(unpack(*store.gather(ids)), [polygons[3], polygons[1]])
    assert store.plane.tolist() == [1, 1, 1, 1, 2, 2]


def test_gather_accepts_int32_ids():
    store = PolygonStore()
    polygons = random_polygons(np.random.default_rng(0), 3)
    ids = store.add(*ragged(polygons), np.ones(3, np.int8))
    assert_same(unpack(*store.gather(ids[::-1])), polygons[::-1])


def test_plane_to_scope_puts_uv_on_each_planes_axes_and_height_on_its_normal():
    uv = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    plane = np.array([0, 1, 2])
    assert np.array_equal(plane_to_scope(uv, plane), [[0, 1, 2], [3, 0, 4], [5, 6, 0]])
    assert np.array_equal(plane_to_scope(uv, plane, np.array([7.0, 8.0, 9.0])), [[7, 1, 2], [3, 8, 4], [5, 6, 9]])


def test_turns_come_back_in_gathers_order_and_are_0_where_none_were_given():
    store = PolygonStore()
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    store.add(square, np.array([0, 4]), np.array([0, 1]), np.array([1], np.int8))
    store.add(np.concatenate([square, square * 0.5]), np.array([0, 4, 8]), np.array([0, 1, 2]),
              np.array([1, 1], np.int8), np.array([0, 1, 0, 2, 0, 0, 1, 1], np.int8))
    assert store.turns(np.array([2, 0, 1])).tolist() == [0, 0, 1, 1, 0, 0, 0, 0, 0, 1, 0, 2]
