"""The chunk's tables: turned frames shared by the shapes turned alike, trim planes by id."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend.chunk import Frames, TrimPlanes
from grammarc.backend.kernels.turns import _MOSTLY_NEW


def rotations(rng, n):
    q, _ = np.linalg.qr(rng.normal(size=(n, 3, 3)))
    q[np.linalg.det(q) < 0, 2] *= -1
    return np.ascontiguousarray(q)


@pytest.mark.parametrize("indexed", [False, True])
def test_turned_frames_are_einsums_bits_one_row_per_distinct_turn(indexed):
    rng = np.random.default_rng(3)
    frames = Frames(capacity=2)
    parents = frames.add(rotations(rng, 5))
    table = rotations(rng, 4)
    table[3] = np.eye(3) * np.array([1.0, -1.0, -1.0])[:, None]  # a turn whose zeros are signed
    m = 200
    frame = parents[rng.integers(0, 5, m)]
    local = rng.integers(0, 4, m)
    before = frames.count
    ids, axes = frames.turned(table, frame, local) if indexed else frames.turned(table[local], frame)
    want = np.einsum("nij,njk->nik", table[local], frames[frame])
    assert ids.dtype == np.int32
    assert np.array_equal(frames[ids].view(np.int64), want.view(np.int64))
    assert np.array_equal(axes.view(np.int64), want.view(np.int64))
    keys = frame.astype(np.int64) * 4 + local
    assert frames.count - before == len(np.unique(keys))  # one new row per (frame, local axes)
    assert (ids >= before).all()  # new rows only: no shape takes a row it did not make here
    same = keys[:, None] == keys[None, :]
    assert np.array_equal(ids[:, None] == ids[None, :], same)


def test_turned_frames_mostly_distinct_each_get_a_row():
    """Past ``turns._MOSTLY_NEW`` distinct turns, more than half of them new: a row per turn, even for those
    that repeat one before."""
    rng = np.random.default_rng(4)
    frames = Frames()
    m = 3 * _MOSTLY_NEW
    parents = frames.add(rotations(rng, m))
    frame = parents.copy()
    frame[-5:] = parents[0]
    local = rotations(rng, 1)
    before = frames.count
    ids, axes = frames.turned(local, frame, np.zeros(m, dtype=np.int64))
    assert np.array_equal(ids, np.arange(before, before + m)) and frames.count == before + m
    want = np.einsum("ij,njk->nik", local[0], frames[frame])
    assert np.array_equal(axes.view(np.int64), want.view(np.int64))
    assert np.array_equal(frames[ids].view(np.int64), want.view(np.int64))


def test_turned_frames_of_nothing_add_no_row():
    frames = Frames()
    ids, axes = frames.turned(np.eye(3)[None], np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.int64))
    assert len(ids) == 0 and ids.dtype == np.int32 and axes.shape == (0, 3, 3) and frames.count == 0


def test_trim_planes_row_0_is_none_and_stays_so_as_the_table_grows():
    """Shapes without planes hold id 0, a NaN row; added rows are numbered from 1 and kept as the table
    grows past its capacity."""
    table = TrimPlanes(24, capacity=2)
    rows = np.arange(3 * 24, dtype=float).reshape(3, 24)
    assert table.add(rows).tolist() == [1, 2, 3]
    got = table[np.array([0, 3, 1], dtype=np.int32)]
    assert got.shape == (3, 24) and np.isnan(got[0]).all()
    np.testing.assert_array_equal(got[1:], rows[[2, 0]])
