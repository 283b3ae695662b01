"""3D Tiles 1.1: ``--emit city.3dtiles``, a folder that a browser streams (``grammarc view``).

The layout::

    city.3dtiles/tileset.json             the tree of tiles (explicit tiling), its bounding boxes and errors
    city.3dtiles/tiles/tile_3_m2.glb      a leaf: the city's instances and polygons in one square tile
    city.3dtiles/tiles/L2_0_1.glb         a coarse tile: boxes standing for the lots, or masses of lots

* **Leaves** are the squares of ``io.instancing`` (``--tile-size``, 250 m by default here: a browser loads
  a leaf at a time), each a GLB as ``io.gltf`` writes a tile (the assets as shared meshes, instanced with
  ``EXT_mesh_gpu_instancing``, the mesh table's polygons as one mesh) with the features of its instances
  and polygons (``io.tile_content``: the lot id, number and attributes, and the symbol, for a click).
* **The quadtree** over the leaves: a node of level ``k`` covers ``2^k x 2^k`` leaves, up to the root that
  covers the city's footprint. A node of level 1 holds a box per lot (the bounding box of the lot's
  instances and polygons, in their mean colour), a node of level ``k >= 2`` merged masses: the lots whose
  box centres fall in one cell of ``2^k * tile_size / 32`` metres become one box spanning their boxes,
  as high as their mean height weighted by footprint (so a tower does not raise a block); a click on a
  mass tells how many lots it merges (its feature, ``io.tile_content``). A node's
  geometric error is that cell edge (``2^k * tile_size / 32``; a box of a lot at level 1), a leaf's 0,
  so a viewer refines the masses into boxes and the boxes into the buildings as the camera comes
  nearer; children replace their parent (``REPLACE``).
* **Frames**: 3D Tiles is z up and its glTF content y up (the runtime turns it), and grammarc's world is y
  up with z south, so a glTF node is at world coordinates and a bounding box at (x, -z, y). Everything is
  relative to a reference point near the middle of the city (the corner of its middle leaf), float64 in
  the JSON, so float32 positions stay exact. Where the lots had a coordinate system (``meta["crs"]``) the
  root's ``transform`` takes that frame to Earth-centred coordinates (EPSG:4978): its columns are the
  directions of the CRS's easting, northing and height at the reference point (with the projection's scale
  and grid convergence, from pyproj) and the point itself; a local scene has no transform.

Writing streams as the other tiled writers do (``TiledWriter``): the chunks are sorted into tile spools,
and ``close`` writes one leaf at a time, so memory follows the largest tile, plus a box per lot (6 floats)
for the coarse levels. The folder is made beside the output and renamed onto it when complete; an older
folder at the path is moved away first and removed, so the path holds the old tileset or the new one, whole.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import ClassVar

import numpy as np

from grammarc.constants import LIMITS
from grammarc.errors import UsageError
from grammarc.io.gltf import INSTANCING, MAX_BYTES
from grammarc.io.instancing import Tile, TiledWriter, compose
from grammarc.io.tile_content import METADATA, LotTable, TileContent
from grammarc.model.lots import Lots

__all__ = ["LEAF_SIZE", "WRITERS", "TilesetWriter", "ecef_frame", "read_tileset", "write_record"]

#: Default leaf edge (metres) of a tileset.
LEAF_SIZE = LIMITS.leaf_size
#: A coarse node's cells per edge: its merged masses are ``edge / _CELLS`` wide, which is its geometric error.
_CELLS = 32
#: The smallest half extent of a bounding box (metres): a flat city still has a box with volume.
_THIN = 0.005


class TilesetWriter(TiledWriter):
    """Streams TerminalChunks into tiles and writes the tileset folder on ``close`` (``TiledWriter``).

    Parameters
    ----------
    path : str or os.PathLike
        The folder, ``.3dtiles``. Its parent must exist.
    assets, symbols, meta, asset_roots, lod
        As ``io.gltf.GltfWriter``'s; ``meta["crs"]`` georeferences the tileset.
    tile_size : float
        Edge of a leaf in metres.
    lots : Lots, optional
        The build's lots: the features' ids and attributes. Without them a lot is ``lot<number>``.
    """

    #: The output is a folder (``io.written_paths``).
    folder: ClassVar[bool] = True

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str], meta: dict,
                 asset_roots: Sequence[str | os.PathLike] | None = None, tile_size: float = LEAF_SIZE,
                 lod: str | None = None, lots: Lots | None = None):
        if Path(path).suffix.lower() != ".3dtiles":
            raise UsageError(f"cannot write `{path}` as 3D Tiles: give a folder name ending in .3dtiles")
        super().__init__(path, assets=assets, meta=meta, asset_roots=asset_roots, tile_size=tile_size, lod=lod)
        self._symbols = [str(s) for s in symbols]
        self._lots = LotTable(lots)

    def _finish(self) -> dict:
        staged = self._tmp / "tileset"
        (staged / "tiles").mkdir(parents=True)
        size = self._spool.tile_size
        keys = np.array(sorted(self._spool.keys), np.int64).reshape(-1, 2)
        first = keys.min(axis=0) if len(keys) else np.zeros(2, np.int64)
        span = int((keys.max(axis=0) - first).max()) + 1 if len(keys) else 1
        depth = int(np.ceil(np.log2(span))) if span > 1 else 0
        # the reference point: the corner of the middle leaf (world, y up)
        middle = (first + (keys.max(axis=0) if len(keys) else first)) // 2
        reference = np.array([middle[0] * size, 0.0, middle[1] * size])
        boxes = _LotBoxes()
        nodes: dict[tuple[int, int, int], dict] = {}
        for tile in self._spool.tiles():
            key = (0, tile.key[0] - int(first[0]), tile.key[1] - int(first[1]))
            nodes[key] = self._write_leaf(staged, replace(tile, origin=tile.origin - reference), boxes)
        corner = np.array([first[0] * size, first[1] * size]) - reference[[0, 2]]
        for level in range(1, depth + 1):
            self._write_level(staged, level, corner, span * size, boxes, nodes)
        root = _tree(nodes, depth, size)
        frame = ecef_frame(self._meta["crs"], reference) if self._meta.get("crs") else None
        if frame is not None:
            root["transform"] = frame
        made_by = f"grammarc {self._meta.get('grammarc', '')}".strip()
        tileset = {"asset": {"version": "1.1", "extras": {"generator": made_by}},
                   "geometricError": 2 * _error(max(depth, 1), size),
                   "root": root,
                   "extras": {"grammarc": self._meta, "crs": self._meta.get("crs"),
                              "reference": reference.tolist(), "symbols": self._symbols}}
        with open(staged / "tileset.json", "w", encoding="utf-8") as out:
            json.dump(tileset, out, separators=(",", ":"))
        _sync(path for path in staged.rglob("*") if path.is_file())
        if self.path.exists() or self.path.is_symlink():
            os.replace(self.path, self._tmp / "previous")  # removed with the temporary folder
        os.replace(staged, self.path)
        return {"contents": sum(1 for node in nodes.values() if node.get("uri")), "levels": depth + 1}

    def _content(self) -> TileContent:
        return TileContent(self._tmp / "content.bin", self._library, self._meta, self._colormap, self._lots,
                           self._symbols)

    def _write_leaf(self, staged: Path, tile: Tile, boxes: _LotBoxes) -> dict:
        """A leaf's GLB (``tile.origin`` relative to the reference point); its node (uri, box)."""
        content = self._content()
        if not content.add_tile(tile, MAX_BYTES):
            raise UsageError(f"{self.path}: tile {tile.name} passes {MAX_BYTES:,} bytes; give a smaller --tile-size")
        uri = f"tiles/{tile.name}.glb"
        content.finish(staged / uri, sync=False)
        low, high, lots, rgb = _tile_boxes(tile)
        boxes.add(lots, low + tile.origin, high + tile.origin, rgb)
        return {"uri": uri, "box": _bounds(low + tile.origin, high + tile.origin)}

    def _write_level(self, staged: Path, level: int, corner: np.ndarray, extent: float, boxes: _LotBoxes,
                     nodes: dict[tuple[int, int, int], dict]) -> None:
        """The coarse nodes of ``level``: boxes (level 1) or merged masses, grouped by node; ``corner``: the
        (x, z) of the quadtree's corner relative to the reference point, ``extent`` its edge."""
        edge = self._spool.tile_size * 2 ** level
        lots, low, high, rgb = boxes.lots()
        if not len(lots):
            return
        # where each box's centre is in the quadtree (a box may reach out of the leaves of its rows)
        offset = np.clip(0.5 * (low + high)[:, [0, 2]] - corner, 0.0, np.nextafter(extent, 0.0))
        if level == 1:
            node_of = np.floor(offset / edge).astype(np.int64)
            merged = None
        else:
            cells = np.floor(offset / (edge / _CELLS)).astype(np.int64)
            low, high, rgb, merged, cells = _masses(cells, low, high, rgb)
            node_of = cells // _CELLS
        packed = (node_of[:, 0] << 32) | node_of[:, 1]
        order = np.argsort(packed, kind="stable")
        starts = np.flatnonzero(np.r_[True, packed[order][1:] != packed[order][:-1]])
        for begin, end in zip(starts, [*starts[1:], len(order)]):
            rows = order[begin:end]
            key = (level, int(node_of[rows[0], 0]), int(node_of[rows[0], 1]))
            content = self._content()
            if merged is None:
                content.add_boxes(low[rows], high[rows] - low[rows], rgb[rows], lots=lots[rows])
            else:
                content.add_boxes(low[rows], high[rows] - low[rows], rgb[rows], merged=merged[rows])
            uri = f"tiles/L{level}_{key[1]}_{key[2]}.glb"
            content.finish(staged / uri, sync=False)
            nodes[key] = {"uri": uri, "box": _bounds(low[rows].min(axis=0), high[rows].max(axis=0))}


#: The extension this module writes (``grammarc.io.writers``): a folder.
WRITERS = {".3dtiles": TilesetWriter}


def _sync(paths) -> None:
    """fsync the files ``paths`` before the folder is renamed into place, many at once, so that the file
    system commits them together rather than one journal commit per tile."""
    def sync(path: Path) -> None:
        with open(path, "rb") as file:
            os.fsync(file.fileno())

    with ThreadPoolExecutor(max_workers=16) as pool:
        list(pool.map(sync, paths))


def _error(level: int, size: float) -> float:
    """The geometric error of a node of ``level`` (0: a leaf) of leaves ``size`` metres wide."""
    return 0.0 if level == 0 else size * 2 ** level / _CELLS


def _tile_boxes(tile: Tile) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The bounding boxes (low, high: (n, 3) float64, relative to the tile's origin), lots and RGB colours of
    a tile's instances (their unit boxes placed) and then its triangles."""
    xform = tile.instances["xform"].astype(np.float64)
    centre = xform[:, :, 3] + 0.5 * xform[:, :, :3].sum(axis=2)
    half = 0.5 * np.abs(xform[:, :, :3]).sum(axis=2)
    corners = tile.triangles["vertices"].astype(np.float64)
    low = np.concatenate([centre - half, corners.min(axis=1)])
    high = np.concatenate([centre + half, corners.max(axis=1)])
    lots = np.concatenate([tile.instances["lot"], tile.triangles["lot"]]).astype(np.int64)
    rgb = np.concatenate([tile.instances["color"][:, :3], tile.triangles["color"][:, :3]]).astype(np.float64)
    return low, high, lots, rgb


class _LotBoxes:
    """Each lot's bounding box (y up, relative to the reference point) and the sum of its rows' colours,
    grown as lots come."""

    def __init__(self):
        self.low = np.full((0, 3), np.inf)
        self.high = np.full((0, 3), -np.inf)
        self.rgb = np.zeros((0, 3))
        self.rows = np.zeros(0, np.int64)

    def add(self, lots: np.ndarray, low: np.ndarray, high: np.ndarray, rgb: np.ndarray) -> None:
        if not len(lots):
            return
        grow = int(lots.max()) + 1 - len(self.rows)
        if grow > 0:
            self.low = np.concatenate([self.low, np.full((grow, 3), np.inf)])
            self.high = np.concatenate([self.high, np.full((grow, 3), -np.inf)])
            self.rgb = np.concatenate([self.rgb, np.zeros((grow, 3))])
            self.rows = np.concatenate([self.rows, np.zeros(grow, np.int64)])
        np.minimum.at(self.low, lots, low)
        np.maximum.at(self.high, lots, high)
        np.add.at(self.rgb, lots, rgb)
        np.add.at(self.rows, lots, 1)

    def lots(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The lots with rows, their boxes' low and high corners and their mean colours (uint8)."""
        lots = np.flatnonzero(self.rows)
        rgb = np.rint(self.rgb[lots] / self.rows[lots, None]).astype(np.uint8)
        return lots, self.low[lots], self.high[lots], rgb


def _masses(cells: np.ndarray, low: np.ndarray, high: np.ndarray, rgb: np.ndarray):
    """Boxes merged by cell (``cells`` (n, 2) int64): each cell's box spans its boxes' footprints and rises
    from their lowest bottom by their heights' mean weighted by footprint area, in their colours' mean so
    weighted; returns low, high, rgb (uint8), the number of boxes merged and the cells, one row per cell in
    cell order."""
    packed = (cells[:, 0] << 32) | cells[:, 1]
    unique, first, group = np.unique(packed, return_index=True, return_inverse=True)
    group = group.reshape(-1)
    area = np.maximum((high[:, 0] - low[:, 0]) * (high[:, 2] - low[:, 2]), 1e-6)
    weight = np.bincount(group, area)
    out_low = np.full((len(unique), 3), np.inf)
    out_high = np.full((len(unique), 3), -np.inf)
    np.minimum.at(out_low, group, low)
    np.maximum.at(out_high, group, high)
    height = np.bincount(group, area * (high[:, 1] - low[:, 1])) / weight
    out_high[:, 1] = out_low[:, 1] + height
    colour = np.stack([np.bincount(group, area * rgb[:, c]) for c in range(3)], axis=1) / weight[:, None]
    return out_low, out_high, np.rint(colour).astype(np.uint8), np.bincount(group), cells[first]


def _bounds(low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The (low, high) of boxes' corners ``low`` and ``high`` (n, 3) or (3,), y up, at least ``2 * _THIN``
    thick (a tile of one flat facade still has a volume, which its parent's box then holds too)."""
    low = np.asarray(low, np.float64).reshape(-1, 3).min(axis=0)
    high = np.asarray(high, np.float64).reshape(-1, 3).max(axis=0)
    pad = np.maximum(_THIN - 0.5 * (high - low), 0.0)
    return low - pad, high + pad


def _tree(nodes: dict[tuple[int, int, int], dict], depth: int, size: float) -> dict:
    """The tileset's root tile: the nodes of every level, a parent over each 2 x 2 of its level below, with
    their contents, bounding boxes (each spanning its content and children) and geometric errors."""
    tiles: dict[tuple[int, int, int], dict] = {}
    spans: dict[tuple[int, int, int], tuple[np.ndarray, np.ndarray]] = {}
    for level in range(depth + 1):
        below = [key for key in tiles if key[0] == level - 1] if level else []
        keys = sorted({key for key in nodes if key[0] == level} | {(level, x >> 1, z >> 1) for _, x, z in below})
        for key in keys:
            children = [(level - 1, 2 * key[1] + a, 2 * key[2] + b) for a in (0, 1) for b in (0, 1)]
            children = [child for child in children if child in tiles] if level else []
            boxes = [spans[child] for child in children]
            if key in nodes:
                boxes.append(nodes[key]["box"])
            low = np.min([b[0] for b in boxes], axis=0)
            high = np.max([b[1] for b in boxes], axis=0)
            spans[key] = (low, high)
            tile = {"boundingVolume": {"box": _box(low, high)}, "geometricError": _error(level, size)}
            if key in nodes:
                tile["content"] = {"uri": nodes[key]["uri"]}
            if children:
                tile["children"] = [tiles.pop(child) for child in children]
            tiles[key] = tile
    if not tiles:  # an empty city: a root without content
        return {"boundingVolume": {"box": _box(*_bounds(np.zeros(3), np.zeros(3)))}, "geometricError": 0.0,
                "refine": "REPLACE"}
    (root,) = tiles.values()
    root["refine"] = "REPLACE"
    return root


def _box(low: np.ndarray, high: np.ndarray) -> list[float]:
    """3D Tiles' ``box`` (centre, then half axes x, y, z) of a y-up box, in the z-up frame (x, -z, y)."""
    centre, half = 0.5 * (low + high), 0.5 * (high - low)
    return [float(centre[0]), float(-centre[2]), float(centre[1]),
            float(half[0]), 0.0, 0.0, 0.0, float(half[2]), 0.0, 0.0, 0.0, float(half[1])]


def ecef_frame(crs: str, reference: np.ndarray) -> list[float]:
    """The 4 x 4 matrix (column-major, 3D Tiles' ``transform``) taking the z-up frame of a tileset whose
    reference point is ``reference`` (world: easting, height, -northing, in ``crs``) to Earth-centred
    coordinates (EPSG:4978): the CRS's easting, northing and up directions at the point, and the point."""
    try:
        from pyproj import CRS, Transformer
    except ImportError as error:
        raise UsageError("a georeferenced 3D Tiles tileset needs pyproj: pip install 'grammarc[gis]' "
                         "(or pip install pyproj)") from error
    to_degrees = Transformer.from_crs(CRS.from_user_input(crs), "EPSG:4326", always_xy=True)
    to_ecef = Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
    easting, height, northing = float(reference[0]), float(reference[1]), -float(reference[2])

    def ecef(de: float, dn: float, dh: float) -> np.ndarray:
        lon, lat = to_degrees.transform(easting + de, northing + dn)
        return np.array(to_ecef.transform(lon, lat, height + dh))

    axes = [(ecef(*step) - ecef(*(-s for s in step))) / 2 for step in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    matrix = np.eye(4)
    matrix[:3, 0], matrix[:3, 1], matrix[:3, 2], matrix[:3, 3] = *axes, ecef(0, 0, 0)
    return [float(v) for v in matrix.T.reshape(-1)]


def write_record(record: dict, path: str | os.PathLike, lod: str | None = None) -> dict:
    """Write a record (``io.npz.read_instances``) as a tileset at ``path``; the writer's counts. The lots
    file is not at hand: a lot's features are its number, as ``lot<number>``."""
    from grammarc.io.npz import record_chunks

    with TilesetWriter(path, assets=record["assets"], symbols=record["symbols"], meta=record["meta"],
                       lod=lod) as writer:
        for chunk in record_chunks(record):
            writer.write(chunk)
        return writer.close()


def read_tileset(path: str | os.PathLike) -> dict:
    """The instances of a tileset written by ``TilesetWriter``, as a record dict (``io.npz.read_instances``'s
    keys that a tileset keeps: assets, asset, xform (float64, world), lot, symbol, symbols, the mesh table as
    triangles with their lots and symbols, meta), read from its leaves; grouped by leaf and (asset, colour),
    not in the record's order."""
    from grammarc.io.gltf import _accessor, _read_part

    folder = Path(path)
    tileset = json.loads((folder / "tileset.json").read_text(encoding="utf-8"))
    reference = np.array(tileset["extras"]["reference"], np.float64)
    names: dict[str, int] = {}
    columns: dict[str, list] = {"asset": [], "xform": [], "lot": [], "symbol": [], "vertices": [],
                                "mesh_lot": [], "mesh_symbol": []}
    leaves = [tile["content"]["uri"] for tile in _walk(tileset["root"])
              if tile["geometricError"] == 0 and "content" in tile]
    for uri in leaves:
        tree, blob = _read_part(folder / uri)
        numbers = _lot_numbers(tree, blob)
        for root in tree["scenes"][0]["nodes"]:
            corner = np.array(tree["nodes"][root]["translation"], np.float64) + reference
            for child in tree["nodes"][root]["children"]:
                node = tree["nodes"][child]
                instancing = node.get("extensions", {}).get(INSTANCING)
                if instancing is None:  # the leaf's polygons: a lot and a symbol per vertex
                    attributes = tree["meshes"][node["mesh"]]["primitives"][0]["attributes"]
                    columns["vertices"].append(_accessor(tree, blob, attributes["POSITION"]) + corner)
                    columns["mesh_lot"].append(numbers[_accessor(tree, blob, attributes["_FEATURE_ID_0"])[::3]
                                                       .astype(np.int64)])
                    columns["mesh_symbol"].append(_accessor(tree, blob, attributes["_FEATURE_ID_1"])[::3])
                    continue
                attributes = instancing["attributes"]
                t, r, s = (_accessor(tree, blob, attributes[k]) for k in ("TRANSLATION", "ROTATION", "SCALE"))
                columns["xform"].append(compose(t.astype(np.float64) + corner, r, s))
                mesh = tree["meshes"][node["mesh"]]["name"]
                columns["asset"].append(np.full(len(t), names.setdefault(mesh, len(names)), np.int32))
                columns["lot"].append(numbers[_accessor(tree, blob, attributes["_FEATURE_ID_0"]).astype(np.int64)])
                columns["symbol"].append(_accessor(tree, blob, attributes["_FEATURE_ID_1"]))
    record = {key: np.concatenate(values) if values else np.zeros(0) for key, values in columns.items()}
    vertices = record.pop("vertices").reshape(-1, 3).astype(np.float64)
    record.update(
        assets=np.array(list(names)), xform=record["xform"].reshape(-1, 3, 4),
        asset=record["asset"].astype(np.int32), lot=record["lot"].astype(np.int32),
        symbol=record["symbol"].astype(np.int32), symbols=np.array(tileset["extras"]["symbols"]),
        meta=tileset["extras"]["grammarc"], mesh_vertices=vertices,
        mesh_ring_offsets=np.arange(0, len(vertices) + 1, 3), mesh_face_offsets=np.arange(len(vertices) // 3 + 1),
        mesh_lot=record["mesh_lot"].astype(np.int32), mesh_symbol=record["mesh_symbol"].astype(np.int32))
    return record


def _walk(tile: dict):
    """``tile`` and every tile under it."""
    yield tile
    for child in tile.get("children", []):
        yield from _walk(child)


def _lot_numbers(tree: dict, blob: bytes) -> np.ndarray:
    """The lot numbers of a leaf's lot table (property table 0), by row."""
    table = tree["extensions"][METADATA]["propertyTables"][0]
    view = tree["bufferViews"][table["properties"]["number"]["values"]]
    return np.frombuffer(blob, np.int32, view["byteLength"] // 4, view.get("byteOffset", 0)).astype(np.int64)
