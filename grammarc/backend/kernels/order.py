"""Stable orderings of rows by a small integer key (a body part, a lot): counting sorts in numba."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def group_by(group, k):
    """Stable counting sort of children by body part: ``order`` (m,) int64 and ``offsets`` (k+1,) int64.

    group [1, 0, 1, 0], k 2 -> order [1, 3, 0, 2], offsets [0, 2, 4]: the children of part g are
    ``order[offsets[g]:offsets[g + 1]]``, so each part's batch is a contiguous slice.
    """
    offsets = np.zeros(k + 1, np.int64)
    for g in group:
        offsets[g + 1] += 1
    for g in range(k):
        offsets[g + 1] += offsets[g]
    fill = offsets[:-1].copy()
    order = np.empty(len(group), np.int64)
    for i in range(len(group)):
        g = group[i]
        order[fill[g]] = i
        fill[g] += 1
    return order, offsets


@njit(cache=True, nogil=True)
def scatter_rows(src, dest, out):
    """out[dest[i]] = src[i] for rows of 2-D arrays: src (k, w), dest (k,) int64, out (N, w)."""
    for i in range(len(dest)):
        d = dest[i]
        for j in range(src.shape[1]):
            out[d, j] = src[i, j]


@njit(cache=True, nogil=True)
def place(group, fill):
    """Each row's place in a stable counting sort by group, advancing ``fill`` (k,) int64, the next free
    place of each group: for rows that come in several pieces, ``fill`` carries over from piece to piece.
    group [1, 0, 1], fill [0, 2] -> [2, 0, 3], fill [1, 4]."""
    dest = np.empty(len(group), np.int64)
    for i in range(len(group)):
        g = group[i]
        dest[i] = fill[g]
        fill[g] += 1
    return dest


@njit(cache=True, nogil=True)
def put(value, dest, out):
    """out[dest[i]] = value for every i: a constant column (a piece's asset or symbol) in sorted places."""
    for i in range(len(dest)):
        out[dest[i]] = value


@njit(cache=True, nogil=True)
def tally(counts, lot, weights):
    """``counts[lot[i]] += weights[i]`` (1 each where ``weights`` is empty) for counts (L,) int64, lot (n,)
    integers, weights (n,) or (0,) int64; returns the sum added. O(n), whatever L is."""
    added = 0
    for i in range(len(lot)):
        w = weights[i] if len(weights) else 1
        counts[lot[i]] += w
        added += w
    return added


@njit(cache=True, nogil=True)
def rank_in_group(group, k):
    """Each row's number among the rows of its group before it, for groups in [0, k): one pass with a
    counter per group. group [5, 3, 5, 5], k 6 -> [0, 0, 1, 2]."""
    seen = np.zeros(k, np.int64)
    rank = np.empty(len(group), np.int64)
    for i in range(len(group)):
        rank[i] = seen[group[i]]
        seen[group[i]] += 1
    return rank


@njit(cache=True, nogil=True)
def fold_groups(group, values, total, counted, low, high):
    """Add ``values`` (n,) to their groups' (k,) sum ``total``, count ``counted``, least ``low`` and
    greatest ``high``, in place: the aggregates of a group in one pass."""
    for i in range(len(group)):
        g = group[i]
        v = values[i]
        total[g] += v
        counted[g] += 1.0
        low[g] = min(low[g], v)
        high[g] = max(high[g], v)
