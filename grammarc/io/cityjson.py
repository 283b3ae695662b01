"""CityJSON 2.0 (``--emit city.city.json``): one ``Building`` per lot, with its attributes and its LoD 2
surfaces, in the lots' coordinate system.

GIS and 3D city model tools (cjio, QGIS, 3DCityDB, the CityJSON viewers) read CityJSON; a city of
instances means nothing to them. So the record is baked as the mesh writers bake it (``io.bake``: each
instance's asset placed, the mesh table's polygons triangulated, at most ``--max-triangles``), and each
lot's triangles become the surfaces of one ``MultiSurface`` of LoD 2 of its Building. Each surface has a
semantic type by the way it faces: ``RoofSurface`` up (its normal within 60 degrees of up),
``GroundSurface`` down, ``WallSurface`` otherwise. (The grammar's own names, a ``comp(f)`` selector's
``top`` or ``side``, are not in the record; a facade's window is a wall here.)

Vertices are integers: ``transform`` (scale 1 mm, ``translate`` the lowest corner of the city in whole
metres) maps them to the coordinate system, easting, northing and height as CityJSON has them (grammarc's
world has y up and z south). ``metadata.referenceSystem`` names the coordinate system where the build's
lots had one (``meta["crs"]``, an EPSG code as an OGC URL); a local scene has none. Each lot's vertices are
its own, deduplicated, in the order of its coordinates: the file does not depend on the chunking.

The file is streamed: each chunk's Buildings go to a spool of objects and its vertices (float64) to a spool
of vertices as they come; ``close`` knows the city's corner then, and writes the document (header,
objects, vertices turned into integers block by block) next to the output and renames it onto it.
"""

from __future__ import annotations

import math
import os
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import ClassVar

import numpy as np
import orjson

from grammarc.atomic import private_folder, replacing
from grammarc.errors import UsageError
from grammarc.io import WriterBlock
from grammarc.io.bake import bake_mesh, made_triangles, triangle_limit
from grammarc.model.assets import asset_library
from grammarc.model.lots import Lots
from grammarc.model.records import TerminalChunk

__all__ = ["SCALE", "SURFACES", "WRITERS", "CityJsonWriter"]

#: Metres per integer unit of the vertices.
SCALE = 0.001
#: The semantic surface types, in the order of their codes.
SURFACES = ("RoofSurface", "WallSurface", "GroundSurface")
#: A surface whose normal's up component is above this share of its length faces up (60 degrees).
_UP = 0.5
#: Vertices turned into text at a time on close.
_BLOCK = 1 << 20


class CityJsonWriter(WriterBlock):
    """Writes TerminalChunks as a CityJSON 2.0 document (see the module docstring); the interface of
    ``io.npz.InstanceWriter``.

    Parameters
    ----------
    path : str or os.PathLike
        The output, ``.json`` (``city.city.json`` by CityJSON's custom).
    assets, symbols, meta
        As ``InstanceWriter``'s; ``meta["crs"]`` names the reference system.
    asset_roots, max_triangles, lod
        As ``io.bake.BakedWriter``'s.
    lots : Lots, optional
        The build's lots: the Buildings' ids and attributes. Without them a Building is ``lot<number>``.
    """

    #: Its surfaces are the baked record (``io.writers``: no instanced writer takes ``.json``).
    bakes: ClassVar[bool] = True

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str], meta: dict,
                 asset_roots: Sequence[str | os.PathLike] | None = None, max_triangles: int | None = None,
                 lod: str | None = None, lots: Lots | None = None):
        self.path = Path(path)
        if self.path.suffix.lower() != ".json":
            raise UsageError(f"cannot write `{path}` as CityJSON: give a .json path (city.city.json)")
        self._meta = dict(meta)
        self._library = asset_library([str(n) for n in assets], {"meta": self._meta}, asset_roots, lod)
        self.max_triangles = triangle_limit(max_triangles)
        self._names = _building_names(lots)
        self._attributes = _attribute_rows(lots)
        self._tmp = Path(private_folder(self.path))
        self._objects = open(self._tmp / "objects.json", "wb")  # noqa: SIM115 - closed by close/abort
        self._vertices = open(self._tmp / "vertices.bin", "wb")  # noqa: SIM115
        self._n_vertices = 0
        self._low = np.full(3, np.inf)
        self._buildings = 0
        self._triangles = 0
        self._rows = 0
        self._state = "open"
        self._counts: dict = {}

    def write(self, chunk: TerminalChunk) -> None:
        """Add the Buildings of a chunk's lots (all of them, a lot without surfaces too)."""
        if self._state != "open":
            raise ValueError(f"write to a CityJsonWriter that is {self._state}")
        asset = np.asarray(chunk.asset, np.int64)
        try:
            triangles = made_triangles(self._library, asset, chunk.mesh)
            if self._triangles + triangles > self.max_triangles:
                raise UsageError(f"{self.path}: CityJSON surfaces pass {self.max_triangles:,} triangles after "
                                 f"{self._rows + len(asset):,} instances; raise the limit with --max-triangles N, "
                                 "or write an instance record (.npz) or instanced .glb/.usdc instead")
            mesh, source = bake_mesh(self._library, asset, chunk.xform, chunk.mesh, self.max_triangles,
                                     origins=chunk.origins, lot=chunk.lot)
            self._add(chunk, np.asarray(mesh.vertices), np.asarray(mesh.faces),
                      np.concatenate([chunk.lot, chunk.mesh.lot]).astype(np.int64)[source])
        except BaseException:
            self.abort()
            raise
        self._triangles += triangles
        self._rows += len(asset)

    def _add(self, chunk: TerminalChunk, world: np.ndarray, faces: np.ndarray, lot: np.ndarray) -> None:
        """Spool the Buildings of the chunk's lots: ``world`` (V, 3) vertices, ``faces`` (T, 3) of lot ``lot``."""
        kind = _surface_kinds(world, faces)
        # each lot's vertices deduplicated and in the order of their coordinates: (lot, easting, northing, up)
        vertex_lot = np.zeros(len(world), np.int64)
        vertex_lot[faces.reshape(-1)] = np.repeat(lot, 3)
        used = np.zeros(len(world), bool)
        used[faces.reshape(-1)] = True
        keys = np.column_stack([vertex_lot, world[:, 0], -world[:, 2], world[:, 1]])[used]
        unique, inverse = _unique_rows(keys)
        index = np.full(len(world), -1, np.int64)
        index[np.flatnonzero(used)] = inverse + self._n_vertices
        self._vertices.write(np.ascontiguousarray(unique[:, 1:]).tobytes())
        if len(unique):
            self._low = np.minimum(self._low, unique[:, 1:].min(axis=0))
        self._n_vertices += len(unique)
        faces = index[faces]
        lots = chunk.origins.lot if len(chunk.origins.lot) else np.unique(lot)
        order = np.argsort(lot, kind="stable")
        bounds = np.searchsorted(lot[order], np.concatenate([lots, [np.iinfo(np.int64).max]]))
        parts = []
        for k, number in enumerate(np.asarray(lots).tolist()):
            rows = order[bounds[k]:bounds[k + 1]]
            parts.append(self._building(int(number), faces[rows], kind[rows]))
        if parts:
            self._objects.write((b"," if self._buildings else b"") + b",".join(parts))
            self._buildings += len(parts)

    def _building(self, lot: int, faces: np.ndarray, kind: np.ndarray) -> bytes:
        """``"id":{...}`` of one lot's Building: its attributes, and a MultiSurface of its triangles."""
        building: dict = {"type": "Building"}
        attributes = self._attributes(lot)
        if attributes:
            building["attributes"] = attributes
        building["geometry"] = []
        if len(faces):
            present = np.unique(kind)
            code = np.zeros(len(SURFACES), np.int64)
            code[present] = np.arange(len(present))
            building["geometry"] = [{
                "type": "MultiSurface", "lod": "2", "boundaries": faces[:, None, :],
                "semantics": {"surfaces": [{"type": SURFACES[s]} for s in present.tolist()],
                              "values": code[kind]},
            }]
        return orjson.dumps(self._names(lot)) + b":" + orjson.dumps(building, option=orjson.OPT_SERIALIZE_NUMPY)

    def close(self) -> dict:
        """Write the document next to the output and rename it onto ``path``.

        Returns
        -------
        counts : dict
            ``buildings``, ``vertices``, ``triangles`` and ``instances`` written. Closing again returns them.
        """
        if self._state == "closed":
            return dict(self._counts)
        if self._state == "aborted":
            raise ValueError("close of a CityJsonWriter that is aborted")
        try:
            self._objects.close()
            self._vertices.close()
            translate = np.floor(self._low) if self._n_vertices else np.zeros(3)
            header = {"type": "CityJSON", "version": "2.0",
                      "transform": {"scale": [SCALE] * 3, "translate": translate.tolist()},
                      "metadata": _metadata(self._meta)}
            with replacing(self.path) as tmp, open(tmp, "wb") as out:
                out.write(orjson.dumps(header)[:-1] + b',"CityObjects":{')
                with open(self._tmp / "objects.json", "rb") as objects:
                    shutil.copyfileobj(objects, out, 1 << 24)
                out.write(b'},"vertices":[')
                self._write_vertices(out, translate)
                out.write(b"]}\n")
        except BaseException:
            self.abort()
            raise
        shutil.rmtree(self._tmp, ignore_errors=True)
        self._state = "closed"
        self._counts = {"buildings": self._buildings, "vertices": self._n_vertices, "triangles": self._triangles,
                        "instances": self._rows}
        return dict(self._counts)

    def _write_vertices(self, out, translate: np.ndarray) -> None:
        """The spooled vertices as integer triples, ``_BLOCK`` at a time."""
        with open(self._tmp / "vertices.bin", "rb") as spool:
            first = True
            while block := spool.read(_BLOCK * 24):
                ints = np.rint((np.frombuffer(block, np.float64).reshape(-1, 3) - translate) / SCALE).astype(np.int64)
                out.write((b"" if first else b",") + orjson.dumps(ints, option=orjson.OPT_SERIALIZE_NUMPY)[1:-1])
                first = False

    def abort(self) -> None:
        """Drop the spools; a file already at ``path`` is left untouched."""
        if self._state == "open":
            self._state = "aborted"
            self._objects.close()
            self._vertices.close()
            shutil.rmtree(self._tmp, ignore_errors=True)


def _unique_rows(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of ``keys`` (n, k) in lexicographic order, and each row's place among them:
    ``np.unique(keys, axis=0, return_inverse=True)`` by a sort of the columns, far faster than its sort of
    rows as opaque bytes."""
    order = np.lexsort(keys.T[::-1])
    ordered = keys[order]
    new = np.ones(len(order), bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    inverse = np.empty(len(order), np.int64)
    inverse[order] = np.cumsum(new) - 1
    return ordered[new], inverse


def _surface_kinds(world: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(T,) int64: each triangle's semantic surface (a code of ``SURFACES``) by its normal (world y up)."""
    a, b, c = (world[faces[:, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    up = normal[:, 1] / np.maximum(np.linalg.norm(normal, axis=1), 1e-300)
    return np.where(up > _UP, 0, np.where(up < -_UP, 2, 1)).astype(np.int64)


def _building_names(lots: Lots | None):
    """The CityObject id of a lot number: its id (with ``#<number>`` where ids repeat: CityObjects' keys are
    unique), else ``lot<number>``."""
    ids = np.asarray(lots.ids if lots is not None else [], dtype=str)
    values, counts = np.unique(ids, return_counts=True)
    repeated = set(values[counts > 1].tolist())
    by_number = dict(zip(lots.index.tolist(), ids.tolist())) if lots is not None else {}

    def name(lot: int) -> str:
        given = by_number.get(lot)
        if given is None:
            return f"lot{lot}"
        return f"{given}#{lot}" if given in repeated else given
    return name


def _attribute_rows(lots: Lots | None):
    """A lot number's attributes as a JSON object: its properties that have a value (numbers and text)."""
    if lots is None or not lots.attrs:
        return lambda lot: {}
    position = {number: k for k, number in enumerate(lots.index.tolist())}
    columns = {name: np.asarray(column) for name, column in lots.attrs.items()}

    def row(lot: int) -> dict:
        k = position.get(lot)
        if k is None:
            return {}
        out = {}
        for name, column in columns.items():
            value = column[k]
            if value is None or (isinstance(value, float) and math.isnan(value)):
                continue
            out[name] = value.item() if isinstance(value, np.generic) else value
        return out
    return row


def _metadata(meta: dict) -> dict:
    """CityJSON's ``metadata``: the reference system where the lots had one with an EPSG code, and what
    made the file."""
    out = {"title": f"{Path(str(meta.get('grammar', 'city'))).stem}, derived by grammarc {meta.get('grammarc', '')}"
           .strip()}
    crs = meta.get("crs")
    if isinstance(crs, str) and crs.upper().startswith("EPSG:"):
        out["referenceSystem"] = f"https://www.opengis.net/def/crs/EPSG/0/{crs.split(':', 1)[1]}"
    return out


#: The extension this module writes (``grammarc.io.writers``).
WRITERS = {".json": CityJsonWriter}
