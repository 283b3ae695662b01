"""instances.npz: round trips, rebased mesh offsets, reproducible bytes, atomicity, bounded memory."""

import dataclasses
import errno
import gc
import io
import json
import os
import struct
import threading
import time
import tracemalloc
import zipfile
import zlib

import numpy as np
import pytest

from grammarc.errors import UsageError
from grammarc.io import npz
from grammarc.io.npz import InstanceWriter, load_record, read_instances
from grammarc.model.records import LotOrigins, MeshChunk, TerminalChunk

ASSETS = ["builtin:cube", "builtin:quad", "facade/window.obj"]
SYMBOLS = ["Wall", "Window", "Roof", "Ledge"]
KEYS = {
    "assets", "asset", "xform", "lot", "lot_origin", "symbols", "symbol", "color", "meta",
    "mesh_vertices", "mesh_ring_offsets", "mesh_face_offsets", "mesh_lot", "mesh_symbol", "mesh_color",
}  # fmt: skip
#: The lots' origins (a UTM-like grid position each), the same in every chunk, as the derivation gives them.
ORIGINS = LotOrigins.of_lots(np.arange(100), np.random.default_rng(1).uniform(0, 6e6, (100, 3)).round(3))


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
        origins=ORIGINS,
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
        origins=chunk.origins,
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
    assert record["lot_origin"].dtype == np.float64
    np.testing.assert_array_equal(record["lot_origin"], ORIGINS.table())

    assert counts == {"instances": 32, "mesh_faces": 15, "mesh_vertices": len(record["mesh_vertices"])}
    assert record["meta"] == {
        "seed": 7,
        "grammar": "city.cga",
        "counts": counts,
        "format": "grammarc.instances/2",
    }


def test_chunks_all_carry_lot_origins_or_none(tmp_path, chunks):
    plain = dataclasses.replace(chunks[0], origins=LotOrigins.empty())
    with InstanceWriter(tmp_path / "a.npz", assets=ASSETS, symbols=SYMBOLS, meta={}) as out:
        out.write(chunks[0])
        with pytest.raises(ValueError, match="all carry lot origins or none"):
            out.write(plain)
    with InstanceWriter(tmp_path / "b.npz", assets=ASSETS, symbols=SYMBOLS, meta={}) as out:
        out.write(plain)
    assert "lot_origin" not in read_instances(tmp_path / "b.npz")  # rows in world coordinates


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
        "color": (np.uint8, (0, 4)),
        "mesh_vertices": (np.float32, (0, 3)),
        "mesh_ring_offsets": (np.int64, (1,)),
        "mesh_face_offsets": (np.int64, (1,)),
        "mesh_lot": (np.int32, (0,)),
        "mesh_symbol": (np.int32, (0,)),
        "mesh_color": (np.uint8, (0, 4)),
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


# The writer's internals: the zip and .npy records it writes by hand, and its background thread.


def bad_record(directory, kind):
    """A path that is no instance record: absent, a folder, a text file, another npz."""
    if kind == "text":
        (directory / "text.npz").write_text("hello")
        return directory / "text.npz"
    if kind == "other npz":
        np.savez(directory / "other.npz", a=np.zeros(2))
        return directory / "other.npz"
    return directory / "none.npz" if kind == "absent" else directory


@pytest.mark.parametrize(("kind", "message"), [
    ("absent", "record `.*none.npz` not found"),
    ("folder", "record `.*` not found"),
    ("text", "`.*text.npz` is not an instance record \\(not an .npz file\\)"),
    ("other npz", "cannot read record `.*other.npz`: .*no 'meta' member"),
])
def test_load_record_names_the_problem_in_a_usage_error(tmp_path, kind, message):
    with pytest.raises(UsageError, match=message):
        load_record(bad_record(tmp_path, kind))


def test_load_record_reads_an_instance_record(tmp_path, chunks):
    write(tmp_path / "city.npz", chunks)
    record = load_record(tmp_path / "city.npz")
    np.testing.assert_array_equal(record["lot"], read_instances(tmp_path / "city.npz")["lot"])


def writer_threads():
    return [t for t in threading.enumerate() if t.name.startswith("InstanceWriter") and t.is_alive()]


@pytest.mark.parametrize(
    ("n1", "n2"), [(0, 0), (0, 7), (7, 0), (1, 1), (3, 1000), (1000, 3), (4096, 65537), (1 << 20, 12345)]
)
def test_crc32_combine_matches_zlib(n1, n2):
    rng = np.random.default_rng(n1 + n2)
    a, b = rng.bytes(n1), rng.bytes(n2)
    assert npz.crc32_combine(zlib.crc32(a), zlib.crc32(b), len(b)) == zlib.crc32(a + b)


def test_crc32_combine_over_pieces_and_long_lengths():
    rng = np.random.default_rng(4)
    pieces = [rng.bytes(int(n)) for n in rng.integers(0, 300, 20)] + [b"", bytes(1 << 16)]
    crc = 0
    for piece in pieces:
        crc = npz.crc32_combine(crc, zlib.crc32(piece), len(piece))
    assert crc == zlib.crc32(b"".join(pieces))
    # Lengths of gigabytes: combining is associative, (a + b) + c == a + (b + c), for any CRCs and lengths.
    c1, c2, c3 = (int(x) for x in rng.integers(0, 1 << 32, 3))
    n2, n3 = (1 << 33) + 5, 3_600_000_123
    left = npz.crc32_combine(npz.crc32_combine(c1, c2, n2), c3, n3)
    assert left == npz.crc32_combine(c1, npz.crc32_combine(c2, c3, n3), n2 + n3)


def test_npy_header_width_does_not_depend_on_rows():
    headers = {rows: npz._npy_header("<f4", (rows, 3, 4)) for rows in (0, 1, 59, 10**9, 10**20)}
    assert len({len(header) for header in headers.values()}) == 1
    for rows, header in headers.items():
        assert len(header) % 64 == 0
        stream = io.BytesIO(header)
        assert np.lib.format.read_magic(stream) == (1, 0)
        assert np.lib.format.read_array_header_1_0(stream) == ((rows, 3, 4), False, np.dtype("<f4"))
        assert stream.tell() == len(header)
    scalar = io.BytesIO(npz._npy_header("<U5", ()))
    np.lib.format.read_magic(scalar)
    assert np.lib.format.read_array_header_1_0(scalar) == ((), False, np.dtype("<U5"))


def test_zip_records(tmp_path, chunks):
    path = tmp_path / "city.npz"
    write(path, chunks)
    with zipfile.ZipFile(path) as zf:
        assert zf.testzip() is None  # every member's CRC and size
        infos = zf.infolist()
    # The central directory lists the record's table in order, whatever the members' order in the file.
    # (the material and texture coordinate columns only where a chunk has them)
    assert [info.filename for info in infos] == [f"{key}.npy" for key in npz._KEYS
                                                 if key not in npz._MATERIAL_KEYS + npz._UV_KEYS]
    unix_0644 = {(info.create_system, info.external_attr, info.flag_bits) for info in infos}
    assert unix_0644 == {(3, 0o644 << 16, 0)}
    # xform is streamed into the file first; the members do not overlap and leave no gaps.
    spans = sorted((info.header_offset, info) for info in infos)
    assert spans[0][1].filename == "xform.npy" and spans[0][0] == 0
    data = path.read_bytes()
    for (offset, info), (next_offset, _) in zip(spans, [*spans[1:], (data.index(b"PK\x01\x02"), None)]):
        name_size, extra_size = struct.unpack("<HH", data[offset + 26 : offset + 30])
        assert offset + 30 + name_size + extra_size + info.compress_size == next_offset
        # The local header agrees with the central directory (zip64 sizes in its extra field).
        crc, size32, _ = struct.unpack("<LLL", data[offset + 14 : offset + 26])
        assert crc == info.CRC and size32 == 0xFFFFFFFF
        sizes = struct.unpack("<HHQQ", data[offset + 30 + name_size : offset + 30 + name_size + 20])
        assert sizes == (1, 16, info.file_size, info.file_size)
        # The columns the thread writes but the first start at a multiple of _ALIGN: the local header padded
        # up to there with zipalign's extra field; the others have none.
        key = info.filename.removesuffix(".npy")
        if key in npz._SPOOLED and key != npz._STREAMED:
            pad_id, pad = struct.unpack("<HH", data[offset + 30 + name_size + 20 : offset + 30 + name_size + 24])
            assert pad_id == npz._PAD_ID and extra_size == 24 + pad
            dtype, row_shape = npz._SPOOLED[key]
            start = offset + 30 + name_size + extra_size + len(npz._npy_header(dtype, (0, *row_shape)))
            assert (start + (8 if key in npz._OFFSETS else 0)) % npz._ALIGN == 0
        else:
            assert extra_size == 20


def test_zip64_records_load(tmp_path, chunks, monkeypatch):
    # A record of more than 2 GB needs zip64 fields in the central directory and a zip64 end record; with the
    # limit at 0, a small record takes them all.
    write(tmp_path / "small.npz", chunks)
    monkeypatch.setattr(npz, "_ZIP64_LIMIT", 0)
    path = tmp_path / "city.npz"
    write(path, chunks)
    data = path.read_bytes()
    assert b"PK\x06\x06" in data and b"PK\x06\x07" in data
    with zipfile.ZipFile(path) as zf:
        assert zf.testzip() is None
        assert all(info.extra.startswith(b"\x01\x00") for info in zf.infolist())
    got, expected = read_instances(path), read_instances(tmp_path / "small.npz")
    assert got["meta"] == expected["meta"]
    for key in KEYS - {"meta"}:
        np.testing.assert_array_equal(got[key], expected[key])


def test_bytes_do_not_depend_on_how_columns_are_written(tmp_path, chunks, monkeypatch):
    """In place where the filesystem collapses a range (here, or else spooled too), spooled and copied in
    the kernel, or through a buffer where it refuses or has no such call."""
    write(tmp_path / "in_place.npz", chunks)
    monkeypatch.setattr(npz, "_FALLOCATE", None)
    write(tmp_path / "kernel.npz", chunks)

    def refused(*args, **kwargs):
        raise OSError(errno.EXDEV, "cross-device")

    monkeypatch.setattr(npz, "_FADVISE", False)
    monkeypatch.setattr(os, "copy_file_range", refused, raising=False)
    write(tmp_path / "refused.npz", chunks)
    monkeypatch.delattr(os, "copy_file_range", raising=False)
    write(tmp_path / "absent.npz", chunks)
    names = ("in_place.npz", "kernel.npz", "refused.npz", "absent.npz")
    assert len({(tmp_path / name).read_bytes() for name in names}) == 1


def collapses(folder) -> bool:
    """Whether the filesystem of ``folder`` takes ranges out of files (``npz._regions``)."""
    fd = os.open(folder / "probe", os.O_RDWR | os.O_CREAT)
    try:
        return bool(npz._regions(fd))
    finally:
        os.close(fd)
        os.unlink(folder / "probe")


def test_columns_are_written_in_place_where_the_filesystem_collapses_ranges(tmp_path, chunks):
    if not collapses(tmp_path):
        pytest.skip("this filesystem cannot collapse a range out of a file: the columns are spooled")
    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    for chunk in chunks:
        out.write(chunk)
    out._sink._join()
    (folder,) = tmp_path.glob(".city.npz.tmp*")
    assert os.listdir(folder) == ["city.npz"]  # no spool files: every column in the output
    sparse = os.stat(folder / "city.npz")
    assert sparse.st_size > npz._REGION and sparse.st_blocks * 512 < 1 << 24  # holes between the columns
    out.close()
    assert os.stat(tmp_path / "city.npz").st_size < 1 << 24 and read_instances(tmp_path / "city.npz")


@pytest.mark.parametrize("collapsing", [True, False])
def test_a_column_past_its_region_fails_the_writer(tmp_path, chunks, monkeypatch, collapsing):
    """Written in place, a column may grow to its region less the slack (spooled, it has no such bound)."""
    if collapsing and not collapses(tmp_path):
        pytest.skip("this filesystem cannot collapse a range out of a file: the columns are spooled")
    if not collapsing:
        monkeypatch.setattr(npz, "_FALLOCATE", None)
    monkeypatch.setattr(npz, "_REGION", 16 * npz._ALIGN)
    monkeypatch.setattr(npz, "_SLACK", 8 * npz._ALIGN)
    path = tmp_path / "city.npz"
    path.write_bytes(b"the previous city")
    rows = 32 * npz._ALIGN // 48  # xform: twice the room
    out = InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={})
    if collapsing:
        with pytest.raises(OSError, match="the record's xform column passes"):
            out.write(random_chunk(np.random.default_rng(1), rows, 0))
            out.close()
        assert path.read_bytes() == b"the previous city" and os.listdir(tmp_path) == ["city.npz"]
    else:
        out.write(random_chunk(np.random.default_rng(1), rows, 0))
        out.close()
        assert len(read_instances(path)["xform"]) == rows


def failing_writes(monkeypatch, after=0):
    """Make the writer's file writes fail with a full disk after ``after`` more of them."""
    write_all = npz._write_all
    calls = []

    def full_disk(fd, data, offset=None):
        calls.append(len(memoryview(data)))
        if len(calls) > after:
            raise OSError(errno.ENOSPC, "No space left on device")
        write_all(fd, data, offset)

    monkeypatch.setattr(npz, "_write_all", full_disk)
    return calls


def test_error_in_background_surfaces_at_a_later_write(tmp_path, chunks, monkeypatch):
    path = tmp_path / "city.npz"
    path.write_bytes(b"the previous city")
    out = InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={})
    failing_writes(monkeypatch)
    # The first chunk fails in the thread; at most the queue's depth of later writes go through before the
    # failure is raised.
    with pytest.raises(OSError, match="No space left"):
        for _ in range(npz._QUEUE_DEPTH + 3):
            out.write(chunks[0])
    assert path.read_bytes() == b"the previous city"
    assert os.listdir(tmp_path) == ["city.npz"]
    assert writer_threads() == []
    with pytest.raises(ValueError, match="aborted"):
        out.close()


def test_error_in_background_surfaces_at_close(tmp_path, chunks, monkeypatch):
    path = tmp_path / "city.npz"
    path.write_bytes(b"the previous city")
    out = InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={})
    failing_writes(monkeypatch)
    out.write(chunks[0])
    with pytest.raises(OSError, match="No space left"):
        out.close()
    assert path.read_bytes() == b"the previous city"
    assert os.listdir(tmp_path) == ["city.npz"]
    assert writer_threads() == []


def test_error_while_finishing_removes_temporaries(tmp_path, chunks, monkeypatch):
    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    for chunk in chunks:
        out.write(chunk)
    out._sink._join()  # the chunks are written; the next write is close() copying the first member
    failing_writes(monkeypatch)
    with pytest.raises(OSError, match="No space left"):
        out.close()
    assert os.listdir(tmp_path) == []


def test_abort_stops_the_thread_with_chunks_queued(tmp_path, chunks, monkeypatch):
    write_all = npz._write_all

    def slow(fd, data, offset=None):
        time.sleep(0.02)
        write_all(fd, data, offset)

    out = InstanceWriter(tmp_path / "city.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    monkeypatch.setattr(npz, "_write_all", slow)
    for _ in range(npz._QUEUE_DEPTH + 2):
        out.write(chunks[0])
    assert len(writer_threads()) == 1
    out.abort()
    assert writer_threads() == []
    assert os.listdir(tmp_path) == []


def test_close_and_drop_stop_the_thread(tmp_path, chunks):
    write(tmp_path / "city.npz", chunks)
    assert writer_threads() == []
    out = InstanceWriter(tmp_path / "dropped.npz", assets=ASSETS, symbols=SYMBOLS, meta={})
    out.write(chunks[0])
    del out
    gc.collect()
    assert writer_threads() == []
    assert os.listdir(tmp_path) == ["city.npz"]


def test_memory_stays_bounded_with_fresh_chunks(tmp_path):
    # As the derivation does: a new chunk for every write. The writer holds the queued chunks, not the rows.
    rows, n_chunks = 50_000, 40  # 2e6 instances, 120 MB of columns, 3 MB a chunk
    template = random_chunk(np.random.default_rng(5), rows, 0)
    chunk_bytes = rows * (4 + 48 + 4 + 4)
    path = tmp_path / "big.npz"

    tracemalloc.start()
    try:
        with InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={}) as out:
            for i in range(n_chunks):
                lot = np.full(rows, i, np.int32)
                out.write(dataclasses.replace(template, xform=template.xform + i, lot=lot))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()

    assert peak < (npz._QUEUE_DEPTH + 5) * chunk_bytes, f"peak {peak / 1e6:.0f} MB"
    with np.load(path) as record:
        assert record["xform"].shape == (n_chunks * rows, 3, 4)
        np.testing.assert_array_equal(record["xform"][-rows:], template.xform + n_chunks - 1)
        np.testing.assert_array_equal(record["lot"][::rows], np.arange(n_chunks))



def test_colours_default_to_white_and_round_trip(tmp_path):
    rng = np.random.default_rng(5)
    plain = random_chunk(rng, 4, 2)
    coloured = TerminalChunk(plain.asset, plain.xform, plain.lot, plain.symbol,
                             MeshChunk(*(getattr(plain.mesh, f) for f in ("vertices", "ring_offsets",
                                                                          "face_offsets", "lot", "symbol")),
                                       color=np.full((len(plain.mesh.lot), 4), 7, np.uint8)),
                             color=np.tile(np.array([[1, 2, 3, 255]], np.uint8), (4, 1)), origins=ORIGINS)
    with InstanceWriter(tmp_path / "c.npz", assets=ASSETS, symbols=SYMBOLS, meta={}) as writer:
        writer.write(plain)
        writer.write(coloured)
    record = read_instances(tmp_path / "c.npz")
    assert record["color"][:4].tolist() == [[255, 255, 255, 255]] * 4
    assert record["color"][4:].tolist() == [[1, 2, 3, 255]] * 4
    n = len(plain.mesh.lot)
    assert (record["mesh_color"][:n] == 255).all() and (record["mesh_color"][n:] == 7).all()


def test_texture_coordinates_from_the_first_chunk_that_has_them(tmp_path, chunks):
    """``uv`` per instance and ``mesh_uv`` per mesh vertex appear once a chunk has texture coordinates; the
    rows of chunks without them, before or after, are NaN."""
    first, second, third = chunks[0], chunks[2], chunks[5]
    uv = np.arange(len(second.asset) * 8, dtype=np.float32).reshape(-1, 2, 4)
    mesh_uv = np.ones((len(second.mesh.vertices), 2), np.float32)
    textured = dataclasses.replace(second, uv=uv, mesh=dataclasses.replace(second.mesh, uv=mesh_uv))
    path = tmp_path / "city.npz"
    write(path, [first, textured, third])
    record = read_instances(path)
    n1, n2 = len(first.asset), len(second.asset)
    assert record["uv"].shape == (n1 + n2 + len(third.asset), 2, 4)
    assert np.isnan(record["uv"][:n1]).all() and np.isnan(record["uv"][n1 + n2:]).all()
    np.testing.assert_array_equal(record["uv"][n1:n1 + n2], uv)
    v1, v2 = len(first.mesh.vertices), len(second.mesh.vertices)
    assert np.isnan(record["mesh_uv"][:v1]).all() and np.isnan(record["mesh_uv"][v1 + v2:]).all()
    np.testing.assert_array_equal(record["mesh_uv"][v1:v1 + v2], mesh_uv)
    write(path, chunks)
    assert "uv" not in read_instances(path)
