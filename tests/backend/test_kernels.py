"""The numba kernels of grammarc.backend.kernels against plain Python/numpy references on random batches."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grammarc.backend.kernels.order import group_by, place, put, scatter_rows, tally
from grammarc.backend.kernels.scope import (
    centred,
    component_origins,
    leaf_kinds,
    place_children,
    translated,
    turned_frames,
    xforms,
)
from grammarc.backend.kernels.split import repeat, repeat_counts, subdiv
from grammarc.backend.kernels.texture import instance_maps, vertex_maps
from grammarc.backend.kernels.turns import _MOSTLY_NEW, distinct_turns
from grammarc.backend.random import child_keys

SIZES = [0, 1, 2, 50]
TOL = 1e-9


def random_frames(rng, f):
    """(f, 3, 3) random rotations, rows the axes."""
    q, _ = np.linalg.qr(rng.normal(size=(f, 3, 3)))
    q[np.linalg.det(q) < 0, 2] *= -1
    return np.ascontiguousarray(q)


# --------------------------------------------------------------------------------------------- split.subdiv


def subdiv_reference(extent, values, relative, tol):
    """Paper section 2: relative sizes share what the absolute ones leave; parts past the scope are cut."""
    out = []
    for i, e in enumerate(extent):
        row = values[0] if len(values) == 1 else values[i]
        absolute = sum(v for v, r in zip(row, relative) if not r)
        rel = sum(v for v, r in zip(row, relative) if r)
        free = max(e - absolute, 0.0)
        at = 0.0
        for j, (v, r) in enumerate(zip(row, relative)):
            size = (v * free / rel if rel > 0 else 0.0) if r else v
            length = min(at + size, e) - at
            if length > tol:
                out.append((i, j, at, length))
            at += size
    return out


def check_subdiv(extent, values, relative, tol=TOL):
    parent, part, pos, length = subdiv(extent, values, relative, tol)
    want = subdiv_reference(extent, values, relative, tol)
    assert parent.dtype == np.int64 and part.dtype == np.int64
    assert list(zip(parent.tolist(), part.tolist())) == [(i, j) for i, j, _, _ in want]
    np.testing.assert_allclose(pos, [w[2] for w in want], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(length, [w[3] for w in want], rtol=1e-12, atol=1e-12)
    return parent, part, pos, length


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("shared", [False, True])
def test_subdiv_random(n, shared):
    rng = np.random.default_rng(n + 100 * shared)
    p = 5
    extent = rng.uniform(0, 20, n)
    extent[rng.random(n) < 0.1] = 0.0
    values = rng.uniform(0.1, 6, (1 if shared else n, p))
    relative = rng.random(p) < 0.4
    parent, _, pos, length = check_subdiv(extent, values, relative)
    # Children tile their parent from 0 and never leave it.
    assert np.all(length > TOL)
    assert np.all(pos + length <= extent[parent] + 1e-12)


def test_subdiv_paper_example():
    """Subdiv("X", 2, 1r, 1r, 2): 2, 4, 4, 2 on width 12 and 2, 3, 3, 2 on width 10."""
    values = np.array([[2.0, 1.0, 1.0, 2.0]])
    relative = np.array([False, True, True, False])
    _, part, pos, length = check_subdiv(np.array([12.0, 10.0]), values, relative)
    assert part.tolist() == [0, 1, 2, 3] * 2
    assert length.tolist() == [2, 4, 4, 2, 2, 3, 3, 2]
    assert pos.tolist() == [0, 2, 6, 10, 0, 2, 5, 8]


def test_subdiv_overflow_cuts_last_and_drops_beyond():
    """Absolute sizes 4, 4, 4 on 10: the third part is cut to 2; 4, 8, 4 drops the third."""
    relative = np.zeros(3, bool)
    _, part, _, length = check_subdiv(np.array([10.0]), np.array([[4.0, 4.0, 4.0]]), relative)
    assert part.tolist() == [0, 1, 2] and length.tolist() == [4, 4, 2]
    _, part, _, length = check_subdiv(np.array([10.0]), np.array([[4.0, 8.0, 4.0]]), relative)
    assert part.tolist() == [0, 1] and length.tolist() == [4, 6]


def test_subdiv_relative_parts_vanish_when_absolutes_fill():
    relative = np.array([False, True, False])
    _, part, _, _ = check_subdiv(np.array([6.0]), np.array([[3.0, 1.0, 3.0]]), relative)
    assert part.tolist() == [0, 2]


def test_subdiv_drops_parts_at_or_below_tol():
    relative = np.zeros(3, bool)
    _, part, _, _ = check_subdiv(np.array([10.0]), np.array([[1.0, 0.5, 2.0]]), relative, tol=0.5)
    assert part.tolist() == [0, 2]


def test_subdiv_float_sum_makes_no_sliver():
    """0.1 + 0.2 overshoots 0.3 in float64: the last part is cut, not followed by a sliver."""
    _, part, _, length = check_subdiv(np.array([0.3]), np.array([[0.1, 0.2]]), np.zeros(2, bool))
    assert part.tolist() == [0, 1]
    assert length.sum() == pytest.approx(0.3)


# --------------------------------------------------------------------------------------------- split.repeat


def repeat_counts_reference(extent, size, tol):
    return [0 if e <= tol else max(math.ceil(e / s - 1e-9), 1) for e, s in zip(extent, size)]


@pytest.mark.parametrize("n", SIZES)
def test_repeat_counts_random(n):
    rng = np.random.default_rng(n)
    extent = rng.uniform(0, 30, n)
    extent[rng.random(n) < 0.2] = 0.0
    size = rng.uniform(0.5, 5, n)
    counts = repeat_counts(extent, size, TOL)
    assert counts.dtype == np.int64
    assert counts.tolist() == repeat_counts_reference(extent, size, TOL)


@pytest.mark.parametrize("extent, size, want", [
    (10.0, 2.0, 5),      # exact fit
    (10.5, 2.0, 6),      # ceil
    (0.6, 0.2, 3),       # 0.6 / 0.2 = 2.9999999999999996
    (0.3, 0.1, 3),       # 0.3 / 0.1 = 2.9999999999999996
    (0.7, 0.1, 7),
    (1.0, 5.0, 1),       # smaller than one element: one, stretched
    (0.0, 1.0, 0),       # zero extent: none
])
def test_repeat_counts_cases(extent, size, want):
    assert repeat_counts(np.array([extent]), np.array([size]), TOL).tolist() == [want]


@pytest.mark.parametrize("n", SIZES)
def test_repeat_random(n):
    rng = np.random.default_rng(n)
    extent = rng.uniform(0, 30, n)
    counts = rng.integers(0, 5, n)
    parent, part, pos, length = repeat(extent, counts)
    want = [(i, j, j * e / c, e / c) for i, (e, c) in enumerate(zip(extent, counts)) for j in range(c)]
    assert parent.tolist() == [w[0] for w in want]
    assert part.tolist() == [w[1] for w in want]
    np.testing.assert_allclose(pos, [w[2] for w in want], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(length, [w[3] for w in want], rtol=1e-12)


# -------------------------------------------------------------------------------------------------- order


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("k", [1, 3, 8])
def test_group_by_is_stable_counting_sort(n, k):
    group = np.random.default_rng(n * k).integers(0, k, n).astype(np.int64)
    order, offsets = group_by(group, k)
    assert order.tolist() == np.argsort(group, kind="stable").tolist()
    assert offsets.tolist() == [0, *np.cumsum(np.bincount(group, minlength=k)).tolist()]
    for g in range(k):
        assert np.all(group[order[offsets[g]:offsets[g + 1]]] == g)


def test_group_by_docstring_example():
    order, offsets = group_by(np.array([1, 0, 1, 0]), 2)
    assert order.tolist() == [1, 3, 0, 2]
    assert offsets.tolist() == [0, 2, 4]


@pytest.mark.parametrize("n", SIZES)
def test_scatter_rows(n):
    rng = np.random.default_rng(n)
    big = n + 3
    src = rng.normal(size=(n, 12))
    dest = rng.permutation(big)[:n].astype(np.int64)
    out = np.zeros((big, 12))
    want = out.copy()
    want[dest] = src
    scatter_rows(src, dest, out)
    assert np.array_equal(out, want)


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("k", [1, 3, 8])
def test_place_in_pieces_is_a_stable_counting_sort(n, k):
    group = np.random.default_rng(n + k).integers(0, k, n).astype(np.int32)
    counts = np.bincount(group, minlength=k)
    fill = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    cut = n // 3
    dest = np.concatenate([place(group[:cut], fill), place(group[cut:], fill)])  # fill carries over
    order = np.argsort(group, kind="stable")
    assert dest.tolist() == np.argsort(order).tolist()
    assert fill.tolist() == np.cumsum(counts).tolist()


def test_place_docstring_example():
    fill = np.array([0, 2], np.int64)
    assert place(np.array([1, 0, 1]), fill).tolist() == [2, 0, 3]
    assert fill.tolist() == [1, 4]


def test_put():
    out = np.zeros(5, np.int32)
    put(7, np.array([4, 1], np.int64), out)
    assert out.tolist() == [0, 7, 0, 0, 7]


# -------------------------------------------------------------------------------------------------- scope


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_place_children(n, axis):
    rng = np.random.default_rng(n + 10 * axis)
    frames = random_frames(rng, 4)
    origin = rng.normal(size=(n, 3)) * 10
    size = rng.uniform(1, 10, (n, 3))
    key = rng.integers(0, 2**64, n, dtype=np.uint64)
    frame, geom, lot, depth = (rng.integers(lo, 4, n).astype(np.int32) for lo in (0, -1, 0, 0))
    m = 3 * n
    parent = np.sort(rng.integers(0, max(n, 1), m)) if n else np.zeros(0, np.int64)
    pos = rng.uniform(0, 5, m)
    length = rng.uniform(0.1, 5, m)
    index = rng.integers(0, 9, m).astype(np.int64)
    order = rng.permutation(m).astype(np.int64)
    site = 7
    out = place_children(origin, size, key, frame, geom, lot, depth, frames, axis, order, parent, pos,
                         length, site, index)
    out_origin, out_size, out_key, out_frame, out_geom, out_lot, out_depth, out_parent = out
    p = parent[order]
    want_origin = origin[p] + pos[order, None] * frames[frame[p], axis]
    want_size = size[p].copy()
    want_size[:, axis] = length[order]
    np.testing.assert_allclose(out_origin, want_origin, rtol=1e-14, atol=1e-12)
    assert np.array_equal(out_size, want_size)
    assert out_key.dtype == np.uint64
    assert np.array_equal(out_key, child_keys(key[p], site, index[order]))
    assert out_parent.dtype == np.int64 and np.array_equal(out_parent, p)
    for got, column in ((out_frame, frame), (out_geom, geom), (out_lot, lot), (out_depth, depth)):
        assert got.dtype == np.int32 and np.array_equal(got, column[p])


@pytest.mark.parametrize("n", SIZES)
def test_xforms(n):
    rng = np.random.default_rng(n)
    frames = random_frames(rng, 5)
    frame = rng.integers(0, 5, n).astype(np.int32)
    size = rng.uniform(0, 10, (n, 3))
    size[rng.random((n, 3)) < 0.2] = 0.0
    lot_origin = rng.uniform(-1e7, 1e7, (4, 3)).round()  # lots' origins, far from the world's
    lot = rng.integers(0, 4, n).astype(np.int32)
    origin = lot_origin[lot] + rng.normal(size=(n, 3)) * 100
    rows = rng.permutation(n)[: n - n // 3]  # some of the batch's rows, in any order
    flat = np.where(rng.random(len(rows)) < 0.5, -1, rng.integers(0, 3, len(rows))).astype(np.int8)
    out = xforms(frames, frame, size, origin, lot, lot_origin, rows, flat)
    assert out.dtype == np.float32 and out.shape == (len(rows), 3, 4)
    want = np.empty((len(rows), 3, 4))
    for c, i in enumerate(rows):
        k = flat[c]
        for j in range(3):
            axis = j if k < 0 else (k + 1 + j) % 3  # a face: its two extents, then its normal times 0
            want[c, :, j] = frames[frame[i], axis] * (size[i, axis] if k < 0 or j < 2 else 0.0)
        want[c, :, 3] = origin[i] - lot_origin[lot[i]]  # relative to the lot's origin, rounded once
    assert np.array_equal(out.view(np.int32), want.astype(np.float32).view(np.int32))  # zeros' signs too


@pytest.mark.parametrize("n", SIZES)
def test_leaf_kinds(n):
    rng = np.random.default_rng(n)
    geom = np.where(rng.random(n) < 0.8, -1, rng.integers(-5, 5, n)).astype(np.int32)
    size = rng.uniform(0, 10, (n, 3))
    size[rng.random((n, 3)) < 0.3] = rng.choice([0.0, 1e-12, np.nan])
    got = leaf_kinds(geom, size, 1e-9)
    flat = size <= 1e-9
    zeros = flat.sum(axis=1)
    want = np.where(zeros == 0, -1, np.where(zeros == 1, np.argmax(flat, axis=1), 3))
    want[geom != -1] = -2
    assert got.dtype == np.int8 and np.array_equal(got, want)


@pytest.mark.parametrize("n", SIZES)
def test_component_origins_give_einsums_bits_signed_zeros_included(n):
    rng = np.random.default_rng(n)
    frames = random_frames(rng, 6)
    frames[5] = np.eye(3) * np.array([1.0, -1.0, -1.0])[:, None]  # a turn whose zeros are signed
    frame = rng.integers(0, 6, n).astype(np.int32)
    origin = rng.normal(size=(n, 3)) * 100
    local_origin = np.where(rng.random((n, 3)) < 0.3, -0.0, rng.normal(size=(n, 3)))
    local_axes = random_frames(rng, n)
    local_axes[::3] = np.eye(3) * np.array([-1.0, -1.0, 1.0])[:, None]
    local_axes[1::7] *= 1e155  # its axes' squares overflow: not orthonormal
    world_origin, bad = component_origins(frames, frame, origin, local_origin, local_axes, 1e-6)
    want_origin = origin + np.einsum("ni,nij->nj", local_origin, frames[frame])
    gram = np.einsum("nij,nkj->nik", local_axes, local_axes)
    assert np.array_equal(world_origin.view(np.int64), want_origin.view(np.int64))
    assert np.array_equal(bad, ~(np.abs(gram - np.eye(3)) < 1e-6).all(axis=(1, 2)))
    assert bad[1::7].all()


def frames_and_ids(rng, n):
    """Four frames, the last a turn whose axes hold signed zeros, and n frame ids among them."""
    frames = random_frames(rng, 4)
    frames[3] = np.eye(3) * np.array([1.0, -1.0, -1.0])[:, None]
    return frames, rng.integers(0, 4, n).astype(np.int32)


@pytest.mark.parametrize("n", SIZES)
def test_translated_gives_einsums_bits_signed_zeros_included(n):
    rng = np.random.default_rng(n)
    frames, frame = frames_and_ids(rng, n)
    origin = np.where(rng.random((n, 3)) < 0.3, -0.0, rng.normal(size=(n, 3)) * 100)
    local = np.where(rng.random((n, 3)) < 0.3, -0.0, rng.normal(size=(n, 3)))
    want = origin + np.einsum("ni,nij->nj", local, frames[frame])
    assert np.array_equal(translated(origin, local, frames, frame).view(np.int64), want.view(np.int64))


def centred_reference(origin, size, frame, base_origin, base_size, base_frame, frames, axes):
    """``center`` as it was first written, in numpy (``einsum``)."""
    base_center = base_origin + np.einsum("ni,nij->nj", base_size / 2, frames[base_frame])
    offset = base_center - (origin + np.einsum("ni,nij->nj", size / 2, frames[frame]))
    out = origin.copy()
    for k in axes:
        axis = frames[frame][:, k]
        out += np.einsum("nj,nj->n", offset, axis)[:, None] * axis
    return out


@pytest.mark.parametrize("n", [*SIZES, 20_000])
@pytest.mark.parametrize("axes", [(0,), (1,), (2,), (0, 2), (1, 2), (0, 1, 2)])
def test_centred_gives_numpys_bits_signed_zeros_included(n, axes):
    """The scopes centred on their bases, whose frames are mostly their own (a push keeps the frame)."""
    rng = np.random.default_rng(n)
    frames, frame = frames_and_ids(rng, n)
    base_frame = np.where(rng.random(n) < 0.7, frame, rng.integers(0, 4, n)).astype(np.int32)

    def values(scale):
        return np.where(rng.random((n, 3)) < 0.3, -0.0, rng.normal(size=(n, 3)) * scale)

    origin, base_origin, size, base_size = values(100), values(1e3), np.abs(values(10)), np.abs(values(10))
    size[::5] = 0.0
    axes = np.array(axes, np.int64)
    got = centred(origin, size, frame, base_origin, base_size, base_frame, frames, axes)
    want = centred_reference(origin, size, frame, base_origin, base_size, base_frame, frames, axes)
    assert np.array_equal(got.view(np.int64), want.view(np.int64))


@pytest.mark.parametrize("n", SIZES)
def test_turned_frames_give_einsums_bits(n):
    rng = np.random.default_rng(n)
    frames, frame = frames_and_ids(rng, n)
    local = np.where(rng.random((n, 3, 3)) < 0.3, -0.0, random_frames(rng, n))
    want = np.einsum("nij,njk->nik", local, frames[frame])
    assert np.array_equal(turned_frames(local, frames, frame).view(np.int64), want.view(np.int64))


def test_xforms_maps_unit_box_corners_to_scope_corners():
    rng = np.random.default_rng(3)
    frames = random_frames(rng, 1)
    size = np.array([[2.0, 3.0, 4.0]])
    origin = np.array([[1.0, -2.0, 5.0]])
    one = np.zeros(1, np.int32)
    x = xforms(frames, one, size, origin, one, np.zeros((1, 3)), np.zeros(1, np.int64), np.full(1, -1, np.int8))[0]
    x = x.astype(np.float64)
    for corner in np.ndindex(2, 2, 2):
        c = np.array(corner, float)
        world = x[:, :3] @ c + x[:, 3]
        np.testing.assert_allclose(world, origin[0] + (c * size[0]) @ frames[0], atol=1e-5)


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("weighted", [False, True])
def test_tally_adds_what_bincount_counts(n, weighted):
    rng = np.random.default_rng(n)
    lot, weights = rng.integers(0, 7, n).astype(np.int32), rng.integers(0, 5, n)
    counts = rng.integers(0, 3, 7)
    want = counts + np.bincount(lot, weights=weights if weighted else None, minlength=7).astype(np.int64)
    added = tally(counts, lot, weights if weighted else np.zeros(0, np.int64))
    assert np.array_equal(counts, want) and added == (weights.sum() if weighted else n)


# ---------------------------------------------------------------------------------- texture.instance_maps


def map_table(rng, n):
    """Texture maps (a table of 9, map 0 NaN, some entries signed zeros), the ids of ``n`` shapes' maps, lot
    origins (some coordinates zero) and the shapes' lots."""
    table = rng.normal(size=(9, 2, 4)) * rng.choice([1e-3, 1.0, 1e4], size=(9, 2, 4))
    table[rng.random((9, 2, 4)) < 0.3] = -0.0
    table[0] = np.nan
    lot_origin = rng.uniform(-1e6, 1e6, (4, 3))
    lot_origin[rng.random((4, 3)) < 0.3] = 0.0
    return table, rng.integers(0, 9, n).astype(np.int32), lot_origin, rng.integers(0, 4, n).astype(np.int32)


def maps_from_lots(table, map_id, lot_origin, lot, rows):
    """numpy's maps of shapes ``rows`` moved to their lots' origins."""
    maps = table[map_id[rows]]
    maps[:, :, 3] += np.einsum("nij,nj->ni", maps[:, :, :3], lot_origin[lot[rows]])
    return maps


@pytest.mark.parametrize("n", SIZES)
def test_instance_maps_give_numpys_bits(n):
    """The maps of records are numpy's composition, bit for bit: the shapes' maps made relative to their
    lots' origins (``einsum``), composed with the records' transforms (``matmul``), for some of the rows in
    any order; map 0 is NaN, some entries and origins are (signed) zeros."""
    rng = np.random.default_rng(n)
    table, map_id, lot_origin, lot = map_table(rng, n)
    rows = rng.permutation(n)[: n - n // 3]
    xform = (rng.normal(size=(len(rows), 3, 4)) * 50).astype(np.float32)
    xform[rng.random(xform.shape) < 0.2] = 0.0
    maps = maps_from_lots(table, map_id, lot_origin, lot, rows)
    want = maps[:, :, :3] @ xform
    want[:, :, 3] += maps[:, :, 3]
    got = instance_maps(table, map_id, rows, lot_origin, lot, xform)
    assert got.dtype == np.float32 and got.shape == (len(rows), 2, 4)
    assert np.array_equal(got.view(np.int32), want.astype(np.float32).view(np.int32))


@pytest.mark.parametrize("n", SIZES)
def test_vertex_maps_give_numpys_bits(n):
    """Mesh vertices' texture coordinates are numpy's, bit for bit: their shapes' maps made relative to
    their lots' origins, applied to the points (``einsum``), the offset added last."""
    rng = np.random.default_rng(n)
    table, map_id, lot_origin, lot = map_table(rng, n)
    vertex_shape = rng.integers(0, n, 3 * n) if n else np.zeros(0, np.int64)
    vertices = (rng.normal(size=(len(vertex_shape), 3)) * 30).astype(np.float32)
    vertices[rng.random(vertices.shape) < 0.2] = -0.0
    maps = maps_from_lots(table, map_id, lot_origin, lot, vertex_shape)
    want = np.einsum("vij,vj->vi", maps[:, :, :3], vertices.astype(np.float64)) + maps[:, :, 3]
    got = vertex_maps(table, map_id, lot_origin, lot, vertex_shape, vertices)
    assert got.dtype == np.float32 and got.shape == (len(vertex_shape), 2)
    assert np.array_equal(got.view(np.int32), want.astype(np.float32).view(np.int32))


# -------------------------------------------------------------------------------------------- turns.distinct


def distinct_reference(frame, local_axes, local):
    """The distinct (frame id, bits of local axes) keys in the order they first come, by a dict."""
    seen, first, which = {}, [], []
    for c in range(len(frame)):
        key = (int(frame[c]), local_axes[c if local is None else local[c]].tobytes())
        if key not in seen:
            seen[key] = len(first)
            first.append(c)
        which.append(seen[key])
    return np.array(first, dtype=np.int64), np.array(which, dtype=np.int32)


def turns_with_repeats(rng, m, n_frames, n_local):
    """m turns of n_frames frame ids by n_local local axes, among them signed zeros and a NaN: -0.0 and
    0.0 are different bits, so different turns; the same NaN's bits are the same turn."""
    local_axes = np.where(rng.random((n_local, 3, 3)) < 0.3, 0.0, rng.normal(size=(n_local, 3, 3)))
    local_axes[1 % n_local] = np.eye(3)
    local_axes[2 % n_local] = np.eye(3) * np.array([1.0, -1.0, -1.0])[:, None]  # signed zeros
    local_axes[3 % n_local] = np.where(np.eye(3) == 0, -0.0, 1.0)  # the identity with -0.0 for its zeros
    local_axes[4 % n_local, 0, 0] = np.nan
    frame = rng.integers(0, n_frames, m).astype(np.int32)
    return frame, np.ascontiguousarray(local_axes), rng.integers(0, n_local, m).astype(np.int64)


@pytest.mark.parametrize("m, n_frames, n_local", [(0, 1, 5), (1, 1, 5), (50, 3, 5), (5000, 40, 9),
                                                  (20000, 300, 12)])
def test_distinct_turns_find_each_key_once_in_order(m, n_frames, n_local):
    rng = np.random.default_rng(m)
    frame, local_axes, local = turns_with_repeats(rng, m, n_frames, n_local)
    local[1::2] = local[:-1:2]  # runs of the same turn, which skip the table
    frame[1::2] = frame[:-1:2]
    want_first, want_which = distinct_reference(frame, local_axes, local)
    first, which = distinct_turns(frame, local_axes, local)
    assert first.dtype == np.int64 and which.dtype == np.int32
    assert np.array_equal(first, want_first) and np.array_equal(which, want_which)
    # the same with every turn's local axes given (local None)
    per_turn = np.ascontiguousarray(local_axes[local])
    first, which = distinct_turns(frame, per_turn, None)
    assert np.array_equal(first, want_first) and np.array_equal(which, want_which)


def test_distinct_turns_tell_signed_zeros_and_frames_apart():
    local_axes = np.stack([np.eye(3), np.where(np.eye(3) == 0, -0.0, 1.0), np.eye(3)])
    frame = np.array([0, 0, 0, 1, 1], dtype=np.int32)
    first, which = distinct_turns(frame, local_axes, np.array([0, 1, 2, 0, 2]))
    assert first.tolist() == [0, 1, 3] and which.tolist() == [0, 1, 0, 2, 2]


def test_distinct_turns_grow_their_table_past_the_mostly_new_mark():
    """More distinct turns than ``_MOSTLY_NEW`` where most turns repeat one: the table grows, all are
    found."""
    rng = np.random.default_rng(7)
    n = 3 * _MOSTLY_NEW
    frame = np.repeat(np.arange(n, dtype=np.int32), 6)
    local_axes = random_frames(rng, 2)
    local = np.tile(np.array([0, 1, 0, 1, 1, 0]), n)
    first, which = distinct_turns(frame, local_axes, local)
    assert len(first) == 2 * n
    assert np.array_equal(which, distinct_reference(frame, local_axes, local)[1])


def test_distinct_turns_give_up_where_they_are_mostly_new():
    """Turns each new: once more than ``_MOSTLY_NEW`` are found every turn is its own, even those that
    repeat after that."""
    m = 4 * _MOSTLY_NEW
    frame = np.arange(m, dtype=np.int32)
    frame[-10:] = 0
    local_axes = np.ascontiguousarray(np.broadcast_to(np.eye(3), (1, 3, 3)))
    first, which = distinct_turns(frame, local_axes, np.zeros(m, dtype=np.int64))
    assert np.array_equal(first, np.arange(m)) and np.array_equal(which, np.arange(m))
    assert which.dtype == np.int32
