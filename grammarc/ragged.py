"""The one ragged-array convention of grammarc, and its helpers.

A ragged array is flat items plus ``offsets`` (n+1,) int64 starting at 0 (Arrow, as in shapely's
``from_ragged_array``): segment i is ``items[offsets[i]:offsets[i + 1]]``. Fan-outs return
``(children, parent)`` like shapely's ``get_parts(return_index=True)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def offsets_from_counts(counts: np.ndarray) -> np.ndarray:
    """(n + 1,) int64 offsets from (n,) counts: [2, 3] -> [0, 2, 5]."""
    offsets = np.zeros(len(counts) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return offsets


def ragged_take(offsets: np.ndarray, sel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Flat item indices of segments ``sel`` and their packed offsets.

    offsets [0, 2, 5, 6], sel [2, 0] -> items [5, 0, 1], offsets [0, 1, 3].
    """
    starts = offsets[sel]
    counts = offsets[sel + 1] - starts
    packed = offsets_from_counts(counts)
    # each item's flat index = its position in the packed output + (old start - new start) of its segment
    items = np.arange(packed[-1], dtype=np.int64) + np.repeat(starts - packed[:-1], counts)
    return items, packed


def rank_within(group: np.ndarray) -> np.ndarray:
    """Each item's number among the items of its group, in order: [5, 3, 5, 5] -> [0, 0, 1, 2]."""
    order = np.argsort(group, kind="stable")
    sorted_group = group[order]
    first = np.r_[True, sorted_group[1:] != sorted_group[:-1]] if len(group) else np.zeros(0, bool)
    starts = np.maximum.accumulate(np.where(first, np.arange(len(group)), 0)) if len(group) else first
    rank = np.empty(len(group), dtype=np.int64)
    rank[order] = np.arange(len(group)) - starts
    return rank


def segment_of(offsets: np.ndarray) -> np.ndarray:
    """(N,) int64: the segment of each item. offsets [0, 2, 3] -> [0, 0, 1]."""
    return np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))


def next_in_segment(offsets: np.ndarray) -> np.ndarray:
    """(N,) int64: the item after each in its segment, the segment's first after its last: a ring's next
    vertex. offsets [0, 3, 5] -> [1, 2, 0, 4, 3]."""
    seg = segment_of(offsets)
    at = np.arange(len(seg))
    return np.where(at + 1 < offsets[1:][seg], at + 1, offsets[:-1][seg])


def segment_reduce(ufunc: np.ufunc, values: np.ndarray, offsets: np.ndarray, empty) -> np.ndarray:
    """``ufunc.reduce`` over each segment (sum with np.add, min with np.minimum, ...).

    Empty segments get ``empty``, which ``reduceat`` alone gets wrong.
    """
    counts = np.diff(offsets)
    out = np.full((len(counts), *values.shape[1:]), empty, dtype=values.dtype)
    nonempty = counts > 0
    if nonempty.any():
        # Only the starts of non-empty segments: each then runs to the next such start (the empty
        # segments between have zero length), the last to the end. offsets [0, 2, 2] -> starts [0].
        out[nonempty] = ufunc.reduceat(values, offsets[:-1][nonempty], axis=0)
    return out


def fan_out(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Children of a ragged fan-out: (parent, index within parent), each (sum(counts),) int64.

    counts [2, 0, 3] -> parent [0, 0, 2, 2, 2], index [0, 1, 0, 1, 2].
    """
    counts = np.asarray(counts, dtype=np.int64)
    offsets = offsets_from_counts(counts)
    parent = np.repeat(np.arange(len(counts)), counts)
    # position of each child minus the offset of its parent's first child
    index = np.arange(offsets[-1], dtype=np.int64) - offsets[:-1][parent]
    return parent, index


def row_groups(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Equal rows of a key table (n, k): each row's group (n,) int64, groups numbered in key order,
    and each group's first row (g,) int64. What ``np.unique(keys, axis=0, return_index=True,
    return_inverse=True)`` gives, from one ``lexsort`` of the columns (its row-wise sort is far slower).

    keys [[1, 5], [0, 2], [1, 5]] -> groups [1, 0, 1], first rows [1, 0].
    """
    if not len(keys):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    order = np.lexsort(keys.T[::-1])  # stable: a group's first row sorts first
    sorted_keys = keys[order]
    new = np.r_[True, (sorted_keys[1:] != sorted_keys[:-1]).any(axis=1)]
    groups = np.empty(len(keys), dtype=np.int64)
    groups[order] = np.cumsum(new) - 1
    return groups, order[new]


def group_bounds(group: np.ndarray, n: int, *values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each group's lowest and highest values (n, d): what ``np.minimum.at`` and ``np.maximum.at`` into
    ``inf`` / ``-inf`` give (a NaN wins, a group without items keeps the infinities), in one pass of a
    kernel (``ufunc.at`` is slow on rows). ``group`` (k,) in [0, n), in any order; ``values`` one or more
    (k, d) arrays whose rows are all of those groups (a segment's starts and ends: no concatenation).

    group [1, 0, 1], values [[2], [5], [-1]] -> low [[5], [-1]], high [[5], [2]]."""
    return _group_bounds(np.ascontiguousarray(group, dtype=np.int64), n,
                         tuple(np.ascontiguousarray(v, dtype=np.float64) for v in values))


@njit(cache=True, nogil=True)
def _group_bounds(group, n, values):
    low = np.full((n, values[0].shape[1]), np.inf)
    high = np.full((n, values[0].shape[1]), -np.inf)
    for rows in values:
        for k in range(len(group)):
            g = group[k]
            for j in range(rows.shape[1]):
                v = rows[k, j]
                # as np.minimum / np.maximum: a NaN, once met, stays
                if v < low[g, j] or np.isnan(v):
                    low[g, j] = v
                if v > high[g, j] or np.isnan(v):
                    high[g, j] = v
    return low, high


@njit(cache=True, nogil=True)
def grow(items: np.ndarray, need: int) -> np.ndarray:
    """``items`` with room for ``need`` rows (the length at least doubles), its rows kept: the append
    buffer of numba kernels that build ragged outputs of unknown size."""
    if need <= len(items):
        return items
    out = np.empty((max(need, 2 * len(items)),) + items.shape[1:], items.dtype)
    out[: len(items)] = items
    return out
