"""What the instancing formats (USD's PointInstancer, glTF's ``EXT_mesh_gpu_instancing``) need of a record.

Both formats place a prototype by translation, rotation (a unit quaternion) and per-axis scale:
``world = position + R(q) (scale * p)``. A record's ``xform`` is ``M p + t`` with the columns of ``M`` the
scope's axes times its sizes (README, "The record"), so ``decompose`` takes the column lengths as the scales and the
normalized columns as the rotation. Two cases need care:

* a flat scope (a facade quad: one zero column; a snap line: two) has no direction for that axis. The
  rotation is completed by cross products (``z = x cross y``, and so on), and the scale of that axis is
  0, which keeps the prototype flat whatever the completed direction is;
* a mirroring transform (negative determinant: ``s('-1, ...)``, a mirrored split) is not a rotation:
  its x axis is negated into a rotation and its x scale made negative, which both formats allow.

Tiles: a city spans kilometres, and both formats store positions as float32, which at 10 km from the
origin is a millimetre step. So instances are grouped in square tiles of the ground plane (world x and
z) by the centre of their box, and positions are stored relative to the tile's corner, computed in float64
from the record's lot origins (``model.records.LotOrigins``): within a 500 m tile float32 is exact to about
30 micrometres. ``TileSpool`` sorts a stream of chunks into tiles on
disk, so a writer can then make one tile at a time with bounded memory (the record may have 10^8 rows).
Within a tile, rows keep the record's order, so the output does not depend on the chunking.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numba as nb
import numpy as np

from grammarc.atomic import private_folder
from grammarc.constants import LIMITS
from grammarc.geometry.triangulation import triangulate_polygons
from grammarc.io import WriterBlock
from grammarc.ir.asset_names import locate
from grammarc.model.assets import asset_library
from grammarc.model.records import WHITE, MaterialTable, TerminalChunk

__all__ = ["INSTANCE", "TRIANGLE", "Tile", "TileSpool", "TiledWriter", "decompose"]

#: Default tile edge (metres): see the module docstring.
TILE_SIZE = LIMITS.tile_size
#: One instance row in a tile's spool, its transform relative to the tile's corner.
INSTANCE = np.dtype([("row", "<i8"), ("asset", "<i4"), ("lot", "<i4"), ("symbol", "<i4"), ("color", "u1", (4,)),
                     ("xform", "<f4", (3, 4))])
#: One triangle of the mesh table in a tile's spool: vertices relative to the tile's corner, the face's colour,
#: symbol and lot, and its vertices' texture coordinates of set 0 (NaN: none).
TRIANGLE = np.dtype([("vertices", "<f4", (3, 3)), ("color", "u1", (4,)), ("symbol", "<i4"), ("lot", "<i4"),
                     ("uv", "<f4", (3, 2))])
#: A column shorter than this (in world units) is a flat axis.
_FLAT = 1e-9


def decompose(xform: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, orientations and scales of instances (see the module docstring).

    Parameters
    ----------
    xform : (n, 3, 4) float
        Transforms (a tile's, relative to its corner).

    Returns
    -------
    positions : (n, 3) float32
    orientations : (n, 4) float32
        Unit quaternions as (x, y, z, w), the memory order of glTF and of USD's ``GfQuat``.
    scales : (n, 3) float32
    """
    xform = np.asarray(xform, np.float64)
    positions = xform[:, :, 3].astype(np.float32)
    orientations = np.empty((len(xform), 4), np.float32)
    scales = np.empty((len(xform), 3), np.float32)
    _decompose(np.ascontiguousarray(xform[:, :, :3]), orientations, scales)
    return positions, orientations, scales


@nb.njit(cache=True, nogil=True)
def _decompose(linear, orientations, scales):
    n = linear.shape[0]
    axes = np.empty((3, 3))
    known = np.empty(3, np.bool_)
    for i in range(n):
        for j in range(3):
            length = np.sqrt(linear[i, 0, j] ** 2 + linear[i, 1, j] ** 2 + linear[i, 2, j] ** 2)
            scales[i, j] = length
            known[j] = length > _FLAT
            for k in range(3):
                axes[k, j] = linear[i, k, j] / length if known[j] else 0.0
        count = known.sum()
        if count == 0:
            axes[:, :] = 0.0
            for k in range(3):
                axes[k, k] = 1.0
        elif count == 1:
            # a line: the next axis perpendicular to it, crossed with the world axis least aligned
            j = np.argmax(known)
            best = np.argmin(np.abs(axes[:, j]))
            helper = np.zeros(3)
            helper[best] = 1.0
            _cross_into(axes[:, j], helper, axes, (j + 1) % 3)
            known[(j + 1) % 3] = True
        # one axis left flat: the cross product of the other two in cyclic order (x = y cross z, ...)
        for j in range(3):
            if not known[j]:
                _cross_into(axes[:, (j + 1) % 3], axes[:, (j + 2) % 3], axes, j)
        det = (axes[0, 0] * (axes[1, 1] * axes[2, 2] - axes[2, 1] * axes[1, 2])
               - axes[0, 1] * (axes[1, 0] * axes[2, 2] - axes[2, 0] * axes[1, 2])
               + axes[0, 2] * (axes[1, 0] * axes[2, 1] - axes[2, 0] * axes[1, 1]))
        if det < 0.0:
            for k in range(3):
                axes[k, 0] = -axes[k, 0]
            scales[i, 0] = -scales[i, 0]
        _quaternion(axes, orientations[i])


@nb.njit(cache=True, nogil=True)
def _cross_into(a, b, axes, out):
    """``axes[:, out] = normalize(a x b)``."""
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    z = a[0] * b[1] - a[1] * b[0]
    norm = np.sqrt(x * x + y * y + z * z)
    axes[0, out], axes[1, out], axes[2, out] = x / norm, y / norm, z / norm


@nb.njit(cache=True, nogil=True)
def _quaternion(m, out):
    """(x, y, z, w) of the rotation matrix ``m`` (Shepperd's method: the largest of the four divisors)."""
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = np.sqrt(trace + 1.0) * 2.0
        w, x, y, z = 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2.0
        w, x, y, z = (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2.0
        w, x, y, z = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2.0
        w, x, y, z = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s
    norm = np.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0:  # one of the two signs, so equal rotations give equal bytes
        norm = -norm
    out[0], out[1], out[2], out[3] = x / norm, y / norm, z / norm, w / norm


@dataclass(frozen=True)
class Tile:
    """One tile of a spool: its grid key, its corner in world coordinates and its rows."""

    key: tuple[int, int]
    origin: np.ndarray  # (3,) float64: (ix * size, 0, iz * size)
    instances: np.ndarray  # (n,) INSTANCE
    triangles: np.ndarray  # (t,) TRIANGLE
    #: (n,) and (t,) int32 rows of the writer's ``materials``, where the record has textures (else None).
    instance_material: np.ndarray | None = None
    triangle_material: np.ndarray | None = None

    def texture_coordinates(self) -> np.ndarray | None:
        """(3 t, 2) float32: the texture coordinates of set 0 of the triangles' vertices, 0 where a face
        has none; None when none of the tile's faces has any (the writers then leave them out)."""
        uv = self.triangles["uv"].reshape(-1, 2)
        known = np.isfinite(uv).all(axis=1)
        if not known.any():
            return None
        return np.where(known[:, None], uv, 0.0).astype(np.float32)

    @property
    def name(self) -> str:
        """A prim or node name: ``tile_<ix>_<iz>`` with ``m`` for a minus sign."""
        return "tile_" + "_".join(str(k).replace("-", "m") for k in self.key)


class TileSpool:
    """Sorts chunks of a record into square tiles, each an append-only pair of files in ``directory``.

    ``add`` groups a chunk's rows by tile with one stable sort and appends each group to its tile's
    file (the record's order is kept inside a tile); the polygons of the mesh table are triangulated
    first (``geometry.triangulation``) and go to the tile of their first vertex. ``tiles()`` reads
    the tiles back one at a time in key order.
    """

    def __init__(self, directory: str | os.PathLike, tile_size: float = TILE_SIZE):
        if not tile_size > 0:
            raise ValueError(f"tile_size must be positive, got {tile_size}")
        self.directory = Path(directory)
        self.tile_size = float(tile_size)
        self.keys: set[tuple[int, int]] = set()
        self.instances = 0
        self.faces = 0
        self.triangles = 0
        #: Whether the chunks carry materials (``add``'s ``material``): all of a record's or none.
        self.materials: bool | None = None

    def add(self, chunk: TerminalChunk, material: np.ndarray | None = None,
            mesh_material: np.ndarray | None = None) -> None:
        """Spool a chunk; ``material`` (n,) and ``mesh_material`` (F,) int32: its instances' and faces'
        rows of the writer's materials, where the record has textures."""
        if self.materials is None:
            self.materials = material is not None
        if self.materials != (material is not None):
            raise ValueError("TerminalChunk.materials: a record's chunks all carry materials or none do")
        rows = np.empty(len(chunk.asset), INSTANCE)
        rows["asset"], rows["lot"], rows["symbol"] = chunk.asset, chunk.lot, chunk.symbol
        rows["color"] = WHITE if chunk.color is None else chunk.color
        rows["row"] = np.arange(self.instances, self.instances + len(rows))
        xform = chunk.world_xform()
        keys = self._keys(xform[:, :, 3] + 0.5 * xform[:, :, :3].sum(axis=2))  # the boxes' centres
        xform[:, :, 3] -= self._corners(keys)
        rows["xform"] = xform
        self._append("instances", keys, rows)
        if material is not None:
            self._append("instance_materials", keys, material.astype(np.int32))
        self.instances += len(rows)

        mesh = chunk.mesh
        if len(mesh.face_offsets) > 1:
            # triangulated near the lots' origins, where the float32 vertices are exact
            faces = triangulate_polygons(np.asarray(mesh.vertices, np.float64), mesh.ring_offsets, mesh.face_offsets)
            face_of_vertex = np.repeat(np.arange(len(mesh.face_offsets) - 1),
                                       np.diff(np.asarray(mesh.ring_offsets)[mesh.face_offsets]))
            face = face_of_vertex[faces[:, 0]]
            vertices = mesh.world(chunk.origins)
            keys = self._keys(vertices[np.asarray(mesh.ring_offsets)[mesh.face_offsets[:-1]]])[face]
            triangles = np.empty(len(faces), TRIANGLE)
            triangles["vertices"] = vertices[faces] - self._corners(keys)[:, None]
            triangles["color"] = mesh.colors()[face]
            triangles["symbol"] = np.asarray(mesh.symbol)[face]
            triangles["lot"] = np.asarray(mesh.lot)[face]
            triangles["uv"] = mesh.texture()[faces]
            self._append("triangles", keys, triangles)
            if mesh_material is not None:
                self._append("triangle_materials", keys, mesh_material[face].astype(np.int32))
            self.faces += len(mesh.face_offsets) - 1
            self.triangles += len(triangles)

    def tiles(self):
        """Each tile, in key order, read back from its files."""
        for key in sorted(self.keys):
            origin = self._corners(np.array([key]))[0]
            materials = [self._read(f"{kind}_materials", key, np.dtype("<i4")) if self.materials else None
                         for kind in ("instance", "triangle")]
            yield Tile(key, origin, self._read("instances", key, INSTANCE), self._read("triangles", key, TRIANGLE),
                       *materials)

    def _keys(self, points: np.ndarray) -> np.ndarray:
        """(n, 2) int64 tile keys of world points."""
        return np.floor(points[:, [0, 2]] / self.tile_size).astype(np.int64)

    def _corners(self, keys: np.ndarray) -> np.ndarray:
        """(n, 3) float64: the world corners of tiles ``keys`` (n, 2), at height 0."""
        corners = np.zeros((len(keys), 3))
        corners[:, [0, 2]] = keys * self.tile_size
        return corners

    def _path(self, kind: str, key: tuple[int, int]) -> Path:
        return self.directory / f"{kind}_{key[0]}_{key[1]}.bin"

    def _append(self, kind: str, keys: np.ndarray, rows: np.ndarray) -> None:
        if not len(rows):
            return
        # one int64 per key (tiles are within +-2^31 of the origin), one stable sort: rows keep their order
        combined = (keys[:, 0] << 32) + (keys[:, 1] & 0xFFFFFFFF)
        order = np.argsort(combined, kind="stable")
        combined = combined[order]
        starts = np.flatnonzero(np.r_[True, combined[1:] != combined[:-1]])
        for first, last in zip(starts, [*starts[1:], len(order)]):
            key = (int(keys[order[first], 0]), int(keys[order[first], 1]))
            with open(self._path(kind, key), "ab") as out:
                out.write(rows[order[first:last]].tobytes())
            self.keys.add(key)

    def _read(self, kind: str, key: tuple[int, int], dtype: np.dtype) -> np.ndarray:
        path = self._path(kind, key)
        return np.fromfile(path, dtype) if path.exists() else np.zeros(0, dtype)


class TiledWriter(WriterBlock):
    """What the instanced writers share: the interface of ``InstanceWriter`` (``write``, ``close``,
    ``abort``, a context manager) over a ``TileSpool`` in a temporary folder next to the output.

    ``write`` validates a chunk and spools it; ``close`` calls the subclass's ``_finish()``, which writes
    the files from ``self._spool.tiles()`` into ``self._tmp`` and moves them into place, and returns
    its counts; any failure (or ``abort``) removes the temporary folder and leaves the output as it was.
    """

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], meta: dict,
                 asset_roots: Sequence[str | os.PathLike] | None, tile_size: float, lod: str | None):
        self.path = Path(path)
        self._meta = dict(meta)
        self._library = asset_library(assets, {"meta": self._meta}, asset_roots, lod=lod)
        self._tmp = Path(private_folder(self.path))
        (self._tmp / "spool").mkdir()
        self._spool = TileSpool(self._tmp / "spool", tile_size)
        self._used = np.zeros(len(self._library.names), np.int64)  # instances of each asset
        self._materials = MaterialTable()
        self._colormaps: dict[int, Path | None] = {}
        self._state = "open"
        self._counts: dict = {}

    def write(self, chunk: TerminalChunk) -> None:
        """Sort a chunk's rows into the tile spools (not kept in memory)."""
        if self._state != "open":
            raise ValueError(f"write to a {type(self).__name__} that is {self._state}")
        asset = np.asarray(chunk.asset)
        if np.asarray(chunk.xform).shape != (len(asset), 3, 4):
            raise ValueError(f"TerminalChunk: asset {asset.shape} and xform {np.shape(chunk.xform)} disagree")
        if len(asset) and (asset.min() < 0 or asset.max() >= len(self._used)):
            raise ValueError(f"TerminalChunk.asset: index out of range [0, {len(self._used)})")
        try:
            self._spool.add(chunk, *self._material_rows(chunk))
            self._used += np.bincount(asset, minlength=len(self._used))
        except BaseException:
            self.abort()
            raise

    def _material_rows(self, chunk: TerminalChunk) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The chunk's instances' and faces' rows of the writer's materials; None without textures."""
        return self._materials.add(chunk) if chunk.materials is not None else (None, None)

    def _colormap(self, material: int) -> Path | None:
        """The colour map file of one of the writer's materials, found in the asset roots; None without one
        (asked for when the output is written, after every chunk: the files are looked for once)."""
        if material not in self._colormaps:
            name = str(self._materials.table()[material, 0])
            found = locate(name, self._library.roots) if name else None
            self._colormaps[material] = found[1] if found else None
        return self._colormaps[material]

    def close(self) -> dict:
        """Write the output and move it into place; the counts (closing again returns them again):
        ``instances``, ``mesh_faces``, ``mesh_triangles``, ``tiles`` and the format's own."""
        if self._state == "closed":
            return dict(self._counts)
        if self._state == "aborted":
            raise ValueError(f"close of a {type(self).__name__} that is aborted")
        try:
            counts = self._finish()
        except BaseException:
            self.abort()
            raise
        shutil.rmtree(self._tmp, ignore_errors=True)
        self._state = "closed"
        self._counts = {"instances": self._spool.instances, "mesh_faces": self._spool.faces,
                        "mesh_triangles": self._spool.triangles, "tiles": len(self._spool.keys), **counts}
        return dict(self._counts)

    def _finish(self) -> dict:
        raise NotImplementedError

    def abort(self) -> None:
        """Drop the spools; nothing is left at ``path`` that was not there before."""
        if self._state == "open":
            self._state = "aborted"
            shutil.rmtree(self._tmp, ignore_errors=True)

    def __del__(self) -> None:
        if getattr(self, "_state", None) == "open":
            self.abort()


def compose(positions: np.ndarray, orientations: np.ndarray, scales: np.ndarray) -> np.ndarray:
    """The record's (n, 3, 4) float64 transforms of translations, (x, y, z, w) unit quaternions and scales:
    what ``decompose`` took apart (readers of the instanced formats use it)."""
    x, y, z, w = (np.asarray(orientations, np.float64)[:, k] for k in range(4))
    rotation = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
    ], axis=1)
    linear = rotation * np.asarray(scales, np.float64)[:, None, :]
    return np.concatenate([linear, np.asarray(positions, np.float64)[:, :, None]], axis=2)
