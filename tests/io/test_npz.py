"""instances.npz: round trips, rebased mesh offsets, reproducible bytes, atomicity, bounded memory."""

import dataclasses
import gc
import json
import os
import tracemalloc
import zipfile

import numpy as np
import pytest

from grammarc.io.npz import InstanceWriter, MeshChunk, TerminalChunk, read_instances

ASSETS = ["builtin:cube", "builtin:quad", "facade/window.obj"]
SYMBOLS = ["Wall", "Window", "Roof", "Ledge"]
KEYS = {
    "assets", "asset", "xform", "lot", "symbols", "symbol", "meta",
    "mesh_vertices", "mesh_ring_offsets", "mesh_face_offsets", "mesh_lot", "mesh_symbol",
}  # fmt: skip


def random_mesh(rng, n_faces):
    """Faces of 1-3 rings (an outline, then holes) of 3-6 vertices each."""
    rings_per_face = rng.integers(1, 4, n_faces)
    vertices_per_ring = rng.integers(3, 7, rings_per_face.sum())
    return MeshChunk(
        vertices=rng.normal(size=(vertices_per_ring.sum(), 3)).astype(np.float32),
        ring_offsets=np.concatenate([[0], np.cumsum(vertices_per_ring)]).astype(np.int64),
        face_offsets=np.concatenate([[0], np.cumsum(rings_per_face)]).astype(np.int64),
        lot=rng.integers(0, 100, n_faces).astype(np.int32),
        symbol=rng.integers(0, len(SYMBOLS), n_faces).astype(np.int32),
    )


def random_chunk(rng, n, n_faces):
    return TerminalChunk(
        asset=rng.integers(0, len(ASSETS), n).astype(np.int32),
        xform=rng.normal(size=(n, 3, 4)).astype(np.float32),
        lot=rng.integers(0, 100, n).astype(np.int32),
        symbol=rng.integers(0, len(SYMBOLS), n).astype(np.int32),
        mesh=random_mesh(rng, n_faces),
    )


def slice_mesh(mesh, f0, f1):
    """Faces f0:f1 of ``mesh`` as a chunk of their own, offsets starting at 0."""
    r0, r1 = mesh.face_offsets[f0], mesh.face_offsets[f1]
    v0, v1 = mesh.ring_offsets[r0], mesh.ring_offsets[r1]
    return MeshChunk(
        vertices=mesh.vertices[v0:v1],
        ring_offsets=mesh.ring_offsets[r0 : r1 + 1] - v0,
        face_offsets=mesh.face_offsets[f0 : f1 + 1] - r0,
        lot=mesh.lot[f0:f1],
        symbol=mesh.symbol[f0:f1],
    )


def slice_chunk(chunk, i0, i1, f0, f1):
    """Instances i0:i1 and faces f0:f1 of ``chunk``."""
    rows = slice(i0, i1)
    return TerminalChunk(
        chunk.asset[rows],
        chunk.xform[rows],
        chunk.lot[rows],
        chunk.symbol[rows],
        slice_mesh(chunk.mesh, f0, f1),
    )


def faces(mesh_vertices, ring_offsets, face_offsets):
    """Each face as a list of its rings' vertex arrays: what the offsets mean, read one face at a time."""
    return [
        [
            mesh_vertices[ring_offsets[r] : ring_offsets[r + 1]]
            for r in range(face_offsets[f], face_offsets[f + 1])
        ]
        for f in range(len(face_offsets) - 1)
    ]


def write(path, chunks, meta=None):
    with InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta=meta or {"seed": 7}) as out:
        for chunk in chunks:
            out.write(chunk)
    return out.close()


@pytest.fixture
def chunks():
    rng = np.random.default_rng(0)
    sizes = [(5, 3), (0, 0), (1, 4), (17, 0), (0, 2), (9, 6)]
    return [random_chunk(rng, n, n_faces) for n, n_faces in sizes]


def test_round_trip(tmp_path, chunks):
    path = tmp_path / "city.npz"
    counts = write(path, chunks, meta={"seed": 7, "grammar": "city.cga"})
    record = read_instances(path)

    assert set(record) == KEYS
    assert record["assets"].tolist() == ASSETS
    assert record["symbols"].tolist() == SYMBOLS
    for key in ("asset", "xform", "lot", "symbol"):
        expected = np.concatenate([getattr(c, key) for c in chunks])
        assert record[key].dtype == expected.dtype
        np.testing.assert_array_equal(record[key], expected)
    np.testing.assert_array_equal(record["mesh_lot"], np.concatenate([c.mesh.lot for c in chunks]))
    np.testing.assert_array_equal(record["mesh_symbol"], np.concatenate([c.mesh.symbol for c in chunks]))

    assert counts == {"instances": 32, "mesh_faces": 15, "mesh_vertices": len(record["mesh_vertices"])}
    assert record["meta"] == {
        "seed": 7,
        "grammar": "city.cga",
        "counts": counts,
        "format": "grammarc.instances/1",
    }


def test_mesh_offsets_are_rebased_across_chunks(tmp_path, chunks):
    path = tmp_path / "city.npz"
    write(path, chunks)
    record = read_instances(path)

    got = faces(record["mesh_vertices"], record["mesh_ring_offsets"], record["mesh_face_offsets"])
    expected = [
        face for c in chunks for face in faces(c.mesh.vertices, c.mesh.ring_offsets, c.mesh.face_offsets)
    ]
    assert len(got) == len(expected) == 15
    assert any(len(face) > 1 for face in got)  # some faces have holes
    for got_face, expected_face in zip(got, expected):
        assert len(got_face) == len(expected_face)
        for got_ring, expected_ring in zip(got_face, expected_face):
            np.testing.assert_array_equal(got_ring, expected_ring)
    assert record["mesh_ring_offsets"][-1] == len(record["mesh_vertices"])
    assert record["mesh_face_offsets"][-1] == len(record["mesh_ring_offsets"]) - 1


def test_concat_matches_written_mesh(tmp_path, chunks):
    path = tmp_path / "city.npz"
    write(path, chunks)
    record = read_instances(path)
    joined = MeshChunk.concat([c.mesh for c in chunks])
    for field in ("vertices", "ring_offsets", "face_offsets", "lot", "symbol"):
        np.testing.assert_array_equal(getattr(joined, field), record[f"mesh_{field}"])


def test_concat_shifts_offsets():
    triangle = MeshChunk(
        vertices=np.zeros((3, 3), np.float32),
        ring_offsets=np.array([0, 3], np.int64),
        face_offsets=np.array([0, 1], np.int64),
        lot=np.array([0], np.int32),
        symbol=np.array([0], np.int32),
    )
    square_with_hole = MeshChunk(
        vertices=np.ones((7, 3), np.float32),
        ring_offsets=np.array([0, 4, 7], np.int64),
        face_offsets=np.array([0, 2], np.int64),
        lot=np.array([1], np.int32),
        symbol=np.array([2], np.int32),
    )
    joined = MeshChunk.concat([triangle, MeshChunk.empty(), square_with_hole, triangle])
    assert joined.ring_offsets.tolist() == [0, 3, 7, 10, 13]
    assert joined.face_offsets.tolist() == [0, 1, 3, 4]
    assert joined.lot.tolist() == [0, 1, 0]
    assert joined.vertices.shape == (13, 3)
    empty = MeshChunk.concat([])
    assert empty.ring_offsets.tolist() == [0] and empty.face_offsets.tolist() == [0]


def test_loads_with_plain_np_load(tmp_path, chunks):
    path = tmp_path / "city.npz"
    write(path, chunks)
    with np.load(path, allow_pickle=False) as npz:
        assert set(npz.files) == KEYS
        dtypes = {key: npz[key].dtype for key in npz.files}
        meta = npz["meta"]
        assert meta.shape == () and meta.dtype.kind == "U"
        assert json.loads(str(meta))["counts"]["instances"] == 32
    assert dtypes["xform"] == np.float32 and dtypes["mesh_vertices"] == np.float32
    assert dtypes["mesh_ring_offsets"] == np.int64 and dtypes["mesh_face_offsets"] == np.int64
    for key in ("asset", "lot", "symbol", "mesh_lot", "mesh_symbol"):
        assert dtypes[key] == np.int32
    with zipfile.ZipFile(path) as zf:
        infos = zf.infolist()
    assert all(info.compress_type == zipfile.ZIP_STORED for info in infos)
    assert {info.date_time for info in infos} == {(1980, 1, 1, 0, 0, 0)}


def test_bytes_do_not_depend_on_chunking_or_run(tmp_path):
    chunk = random_chunk(np.random.default_rng(1), 10, 10)
    one = write(tmp_path / "one.npz", [chunk])
    write(tmp_path / "again.npz", [chunk])
    rows = [slice_chunk(chunk, i, i + 1, i, i + 1) for i in range(10)]
    write(tmp_path / "rows.npz", rows)
    # Uneven pieces, with all faces in a chunk that has no instances and empty chunks between.
    pieces = [
        slice_chunk(chunk, 0, 0, 0, 10),
        slice_chunk(chunk, 0, 3, 10, 10),
        slice_chunk(chunk, 3, 10, 10, 10),
    ]
    write(tmp_path / "pieces.npz", pieces)

    assert one["mesh_faces"] == 10
    data = {
        name: (tmp_path / name).read_bytes() for name in ("one.npz", "again.npz", "rows.npz", "pieces.npz")
    }
    assert len(set(data.values())) == 1


def test_zero_chunks_give_empty_arrays(tmp_path):
    path = tmp_path / "empty.npz"
    assert write(path, []) == {"instances": 0, "mesh_faces": 0, "mesh_vertices": 0}
    with InstanceWriter(tmp_path / "bare.npz", assets=[], symbols=[], meta={}):
        pass
    record = read_instances(path)
    expected = {
        "asset": (np.int32, (0,)),
        "xform": (np.float32, (0, 3, 4)),
        "lot": (np.int32, (0,)),
        "symbol": (np.int32, (0,)),
        "mesh_vertices": (np.float32, (0, 3)),
        "mesh_ring_offsets": (np.int64, (1,)),
        "mesh_face_offsets": (np.int64, (1,)),
        "mesh_lot": (np.int32, (0,)),
        "mesh_symbol": (np.int32, (0,)),
    }
    for key, (dtype, shape) in expected.items():
        assert (record[key].dtype, record[key].shape) == (np.dtype(dtype), shape), key
    assert record["mesh_ring_offsets"].tolist() == [0]
    bare = read_instances(tmp_path / "bare.npz")
    assert bare["assets"].shape == (0,) and bare["assets"].dtype.kind == "U"
    assert bare["symbols"].shape == (0,) and bare["symbols"].dtype.kind == "U"


def test_close_leaves_only_the_output(tmp_path, chunks):
    write(tmp_path / "city.npz", chunks)
    assert os.listdir(tmp_path) == ["city.npz"]


def test_abort_leaves_no_file_and_no_temporaries(tmp_path, chunks):
    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    out.write(chunks[0])
    assert len(os.listdir(tmp_path)) == 1  # the spool directory, hidden, next to the output
    assert os.listdir(tmp_path)[0].startswith(".city.npz.tmp")
    out.abort()
    assert os.listdir(tmp_path) == []
    with pytest.raises(ValueError, match="aborted"):
        out.write(chunks[0])
    with pytest.raises(ValueError, match="aborted"):
        out.close()


def test_dropped_writer_removes_its_temporaries(tmp_path, chunks):
    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    out.write(chunks[0])
    del out
    gc.collect()
    assert os.listdir(tmp_path) == []


def test_exception_inside_with_keeps_existing_file(tmp_path, chunks):
    path = tmp_path / "city.npz"
    path.write_bytes(b"the previous city")
    with (
        pytest.raises(RuntimeError, match="derivation failed"),
        InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={}) as out,
    ):
        out.write(chunks[0])
        raise RuntimeError("derivation failed")
    assert path.read_bytes() == b"the previous city"
    assert os.listdir(tmp_path) == ["city.npz"]


def test_close_replaces_existing_file(tmp_path, chunks):
    path = tmp_path / "city.npz"
    path.write_bytes(b"the previous city")
    write(path, chunks)
    assert read_instances(path)["asset"].shape == (32,)


@pytest.mark.parametrize(
    ("field", "bad", "message"),
    [
        ("asset", lambda c: c.asset.astype(np.int64), "TerminalChunk.asset: expected int32"),
        ("xform", lambda c: c.xform.astype(np.float64), "TerminalChunk.xform: expected float32"),
        ("xform", lambda c: c.xform[:, :, :3], r"TerminalChunk.xform: expected float32 \(n, 3, 4\)"),
        ("lot", lambda c: c.lot.tolist(), "TerminalChunk.lot: expected int32"),
        ("lot", lambda c: c.lot[:-1], "TerminalChunk.lot: 4 rows, asset has 5"),
        ("symbol", lambda c: c.symbol + 10, r"TerminalChunk.symbol: index out of range \[0, 4\)"),
        ("asset", lambda c: c.asset - 10, r"TerminalChunk.asset: index out of range \[0, 3\)"),
        ("symbol", lambda c: c.symbol.astype(">i4"), "TerminalChunk.symbol: expected int32"),
    ],
)
def test_bad_chunk_raises(tmp_path, chunks, field, bad, message):
    good = chunks[0]
    with InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={}) as out:
        with pytest.raises(ValueError, match=message):
            out.write(dataclasses.replace(good, **{field: bad(good)}))
        out.write(good)  # a rejected chunk leaves the writer usable
    assert read_instances(tmp_path / "city.npz")["asset"].tolist() == good.asset.tolist()


@pytest.mark.parametrize(
    ("field", "bad", "message"),
    [
        ("vertices", lambda m: m.vertices.astype(np.float64), "MeshChunk.vertices: expected float32"),
        ("ring_offsets", lambda m: m.ring_offsets.astype(np.int32), "MeshChunk.ring_offsets: expected int64"),
        ("ring_offsets", lambda m: m.ring_offsets[:-1], "MeshChunk.ring_offsets: must start at 0 and end at"),
        ("ring_offsets", lambda m: m.ring_offsets[::-1].copy(), "MeshChunk.ring_offsets: must start at 0"),
        ("face_offsets", lambda m: m.face_offsets + 1, "MeshChunk.face_offsets: must start at 0"),
        (
            "face_offsets",
            lambda m: np.insert(m.face_offsets, 1, 0),
            "MeshChunk.face_offsets: must be increasing",
        ),
        ("lot", lambda m: m.lot[:-1], "MeshChunk.lot: 2 rows, face_offsets has 3 faces"),
        ("symbol", lambda m: m.symbol.astype(np.int16), "MeshChunk.symbol: expected int32"),
    ],
)
def test_bad_mesh_raises(tmp_path, chunks, field, bad, message):
    good = chunks[0]
    mesh = dataclasses.replace(good.mesh, **{field: bad(good.mesh)})
    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    with pytest.raises(ValueError, match=message):
        out.write(dataclasses.replace(good, mesh=mesh))
    out.abort()


def test_non_contiguous_columns_are_written_in_order(tmp_path):
    chunk = TerminalChunk(
        asset=np.zeros(8, np.int32)[::2],
        xform=np.arange(48, dtype=np.float32).reshape(4, 4, 3).transpose(0, 2, 1),
        lot=np.arange(4, dtype=np.int32)[::-1],
        symbol=np.zeros(4, np.int32),
        mesh=MeshChunk.empty(),
    )
    assert not chunk.xform.flags.c_contiguous
    write(tmp_path / "city.npz", [chunk])
    record = read_instances(tmp_path / "city.npz")
    np.testing.assert_array_equal(record["xform"], chunk.xform)
    assert record["lot"].tolist() == [3, 2, 1, 0]


def test_writer_refuses_use_after_close_and_bad_setup(tmp_path, chunks):
    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    counts = out.close()
    assert out.close() == counts  # closing twice is harmless
    out.abort()  # and so is aborting a closed writer: the output stays
    assert os.listdir(tmp_path) == ["city.npz"]
    with pytest.raises(ValueError, match="closed"):
        out.write(chunks[0])
    with pytest.raises(ValueError, match="counts"):
        InstanceWriter(tmp_path / "x.npz", assets=ASSETS, symbols=SYMBOLS, meta={"counts": 1})
    with pytest.raises(ValueError, match="unique"):
        InstanceWriter(tmp_path / "x.npz", assets=["a", "a"], symbols=SYMBOLS, meta={})
    with pytest.raises(TypeError):
        InstanceWriter(tmp_path / "x.npz", assets=ASSETS, symbols=SYMBOLS, meta={"path": tmp_path})
    assert os.listdir(tmp_path) == ["city.npz"]


def test_large_write_holds_one_chunk_in_memory(tmp_path):
    rows, n_chunks = 100_000, 20  # 2e6 instances, 60 bytes each: 120 MB of columns
    rng = np.random.default_rng(2)
    chunk = random_chunk(rng, rows, 0)
    total = n_chunks * rows * (4 + 48 + 4 + 4)
    path = tmp_path / "big.npz"

    tracemalloc.start()
    try:
        with InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={}) as out:
            for _ in range(n_chunks):
                out.write(chunk)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()

    # Joining all rows in memory would need `total` bytes; the writer needs a chunk and a copy buffer.
    assert peak < total / 4, f"peak {peak / 1e6:.0f} MB for {total / 1e6:.0f} MB of rows"
    assert out.close()["instances"] == n_chunks * rows
    with np.load(path) as npz:
        assert npz["xform"].shape == (n_chunks * rows, 3, 4)
        np.testing.assert_array_equal(npz["xform"][-rows:], chunk.xform)
        np.testing.assert_array_equal(npz["lot"][:rows], chunk.lot)


def test_read_instances_refuses_other_npz(tmp_path):
    np.savez(tmp_path / "plain.npz", asset=np.zeros(3, np.int32))
    with pytest.raises(ValueError, match="no 'meta' member"):
        read_instances(tmp_path / "plain.npz")
    np.savez(tmp_path / "other.npz", meta=np.array(json.dumps({"format": "grammarc.instances/9"})))
    with pytest.raises(ValueError, match="grammarc.instances/9"):
        read_instances(tmp_path / "other.npz")
