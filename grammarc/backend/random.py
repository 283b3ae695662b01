"""Counter-based random streams: a shape's randomness is a pure function of (seed, lot, derivation path).

Every shape carries a 64-bit key. A lot's key mixes the seed with the lot's number in the input; a child's
key mixes its parent's key with the site of the operation that made it (numbered in the grammar) and its
index among that operation's children. ``rand`` draws ``uniform(key, site)``. No state is shared between
shapes, so the same lot gives the same numbers whether it is derived alone, in a chunk, or on a worker.
The mixer is SplitMix64's finalizer (Steele et al. 2014); uint64 arithmetic wraps.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_SEED_SALT = 0x5EED


@njit(cache=True, nogil=True, inline="always")
def mix1(key, value):
    """One key mixed with one integer: SplitMix64's finalizer of key ^ ((value + 1) * golden)."""
    z = key ^ ((np.uint64(value) + np.uint64(1)) * np.uint64(0x9E3779B97F4A7C15))
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True, nogil=True)
def _mix(key, value):
    out = np.empty(len(key), np.uint64)
    for i in range(len(key)):
        out[i] = mix1(key[i], value[i])
    return out


@njit(cache=True, nogil=True, inline="always")
def child_key1(key, site, index):
    """The key of child ``index`` made at ``site`` of a shape of ``key`` (fused kernels call it too)."""
    return mix1(mix1(key, site), index)


@njit(cache=True, nogil=True, inline="always")
def uniform1(key, site):
    """The draw in [0, 1) of a shape of ``key`` at ``site``: its mixed key's top 53 bits times 2**-53."""
    return (mix1(key, site) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, nogil=True)
def _child_keys(key, site, index):
    out = np.empty(len(key), np.uint64)
    for i in range(len(key)):
        out[i] = child_key1(key[i], site, index[i])
    return out


@njit(cache=True, nogil=True)
def _uniform(key, site):
    out = np.empty(len(key))
    for i in range(len(key)):
        out[i] = uniform1(key[i], site)
    return out


def mix(key: np.ndarray, value) -> np.ndarray:
    """Keys (n,) uint64 derived from ``key`` (n,) uint64 and ``value`` (scalar or (n,) integers)."""
    value = np.broadcast_to(np.asarray(value, dtype=np.int64), key.shape)
    return _mix(np.ascontiguousarray(key), np.ascontiguousarray(value))


def child_keys(key: np.ndarray, site: int, index: np.ndarray | int = 0) -> np.ndarray:
    """Keys (n,) uint64 of children made at ``site``; ``index`` numbers the children of one parent."""
    index = np.broadcast_to(np.asarray(index, dtype=np.int64), key.shape)
    return _child_keys(np.ascontiguousarray(key), site, np.ascontiguousarray(index))


def lot_keys(seed: int, lot_index: np.ndarray) -> np.ndarray:
    """Root keys (L,) uint64 of lots numbered ``lot_index`` (their positions in the input)."""
    base = mix(np.array([seed & 0xFFFFFFFFFFFFFFFF], dtype=np.uint64), _SEED_SALT)[0]
    return mix(np.full(len(lot_index), base, dtype=np.uint64), lot_index)


def uniform(key: np.ndarray, site: int) -> np.ndarray:
    """One uniform draw in [0, 1) per key for the draw site ``site``: (n,) float64."""
    return _uniform(np.ascontiguousarray(key), site)
