"""Instanced USD: ``--emit city.usda | city.usdc | city.usd`` (the ``usd`` extra, usd-core).

The layout, for ``city.usdc``::

    city.usdc                        root layer: /City (the default prim), one child per tile
    city.usdc.tiles/prototypes.usdc  /Prototypes/<asset>: one Mesh per asset, in its unit box [0, 1]^3
    city.usdc.tiles/tile_3_m2.usdc   /Tile: Instances (a PointInstancer) and Meshes (the mesh table)

* **Tiles** (``io.instancing``): instances are grouped in square tiles of the ground plane, each tile's
  prim translated to its corner in float64 and its positions relative to the corner, so float32
  positions stay exact far from the origin. The root layer references each tile's layer, so a viewer
  or a pipeline can load, deactivate or swap a tile on its own.
* **Instances**: one ``UsdGeomPointInstancer`` per tile: ``protoIndices``, ``positions``,
  ``orientations`` (quath), ``scales``, ``ids`` (the instance's row in the record, so a tile's
  instances can be matched with ``instances.npz``), the per-instance colour as ``primvars:displayColor``
  (and ``displayOpacity``) of vertex interpolation, which prototypes inherit, and ``grammarc:lot`` and
  ``grammarc:symbol``. Its ``prototypes`` are children of the instancer referencing the prototype
  layer, one for each asset the tile uses (for each asset and material where the record has textures:
  those with a colour map are bound to a ``UsdPreviewSurface`` reading it through a ``UsdUVTexture``; a
  rule package's colour maps are copied into the tile folder's ``textures``, ``io.textures``).
* **Prototypes**: the asset meshes as ``model.assets`` loads them (OBJ by its own reader, other formats
  through trimesh, built-ins generated), fitted to the unit box as CityEngine fits an inserted asset to its
  scope; ``subdivisionScheme`` is ``none`` (they are polygon models, not subdivision cages).
* **Meshes**: the mesh table's polygons (leaves that are not instances) triangulated, one Mesh per
  tile with a colour per face (and a ``GeomSubset`` per material bound to it where the record has textures),
  and the texture coordinates of set 0 as ``primvars:st`` (vertex interpolation: each triangle has its own
  points) where the record has them, which the materials' ``UsdUVTexture`` reads.

Writing streams: ``write`` sorts each chunk into tile spools on disk (``TileSpool``), and ``close``
makes one tile layer at a time, so memory is bounded by the largest tile, not by the city. Everything
is written in a temporary folder next to the output. The tile folder is named by a digest of its layers
(``city.usdc.tiles-<12 hex>``, the root keeps the name as ``grammarc:tiles``), so a new build's tiles never
take the place of those the old root names: ``close`` moves the new tile folder in beside the old one, then
the root layer onto the old root, and only then removes the old tiles. A build stopped anywhere leaves the
old root with its own tiles, or the new root with its own; the tile folders no root names (a stopped
build's) go at the next build of the same output. ``.usda`` writes text
layers throughout (small cities, for reading); ``.usdc`` and ``.usd`` write crate layers.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from grammarc.atomic import replacing
from grammarc.errors import UsageError
from grammarc.io.instancing import TILE_SIZE, Tile, TiledWriter, compose, decompose
from grammarc.io.textures import PackagedTextures

# usd-core's modules (the `usd` extra), imported by _require_pxr when USD is first written or read: the writer
# registry imports this module for every output, which must not load usd-core.
Gf = Sdf = Tf = Usd = UsdGeom = UsdShade = Vt = None

__all__ = ["WRITERS", "UsdWriter", "read_usd", "tiles_folder", "write_shards_root"]


#: The hexadecimal digits of the digest that names a tile folder.
_DIGEST = 12


def tiles_folder(path: str | os.PathLike) -> Path:
    """The folder of a root layer's tile layers, as the root names it: ``city.usdc`` ->
    ``city.usdc.tiles-<digest>`` (so ``city.usda`` and ``city.usdc`` side by side do not share one)."""
    _require_pxr()
    path = Path(path)
    layer = Sdf.Layer.OpenAsAnonymous(str(path))  # not a layer of the registry, which may hold an older root
    if layer is None:
        raise ValueError(f"{path}: not a USD layer")
    return path.with_name(layer.customLayerData.get("grammarc:tiles", _tiles_base(path).name))


def _tiles_base(path: Path) -> Path:
    """``city.usdc`` -> ``city.usdc.tiles``: the tile folders' names begin so."""
    return path.with_name(f"{path.name}.tiles")


def _digest_folder(path: Path, staged: Path) -> Path:
    """The tile folder of root ``path`` named by the SHA-256 of the files in ``staged`` (the layers and any
    copied textures: paths and bytes, in path order)."""
    digest = hashlib.sha256()
    for staged_file in sorted(p for p in staged.rglob("*") if p.is_file()):
        with open(staged_file, "rb") as file:
            name = staged_file.relative_to(staged).as_posix()
            digest.update(name.encode() + b"\0" + hashlib.file_digest(file, "sha256").digest())
    return path.with_name(f"{_tiles_base(path).name}-{digest.hexdigest()[:_DIGEST]}")


def _require_pxr() -> None:
    """Import usd-core's modules into this module's globals, or say which extra to install."""
    global Gf, Sdf, Tf, Usd, UsdGeom, UsdShade, Vt
    if Usd is not None:
        return
    try:
        from pxr import Gf, Sdf, Tf, Usd, UsdGeom, UsdShade, Vt
    except ImportError as error:
        raise UsageError("writing USD needs usd-core: pip install 'grammarc[usd]' (or pip install usd-core)") \
            from error


class UsdWriter(TiledWriter):
    """Streams TerminalChunks into tiles and writes the instanced USD layers on ``close`` (``TiledWriter``).

    Parameters
    ----------
    path : str or os.PathLike
        The root layer: ``.usda``, ``.usdc`` or ``.usd``. Its directory must exist.
    assets, symbols : sequence of str
        The record's asset and symbol names.
    meta : dict
        Facts about the run, kept as the root layer's ``customLayerData["grammarc"]`` (JSON); its
        ``grammar`` and ``asset_roots`` give the asset roots when ``asset_roots`` is not given.
    asset_roots : sequence of path-like, optional
        Folders to resolve file assets in.
    tile_size : float
        Edge of a tile in metres.
    lod : str, optional
        Level of detail of the prototypes (``model.assets.load_asset``).
    """

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str], meta: dict,
                 asset_roots: Sequence[str | os.PathLike] | None = None, tile_size: float = TILE_SIZE,
                 lod: str | None = None):
        _require_pxr()
        if Path(path).suffix.lower() not in WRITERS:
            raise UsageError(f"cannot write `{path}` as USD: use .usda, .usdc or .usd")
        super().__init__(path, assets=assets, meta=meta, asset_roots=asset_roots, tile_size=tile_size, lod=lod)
        self._ext = ".usda" if self.path.suffix.lower() == ".usda" else ".usdc"
        self._symbols = list(symbols)

    @staticmethod
    def beside(path: Path) -> tuple[list[Path], list[Path]]:
        """The folders written beside ``path`` (``io.written_paths``): the tile folder."""
        return [], [path.with_name(f"{_tiles_base(path).name}-{'0' * _DIGEST}")]

    def _finish(self) -> dict:
        """The prototype, tile and root layers, moved into place."""
        staged = self._tmp / "tiles"
        staged.mkdir()
        self._textures = PackagedTextures(self._meta, self._library.roots, staged / "textures")
        prototypes = self._write_prototypes(staged / f"prototypes{self._ext}")
        tiles = [self._write_tile(staged, tile, prototypes) for tile in self._spool.tiles()]  # (name, origin)
        folder = _digest_folder(self.path, staged)
        staged = staged.rename(self._tmp / folder.name)  # beside the new root as beside the output (composed)
        root = self._tmp / self.path.name
        self._write_root(root, tiles, folder.name)
        self._move_into_place(staged, folder, root)
        return {}

    # ------------------------------------------------------------------------------------------ layers

    def _write_prototypes(self, path: Path) -> dict[int, str]:
        """The prototype layer: a Mesh per used asset; returns asset index -> prim path."""
        stage = _new_stage(path, UsdGeom.Scope, "/Prototypes")
        paths = {}
        for index in np.flatnonzero(self._used):
            shape = self._library[int(index)]
            prim = f"/Prototypes/{_prim_name(int(index), self._library.names[index])}"
            mesh = UsdGeom.Mesh.Define(stage, prim)
            mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(shape.vertices.astype(np.float32)))
            mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(shape.faces), 3, np.int32)))
            mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(shape.faces.astype(np.int32).reshape(-1)))
            mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            low, high = shape.vertices.min(axis=0), shape.vertices.max(axis=0)
            mesh.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*map(float, low)), Gf.Vec3f(*map(float, high))]))
            mesh.GetPrim().SetCustomDataByKey("grammarc:asset", self._library.names[index])
            paths[int(index)] = prim
        stage.GetRootLayer().Save()
        return paths

    def _write_tile(self, folder: Path, tile: Tile, prototypes: dict[int, str]) -> tuple[str, np.ndarray]:
        """One tile's layer: /Tile with its PointInstancer and its Mesh; the tile's name and origin (not
        the tile: its rows are let go)."""
        stage = _new_stage(folder / f"{tile.name}{self._ext}", UsdGeom.Xform, "/Tile")
        rows = tile.instances
        if len(rows):
            instancer = UsdGeom.PointInstancer.Define(stage, "/Tile/Instances")
            # a prototype per asset, and per (asset, material) where the record has textures
            material = tile.instance_material if tile.instance_material is not None else np.zeros(len(rows))
            used, local = np.unique(rows["asset"].astype(np.int64) << 32 | material.astype(np.int64),
                                    return_inverse=True)
            UsdGeom.Scope.Define(stage, "/Tile/Instances/Prototypes")
            targets = []
            for key in used.tolist():
                asset, textures = key >> 32, key & 0xFFFFFFFF
                name = prototypes[asset].rsplit("/", 1)[1] + (f"_m{textures}" if textures else "")
                child = stage.DefinePrim(f"/Tile/Instances/Prototypes/{name}")
                child.GetReferences().AddReference(f"./prototypes{self._ext}", prototypes[asset])
                self._bind(stage, child, textures)
                targets.append(child.GetPath())
            instancer.CreatePrototypesRel().SetTargets(targets)
            positions, orientations, scales = decompose(rows["xform"])
            instancer.CreateProtoIndicesAttr(Vt.IntArray.FromNumpy(local.astype(np.int32).reshape(-1)))
            instancer.CreatePositionsAttr(Vt.Vec3fArray.FromNumpy(positions))
            instancer.CreateOrientationsAttr(Vt.QuathArray.FromNumpy(orientations.astype(np.float16)))
            instancer.CreateScalesAttr(Vt.Vec3fArray.FromNumpy(scales))
            instancer.CreateIdsAttr(Vt.Int64Array.FromNumpy(rows["row"]))
            _colors(UsdGeom.PrimvarsAPI(instancer), rows["color"], UsdGeom.Tokens.vertex)
            for name, column in (("grammarc:lot", "lot"), ("grammarc:symbol", "symbol")):
                instancer.GetPrim().CreateAttribute(name, Sdf.ValueTypeNames.IntArray).Set(
                    Vt.IntArray.FromNumpy(np.ascontiguousarray(rows[column])))
        triangles = tile.triangles
        if len(triangles):
            mesh = UsdGeom.Mesh.Define(stage, "/Tile/Meshes")
            points = np.ascontiguousarray(triangles["vertices"].reshape(-1, 3))
            mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points))
            mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(triangles), 3, np.int32)))
            mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.arange(len(points), dtype=np.int32)))
            mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            _colors(UsdGeom.PrimvarsAPI(mesh), triangles["color"], UsdGeom.Tokens.uniform)
            uv = tile.texture_coordinates()
            if uv is not None:  # the points are the triangles' own: a coordinate per point
                UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                        UsdGeom.Tokens.vertex).Set(Vt.Vec2fArray.FromNumpy(uv))
            if tile.triangle_material is not None:
                imageable = UsdGeom.Imageable(mesh)
                for textures in np.unique(tile.triangle_material).tolist():
                    faces = np.flatnonzero(tile.triangle_material == textures).astype(np.int32)
                    subset = UsdGeom.Subset.CreateGeomSubset(imageable, f"m{textures}", UsdGeom.Tokens.face,
                                                             Vt.IntArray.FromNumpy(faces), "materialBind")
                    self._bind(stage, subset.GetPrim(), textures)
        stage.GetRootLayer().Save()
        return tile.name, tile.origin

    def _bind(self, stage, prim, textures: int) -> None:
        """Bind ``prim`` to the tile's material of the writer's material ``textures`` when it has a colour map
        found in the asset roots: a ``UsdPreviewSurface`` whose diffuse colour is a ``UsdUVTexture`` of the
        file (its path relative to the tile layer), read at the primvar ``st``."""
        colormap = self._colormap(textures)
        if colormap is None:
            return
        path = f"/Tile/Materials/m{textures}"
        material = UsdShade.Material.Get(stage, path)
        if not material:
            UsdGeom.Scope.Define(stage, "/Tile/Materials")
            material = UsdShade.Material.Define(stage, path)
            surface = UsdShade.Shader.Define(stage, f"{path}/Surface")
            surface.CreateIdAttr("UsdPreviewSurface")
            reader = UsdShade.Shader.Define(stage, f"{path}/St")
            reader.CreateIdAttr("UsdPrimvarReader_float2")
            reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("st")
            texture = UsdShade.Shader.Define(stage, f"{path}/Colormap")
            texture.CreateIdAttr("UsdUVTexture")
            texture.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(self._texture_path(colormap)))
            texture.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
                reader.ConnectableAPI(), "result")
            surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
                texture.ConnectableAPI(), "rgb")
            material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
        UsdShade.MaterialBindingAPI.Apply(prim).Bind(material)

    def _texture_path(self, colormap: Path) -> str:
        """A colour map's path as a tile layer names it: a rule package's copied into the tile folder's
        ``textures`` (``io.textures``), any other relative to the tile folder, beside which it lies."""
        return self._textures.named(colormap, f"./{self._textures.into.name}", _tiles_base(self.path).resolve())

    def _write_root(self, path: Path, tiles: list[tuple[str, np.ndarray]], folder: str) -> None:
        stage = _new_stage(path, UsdGeom.Xform, "/City")
        for name, origin in tiles:
            xform = UsdGeom.Xform.Define(stage, f"/City/{name}")
            xform.AddTranslateOp().Set(Gf.Vec3d(*map(float, origin)))
            xform.GetPrim().GetReferences().AddReference(f"./{folder}/{name}{self._ext}")
        layer = stage.GetRootLayer()
        # the coordinate system of the world the tiles are placed in (null for a local scene), by itself too
        layer.customLayerData = {"grammarc": json.dumps(self._meta, sort_keys=True),
                                 "grammarc:symbols": json.dumps(self._symbols),
                                 "grammarc:crs": self._meta.get("crs") or "",
                                 "grammarc:tiles": folder}
        layer.Save()

    def _move_into_place(self, staged: Path, folder: Path, root: Path) -> None:
        """The new tile folder beside the old one, the root layer onto the old root, then the tile folders
        the root does not name (the old root's, a stopped build's) removed. A folder of the new tiles'
        name already there holds the same layers (an earlier build of the same city) and is kept."""
        if not folder.exists():
            os.replace(staged, folder)
        with open(root, "rb") as file:
            os.fsync(file.fileno())
        os.replace(root, self.path)
        pattern = re.compile(rf"{re.escape(_tiles_base(self.path).name)}(-[0-9a-f]{{{_DIGEST}}})?")
        for old in self.path.parent.iterdir():
            if old != folder and pattern.fullmatch(old.name) and old.is_dir():
                shutil.rmtree(old, ignore_errors=True)


#: The extensions this module writes (``grammarc.io.writers``).
WRITERS = dict.fromkeys((".usda", ".usdc", ".usd"), UsdWriter)


def write_shards_root(output: Path, manifest: dict) -> None:
    """The root layer of a cluster build (``io.shards``): ``/City`` with a child per shard the manifest
    lists, referencing the shard's own root layer (whose tiles it places). Written atomically."""
    _require_pxr()
    with replacing(output) as tmp:
        stage = _new_stage(tmp, UsdGeom.Xform, "/City")
        for shard in manifest["shards"]:
            name = Path(shard["path"]).name.split(".")[0].replace("-", "_")
            UsdGeom.Xform.Define(stage, f"/City/{name}").GetPrim().GetReferences().AddReference(f"./{shard['path']}")
        layer = stage.GetRootLayer()
        layer.customLayerData = {"grammarc": json.dumps(manifest["meta"], sort_keys=True),
                                 "grammarc:symbols": json.dumps(manifest["symbols"]),
                                 "grammarc:manifest": output.stem + ".manifest.json"}
        layer.Save()


def _new_stage(path: Path, kind, root: str):
    """A new layer at ``path``, y up in metres, whose default prim is ``root``, a ``kind`` prim."""
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetDefaultPrim(kind.Define(stage, root).GetPrim())
    return stage


def _prim_name(index: int, name: str) -> str:
    """A valid, unique prim name for asset ``index``: ``a3_window_obj`` for ``facade/window.obj``."""
    return f"a{index}_{Tf.MakeValidIdentifier(name.rsplit('/', 1)[-1].removeprefix('builtin:'))}"


def _colors(primvars, rgba: np.ndarray, interpolation) -> None:
    """``displayColor`` (and ``displayOpacity`` where any alpha is below 255) from RGBA bytes."""
    color = primvars.CreatePrimvar("displayColor", Sdf.ValueTypeNames.Color3fArray, interpolation)
    color.Set(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(rgba[:, :3], np.float32) / 255.0))
    if (rgba[:, 3] < 255).any():
        opacity = primvars.CreatePrimvar("displayOpacity", Sdf.ValueTypeNames.FloatArray, interpolation)
        opacity.Set(Vt.FloatArray.FromNumpy(rgba[:, 3].astype(np.float32) / 255.0))


def read_usd(path: str | os.PathLike) -> dict:
    """The instances of a city written by ``UsdWriter``, as a record dict (``io.npz.read_instances``'s
    keys): assets, asset, xform (float64, world), lot, symbol, symbols, the mesh table (a face per
    triangle), meta; rows in the record's order (by ``ids``)."""
    _require_pxr()
    stage = Usd.Stage.Open(str(path))
    if stage is None:
        raise ValueError(f"{path}: not a USD stage")
    data = stage.GetRootLayer().customLayerData
    meta = json.loads(data.get("grammarc", "{}"))
    symbols = json.loads(data.get("grammarc:symbols", "[]"))
    names: dict[str, int] = {}
    columns: dict[str, list] = {"id": [], "asset": [], "xform": [], "lot": [], "symbol": []}
    triangles = []
    time = Usd.TimeCode.Default()
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.PointInstancer):
            instancer = UsdGeom.PointInstancer(prim)
            corner = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(time).ExtractTranslation())
            targets = instancer.GetPrototypesRel().GetTargets()
            local = np.array([names.setdefault(str(stage.GetPrimAtPath(t).GetCustomDataByKey("grammarc:asset")),
                                               len(names)) for t in targets], np.int64)
            orientations = np.array([[*q.GetImaginary(), q.GetReal()] for q in instancer.GetOrientationsAttr().Get()])
            columns["xform"].append(compose(np.array(instancer.GetPositionsAttr().Get(), np.float64) + corner,
                                            orientations.reshape(-1, 4), np.array(instancer.GetScalesAttr().Get())))
            columns["asset"].append(local[np.array(instancer.GetProtoIndicesAttr().Get(), np.int64)])
            columns["id"].append(np.array(instancer.GetIdsAttr().Get(), np.int64))
            for name in ("lot", "symbol"):
                columns[name].append(np.array(prim.GetAttribute(f"grammarc:{name}").Get(), np.int64))
        elif prim.IsA(UsdGeom.Mesh) and prim.GetName() == "Meshes":
            corner = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(time).ExtractTranslation())
            triangles.append(np.array(UsdGeom.Mesh(prim).GetPointsAttr().Get(), np.float64) + corner)
    order = np.argsort(np.concatenate(columns["id"])) if columns["id"] else np.zeros(0, np.int64)
    record = {name: np.concatenate(values)[order] if values else np.zeros(0, np.int64)
              for name, values in columns.items() if name != "xform"}
    record["xform"] = np.concatenate(columns["xform"])[order] if columns["xform"] else np.zeros((0, 3, 4))
    vertices = np.concatenate(triangles) if triangles else np.zeros((0, 3))
    record.update(assets=np.array(list(names)), symbols=np.array(symbols), meta=meta,
                  mesh_vertices=vertices, mesh_ring_offsets=np.arange(0, len(vertices) + 1, 3),
                  mesh_face_offsets=np.arange(len(vertices) // 3 + 1))
    del record["id"]
    return record
