"""The content of a 3D Tiles tile: a GLB with GPU instancing whose instances and polygons name their lot.

A leaf tile is what ``io.gltf`` writes of one tile of the city (an asset per mesh, a node per (asset,
colour) group carrying its instances in ``EXT_mesh_gpu_instancing``, the mesh table's polygons as one mesh)
plus its features, so that a viewer can say what was clicked:

* ``EXT_structural_metadata`` on the root: a schema of the classes ``lot`` (its id, its number in the
  input and the lots file's attributes of the build, one property each), ``symbol`` (the shape's symbol
  name) and ``mass`` (below), and two property tables: the tile's lots (one row per lot with rows in the
  tile, in the order of their numbers) and the record's symbols;
* ``EXT_instance_features`` on each instancing node: the feature IDs of its instances, ``_FEATURE_ID_0``
  (the row of the lot table) and ``_FEATURE_ID_1`` (the symbol), extra attributes of its
  ``EXT_mesh_gpu_instancing``;
* ``EXT_mesh_features`` on the polygons' primitives: the same two feature IDs per vertex.

Feature IDs are FLOAT accessors (exact to 2^24: glTF has no 32-bit integer vertex attributes), as the
extension's specification advises. Property values follow the 3D Metadata binary table format: each column
a buffer view aligned to 8 bytes, strings as UTF-8 bytes with a UINT32 offset per row and one past the end.

A coarse tile (``add_boxes``) is one node instancing a unit cube with a translation, a scale and a colour
(``_COLOR_0``, linear RGB) per box; a box of one lot has that lot's feature (a table of its lots), a mass of
merged lots its own (a ``mass`` table: how many lots, how high).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from grammarc.io.gltf import ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, INSTANCING, GlbPart
from grammarc.io.instancing import Tile
from grammarc.model.lots import Lots

__all__ = ["LotTable", "TileContent", "linear_rgb"]

INSTANCE_FEATURES = "EXT_instance_features"
MESH_FEATURES = "EXT_mesh_features"
METADATA = "EXT_structural_metadata"
#: The unit cube of box tiles: corners and triangles (outward, counter-clockwise).
_CUBE_VERTICES = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], np.float32)
_CUBE_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], np.uint32)
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def linear_rgb(rgb: np.ndarray) -> np.ndarray:
    """(n, 3) float32 linear colours of sRGB bytes (glTF's colours are linear)."""
    srgb = np.asarray(rgb, np.float64) / 255.0
    return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4).astype(np.float32)


class LotTable:
    """The build's lots as property table rows: a lot number's id and attributes (``Lots.attrs``), and the
    schema of the ``lot`` class. Without lots (a record written again) a lot's id is ``lot<number>``."""

    def __init__(self, lots: Lots | None):
        self.names: dict[str, str] = {}  # property id -> the attribute's name in the lots file
        self.columns: dict[str, np.ndarray] = {}
        self._position = np.zeros(0, np.int64)
        self._ids = np.zeros(0, object)
        if lots is not None and len(lots):
            self._position = np.full(int(lots.index.max()) + 1, -1, np.int64)
            self._position[lots.index] = np.arange(len(lots))
            self._ids = np.asarray(lots.ids, object)
            for name, column in lots.attrs.items():
                key = _identifier(name, set(self.names) | {"id", "number"})
                self.names[key] = name
                self.columns[key] = np.asarray(column)

    def schema(self) -> dict:
        """The ``lot`` and ``symbol`` classes."""
        properties = {"id": {"type": "STRING", "description": "the lot's id in the lots file"},
                      "number": {"type": "SCALAR", "componentType": "INT32",
                                 "description": "the lot's number in the lots file, from 0"}}
        for key, column in self.columns.items():
            kind = ({"type": "SCALAR", "componentType": "FLOAT64"} if column.dtype.kind == "f"
                    else {"type": "STRING"})
            properties[key] = {**kind, "name": self.names[key]}
        return {"id": "grammarc", "classes": {
            "lot": {"name": "Lot", "description": "a lot (initial shape) of the build", "properties": properties},
            "symbol": {"name": "Symbol", "description": "the rule symbol a shape had when it became a leaf",
                       "properties": {"name": {"type": "STRING"}}},
            "mass": {"name": "Mass", "description": "lots merged into one box for the far view",
                     "properties": {"lots": {"type": "SCALAR", "componentType": "INT32",
                                             "description": "the lots merged"},
                                    "height": {"type": "SCALAR", "componentType": "FLOAT64",
                                               "description": "their mean height weighted by footprint (m)"}}}}}

    def rows(self, numbers: np.ndarray) -> dict[str, np.ndarray]:
        """The property columns of lots ``numbers`` (k,): ``id`` (str), ``number`` (int32), attributes."""
        numbers = np.asarray(numbers, np.int64)
        at = np.full(len(numbers), -1, np.int64)  # their rows of the lots, -1 for a lot not among them
        inside = numbers < len(self._position)
        at[inside] = self._position[numbers[inside]]
        ids = np.array([f"lot{n}" for n in numbers.tolist()], object)
        if (at >= 0).any():
            ids[at >= 0] = self._ids[at[at >= 0]]
        out = {"id": ids, "number": numbers.astype(np.int32)}
        for key, column in self.columns.items():
            out[key] = np.where(at >= 0, column[np.maximum(at, 0)], np.nan if column.dtype.kind == "f" else None)
        return out


def _identifier(name: str, taken: set[str]) -> str:
    """A property id for an attribute name: its characters outside ``[A-Za-z0-9_]`` as ``_``, a ``_`` before
    a leading digit, and a number after it where that id is taken."""
    key = re.sub(r"[^A-Za-z0-9_]", "_", name) or "_"
    if not _IDENTIFIER.fullmatch(key):
        key = "_" + key
    base, k = key, 1
    while key in taken:
        key, k = f"{base}_{k}", k + 1
    return key


class TileContent(GlbPart):
    """One tile's GLB (``io.gltf``'s part) with the features of its instances and polygons.

    ``add_tile`` (a leaf) or ``add_boxes`` (a coarse tile) once, then ``finish``. Feature ID set ``k`` of a
    node or primitive is its ``_FEATURE_ID_k`` attribute and reads property table ``k``: a leaf's are the
    lots and the symbols, a coarse tile's its lots or its masses.
    """

    def __init__(self, binary: Path, library, meta: dict, colormap, lots: LotTable, symbols: list[str]):
        super().__init__(binary, library, meta, colormap)
        self.lots = lots
        self.symbols = symbols
        self._lot_row = np.zeros(0, np.int64)  # a lot number -> its row of this tile's lot table
        self._tables: list[tuple[str, dict[str, np.ndarray]]] = []  # (class, columns) of each property table

    # --------------------------------------------------------------------------------- leaf tiles

    def add_tile(self, tile: Tile, max_bytes: int) -> bool:
        """The tile's nodes (``io.gltf``) with feature IDs, and its two property tables."""
        numbers = np.unique(np.concatenate([tile.instances["lot"], tile.triangles["lot"]]).astype(np.int64))
        self._tables = [("lot", self._lot_columns(numbers)), ("symbol", {"name": np.array(self.symbols, object)})]
        return super().add_tile(tile, max_bytes)

    def _describe_instances(self, node: dict, tile: Tile, members: np.ndarray) -> None:
        attributes = node["extensions"][INSTANCING]["attributes"]
        rows = tile.instances
        for k, ids in enumerate((self._lot_row[rows["lot"][members]], rows["symbol"][members])):
            attributes[f"_FEATURE_ID_{k}"] = self._accessor(ids.astype(np.float32), "SCALAR")
        node["extensions"][INSTANCE_FEATURES] = {"featureIds": self._feature_sets()}

    def _describe_polygons(self, primitives: list[dict], tile: Tile) -> None:
        triangles = tile.triangles
        attributes = primitives[0]["attributes"]  # the primitives share their attributes
        for k, ids in enumerate((self._lot_row[triangles["lot"]], triangles["symbol"])):
            attributes[f"_FEATURE_ID_{k}"] = self._accessor(np.repeat(ids, 3).astype(np.float32), "SCALAR",
                                                            ARRAY_BUFFER)
        for primitive in primitives:
            primitive["extensions"] = {MESH_FEATURES: {"featureIds": self._feature_sets()}}

    # -------------------------------------------------------------------------------- coarse tiles

    def add_boxes(self, low: np.ndarray, size: np.ndarray, rgb: np.ndarray, lots: np.ndarray | None = None,
                  merged: np.ndarray | None = None) -> None:
        """One node instancing a unit cube: box ``i`` from ``low[i]`` (n, 3) float32, relative to the tile's
        node, of ``size[i]`` (n, 3), colour ``rgb[i]`` (n, 3) uint8; its feature is its lot (``lots`` (n,):
        lot numbers) or its mass (``merged`` (n,): the number of lots merged into each box)."""
        position = self._accessor(_CUBE_VERTICES, "VEC3", ARRAY_BUFFER, bounds=True)
        indices = self._accessor(_CUBE_FACES.reshape(-1), "SCALAR", ELEMENT_ARRAY_BUFFER)
        self.json["meshes"].append({"name": "box", "primitives": [
            {"attributes": {"POSITION": position}, "indices": indices,
             "material": self._material((255, 255, 255, 255))}]})
        attributes = {"TRANSLATION": self._accessor(np.asarray(low, np.float32), "VEC3"),
                      "SCALE": self._accessor(np.asarray(size, np.float32), "VEC3"),
                      "_COLOR_0": self._accessor(linear_rgb(rgb), "VEC3")}
        if lots is not None:
            self._tables = [("lot", self._lot_columns(np.unique(lots)))]
            ids = self._lot_row[lots]
        else:
            self._tables = [("mass", {"lots": np.asarray(merged, np.int32),
                                      "height": np.asarray(size, np.float64)[:, 1]})]
            ids = np.arange(len(low))
        attributes["_FEATURE_ID_0"] = self._accessor(ids.astype(np.float32), "SCALAR")
        self.json["nodes"].append({"name": "boxes", "mesh": 0, "extensions": {
            INSTANCING: {"attributes": attributes}, INSTANCE_FEATURES: {"featureIds": self._feature_sets()}}})
        self.json["scenes"][0]["nodes"].append(len(self.json["nodes"]) - 1)

    # ------------------------------------------------------------------------------------ features

    def finish(self, out: Path, sync: bool = True) -> None:
        """The property tables and the extensions' names, then the GLB (``io.gltf``)."""
        used = {INSTANCING}
        if self._tables:
            self.json.setdefault("extensions", {})[METADATA] = {
                "schema": self.lots.schema(),
                "propertyTables": [self._table(name, columns) for name, columns in self._tables]}
            used |= {METADATA, INSTANCE_FEATURES}
            if any(MESH_FEATURES in p.get("extensions", {}) for m in self.json["meshes"] for p in m["primitives"]):
                used.add(MESH_FEATURES)
        self.json["extensionsUsed"] = sorted(used)
        super().finish(out, sync)

    def _lot_columns(self, numbers: np.ndarray) -> dict[str, np.ndarray]:
        """The lot table of lots ``numbers`` (ascending), and each lot's row of it in ``_lot_row``."""
        numbers = np.asarray(numbers, np.int64)
        self._lot_row = np.full(int(numbers.max()) + 1 if len(numbers) else 0, -1, np.int64)
        self._lot_row[numbers] = np.arange(len(numbers))
        return self.lots.rows(numbers)

    def _feature_sets(self) -> list[dict]:
        """Feature ID set ``k``: attribute ``_FEATURE_ID_k``, property table ``k``."""
        return [{"featureCount": len(next(iter(columns.values()))), "attribute": k, "propertyTable": k,
                 "label": name} for k, (name, columns) in enumerate(self._tables)]

    def _table(self, name: str, columns: dict[str, np.ndarray]) -> dict:
        """A property table of class ``name``: each column's values (and string offsets) in buffer views."""
        properties = {}
        for key, values in columns.items():
            if values.dtype == object:  # strings (None: "")
                data = [("" if v is None else str(v)).encode("utf-8") for v in values.tolist()]
                offsets = np.concatenate([[0], np.cumsum([len(b) for b in data])]).astype(np.uint32)
                properties[key] = {"values": self._aligned(np.frombuffer(b"".join(data) or b"\0", np.uint8)),
                                   "stringOffsets": self._aligned(offsets), "stringOffsetType": "UINT32"}
            else:
                properties[key] = {"values": self._aligned(values)}
        return {"class": name, "count": len(next(iter(columns.values()))), "properties": properties}

    def _aligned(self, data: np.ndarray) -> int:
        """A buffer view of ``data`` starting at a multiple of 8 bytes, as property tables need."""
        pad = -self.size % 8
        self.binary.write(b"\0" * pad)
        self.size += pad
        return self._view(np.ascontiguousarray(data))
