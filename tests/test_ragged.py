"""grammarc.ragged against plain-Python references on random ragged arrays, empty segments included."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.ragged import (
    fan_out,
    group_bounds,
    next_in_segment,
    offsets_from_counts,
    ragged_take,
    rank_within,
    row_groups,
    segment_of,
    segment_reduce,
)


def random_counts(rng, n):
    """Counts with many zeros, so empty segments occur first, in the middle and last."""
    return rng.integers(0, 4, n) * (rng.random(n) < 0.7)


def segments(counts):
    """Python reference: [(start, stop)] of each segment."""
    out, at = [], 0
    for c in counts:
        out.append((at, at + int(c)))
        at += int(c)
    return out


@pytest.mark.parametrize("n", [0, 1, 2, 17])
def test_offsets_from_counts(n):
    counts = random_counts(np.random.default_rng(n), n)
    offsets = offsets_from_counts(counts)
    assert offsets.dtype == np.int64
    assert offsets.tolist() == [0] + [b for _, b in segments(counts)]


def test_offsets_docstring_example():
    assert offsets_from_counts(np.array([2, 3])).tolist() == [0, 2, 5]


@pytest.mark.parametrize("n", [0, 1, 2, 17])
def test_ragged_take(n):
    rng = np.random.default_rng(n)
    counts = random_counts(rng, n)
    offsets = offsets_from_counts(counts)
    for sel in (np.arange(n), rng.permutation(n), rng.integers(0, max(n, 1), 3 * n) if n else np.arange(0),
                np.zeros(0, np.int64)):
        items, packed = ragged_take(offsets, sel)
        want = [i for s in sel for i in range(*segments(counts)[s])]
        assert items.tolist() == want
        assert packed.tolist() == offsets_from_counts(counts[sel]).tolist()


def test_ragged_take_docstring_example():
    items, packed = ragged_take(np.array([0, 2, 5, 6]), np.array([2, 0]))
    assert items.tolist() == [5, 0, 1]
    assert packed.tolist() == [0, 1, 3]


def test_rank_within():
    np.testing.assert_array_equal(rank_within(np.array([5, 3, 5, 5])), [0, 0, 1, 2])
    assert rank_within(np.zeros(0, np.int64)).shape == (0,)


@pytest.mark.parametrize("n", [0, 1, 2, 17])
def test_segment_of(n):
    counts = random_counts(np.random.default_rng(n), n)
    want = [s for s, c in enumerate(counts) for _ in range(c)]
    assert segment_of(offsets_from_counts(counts)).tolist() == want


@pytest.mark.parametrize("ufunc, empty, ref", [
    (np.add, 0.0, sum), (np.minimum, np.inf, min), (np.maximum, -np.inf, max),
])
@pytest.mark.parametrize("n", [0, 1, 2, 17, 40])
def test_segment_reduce(ufunc, empty, ref, n):
    rng = np.random.default_rng(n)
    counts = random_counts(rng, n)
    offsets = offsets_from_counts(counts)
    values = rng.normal(size=(offsets[-1], 3))
    out = segment_reduce(ufunc, values, offsets, empty)
    assert out.shape == (n, 3)
    for s, (a, b) in enumerate(segments(counts)):
        for j in range(3):
            want = ref(values[a:b, j].tolist()) if b > a else empty
            assert out[s, j] == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("offsets, want", [
    ([0, 2, 2], [3.0, 0.0]),  # regression: trailing empty segments cut the last non-empty one short
    ([0, 0, 2, 3, 3, 3], [0.0, 3.0, 4.0, 0.0, 0.0]),
    ([0, 0], [0.0]),
    ([0], []),
])
def test_segment_reduce_empty_segments(offsets, want):
    values = np.array([1.0, 2.0, 4.0])[: offsets[-1]]
    assert segment_reduce(np.add, values, np.array(offsets), 0.0).tolist() == want


@pytest.mark.parametrize("n", [0, 1, 2, 17])
def test_fan_out(n):
    counts = random_counts(np.random.default_rng(n), n)
    parent, index = fan_out(counts)
    assert parent.dtype == np.int64 and index.dtype == np.int64
    assert parent.tolist() == [p for p, c in enumerate(counts) for _ in range(c)]
    assert index.tolist() == [i for c in counts for i in range(c)]


def test_fan_out_docstring_example():
    parent, index = fan_out([2, 0, 3])
    assert parent.tolist() == [0, 0, 2, 2, 2]
    assert index.tolist() == [0, 1, 0, 1, 2]


def test_row_groups_number_equal_rows_as_unique_does():
    keys = np.array([[1, 5], [0, 2], [1, 5], [0, 3], [0, 2]])
    groups, first = row_groups(keys)
    _, want_first, want_groups = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    assert groups.tolist() == want_groups.reshape(-1).tolist() and first.tolist() == want_first.tolist()
    empty_groups, empty_first = row_groups(np.zeros((0, 2), dtype=np.int64))
    assert len(empty_groups) == len(empty_first) == 0


def test_next_in_segment_wraps_each_ring():
    assert next_in_segment(np.array([0, 3, 5, 6])).tolist() == [1, 2, 0, 4, 3, 5]
    assert next_in_segment(np.array([0])).tolist() == []


@pytest.mark.parametrize("n", [0, 1, 7, 200])
def test_group_bounds_are_what_minimum_at_and_maximum_at_give(n):
    rng = np.random.default_rng(n)
    groups = 9
    group = rng.integers(0, groups, n)
    values = rng.normal(size=(n, 3))
    values[rng.random((n, 3)) < 0.05] = np.nan  # a NaN wins, as in np.minimum
    low, high = group_bounds(group, groups, values)
    want_low, want_high = np.full((groups, 3), np.inf), np.full((groups, 3), -np.inf)
    np.minimum.at(want_low, group, values)
    np.maximum.at(want_high, group, values)
    np.testing.assert_array_equal(low, want_low)
    np.testing.assert_array_equal(high, want_high)


def test_group_bounds_of_several_arrays_are_those_of_their_rows_together():
    rng = np.random.default_rng(3)
    group = rng.integers(0, 4, 50)
    start, end = rng.normal(size=(50, 2)), rng.normal(size=(50, 2))
    end[7, 1] = np.nan
    together = group_bounds(np.tile(group, 2), 4, np.concatenate([start, end]))
    np.testing.assert_array_equal(group_bounds(group, 4, start, end), together)


def test_group_bounds_docstring_example():
    low, high = group_bounds(np.array([1, 0, 1]), 2, np.array([[2.0], [5.0], [-1.0]]))
    assert low.tolist() == [[5.0], [-1.0]] and high.tolist() == [[5.0], [2.0]]
