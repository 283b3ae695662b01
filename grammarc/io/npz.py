"""The terminal record ``instances.npz``: a streaming, atomic writer and its reader.

A city's terminals (10^7-10^8 rows, gigabytes) arrive chunk by chunk from the derivation, and the writer must
hold no more than one chunk in memory (DESIGN.md, invariant 3). ``np.savez`` needs every array whole, so the
writer appends each column's raw bytes to a spool file instead and, on ``close()``, writes the npz member by
member: the ``.npy`` header with the final shape, then the spooled bytes copied in fixed-size blocks.

The result is what ``np.savez`` writes (uncompressed, loadable by ``np.load(path)`` without pickles), except
that it is reproducible: zip entries carry a fixed date and mode, and the bytes depend only on the rows, not on
how they were chunked, so example cities can keep hashes of their output (STYLE.md, "Replay before you
refactor").

An output is complete or absent (invariant 5). Everything is written under a temporary directory next to the
output (``.<name>.tmp*``, so on the same filesystem), fsynced, and moved into place with ``os.replace``.
``abort()``, an exception inside ``with``, a failed write or a writer dropped without ``close()`` removes the
temporaries and leaves a file already at the output path untouched.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import weakref
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.lib import format as npy_format

if TYPE_CHECKING:
    from typing_extensions import Self

__all__ = ["InstanceWriter", "MeshChunk", "TerminalChunk", "read_instances"]

_FORMAT = "grammarc.instances/1"
_BLOCK = 16 << 20  # bytes per copy from a spool file into the npz: bounds the memory of close()
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)  # the earliest date zip can store; fixed so that runs are byte-identical

# Columns spooled to disk: npz key -> (dtype, shape of one row). Offsets are spooled without their leading 0
# and already rebased, so each has one row per ring or face and the member gets the 0 written in front.
_SPOOLED = {
    "asset": ("<i4", ()),
    "xform": ("<f4", (3, 4)),
    "lot": ("<i4", ()),
    "symbol": ("<i4", ()),
    "mesh_vertices": ("<f4", (3,)),
    "mesh_ring_offsets": ("<i8", ()),
    "mesh_face_offsets": ("<i8", ()),
    "mesh_lot": ("<i4", ()),
    "mesh_symbol": ("<i4", ()),
}
_OFFSETS = ("mesh_ring_offsets", "mesh_face_offsets")
# Member order in the file: the record's table in DESIGN.md, then the mesh table.
_KEYS = (
    "assets", "asset", "xform", "lot", "symbols", "symbol", "meta",
    "mesh_vertices", "mesh_ring_offsets", "mesh_face_offsets", "mesh_lot", "mesh_symbol",
)  # fmt: skip


# eq=False: the generated __eq__ would compare arrays elementwise and fail on truth testing.
@dataclass(frozen=True, eq=False)
class MeshChunk:
    """Leaf polygons that cannot be instances: faces with holes, in world coordinates.

    Attributes
    ----------
    vertices : (V, 3) float32
        Ring vertices, ring after ring.
    ring_offsets : (R+1,) int64
        Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r+1]]`` (Arrow-style, starts at 0).
    face_offsets : (F+1,) int64
        Face ``f`` is rings ``face_offsets[f]:face_offsets[f+1]``: its outline, then its holes.
    lot : (F,) int32
        Lot of each face.
    symbol : (F,) int32
        Symbol of each face, an index into the writer's ``symbols``.
    """

    vertices: np.ndarray
    ring_offsets: np.ndarray
    face_offsets: np.ndarray
    lot: np.ndarray
    symbol: np.ndarray

    @staticmethod
    def empty() -> MeshChunk:
        """A chunk without faces: zero-length arrays of the right dtypes, offsets ``[0]``."""
        return MeshChunk(
            vertices=np.zeros((0, 3), np.float32),
            ring_offsets=np.zeros(1, np.int64),
            face_offsets=np.zeros(1, np.int64),
            lot=np.zeros(0, np.int32),
            symbol=np.zeros(0, np.int32),
        )

    @staticmethod
    def concat(chunks: Sequence[MeshChunk]) -> MeshChunk:
        """The faces of ``chunks``, in order, as one chunk whose offsets index the joined arrays."""
        if not chunks:
            return MeshChunk.empty()
        n_vertices = np.array([len(c.vertices) for c in chunks], np.int64)
        n_rings = np.array([len(c.ring_offsets) - 1 for c in chunks], np.int64)
        n_faces = np.array([len(c.face_offsets) - 1 for c in chunks], np.int64)
        return MeshChunk(
            vertices=np.concatenate([c.vertices for c in chunks]),
            ring_offsets=_join_offsets([c.ring_offsets for c in chunks], n_vertices, n_rings),
            face_offsets=_join_offsets([c.face_offsets for c in chunks], n_rings, n_faces),
            lot=np.concatenate([c.lot for c in chunks]),
            symbol=np.concatenate([c.symbol for c in chunks]),
        )


def _join_offsets(offsets: list[np.ndarray], n_items: np.ndarray, n_groups: np.ndarray) -> np.ndarray:
    """Join per-chunk offsets, shifting each chunk's by the items (vertices, rings) of the chunks before it."""
    # n_items [3, 5], n_groups [1, 2]: bases [0, 3], repeated per group [0, 3, 3], added to the offsets
    # without their leading 0: [3] + [2, 5] -> [3, 5, 8], and 0 in front.
    bases = np.cumsum(n_items) - n_items
    tails = np.concatenate([o[1:] for o in offsets]) + np.repeat(bases, n_groups)
    return np.concatenate([np.zeros(1, np.int64), tails])


@dataclass(frozen=True, eq=False)
class TerminalChunk:
    """A batch of terminals: instances of assets, and the leaf polygons that could not be instances.

    Attributes
    ----------
    asset : (n,) int32
        Index into the writer's ``assets``.
    xform : (n, 3, 4) float32
        Affine map from the asset's unit box to world: ``world = xform[:, :, :3] @ p + xform[:, :, 3]``.
    lot : (n,) int32
        Lot (initial shape) of each instance.
    symbol : (n,) int32
        Index into the writer's ``symbols``: the shape's symbol when it became a terminal.
    mesh : MeshChunk
        Faces of this batch that are not instances.
    """

    asset: np.ndarray
    xform: np.ndarray
    lot: np.ndarray
    symbol: np.ndarray
    mesh: MeshChunk


class InstanceWriter:
    """Streams TerminalChunks into an .npz; the output appears complete on close() or not at all.

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
        self._counts: dict[str, int] = {}
        self._state = "open"
        self._tmpdir = tempfile.mkdtemp(prefix=f".{self.path.name}.tmp", dir=self.path.parent)
        self._spools: dict = {}
        # Removes the temporaries on abort(), after close(), or when a writer is dropped unclosed.
        self._cleanup = weakref.finalize(self, _remove_temporaries, self._spools, self._tmpdir)
        try:
            for key in _SPOOLED:
                # Open until close() or abort(), which close them through self._cleanup.
                self._spools[key] = open(os.path.join(self._tmpdir, key), "wb")  # noqa: SIM115
        except BaseException:
            self._cleanup()
            raise

    def write(self, chunk: TerminalChunk) -> None:
        """Append a chunk's rows; its mesh offsets are rebased onto the rows written before.

        Raises
        ------
        ValueError
            If the writer is closed or aborted, or a field of ``chunk`` has the wrong dtype or shape,
            inconsistent lengths, bad offsets or an asset or symbol index out of range. The writer is
            unchanged by a rejected chunk.
        """
        if self._state != "open":
            raise ValueError(f"write to an InstanceWriter that is {self._state}")
        columns = _validate(chunk, len(self._assets), len(self._symbols))
        columns["mesh_ring_offsets"] = columns["mesh_ring_offsets"] + self._rows["mesh_vertices"]
        columns["mesh_face_offsets"] = columns["mesh_face_offsets"] + self._rows["mesh_ring_offsets"]
        try:
            for key, column in columns.items():
                # A byte view of the contiguous column: no copy on the way to the file.
                self._spools[key].write(column.reshape(-1).view(np.uint8))
                self._rows[key] += len(column)
        except BaseException:
            # The spools may now disagree on the rows written: this output cannot be completed.
            self.abort()
            raise

    def close(self) -> dict:
        """Write the npz next to the output, fsync it, and rename it onto ``path``.

        Returns
        -------
        counts : dict
            ``{"instances": N, "mesh_faces": F, "mesh_vertices": V}``, as stored in ``meta["counts"]``.
            Closing again returns the same counts.
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
            for spool in self._spools.values():
                spool.close()
            # Inside the temporary directory, so abort() removes it; created with the umask's permissions.
            tmp = os.path.join(self._tmpdir, self.path.name)
            with open(tmp, "xb") as out:
                self._write_npz(out, counts)
                out.flush()
                os.fsync(out.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            self.abort()
            raise
        self._state = "closed"
        self._counts = counts
        self._cleanup()
        _fsync_dir(self.path.parent)
        return dict(counts)

    def abort(self) -> None:
        """Remove every temporary; a file already at ``path`` is left untouched. No-op once closed."""
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

    def _write_npz(self, out, counts: dict) -> None:
        """Write the record to the binary file ``out``, member by member, in the order of ``_KEYS``."""
        # Sorted keys: the bytes must not depend on the order in which meta was built.
        meta = json.dumps({**self._meta, "counts": counts, "format": _FORMAT}, sort_keys=True)
        in_memory = {"assets": self._assets, "symbols": self._symbols, "meta": np.array(meta)}
        with zipfile.ZipFile(out, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
            for key in _KEYS:
                if key in in_memory:
                    array = in_memory[key]
                    _write_member(zf, key, array.dtype, array.shape, array.tobytes())
                    continue
                dtype, row_shape = _SPOOLED[key]
                rows = self._rows[key] + (key in _OFFSETS)
                head = np.zeros(1, np.int64).tobytes() if key in _OFFSETS else b""
                _write_member(zf, key, dtype, (rows, *row_shape), head, self._spools[key].name)


def read_instances(path: str | os.PathLike) -> dict[str, np.ndarray | dict]:
    """Load an instances.npz written by InstanceWriter.

    Returns
    -------
    record : dict
        Every array of the record by key (see DESIGN.md, "The terminal record"), with ``"meta"``
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
    if meta.get("format") != _FORMAT:
        raise ValueError(f"{os.fspath(path)}: format {meta.get('format')!r}, expected {_FORMAT!r}")
    record["meta"] = meta
    return record


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
        ("mesh_vertices", "MeshChunk.vertices", chunk.mesh.vertices),
        ("mesh_ring_offsets", "MeshChunk.ring_offsets", chunk.mesh.ring_offsets),
        ("mesh_face_offsets", "MeshChunk.face_offsets", chunk.mesh.face_offsets),
        ("mesh_lot", "MeshChunk.lot", chunk.mesh.lot),
        ("mesh_symbol", "MeshChunk.symbol", chunk.mesh.symbol),
    ):
        columns[key] = _column(field, value, *_SPOOLED[key])
    n = len(columns["asset"])
    for key in ("xform", "lot", "symbol"):
        if len(columns[key]) != n:
            raise ValueError(f"TerminalChunk.{key}: {len(columns[key])} rows, asset has {n}")
    _check_offsets("MeshChunk.ring_offsets", columns["mesh_ring_offsets"], len(columns["mesh_vertices"]), 0)
    _check_offsets(
        "MeshChunk.face_offsets", columns["mesh_face_offsets"], len(columns["mesh_ring_offsets"]) - 1, 1
    )
    n_faces = len(columns["mesh_face_offsets"]) - 1
    for key in ("mesh_lot", "mesh_symbol"):
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


def _write_member(zf: zipfile.ZipFile, key: str, dtype, shape: tuple, head: bytes, spool: str = "") -> None:
    """Write ``key.npy``: the .npy header of an array ``shape`` of ``dtype``, ``head``, the ``spool`` file."""
    info = zipfile.ZipInfo(f"{key}.npy", date_time=_ZIP_DATE)
    info.create_system = 3  # Unix, whatever the platform, so the bytes do not depend on it
    info.external_attr = 0o644 << 16
    header = {"descr": npy_format.dtype_to_descr(np.dtype(dtype)), "fortran_order": False, "shape": shape}
    # force_zip64 as np.savez does: the size is not known to zipfile before the member is written.
    with zf.open(info, "w", force_zip64=True) as member:
        npy_format.write_array_header_1_0(member, header)
        member.write(head)
        if spool:
            with open(spool, "rb") as source:
                _copy(source, member)


def _copy(source, target) -> None:
    """Copy ``source`` to ``target`` through one reused buffer of ``_BLOCK`` bytes."""
    buffer = memoryview(bytearray(_BLOCK))
    while n := source.readinto(buffer):
        target.write(buffer[:n])


def _remove_temporaries(spools: dict, tmpdir: str) -> None:
    """Close the spool files and delete the temporary directory with everything in it."""
    for spool in spools.values():
        spool.close()
    shutil.rmtree(tmpdir, ignore_errors=True)


def _fsync_dir(path: Path) -> None:
    """Make a rename in directory ``path`` durable (POSIX only: Windows cannot open a directory)."""
    if os.name != "posix":
        return
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
