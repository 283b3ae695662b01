"""glTF with GPU instancing: ``--emit city.glb`` (``--bake`` writes a baked mesh instead, ``io/bake.py``).

One binary glTF (GLB) whose scene has a node per tile of the city (``io.instancing``), translated to
the tile's corner (JSON numbers: exact), and under it a node per (asset, colour) group carrying the
group's instances in ``EXT_mesh_gpu_instancing``: ``TRANSLATION``, ``ROTATION`` and ``SCALE``
accessors, float32 relative to the tile. Each asset is one mesh of the file, in its unit box (as
``model.assets`` loads it); each colour is a material whose ``baseColorFactor`` is the record's colour
(converted from sRGB to glTF's linear factors), so colours show in any viewer. Where the record has
textures, groups are by (asset, material, colour), and a material's colour map (found in the asset
roots, PNG or JPEG) is embedded as its ``baseColorTexture``. A tile with more than
``MAX_GROUPS`` (asset, colour) groups, which a grammar colouring each shape at random makes, groups by
asset only and draws them white: a node per colour would make the file a node per instance. Normals are
left out: viewers compute flat normals, which is what the assets' polygons are. The mesh table's
polygons are triangulated into one mesh per tile with per-vertex colours (``COLOR_0``) and, where the record
has them, the texture coordinates of set 0 (``TEXCOORD_0``, v down the image as glTF has it), which the
colour maps of its materials read.

The extension is listed in ``extensionsUsed`` but not required: a viewer without it (trimesh, at the
time of writing, among them) still opens the file and shows each group's mesh once.

GLB keeps sizes in 32-bit fields, so a file holds at most 4 GiB. Tiles are written one at a time into a
part's binary chunk; a tile that would pass ``max_bytes`` starts a new part. One part is ``city.glb``;
more are ``city.glb``, ``city.1.glb``, ... with ``city.glb.json`` listing them. Memory is bounded by a
tile (the binary chunk goes to a temporary file, and the JSON is small), and nothing is moved into
place before every part is complete: then the parts after the first, the index, and ``city.glb`` last;
an earlier build's index or parts that the new output does not have are removed.
"""

from __future__ import annotations

import glob
import json
import os
import re
import shutil
import struct
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from grammarc.errors import UsageError
from grammarc.io.instancing import TILE_SIZE, Tile, TiledWriter, compose, decompose
from grammarc.ir.asset_names import locate

__all__ = [
    "ARRAY_BUFFER", "ELEMENT_ARRAY_BUFFER", "INSTANCING", "MAX_BYTES", "MAX_GROUPS", "WRITERS", "GlbPart", "GltfWriter",
    "baked_glb", "index_path", "part_paths", "read_glb", "written_parts",
]

#: GLB's 32-bit length fields, less room for the JSON chunk.
MAX_BYTES = (1 << 32) - (64 << 20)
#: (asset, colour) groups of a tile beyond which it groups by asset only (module docstring).
MAX_GROUPS = 256
INSTANCING = "EXT_mesh_gpu_instancing"
_FLOAT, _UINT, _UBYTE = 5126, 5125, 5121
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
_WHITE = (255, 255, 255, 255)
#: The image formats glTF's core takes for textures, by file ending.
_IMAGE_TYPES = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}


def index_path(path: str | os.PathLike) -> Path:
    """The index of a GLB written in parts: ``city.glb`` -> ``city.glb.json``."""
    path = Path(path)
    return path.with_name(path.name + ".json")


def written_parts(path: str | os.PathLike) -> list[Path]:
    """The part files of a GLB as ``GltfWriter`` wrote it: those its index lists, else the file alone."""
    path, index = Path(path), index_path(path)
    return [path.with_name(name) for name in json.loads(index.read_text())["parts"]] if index.exists() else [path]


def part_paths(path: str | os.PathLike, parts: int) -> list[Path]:
    """The files of a GLB written in ``parts`` parts: ``city.glb``, ``city.1.glb``, ..."""
    path = Path(path)
    return [path] + [path.with_name(f"{path.stem}.{k}{path.suffix}") for k in range(1, parts)]


class GltfWriter(TiledWriter):
    """Streams TerminalChunks into tiles and writes the instanced GLB on ``close`` (``TiledWriter``).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.glb`` file. Its directory must exist.
    assets, symbols : sequence of str
        The record's asset and symbol names.
    meta : dict
        Facts about the run, kept in ``asset.extras.grammarc``; its ``grammar`` and ``asset_roots`` give
        the asset roots when ``asset_roots`` is not given.
    asset_roots : sequence of path-like, optional
    tile_size : float
        Edge of a tile in metres.
    lod : str, optional
        Level of detail of the asset meshes (``model.assets.load_asset``).
    max_bytes : int
        The largest binary chunk of one part.
    """

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str], meta: dict,
                 asset_roots: Sequence[str | os.PathLike] | None = None, tile_size: float = TILE_SIZE,
                 lod: str | None = None, max_bytes: int = MAX_BYTES):
        if Path(path).suffix.lower() != ".glb":
            raise UsageError(f"cannot write `{path}` as instanced glTF: use .glb")
        super().__init__(path, assets=assets, meta=meta, asset_roots=asset_roots, tile_size=tile_size, lod=lod)
        self.max_bytes = int(max_bytes)

    @staticmethod
    def beside(path: Path) -> tuple[list[Path], list[Path]]:
        """The files written beside ``path`` (``io.written_paths``): the index, and the parts after the
        first, named as a ten-thousandth would be."""
        return [index_path(path), path.with_name(f"{path.stem}.9999{path.suffix}")], []

    def _finish(self) -> dict:
        """The parts (``parts`` in the counts), the index when there are several."""
        parts = [GlbPart(self._tmp / "part0.bin", self._library, self._meta, self._colormap)]
        for tile in self._spool.tiles():
            if not parts[-1].add_tile(tile, self.max_bytes):
                parts.append(GlbPart(self._tmp / f"part{len(parts)}.bin", self._library, self._meta, self._colormap))
                if not parts[-1].add_tile(tile, self.max_bytes):
                    raise UsageError(f"{self.path}: tile {tile.name} alone passes {self.max_bytes:,} bytes; "
                                     "give a smaller --tile-size")
        paths = part_paths(self.path, len(parts))
        staged = [self._tmp / f"part{k}.glb" for k in range(len(parts))]
        for part, out in zip(parts, staged):
            part.finish(out)
        for out, path in list(zip(staged, paths))[1:]:
            os.replace(out, path)
        if len(parts) > 1:
            index = self._tmp / "index.json"
            index.write_text(json.dumps({"parts": [p.name for p in paths],
                                         "instances": [p.instances for p in parts]}, indent=1))
            os.replace(index, index_path(self.path))
        else:
            index_path(self.path).unlink(missing_ok=True)  # an earlier build's, which would name its parts
        os.replace(staged[0], self.path)
        for stale in self.path.parent.glob(f"{glob.escape(self.path.stem)}.*{self.path.suffix}"):
            if stale not in paths and re.fullmatch(r"\d+", stale.name[len(self.path.stem) + 1:-len(self.path.suffix)]):
                stale.unlink()  # a part of an earlier build of more parts
        return {"parts": len(parts)}


#: The extension this module writes (``grammarc.io.writers``); ``--bake`` writes it with ``io.bake`` instead.
WRITERS = {".glb": GltfWriter}


class GlbPart:
    """One GLB file being built: its JSON lists and its binary chunk in a temporary file (``io.tile_content``
    makes a 3D Tiles tile's content of one)."""

    def __init__(self, binary: Path, library, meta: dict, colormap=lambda material: None):
        self.library = library
        #: material (a row of the writer's materials) -> its colour map file, or None
        self.colormap = colormap
        self.binary = open(binary, "w+b")  # noqa: SIM115 - closed by finish(), or with the temporary folder
        self.size = 0
        self.instances = 0
        self.json: dict = {
            "asset": {"version": "2.0", "generator": f"grammarc {meta.get('grammarc', '')}".strip(),
                      # world = a node's translation (double) + its positions; the world's coordinate system
                      "extras": {"grammarc": meta, "origin": [0.0, 0.0, 0.0], "crs": meta.get("crs")}},
            "extensionsUsed": [INSTANCING],
            "scene": 0, "scenes": [{"nodes": []}],
            "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
            "buffers": [{"byteLength": 0}],
        }
        self._assets: dict[int, tuple[int, int]] = {}  # asset -> (POSITION accessor, indices accessor)
        self._meshes: dict[tuple[int, int], int] = {}  # (asset, material) -> mesh
        self._materials: dict[tuple, int] = {}  # (RGBA, translucent, colour map) -> material
        self._textures: dict[Path, int | None] = {}  # image file -> texture (None: not an image glTF takes)

    def add_tile(self, tile: Tile, max_bytes: int) -> bool:
        """Add a tile's nodes, unless it would take the part past ``max_bytes`` (a part keeps at least
        one tile when it can): returns whether it was added."""
        groups = _groups(tile.instances, tile.instance_material)
        new_assets = {int(group[0]) for group in groups} - set(self._assets)
        need = (tile.instances.size * 40 + tile.triangles.size * 3 * 16
                + sum(self.library[a].vertices.size * 4 + self.library[a].faces.size * 4 + 8
                      for a in new_assets) + 64 * (len(groups) + 2))
        if self.size + need > max_bytes:
            return False
        nodes = []
        rows = tile.instances
        if len(rows):
            positions, orientations, scales = decompose(rows["xform"])
            for asset, color, material, members in groups:
                node = {
                    "name": self.library.names[asset],
                    "mesh": self._mesh(asset, color, self.colormap(material)),
                    "extensions": {INSTANCING: {"attributes": {
                        "TRANSLATION": self._accessor(positions[members], "VEC3"),
                        "ROTATION": self._accessor(orientations[members], "VEC4"),
                        "SCALE": self._accessor(scales[members], "VEC3"),
                    }}},
                }
                self._describe_instances(node, tile, members)
                nodes.append(node)
        if len(tile.triangles):
            nodes.append({"name": "mesh", "mesh": self._polygons(tile)})
        self.json["nodes"].extend(nodes)
        first = len(self.json["nodes"]) - len(nodes)
        self.json["nodes"].append({"name": tile.name, "translation": [float(v) for v in tile.origin],
                                   "children": list(range(first, first + len(nodes)))})
        self.json["scenes"][0]["nodes"].append(len(self.json["nodes"]) - 1)
        self.instances += len(rows)
        return True

    def finish(self, out: Path, sync: bool = True) -> None:
        """Write the GLB: header, JSON chunk, binary chunk (copied from the temporary file); fsynced unless
        ``sync`` is false (a writer of many files syncs them together, ``io.tiles3d``)."""
        self.json["buffers"][0]["byteLength"] = self.size
        for key in ("meshes", "materials", "accessors", "bufferViews"):
            if not self.json[key]:
                del self.json[key]
        text = json.dumps(self.json, separators=(",", ":")).encode("utf-8")
        text += b" " * (-len(text) % 4)
        total = 12 + 8 + len(text) + 8 + self.size
        with open(out, "wb") as glb:
            glb.write(struct.pack("<4sII", b"glTF", 2, total))
            glb.write(struct.pack("<I4s", len(text), b"JSON"))
            glb.write(text)
            glb.write(struct.pack("<I4s", self.size, b"BIN\x00"))
            self.binary.seek(0)
            shutil.copyfileobj(self.binary, glb, 16 << 20)
            glb.flush()
            if sync:
                os.fsync(glb.fileno())
        self.binary.close()

    def _describe_instances(self, node: dict, tile: Tile, members: np.ndarray) -> None:
        """Add what a subclass says of a group's instances (``tile.instances[members]``) to its node: here
        nothing (``io.tiles3d`` adds their features)."""

    def _describe_polygons(self, primitives: list[dict], tile: Tile) -> None:
        """Add what a subclass says of a tile's polygons to their primitives: here nothing."""

    # ------------------------------------------------------------------------------------------- parts

    def _view(self, data: np.ndarray, target: int | None = None) -> int:
        data = np.ascontiguousarray(data)
        self.binary.write(data.tobytes())
        view = {"buffer": 0, "byteOffset": self.size, "byteLength": data.nbytes}
        if target is not None:
            view["target"] = target
        self.size += data.nbytes
        pad = -self.size % 4
        self.binary.write(b"\x00" * pad)
        self.size += pad
        self.json["bufferViews"].append(view)
        return len(self.json["bufferViews"]) - 1

    def _accessor(self, data: np.ndarray, kind: str, target: int | None = None, bounds: bool = False,
                  normalized: bool = False) -> int:
        component = {np.dtype(np.float32): _FLOAT, np.dtype(np.uint32): _UINT,
                     np.dtype(np.uint8): _UBYTE}[data.dtype]
        accessor = {"bufferView": self._view(data, target), "componentType": component,
                    "count": len(data), "type": kind}
        if normalized:
            accessor["normalized"] = True
        if bounds:
            accessor["min"] = [float(v) for v in data.min(axis=0)]
            accessor["max"] = [float(v) for v in data.max(axis=0)]
        self.json["accessors"].append(accessor)
        return len(self.json["accessors"]) - 1

    def _material(self, rgba: tuple[int, ...], translucent: bool = False, colormap: Path | None = None) -> int:
        """The material of a colour; ``translucent``: its vertex colours have alpha below 1; ``colormap``:
        the image file of its ``baseColorTexture`` (left out when it is neither PNG nor JPEG)."""
        key = (*rgba, translucent, colormap)
        if key not in self._materials:
            srgb = np.array(rgba[:3], float) / 255.0
            linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
            material = {"pbrMetallicRoughness": {"baseColorFactor": [*map(float, linear), rgba[3] / 255.0],
                                                 "metallicFactor": 0.0, "roughnessFactor": 0.9},
                        "doubleSided": True}
            texture = self._texture(colormap) if colormap is not None else None
            if texture is not None:
                material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}
            if rgba[3] < 255 or translucent:
                material["alphaMode"] = "BLEND"
            self.json["materials"].append(material)
            self._materials[key] = len(self.json["materials"]) - 1
        return self._materials[key]

    def _texture(self, path: Path) -> int | None:
        """The texture of an image file, its bytes in the binary chunk; None for a format glTF does not take."""
        if path not in self._textures:
            mime = _IMAGE_TYPES.get(path.suffix.lower())
            self._textures[path] = None
            if mime is not None:
                view = self._view(np.frombuffer(path.read_bytes(), np.uint8))
                self.json.setdefault("images", []).append({"bufferView": view, "mimeType": mime})
                self.json.setdefault("textures", []).append({"source": len(self.json["images"]) - 1})
                self._textures[path] = len(self.json["textures"]) - 1
        return self._textures[path]

    def _mesh(self, asset: int, rgba: tuple[int, ...], colormap: Path | None = None) -> int:
        material = self._material(rgba, colormap=colormap)
        if (asset, material) not in self._meshes:
            if asset not in self._assets:
                shape = self.library[asset]
                self._assets[asset] = (
                    self._accessor(shape.vertices.astype(np.float32), "VEC3", ARRAY_BUFFER, bounds=True),
                    self._accessor(shape.faces.astype(np.uint32).reshape(-1), "SCALAR", ELEMENT_ARRAY_BUFFER),
                )
            position, indices = self._assets[asset]
            self.json["meshes"].append({"name": self.library.names[asset], "primitives": [
                {"attributes": {"POSITION": position}, "indices": indices, "material": material}]})
            self._meshes[asset, material] = len(self.json["meshes"]) - 1
        return self._meshes[asset, material]

    def _polygons(self, tile: Tile) -> int:
        """The tile's mesh-table triangles as one mesh with per-vertex colours, a primitive per colour map
        where the record has textures."""
        triangles = tile.triangles
        points = np.ascontiguousarray(triangles["vertices"].reshape(-1, 3))
        colors = np.repeat(triangles["color"], 3, axis=0)
        attributes = {"POSITION": self._accessor(points, "VEC3", ARRAY_BUFFER, bounds=True),
                      "COLOR_0": self._accessor(colors, "VEC4", ARRAY_BUFFER, normalized=True)}
        uv = tile.texture_coordinates()
        if uv is not None:
            attributes["TEXCOORD_0"] = self._accessor(_gltf_uv(uv), "VEC2", ARRAY_BUFFER)
        translucent = bool((colors[:, 3] < 255).any())
        primitives = [{"attributes": attributes, "material": self._material(_WHITE, translucent=translucent)}]
        if tile.triangle_material is not None:
            maps = [self.colormap(m) for m in range(int(tile.triangle_material.max()) + 1)]
            used = np.array([maps[m] for m in tile.triangle_material.tolist()], dtype=object)
            primitives = []
            for colormap in dict.fromkeys(used.tolist()):
                vertices = (np.flatnonzero(used == colormap)[:, None] * 3 + np.arange(3)).reshape(-1)
                primitives.append({"attributes": attributes, "material": self._material(
                    _WHITE, translucent=translucent, colormap=colormap),
                    "indices": self._accessor(vertices.astype(np.uint32), "SCALAR", ELEMENT_ARRAY_BUFFER)})
        self._describe_polygons(primitives, tile)
        self.json["meshes"].append({"name": f"{tile.name}_polygons", "primitives": primitives})
        return len(self.json["meshes"]) - 1


def baked_glb(vertices: np.ndarray, faces: np.ndarray, looks: np.ndarray | None, materials: np.ndarray,
              roots: Sequence[Path], meta: dict, uv: np.ndarray | None = None,
              origin: np.ndarray | None = None) -> bytes:
    """A baked mesh as a GLB: one mesh, a primitive (and a material) per look of its triangles.

    Parameters
    ----------
    vertices : (V, 3) float
        Coordinates relative to ``origin`` (written as float32).
    faces : (T, 3) int
        Triangles.
    looks : (T,) int64 or None
        Each triangle's material (an index into ``materials``) times 2^32 plus its RGBA as a uint32
        (``io.bake.BakedWriter``); None: all white.
    materials : (M, len(ir.MATERIAL_MAPS)) str
        Texture paths per channel (``model.records.MaterialTable``); a colour map found in ``roots`` becomes
        the primitive's ``baseColorTexture``.
    uv : (V, 2) float, optional
        Texture coordinates of the vertices (``TEXCOORD_0``, v turned to glTF's, down the image).
    origin : (3,) float, optional
        World point of the vertices' zero: the node's translation (and ``extras.origin``).
    """
    with tempfile.TemporaryDirectory() as folder:
        part = GlbPart(Path(folder) / "part.bin", None, meta)
        del part.json["extensionsUsed"]
        if looks is None:
            looks = np.full(len(faces), 0xFFFFFFFF, np.int64)
        primitives = []
        if len(faces):
            attributes = {"POSITION": part._accessor(np.asarray(vertices, np.float32), "VEC3", ARRAY_BUFFER,
                                                     bounds=True)}
            if uv is not None:
                attributes["TEXCOORD_0"] = part._accessor(_gltf_uv(uv), "VEC2", ARRAY_BUFFER)
            distinct, inverse = np.unique(looks, return_inverse=True)
            order = np.argsort(inverse.reshape(-1), kind="stable")
            bounds = np.searchsorted(inverse.reshape(-1)[order], np.arange(len(distinct) + 1))
            for k, look in enumerate(distinct.tolist()):
                rgba = tuple(np.array([look & 0xFFFFFFFF], np.uint32).view(np.uint8).tolist())
                colormap = str(materials[look >> 32, 0])
                found = locate(colormap, roots) if colormap else None
                triangles = np.asarray(faces, np.int64)[order[bounds[k]:bounds[k + 1]]]
                primitives.append({
                    "attributes": attributes,
                    "indices": part._accessor(triangles.astype(np.uint32).reshape(-1), "SCALAR",
                                              ELEMENT_ARRAY_BUFFER),
                    "material": part._material(rgba, colormap=found[1] if found else None)})
            part.json["meshes"].append({"name": "city", "primitives": primitives})
            node = {"name": "city", "mesh": 0}
            if origin is not None and np.any(origin):
                node.update(translation=[float(v) for v in origin], extras={"origin": [float(v) for v in origin]})
            part.json["nodes"].append(node)
            part.json["scenes"][0]["nodes"].append(0)
        out = Path(folder) / "baked.glb"
        part.finish(out)
        return out.read_bytes()


def _gltf_uv(uv: np.ndarray) -> np.ndarray:
    """(V, 2) float32: texture coordinates (u, v up the image) as glTF's, v down the image."""
    return np.stack([uv[:, 0], 1 - uv[:, 1]], axis=1).astype(np.float32)


def _groups(rows: np.ndarray, material: np.ndarray | None = None
            ) -> list[tuple[int, tuple[int, ...], int, np.ndarray]]:
    """(asset, RGBA, material, row indices) of a tile's instances, by (asset, material, colour) unless that
    makes more than ``MAX_GROUPS`` groups, then by (asset, material) in white; in order of asset, material,
    then colour. ``material`` (n,) int32: the rows' materials (None: all 0)."""
    if not len(rows):
        return []
    color = rows["color"].view(np.uint32).reshape(-1).astype(np.int64)
    material = np.zeros(len(rows), np.int64) if material is None else material.astype(np.int64)
    # (asset, material) pairs numbered in their order, in the high half of the key
    pairs, pair = np.unique(rows["asset"].astype(np.int64) << 32 | material, return_inverse=True)
    high = pair.reshape(-1).astype(np.int64) << 32
    unique, inverse = np.unique(high | color, return_inverse=True)
    if len(unique) > MAX_GROUPS:
        unique, inverse = np.unique(high | np.int64(0xFFFFFFFF), return_inverse=True)
    inverse = inverse.reshape(-1)
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(len(unique) + 1))
    groups = []
    for k, value in enumerate(unique.tolist()):
        rgba = tuple(np.array([value & 0xFFFFFFFF], np.uint32).view(np.uint8).tolist())
        asset_and_material = int(pairs[value >> 32])
        groups.append((asset_and_material >> 32, rgba, asset_and_material & 0xFFFFFFFF,
                       order[bounds[k]:bounds[k + 1]]))
    return groups


def read_glb(path: str | os.PathLike) -> dict:
    """The instances of a city written by ``GltfWriter`` (all its parts), as a record dict (the keys of
    ``io.npz.read_instances`` that glTF keeps: assets, asset, xform (float64, world), the mesh table as
    triangles, meta); grouped by tile and (asset, colour), not in the record's order."""
    parts = written_parts(path)
    names: dict[str, int] = {}
    assets, xforms, triangles, meta = [], [], [], {}
    for part in parts:
        tree, blob = _read_part(part)
        meta = tree.get("asset", {}).get("extras", {}).get("grammarc", meta)
        nodes = tree.get("nodes", [])
        for root in tree.get("scenes", [{}])[0].get("nodes", []):
            corner = np.array(nodes[root].get("translation", [0.0, 0.0, 0.0]), np.float64)
            for child in nodes[root].get("children", []):
                node = nodes[child]
                mesh = tree["meshes"][node["mesh"]]
                instancing = node.get("extensions", {}).get(INSTANCING)
                if instancing is None:  # the tile's polygons
                    points = _accessor(tree, blob, mesh["primitives"][0]["attributes"]["POSITION"])
                    triangles.append(points.astype(np.float64) + corner)
                    continue
                attributes = instancing["attributes"]
                t, r, s = (_accessor(tree, blob, attributes[k]) for k in ("TRANSLATION", "ROTATION", "SCALE"))
                xforms.append(compose(t.astype(np.float64) + corner, r, s))
                assets.append(np.full(len(t), names.setdefault(mesh["name"], len(names)), np.int64))
    vertices = np.concatenate(triangles) if triangles else np.zeros((0, 3))
    return {"assets": np.array(list(names)), "asset": np.concatenate(assets) if assets else np.zeros(0, np.int64),
            "xform": np.concatenate(xforms) if xforms else np.zeros((0, 3, 4)), "meta": meta,
            "mesh_vertices": vertices, "mesh_ring_offsets": np.arange(0, len(vertices) + 1, 3),
            "mesh_face_offsets": np.arange(len(vertices) // 3 + 1)}


def _read_part(path: Path) -> tuple[dict, bytes]:
    data = path.read_bytes()
    magic, _, _ = struct.unpack_from("<4sII", data, 0)
    length, kind = struct.unpack_from("<I4s", data, 12)
    if magic != b"glTF" or kind != b"JSON":
        raise ValueError(f"{path}: not a binary glTF")
    tree = json.loads(data[20:20 + length])
    start = 20 + length
    blob = data[start + 8:] if len(data) > start else b""
    return tree, blob


def _accessor(tree: dict, blob: bytes, index: int) -> np.ndarray:
    accessor = tree["accessors"][index]
    view = tree["bufferViews"][accessor["bufferView"]]
    dtype = {_FLOAT: np.float32, _UINT: np.uint32, _UBYTE: np.uint8}[accessor["componentType"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[accessor["type"]]
    offset = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    values = np.frombuffer(blob, dtype, accessor["count"] * width, offset)
    return values.reshape(-1, width) if width > 1 else values
