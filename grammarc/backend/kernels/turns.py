"""The distinct turns among many, so that shapes turned alike share one new frame.

A component split or an extrusion gives each shape new axes, its local axes (a face's, a normal's) in its
parent's frame. Many shapes share both: every window's box in one facade's frame, its front face turned
the same way. Their frame is computed and stored once (``chunk.Frames.turned``); the frame table then
holds a row per distinct frame rather than one per shape, and the rows read back stay in cache.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Odd 64-bit constants (SplitMix64's and others of its kind): the frame id's, then one per word of the
#: local axes.
_FACTORS = np.array([0x9E3779B97F4A7C15, 0xBF58476D1CE4E5B9, 0x94D049BB133111EB, 0xD6E8FEB86659FD93,
                     0xA0761D6478BD642F, 0xE7037ED1A0B428DB, 0x8EBC6AF09C88C6E3, 0x589965CC75374CC3,
                     0x1D8E4E27C47D124F, 0xFF51AFD7ED558CCD], dtype=np.uint64)

#: Distinct turns past which, if more than half of the turns so far were new, the table is given up.
_MOSTLY_NEW = 4096


@njit(cache=True, nogil=True)
def distinct_turns(frame, local_axes, local):
    """The distinct turns among m: turn c gives the axes ``local_axes[local[c]]`` (rows in the frame
    ``frame[c]``), and two turns are the same where their frame ids and the bits of their local axes are
    (-0.0 is not 0.0: turning keeps signed zeros). ``frame`` (m,) int32, ``local_axes`` (T, 3, 3) float64
    C-contiguous, ``local`` (m,) int64 or None (turn c gives ``local_axes[c]``).

    Returns ``first`` (k,) int64, the first turn of each distinct one in the order they come, and
    ``which`` (m,) int32, each turn's distinct one. One pass over an open-addressing hash table that starts
    small and doubles as distinct turns come, so that it stays in cache where they are few (``np.unique``
    would sort the m keys, several times slower); a turn of the frame and local row of the turn before it
    is that one's without a look-up. Where the turns are mostly distinct (more than half of them new once
    ``_MOSTLY_NEW`` are found) the table would cost more than the rows it saves: every turn is then its
    own (``first`` and ``which`` are ``arange(m)``).
    """
    m = len(frame)
    words = local_axes.reshape((len(local_axes), 9)).view(np.uint64)
    first = np.empty(m, np.int64)
    which = np.empty(m, np.int32)
    keys = np.empty((m, 10), np.uint64)  # each distinct turn's frame id and words, where the table finds them
    hashes = np.empty(m, np.uint64)  # and its hash, to place it again when the table grows
    slot_turn = np.full(64, -1, np.int64)  # the distinct turn in each slot, -1 where free
    slot_hash = np.zeros(64, np.uint64)  # its hash: most slots of other turns are passed without a compare
    k = 0
    for c in range(m):
        if local is None:
            row = c
        else:
            row = local[c]
            if c > 0 and frame[c] == frame[c - 1] and row == local[c - 1]:
                which[c] = which[c - 1]
                continue
        h = np.uint64(frame[c]) * _FACTORS[0]
        for i in range(9):  # products that do not wait for each other
            h += words[row, i] * _FACTORS[i + 1]
        h ^= (h >> np.uint64(29)) ^ (h >> np.uint64(47))  # high bits into the low ones the slots use
        mask = np.uint64(len(slot_turn) - 1)
        s = h & mask
        while True:
            d = slot_turn[s]
            if d < 0:
                slot_turn[s] = k
                slot_hash[s] = h
                first[k] = c
                which[c] = k
                hashes[k] = h
                keys[k, 0] = np.uint64(frame[c])
                for i in range(9):
                    keys[k, i + 1] = words[row, i]
                k += 1
                if 2 * k > len(slot_turn):  # at most half full, so that probes stay short
                    if k > _MOSTLY_NEW and 2 * k > c + 1:
                        return np.arange(m), np.arange(m).astype(np.int32)
                    slot_turn, slot_hash = _grown(hashes, k, 2 * len(slot_turn))
                break
            if slot_hash[s] == h and _same_key(keys, d, frame[c], words, row):
                which[c] = d
                break
            s = (s + np.uint64(1)) & mask
    return first[:k].copy(), which


@njit(cache=True, nogil=True)
def _same_key(keys, d, frame, words, row):
    """Whether distinct turn d's key is ``frame`` and the words of local row ``row``."""
    if keys[d, 0] != np.uint64(frame):
        return False
    for i in range(9):
        if keys[d, i + 1] != words[row, i]:
            return False
    return True


@njit(cache=True, nogil=True)
def _grown(hashes, k, size):
    """A table of ``size`` slots (a power of two) holding distinct turns 0..k-1 by their ``hashes``."""
    slot_turn = np.full(size, -1, np.int64)
    slot_hash = np.zeros(size, np.uint64)
    mask = np.uint64(size - 1)
    for d in range(k):
        s = hashes[d] & mask
        while slot_turn[s] >= 0:
            s = (s + np.uint64(1)) & mask
        slot_turn[s] = d
        slot_hash[s] = hashes[d]
    return slot_turn, slot_hash
