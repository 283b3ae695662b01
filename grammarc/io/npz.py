"""The terminal record ``instances.npz``: a streaming, atomic writer and its reader.

A city's terminals (10^7-10^8 rows, gigabytes) arrive chunk by chunk from the derivation
(``model.records``), and the writer must hold no more than a few chunks in memory (docs/architecture.md, invariant 3).
``np.savez`` needs every array whole, so the writer builds the zip itself, as the rows arrive:

* ``xform`` (48 of the 60 bytes of a row) is written once, straight into the output: it is the first member of
  the file, its local header and ``.npy`` header are written up front with a placeholder shape and sizes of fixed
  width, each chunk's bytes are appended behind them, and ``close()`` patches the headers in place. Its CRC is
  kept running over the data and combined with the CRC of the final ``.npy`` header (zlib's ``crc32_combine``).
* The other columns (12 bytes a row, more with colours, materials and texture coordinates, and the mesh table)
  are written in place too where the filesystem can take a range out of a file (Linux's ``fallocate`` with
  ``FALLOC_FL_COLLAPSE_RANGE``: ext4, XFS): each into its own region of a sparse temporary, far apart, and
  ``close()`` collapses the holes between them, so no byte is copied and the data went to disk as it came.
  Elsewhere they are appended to spool files, and ``close()`` copies each spool into place in the kernel
  (``os.copy_file_range``) and unlinks it. Either way each of these members' data starts at a multiple of
  ``_ALIGN`` bytes, its local header padded up to there: the file's bytes do not depend on the way.
* ``write()`` validates the chunk and hands its columns to one background thread that does the file I/O
  (through a queue two chunks deep, so the derivation overlaps the writes and memory stays bounded). The
  arrays are not copied: the caller must not modify them after ``write()``.
* Where it can (Linux), the thread starts the writeback of the data written in place as it goes and drops the
  pages already written back (``posix_fadvise(DONTNEED)``), so the final fsync has little left to write and
  the output does not fill the page cache.

Zip readers find members through the central directory, which lists them in the order of the record's table
(``_KEYS``), whatever their order in the file. Members are stored (no compression) with zip64 local headers,
as ``np.savez`` writes them, so ``np.load(path)`` reads the file without pickles. The bytes are reproducible:
entries carry a fixed date and mode, and the bytes depend only on the rows, not on how they were chunked, so
example cities can keep hashes of their output (STYLE.md, "Replay before you refactor"). Outputs of the writer
before xform was streamed (which went through ``zipfile``, members in key order) hold the same arrays, but
their bytes differ: xform now comes first in the file.

An output is complete or absent (invariant 5). Everything is written under a temporary directory next to the
output (``.<name>.tmp*``, so on the same filesystem), the output is fsynced and moved into place with
``os.replace``. ``abort()``, an exception inside ``with``, a failed write (also one that fails later, in the
background thread) or a writer dropped without ``close()`` stops the thread, removes the temporaries and leaves
a file already at the output path untouched.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import json
import os
import queue
import shutil
import struct
import sys
import threading
import weakref
import zipfile
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

# zlib's CRC-32 with SIMD (every record byte passes it), and its crc32_combine
from zlib_ng.zlib_ng import crc32, crc32_combine

from grammarc import releases
from grammarc.atomic import private_folder
from grammarc.errors import UsageError
from grammarc.model.records import LotOrigins, MaterialTable, MeshChunk, TerminalChunk, record_mesh

if TYPE_CHECKING:
    from typing_extensions import Self

__all__ = ["WRITERS", "InstanceWriter", "load_record", "read_instances", "record_chunks"]

_FORMAT = "grammarc.instances/2"
#: Formats this version reads: /1 has no ``lot_origin`` (its transforms and vertices are in world coordinates).
_READS = ("grammarc.instances/1", _FORMAT)
_FADVISE = hasattr(os, "posix_fadvise")  # Linux: DONTNEED starts the writeback of a range, drops clean pages
_QUEUE_DEPTH = 2  # chunks waiting for the background thread: bounds the memory of write()
_BLOCK = 16 << 20  # bytes per copy call from a spool into the npz (and the buffer of the fallback copy)
#: The data of each member the thread writes (but the streamed one, first in the file) starts at a multiple of
#: this many bytes: its local header is padded up to there with an extra field, as Android's zipalign pads
#: (its id, which readers skip as they skip any they do not know). The layout, and so the bytes, are the same
#: whether the member was written in place or spooled and copied.
_ALIGN = 4096
_PAD_ID = 0xD935
#: Written in place, column k (in file order, after the streamed one) starts at (k + 1) * _REGION of the
#: sparse temporary; it may grow to _REGION - _SLACK bytes, the slack left for the members held in memory
#: that follow it in the file. 15 regions of 2^39 bytes: 7.5 TiB, within ext4's largest file (16 TiB).
_REGION = 1 << 39
_SLACK = 1 << 32
_COLLAPSE_RANGE = 0x08  # Linux's FALLOC_FL_COLLAPSE_RANGE
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)  # the earliest date zip can store; fixed so that runs are byte-identical

# Columns written by the background thread: npz key -> (dtype, shape of one row). Offsets are written without
# their leading 0 and already rebased, so each has one row per ring or face and the member gets the 0 in front.
_SPOOLED = {
    "asset": ("<i4", ()),
    "xform": ("<f4", (3, 4)),
    "lot": ("<i4", ()),
    "symbol": ("<i4", ()),
    "color": ("|u1", (4,)),
    "mesh_vertices": ("<f4", (3,)),
    "mesh_ring_offsets": ("<i8", ()),
    "mesh_face_offsets": ("<i8", ()),
    "mesh_lot": ("<i4", ()),
    "mesh_symbol": ("<i4", ()),
    "mesh_color": ("|u1", (4,)),
    "material": ("<i4", ()),
    "mesh_material": ("<i4", ()),
    "uv": ("<f4", (2, 4)),
    "mesh_uv": ("<f4", (2,)),
}
#: The columns of a record whose grammar sets textures (``TerminalChunk.materials``), else left out.
_MATERIAL_KEYS = ("materials", "material", "mesh_material")
#: The columns of a record whose grammar has texture coordinates (``TerminalChunk.uv``, ``MeshChunk.uv``).
_UV_KEYS = ("uv", "mesh_uv")
_OFFSETS = ("mesh_ring_offsets", "mesh_face_offsets")
# The column written straight into the output, as its first member; the others are spooled.
_STREAMED = "xform"
# Central directory order, the order of np.load(path).files: the record's table in the README, then the mesh
# table. In the file, xform comes first and the others follow in this order.
_KEYS = (
    "assets", "asset", "xform", "lot", "lot_origin", "symbols", "symbol", "color", "materials", "material", "uv", "meta",
    "mesh_vertices", "mesh_ring_offsets", "mesh_face_offsets", "mesh_lot", "mesh_symbol", "mesh_color",
    "mesh_material", "mesh_uv",
)  # fmt: skip
class InstanceWriter:
    """Streams TerminalChunks into an .npz; the output appears complete on close() or not at all.

    The file I/O runs in a background thread, so the caller derives the next chunk while the last ones are
    written. ``write()`` does not copy the chunk's arrays: it keeps them until they are written, so the caller
    must not modify them after ``write()`` (``derive_chunk`` allocates fresh arrays for every chunk).

    Parameters
    ----------
    path : str or os.PathLike
        The output file. Its directory must exist; temporaries are created there.
    assets : sequence of str
        Asset names, unique; ``TerminalChunk.asset`` indexes them.
    symbols : sequence of str
        Symbol names, unique; ``TerminalChunk.symbol`` and ``MeshChunk.symbol`` index them.
    meta : dict
        JSON-serializable facts about the run (grammar path and hash, seed, version). The writer adds
        ``"counts"`` and ``"format"``, so these keys are refused.

    Examples
    --------
    >>> import tempfile
    >>> from grammarc.model.records import MeshChunk, TerminalChunk
    >>> tmp = tempfile.TemporaryDirectory()
    >>> path = os.path.join(tmp.name, "city.npz")
    >>> chunk = TerminalChunk(
    ...     asset=np.zeros(2, np.int32), xform=np.zeros((2, 3, 4), np.float32),
    ...     lot=np.array([0, 1], np.int32), symbol=np.zeros(2, np.int32), mesh=MeshChunk.empty())
    >>> with InstanceWriter(path, assets=["builtin:cube"], symbols=["Wall"], meta={"seed": 1}) as out:
    ...     out.write(chunk)
    ...     out.write(chunk)
    >>> read_instances(path)["lot"]
    array([0, 1, 0, 1], dtype=int32)
    >>> read_instances(path)["meta"]["counts"]
    {'instances': 4, 'mesh_faces': 0, 'mesh_vertices': 0}
    >>> tmp.cleanup()
    """

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str], meta: dict):
        self.path = Path(path)
        self._assets = _names("assets", assets)
        self._symbols = _names("symbols", symbols)
        reserved = sorted({"counts", "format"} & set(meta))
        if reserved:
            raise ValueError(f"meta: keys {reserved} are written by InstanceWriter")
        self._meta = dict(meta)
        json.dumps(self._meta)  # a TypeError now, not after hours of derivation
        self._rows = dict.fromkeys(_SPOOLED, 0)
        #: The record's materials, once a chunk has textures (else None: no material columns).
        self._materials: MaterialTable | None = None
        #: Whether a chunk had texture coordinates (else no uv columns).
        self._textured = False
        #: The chunks' lot origins (``LotOrigins``); None until the first chunk, [] if they have none.
        self._origins: list[LotOrigins] | None = None
        self._counts: dict[str, int] = {}
        self._state = "open"
        tmpdir = private_folder(self.path)
        self._sink = _Sink(tmpdir, self.path.name)  # removes tmpdir itself if it fails
        # Stops the thread and removes the temporaries on abort(), after close(), or when a writer is dropped
        # unclosed. Neither the sink nor its thread refers to the writer, so a dropped writer is collected.
        self._cleanup = weakref.finalize(self, self._sink.discard)

    def write(self, chunk: TerminalChunk) -> None:
        """Append a chunk's rows; its mesh offsets are rebased onto the rows written before.

        The rows are written in the background: keep the chunk's arrays unmodified after the call.

        Raises
        ------
        ValueError
            If the writer is closed or aborted, or a field of ``chunk`` has the wrong dtype or shape,
            inconsistent lengths, bad offsets or an asset or symbol index out of range. The writer is
            unchanged by a rejected chunk.
        OSError
            If writing an earlier chunk failed in the background; the writer has aborted.
        """
        if self._state != "open":
            raise ValueError(f"write to an InstanceWriter that is {self._state}")
        columns = _validate(chunk, len(self._assets), len(self._symbols))
        has_origins = len(chunk.origins.lot) > 0
        if self._origins is not None and has_origins != bool(self._origins):
            raise ValueError("TerminalChunk.origins: a record's chunks all carry lot origins or none do")
        self._material_columns(chunk, columns)
        self._uv_columns(chunk, columns)
        columns["mesh_ring_offsets"] = columns["mesh_ring_offsets"] + self._rows["mesh_vertices"]
        columns["mesh_face_offsets"] = columns["mesh_face_offsets"] + self._rows["mesh_ring_offsets"]
        try:
            self._sink.put(columns)
        except BaseException:
            # A failed or interrupted append: the columns may disagree on the rows written, so this output
            # cannot be completed.
            self.abort()
            raise
        for key, column in columns.items():
            self._rows[key] += len(column)
        self._origins = self._origins if self._origins is not None else []
        if has_origins:
            self._origins.append(chunk.origins)

    def _material_columns(self, chunk: TerminalChunk, columns: dict[str, np.ndarray]) -> None:
        """Add the chunk's ``material`` and ``mesh_material`` columns, indexing the record's ``materials``,
        once any chunk has textures: row 0 of the table is no texture, which the rows of chunks without
        (and those written before the first with) take."""
        if chunk.materials is None and self._materials is None:
            return
        if self._materials is None:
            self._materials = MaterialTable()
        before = {"material": self._rows["asset"] - self._rows["material"],
                  "mesh_material": self._rows["mesh_lot"] - self._rows["mesh_material"]}
        for key, own in zip(("material", "mesh_material"), self._materials.add(chunk)):
            columns[key] = np.concatenate([np.zeros(before[key], np.int32), own]) if before[key] else own

    def _uv_columns(self, chunk: TerminalChunk, columns: dict[str, np.ndarray]) -> None:
        """Add the chunk's texture coordinates of set 0, ``uv`` per instance (a map of its unit box) and
        ``mesh_uv`` per mesh vertex, once any chunk has them: NaN for the rows of chunks without (and of
        those written before the first with)."""
        if chunk.uv is None and chunk.mesh.uv is None and not self._textured:
            return
        self._textured = True
        own = {"uv": chunk.texture(), "mesh_uv": chunk.mesh.texture()}
        for key, rows in (("uv", "asset"), ("mesh_uv", "mesh_vertices")):
            dtype, row_shape = _SPOOLED[key]
            column = _column(f"texture coordinates ({key})", np.asarray(own[key], dtype), dtype, row_shape)
            before = self._rows[rows] - self._rows[key]
            columns[key] = np.concatenate([np.full((before, *row_shape), np.nan, dtype), column]) if before \
                else column

    def close(self) -> dict:
        """Finish the npz next to the output, fsync it, and rename it onto ``path``.

        Returns
        -------
        counts : dict
            ``{"instances": N, "mesh_faces": F, "mesh_vertices": V}``, as stored in ``meta["counts"]``.
            Closing again returns the same counts.

        Raises
        ------
        ValueError
            If the writer is aborted.
        OSError
            If a write failed, in the background or now; the writer has aborted and left ``path`` untouched.
        """
        if self._state == "closed":
            return dict(self._counts)
        if self._state == "aborted":
            raise ValueError("close of an InstanceWriter that is aborted")
        counts = {
            "instances": self._rows["asset"],
            "mesh_faces": self._rows["mesh_lot"],
            "mesh_vertices": self._rows["mesh_vertices"],
        }
        try:
            tmp = self._sink.finish(self._members(counts))
            releases.replace(tmp, self.path)
        except BaseException:
            self.abort()
            raise
        self._state = "closed"
        self._counts = counts
        self._cleanup()
        _fsync_dir(self.path.parent)
        return dict(counts)

    def abort(self) -> None:
        """Stop writing and remove every temporary; a file already at ``path`` is left untouched.

        No-op once closed.
        """
        if self._state == "open":
            self._state = "aborted"
            self._cleanup()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()

    def _members(self, counts: dict) -> dict[str, tuple[str, tuple, bytes]]:
        """Each key, in ``_KEYS`` order, to its array's descr and shape and the bytes of its member that the
        background thread did not write: all of them for an array in memory, the offsets' leading 0."""
        # Sorted keys: the bytes must not depend on the order in which meta was built.
        meta = json.dumps({**self._meta, "counts": counts, "format": _FORMAT}, sort_keys=True)
        arrays = {"assets": self._assets, "symbols": self._symbols, "meta": np.array(meta)}
        if self._origins:
            arrays["lot_origin"] = LotOrigins.concat(self._origins).table()
        if self._materials is not None:
            arrays["materials"] = self._materials.table()
        members = {}
        for key in _KEYS:
            if (key in _MATERIAL_KEYS and self._materials is None) or (key in _UV_KEYS and not self._textured) \
                    or (key == "lot_origin" and "lot_origin" not in arrays):
                continue
            if key in arrays:
                array = arrays[key]
                members[key] = (_descr(array.dtype), array.shape, array.tobytes())
            else:
                dtype, row_shape = _SPOOLED[key]
                rows = self._rows[key] + (key in _OFFSETS)
                head = np.zeros(1, np.int64).tobytes() if key in _OFFSETS else b""
                members[key] = (_descr(dtype), (rows, *row_shape), head)
        return members


def read_instances(path: str | os.PathLike) -> dict[str, np.ndarray | dict]:
    """Load an instances.npz written by InstanceWriter.

    Returns
    -------
    record : dict
        Every array of the record by key (see the README, "The record"), with ``"meta"``
        parsed from JSON into a dict.

    Raises
    ------
    ValueError
        If the file is not a grammarc instance record of a format this version reads.
    """
    with np.load(path, allow_pickle=False) as npz:
        record = {key: npz[key] for key in npz.files}
    if "meta" not in record:
        raise ValueError(f"{os.fspath(path)}: no 'meta' member, not a grammarc instance record")
    meta = json.loads(record["meta"].item())
    if meta.get("format") not in _READS:
        raise ValueError(f"{os.fspath(path)}: format {meta.get('format')!r}, expected {_FORMAT!r}")
    record["meta"] = meta
    return record


#: The extension this module writes (``grammarc.io.writers``).
WRITERS = {".npz": InstanceWriter}


def record_chunks(record: dict, rows: int = 1 << 20):
    """A record (``read_instances``) as TerminalChunks of at most ``rows`` instances, in its order, to write
    it in another format (``grammarc view`` of an .npz); the mesh table comes with the first chunk."""
    origins = LotOrigins.from_table(record.get("lot_origin"))
    textured = "material" in record
    mesh = replace(record_mesh(record) or MeshChunk.empty(), color=record.get("mesh_color"),
                   material=record.get("mesh_material"), materials=record.get("materials") if textured else None,
                   uv=record.get("mesh_uv"))
    total = len(record["asset"])
    for start in range(0, max(total, 1), rows):
        part = slice(start, start + rows)
        yield TerminalChunk(
            asset=record["asset"][part], xform=record["xform"][part], lot=record["lot"][part],
            symbol=record["symbol"][part], mesh=mesh if start == 0 else MeshChunk.empty(),
            color=record["color"][part] if "color" in record else None,
            material=record["material"][part] if textured else None,
            materials=record["materials"] if textured else None,
            uv=record["uv"][part] if "uv" in record else None, origins=origins)


def load_record(path: str | os.PathLike) -> dict[str, np.ndarray | dict]:
    """``read_instances`` of a record the user named (``grammarc render``): every problem a UsageError.

    Raises
    ------
    UsageError
        If ``path`` is not a file, not a zip (so not an .npz), or not an instance record this version
        reads.
    """
    if not Path(path).is_file():
        raise UsageError(f"record `{path}` not found")
    # np.load takes any other file for a pickle, and says so: name the actual problem instead.
    if not zipfile.is_zipfile(path):
        raise UsageError(f"`{path}` is not an instance record (not an .npz file)")
    try:
        return read_instances(path)
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        raise UsageError(f"cannot read record `{path}`: {error}") from error


def _names(field: str, names: Sequence[str]) -> np.ndarray:
    """``names`` as a numpy unicode array ``(k,)``, after checking they are unique strings."""
    names = list(names)
    if not all(isinstance(name, str) for name in names):
        raise ValueError(f"{field}: names must be str")
    if len(set(names)) != len(names):
        raise ValueError(f"{field}: names must be unique")
    return np.array(names, dtype=str)


def _validate(chunk: TerminalChunk, n_assets: int, n_symbols: int) -> dict[str, np.ndarray]:
    """The chunk's columns by npz key, C-contiguous, offsets without their leading 0 (not yet rebased)."""
    columns = {}
    for key, field, value in (
        ("asset", "TerminalChunk.asset", chunk.asset),
        ("xform", "TerminalChunk.xform", chunk.xform),
        ("lot", "TerminalChunk.lot", chunk.lot),
        ("symbol", "TerminalChunk.symbol", chunk.symbol),
        ("color", "TerminalChunk.color",
         chunk.colors()),
        ("mesh_vertices", "MeshChunk.vertices", chunk.mesh.vertices),
        ("mesh_ring_offsets", "MeshChunk.ring_offsets", chunk.mesh.ring_offsets),
        ("mesh_face_offsets", "MeshChunk.face_offsets", chunk.mesh.face_offsets),
        ("mesh_lot", "MeshChunk.lot", chunk.mesh.lot),
        ("mesh_symbol", "MeshChunk.symbol", chunk.mesh.symbol),
        ("mesh_color", "MeshChunk.color", chunk.mesh.colors()),
    ):
        columns[key] = _column(field, value, *_SPOOLED[key])
    n = len(columns["asset"])
    for key in ("xform", "lot", "symbol", "color"):
        if len(columns[key]) != n:
            raise ValueError(f"TerminalChunk.{key}: {len(columns[key])} rows, asset has {n}")
    _check_offsets("MeshChunk.ring_offsets", columns["mesh_ring_offsets"], len(columns["mesh_vertices"]), 0)
    _check_offsets(
        "MeshChunk.face_offsets", columns["mesh_face_offsets"], len(columns["mesh_ring_offsets"]) - 1, 1
    )
    n_faces = len(columns["mesh_face_offsets"]) - 1
    for key in ("mesh_lot", "mesh_symbol", "mesh_color"):
        if len(columns[key]) != n_faces:
            raise ValueError(
                f"MeshChunk.{key[5:]}: {len(columns[key])} rows, face_offsets has {n_faces} faces"
            )
    _check_index("TerminalChunk.asset", columns["asset"], n_assets)
    _check_index("TerminalChunk.symbol", columns["symbol"], n_symbols)
    _check_index("MeshChunk.symbol", columns["mesh_symbol"], n_symbols)
    for key in _OFFSETS:
        columns[key] = columns[key][1:]
    return columns


def _column(field: str, value, dtype: str, row_shape: tuple) -> np.ndarray:
    """``value`` as a C-contiguous array after checking it is ``dtype`` with shape ``(rows, *row_shape)``."""
    if not (
        isinstance(value, np.ndarray)
        and value.dtype == np.dtype(dtype)
        and value.ndim == 1 + len(row_shape)
        and value.shape[1:] == row_shape
    ):
        got = f"{value.dtype} {value.shape}" if isinstance(value, np.ndarray) else type(value).__name__
        expected = str(("n", *row_shape)).replace("'", "")
        raise ValueError(f"{field}: expected {np.dtype(dtype).name} {expected}, got {got}")
    return np.ascontiguousarray(value)


def _check_offsets(field: str, offsets: np.ndarray, end: int, min_step: int) -> None:
    """Raise unless ``offsets`` runs from 0 to ``end`` in steps of at least ``min_step``."""
    if len(offsets) == 0 or offsets[0] != 0 or offsets[-1] != end:
        raise ValueError(f"{field}: must start at 0 and end at {end}")
    if len(offsets) > 1 and np.diff(offsets).min() < min_step:
        kind = "increasing (every face has an outline)" if min_step else "non-decreasing"
        raise ValueError(f"{field}: must be {kind}")


def _check_index(field: str, index: np.ndarray, size: int) -> None:
    """Raise unless every entry of ``index`` is in ``[0, size)``."""
    if len(index) and (index.min() < 0 or index.max() >= size):
        raise ValueError(f"{field}: index out of range [0, {size})")


class _Sink:
    """The files of one output and the thread that appends the chunks' columns to them.

    A temporary directory holds the output (named as the final file) and a spool file per column but
    ``_STREAMED``, whose bytes go straight into the output behind placeholder headers. ``put()`` queues a chunk's
    columns and the thread writes them, keeping each column's byte count and CRC-32; ``finish()`` completes the
    zip and ``discard()`` stops the thread and removes the directory. Nothing here refers to the writer, so a
    writer dropped unclosed is collected and its finalizer calls ``discard()``.
    """

    def __init__(self, tmpdir: str, name: str):
        self.tmpdir = tmpdir
        self.path = os.path.join(tmpdir, name)
        self._fds: dict[str, int] = {}  # open files: "" the output, a column's key its spool
        self._crc = dict.fromkeys(_SPOOLED, 0)  # CRC-32 of each column's bytes so far
        self._size = dict.fromkeys(_SPOOLED, 0)  # and their number
        self._queue: queue.Queue = queue.Queue(_QUEUE_DEPTH)
        self._error: BaseException | None = None  # the thread's failure, raised by put() or finish()
        self._stop = False  # set by discard(): the thread drops what is queued and ends
        self._remove_on_exit = False  # set by discard() run in the thread itself (by the garbage collector)
        self._thread: threading.Thread | None = None
        try:
            self._fds[""] = _create(self.path)
            # where each column's data goes in the output; none: into spool files
            self._regions = _regions(self._fds[""])
            if not self._regions:
                for key in _SPOOLED:
                    if key != _STREAMED:
                        self._fds[key] = _create(os.path.join(tmpdir, key))
            # The streamed member's headers, for 0 rows: as wide as the final ones, which finish() writes over.
            dtype, row_shape = _SPOOLED[_STREAMED]
            header = _npy_header(_descr(dtype), (0, *row_shape))
            head = _local_header(f"{_STREAMED}.npy".encode(), 0, 0) + header
            _write_all(self._fds[""], head)
            self._head_size = len(head)
            # For _FADVISE: where each column written in place starts, and how far its data is on disk
            # (dropped from memory) and on its way there (written back)
            self._starts = {_STREAMED: self._head_size, **self._regions}
            self._dropped = dict(self._starts)
            self._written = dict(self._starts)
            self._thread = threading.Thread(target=self._run, name=f"InstanceWriter {name}", daemon=True)
            self._thread.start()
        except BaseException:
            self.discard()
            raise

    def put(self, columns: dict[str, np.ndarray]) -> None:
        """Queue a chunk's columns for the thread, after raising its failure on an earlier chunk, if any.

        Blocks while ``_QUEUE_DEPTH`` chunks wait. The arrays are written later, as they are then.
        """
        self._raise_error()
        self._queue.put(columns)

    def finish(self, members: dict[str, tuple[str, tuple, bytes]]) -> str:
        """Write the rest of the zip after the streamed column, fsync it, and return its path.

        ``members`` maps every key, in central directory order, to the ``.npy`` descr and shape of its array
        and the bytes of the member before those written by the thread (all of them for an array held in
        memory). Written in place, the holes before each column's data are collapsed out of the file; else
        each spool is copied into the output in the kernel and unlinked.
        """
        self._join()
        self._raise_error()
        out = self._fds[""]
        position = self._head_size + self._size[_STREAMED]  # where the file ends: after the streamed data
        removed = 0  # the bytes collapsed out of the file so far
        entries = []  # (name, crc, size, offset of the local header) of each member, in central order
        for key, (descr, shape, body) in members.items():
            header = _npy_header(descr, shape)
            written = self._size.get(key, 0)
            if len(body) + written != np.dtype(descr).itemsize * int(np.prod(shape)):
                raise RuntimeError(f"{key}: {len(body) + written} bytes for an array {descr} {shape}")
            size = len(header) + len(body) + written
            crc = crc32_combine(crc32(body, crc32(header)), self._crc.get(key, 0), written)
            name = f"{key}.npy".encode()
            if key == _STREAMED:
                head = _local_header(name, crc, size) + header
                if len(head) != self._head_size:
                    raise RuntimeError(f"{key}: the final headers do not fit the space left for them")
                entries.append((name, crc, size, 0))
                continue
            entries.append((name, crc, size, position))
            local = _local_header(name, crc, size)
            if key in _SPOOLED:  # its data at the next multiple of _ALIGN that leaves room for its headers
                local = _local_header(name, crc, size, -(position + len(local) + len(header) + len(body) + 4)
                                      % _ALIGN + 4)
            start = position + len(local) + len(header) + len(body)  # where the thread's bytes of the member go
            if key in self._regions:
                gap = self._regions[key] - removed - start
                if gap < 0:
                    raise OSError(errno.EFBIG, f"the record's columns before {key} pass the room left for them")
                if gap:
                    _collapse(out, -(-position // _ALIGN) * _ALIGN, gap)
                    removed += gap
            _write_all(out, local + header + body, position)
            if key in self._fds:
                _copy_file(self._fds[key], out, written, start)
                # Unlinked at once: its pages are freed, and if not written back yet, never will be.
                os.close(self._fds.pop(key))
                os.unlink(os.path.join(self.tmpdir, key))
            position = start + written
        directory = b"".join(_central_header(*entry) for entry in entries)
        end = directory + _end_records(len(entries), position, len(directory))
        _write_all(out, end, position)
        os.ftruncate(out, position + len(end))  # the regions of the columns a record has not: holes
        _write_all(out, head, 0)
        os.fsync(out)
        os.close(self._fds.pop(""))
        return self.path

    def discard(self) -> None:
        """Stop the thread, dropping what is queued, close the files and remove the directory."""
        self._stop = True
        if threading.current_thread() is self._thread:
            # The garbage collector dropped the writer inside the thread: it removes the files as it ends.
            self._remove_on_exit = True
            with contextlib.suppress(queue.Full):
                self._queue.put_nowait(None)  # in case it waits for a chunk: no writer will send one
            return
        if self._thread is not None and self._thread.is_alive():
            while True:  # make room for the wake-up call, which must not block
                try:
                    self._queue.get_nowait()
                except queue.Empty:
                    break
        self._join()
        self._remove()

    def _run(self) -> None:
        """The thread: append queued columns until None (finish) or _stop (discard); keep its first error."""
        while not self._stop:
            columns = self._queue.get()
            if columns is None or self._stop:
                break
            if self._error is None:  # after a failure, keep taking chunks so that put() never blocks
                try:
                    self._append(columns)
                except BaseException as error:  # noqa: BLE001 - raised in the caller's thread by put(), finish()
                    self._error = error
            del columns  # hold no chunk while waiting for the next
        if self._remove_on_exit:
            self._remove()

    def _append(self, columns: dict[str, np.ndarray]) -> None:
        for key, column in columns.items():
            data = column.reshape(-1).view(np.uint8)  # the bytes of the contiguous column, not a copy
            if len(data):
                self._crc[key] = crc32(data, self._crc[key])
                if key in self._starts:
                    if self._regions and self._size[key] + len(data) > _REGION - _SLACK:
                        room = (_REGION - _SLACK) >> 30
                        raise OSError(errno.EFBIG, f"the record's {key} column passes {room} GiB")
                    _write_all(self._fds[""], data, self._starts[key] + self._size[key])
                else:
                    _write_all(self._fds[key], data)
                self._size[key] += len(data)
        if not _FADVISE:
            return
        for key, start in self._starts.items():
            end = start + self._size[key]
            if end > self._written[key]:
                # Start writing the new data to disk now, while the caller derives, rather than in the final
                # fsync, and drop the pages of the previous chunk, written back by now: the output need not
                # stay in memory, and new pages cost more system time than reused ones.
                try:
                    os.posix_fadvise(self._fds[""], self._dropped[key], end - self._dropped[key],
                                     os.POSIX_FADV_DONTNEED)
                except OSError:
                    pass  # advice only: this filesystem does not take it
                self._dropped[key], self._written[key] = self._written[key], end

    def _join(self) -> None:
        """Tell the thread to end once the queue is empty, and wait for it."""
        if self._thread is not None and self._thread.is_alive():
            self._queue.put(None)
            self._thread.join()

    def _raise_error(self) -> None:
        if self._error is not None:
            raise self._error

    def _remove(self) -> None:
        while self._fds:
            os.close(self._fds.popitem()[1])
        shutil.rmtree(self.tmpdir, ignore_errors=True)


def _create(path: str) -> int:
    """A new file at ``path``, open for reading and writing, with the umask's permissions."""
    return os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)


def _write_all(fd: int, data, offset: int | None = None) -> None:
    """Write the bytes of the buffer ``data`` at ``offset`` of ``fd`` (None: at its position), all of them
    (os.write may write fewer)."""
    view = memoryview(data).cast("B")
    if offset is not None and not hasattr(os, "pwrite"):  # Windows
        os.lseek(fd, offset, os.SEEK_SET)
        offset = None
    while view:
        if offset is None:
            view = view[os.write(fd, view) :]
        else:
            n = os.pwrite(fd, view, offset)
            view, offset = view[n:], offset + n


# Errors of os.copy_file_range that mean "not between these files": copy through a buffer instead.
_NO_COPY_RANGE = {errno.EXDEV, errno.ENOSYS, errno.EINVAL, errno.EPERM, errno.ETXTBSY, errno.EOPNOTSUPP}
_NO_COPY_RANGE.add(getattr(errno, "ENOTSUP", errno.EOPNOTSUPP))


def _copy_file(source: int, target: int, size: int, at: int) -> None:
    """Copy the first ``size`` bytes of file ``source`` to offset ``at`` of ``target``.

    In the kernel with ``os.copy_file_range`` (Linux): the bytes do not pass through Python. Elsewhere, or where
    the filesystem refuses, through a buffer of ``_BLOCK`` bytes.
    """
    done = 0
    copy_range = getattr(os, "copy_file_range", None)
    while copy_range is not None and done < size:
        try:
            n = copy_range(source, target, min(size - done, _BLOCK), done, at + done)
        except OSError as error:
            if error.errno not in _NO_COPY_RANGE:
                raise
            n = 0
        if n == 0:  # refused, or a source shorter than size (the loop below raises then)
            break
        done += n
    if done < size:
        os.lseek(source, done, os.SEEK_SET)
    while done < size:
        data = os.read(source, min(size - done, _BLOCK))
        if not data:
            raise OSError(errno.EIO, f"spool file ended after {done} of {size} bytes")
        _write_all(target, data, at + done)
        done += len(data)


def _fallocate():
    """libc's ``fallocate`` (Linux), or None."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        function = ctypes.CDLL(None, use_errno=True).fallocate
    except (OSError, AttributeError):
        return None
    function.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int64, ctypes.c_int64]
    function.restype = ctypes.c_int
    return function


_FALLOCATE = _fallocate()


def _regions(fd: int) -> dict[str, int]:
    """The offset of each spooled column's region in the new, empty file ``fd``, which this makes as large as
    they need (holes); none where its filesystem cannot collapse a range out of a file (tried on its first
    blocks) or hold a file that large."""
    if _FALLOCATE is None:
        return {}
    keys = [key for key in _KEYS if key in _SPOOLED and key != _STREAMED]
    try:
        os.ftruncate(fd, 2 * _ALIGN)
        collapses = _FALLOCATE(fd, _COLLAPSE_RANGE, 0, _ALIGN) == 0
        os.ftruncate(fd, 0)
        if collapses:
            os.ftruncate(fd, (len(keys) + 1) * _REGION)
    except OSError:
        os.ftruncate(fd, 0)
        return {}
    return {key: (k + 1) * _REGION for k, key in enumerate(keys)} if collapses else {}


def _collapse(fd: int, offset: int, length: int) -> None:
    """Take ``length`` bytes at ``offset`` out of file ``fd``, what follows moved down (no data copied)."""
    if _FALLOCATE(fd, _COLLAPSE_RANGE, offset, length) != 0:
        error = ctypes.get_errno()
        raise OSError(error, f"cannot collapse the record's temporary file: {os.strerror(error)}")


def _descr(dtype) -> str:
    """The ``.npy`` descr of a dtype without fields ('<f4', '<U12'): its string."""
    return np.dtype(dtype).str


def _npy_header(descr: str, shape: tuple) -> bytes:
    """The ``.npy`` 1.0 header of a C-order array, as numpy writes it.

    The text is padded so that the data starts at a multiple of 64 bytes, with room for 21 digits of
    ``shape[0]``: the header's length does not depend on the number of rows, so it can be written before the
    rows are known and replaced afterwards.
    """
    shape = tuple(int(n) for n in shape)  # numpy integers would print as np.int64(...)
    text = f"{{'descr': {descr!r}, 'fortran_order': False, 'shape': {shape!r}, }}"
    if shape:
        text += " " * (21 - len(repr(shape[0])))
    pad = 64 - (10 + len(text) + 1) % 64  # magic, version and length take 10 bytes; 64, not 0, when aligned
    body = text.encode("latin1") + b" " * pad + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(body)) + body


# Zip records, written as zipfile writes a stored member with force_zip64 (as np.savez does): made by Unix,
# version 4.5 (zip64), mode 0644, the date _ZIP_DATE, no flags and no compression.
_ZIP_VERSION = 45
_ZIP_UNIX = 3
_ZIP_MODE = 0o644 << 16
_DOS_DATE = (_ZIP_DATE[0] - 1980) << 9 | _ZIP_DATE[1] << 5 | _ZIP_DATE[2]
_DOS_TIME = _ZIP_DATE[3] << 11 | _ZIP_DATE[4] << 5 | _ZIP_DATE[5] // 2
_ZIP64_LIMIT = (1 << 31) - 1  # as zipfile: beyond this, a size or offset goes into a zip64 field
_FULL32 = 0xFFFFFFFF  # a 32-bit size or offset whose value is in the zip64 extra field


def _local_header(name: bytes, crc: int, size: int, pad: int = 0) -> bytes:
    """The local header of a stored member of ``size`` bytes; always zip64, so its width does not depend on size.
    ``pad`` (0, or 4 or more) bytes more, an extra field of zeros (``_PAD_ID``) after the zip64 one."""
    extra = struct.pack("<HHQQ", 1, 16, size, size)
    if pad:
        extra += struct.pack("<HH", _PAD_ID, pad - 4) + bytes(pad - 4)
    fixed = struct.pack(
        "<4s2B4HL2L2H", b"PK\x03\x04", _ZIP_VERSION, 0, 0, 0, _DOS_TIME, _DOS_DATE,
        crc, _FULL32, _FULL32, len(name), len(extra),
    )  # fmt: skip
    return fixed + name + extra


def _central_header(name: bytes, crc: int, size: int, offset: int) -> bytes:
    """The central directory entry of a stored member; zip64 fields only for what does not fit 32 bits."""
    zip64 = []
    if size > _ZIP64_LIMIT:
        zip64 += [size, size]
        size = _FULL32
    if offset > _ZIP64_LIMIT:
        zip64.append(offset)
        offset = _FULL32
    extra = struct.pack(f"<HH{len(zip64)}Q", 1, 8 * len(zip64), *zip64) if zip64 else b""
    fixed = struct.pack(
        "<4s4B4HL2L5HLL", b"PK\x01\x02", _ZIP_VERSION, _ZIP_UNIX, _ZIP_VERSION, 0, 0, 0, _DOS_TIME, _DOS_DATE,
        crc, size, size, len(name), len(extra), 0, 0, 0, _ZIP_MODE, offset,
    )  # fmt: skip
    return fixed + name + extra


def _end_records(count: int, offset: int, size: int) -> bytes:
    """The end of central directory record, after the zip64 end record and locator if they are needed."""
    records = b""
    if count > 0xFFFF or offset > _ZIP64_LIMIT or size > _ZIP64_LIMIT:
        records += struct.pack(
            "<4sQ2H2L4Q", b"PK\x06\x06", 44, _ZIP_VERSION, _ZIP_VERSION, 0, 0, count, count, size, offset
        )
        records += struct.pack("<4sLQL", b"PK\x06\x07", 0, offset + size, 1)
        count, offset, size = min(count, 0xFFFF), min(offset, _FULL32), min(size, _FULL32)
    return records + struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, count, count, size, offset, 0)


def _fsync_dir(path: Path) -> None:
    """Make a rename in directory ``path`` durable (POSIX only: Windows cannot open a directory)."""
    if os.name != "posix":
        return
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
