"""Baking an instance record into one triangle mesh, and the mesh writers (.obj + .mtl, .ply, .stl, .glb).

A record (README, "The record") holds instances (an asset and the affine map of its unit box) and leaf
polygons (the mesh table). Baking expands every instance into its asset's triangles (``model.assets``) and
triangulates the polygons (``geometry.triangulation``), so that the city can be looked at, exported, or
measured against PRT (``grammarc.conform``).

Instances are expanded per asset, all instances of one asset at once: ``einsum`` of the (n, 3, 3) linear
parts with the asset's (v, 3) vertices, faces offset by ``arange(n) * v``. An instance whose transform
mirrors (negative determinant) gets its triangles reversed, so a mirrored cube still faces outward; a flat
transform (a quad's zero column) keeps the asset's winding, whose normal is then ``col0 x col1``, the
face's normal by the record's convention.

Polygon counts. Conformance compares face counts with PRT, whose encoder returns polygons, not triangles,
so ``bake`` also counts the polygons before triangulation, in the mesh's ``metadata``:

* an instance counts its asset's polygons (``AssetMesh.polygon_sizes``, see ``model.assets``);
* a face of the mesh table counts each of its rings, outline and holes, as PRT's encoder returns them
  (README of the PRT kit: "a face with holes comes back as its outer ring plus one face per hole ring").

Colours and textures. Every triangle keeps how its instance or face looks: its RGBA colour and its material
(texture paths, ``model.records.MaterialTable``). The OBJ gets a material library beside it (``city.mtl``:
a material per look, ``Kd`` and ``d`` from the colour, ``map_Kd`` and the other maps from the textures,
resolved in the asset roots; a rule package's textures copied into ``city.obj.textures``, ``io.textures``)
and its triangles in a group ``g lot_N`` per lot, a ``usemtl`` run per look; the PLY gets vertex colours;
the GLB a primitive and material per look, its colour map embedded.

Memory: the baked mesh holds ~60 bytes a triangle (float64 vertices, int64 faces), so ``bake`` counts the
triangles before it allocates anything and refuses a record beyond ``max_triangles``.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import ClassVar

import numpy as np

from grammarc.atomic import private_folder, replace_folder
from grammarc.constants import LIMITS
from grammarc.errors import UsageError
from grammarc.geometry.triangulation import triangulate_polygons
from grammarc.io import WriterBlock
from grammarc.io.gltf import baked_glb
from grammarc.io.obj import obj_bytes, with_lines
from grammarc.io.textures import PackagedTextures
from grammarc.ir.asset_names import locate
from grammarc.ir.nodes import MATERIAL_MAPS
from grammarc.model.assets import AssetLibrary, AssetMesh, asset_library
from grammarc.model.records import LotOrigins, MaterialTable, MeshChunk, TerminalChunk, record_mesh
from grammarc.ragged import offsets_from_counts, segment_of

__all__ = ["MAX_TRIANGLES", "WRITERS", "BakedWriter", "bake", "bake_mesh", "count_triangles", "made_triangles",
           "mesh_triangles", "triangle_limit"]

#: Default limit of ``bake`` (``constants.Limits.max_triangles``).
MAX_TRIANGLES = LIMITS.max_triangles
#: Vertices expanded per einsum call: bounds the float64 temporaries of a block of instances (~50 MB).
_BLOCK_VERTICES = 1 << 21
# ---------------------------------------------------------------------------------------- the record


def count_triangles(record: Mapping, asset_roots: Sequence[str | os.PathLike] | None = None,
                    lod: str | None = None) -> int:
    """The number of triangles ``bake`` makes of ``record`` at most, without baking it.

    Loads the assets the record uses (not the mesh). Faces of the mesh table count ``V + 2H - 2``
    triangles (V vertices in all rings, H holes), what earcut makes of a simple polygon.
    """
    names, asset, _, mesh, _ = _columns(record)
    return made_triangles(asset_library(names, record, asset_roots, lod), asset, mesh)


def bake(
    record: Mapping,
    asset_roots: Sequence[str | os.PathLike] | None = None,
    *,
    max_triangles: int = MAX_TRIANGLES,
):
    """One triangle mesh of a record: instances expanded, polygons triangulated.

    Parameters
    ----------
    record : mapping
        The dict of ``read_instances`` (``assets``, ``asset`` (N,) int32, ``xform`` (N, 3, 4) float32,
        ``mesh_vertices`` (V, 3), ``mesh_ring_offsets`` (R+1,), ``mesh_face_offsets`` (F+1,)), or the same
        columns with the mesh table as ``"mesh"``: a ``MeshChunk`` (the dict of ``build.derive``). The mesh
        table may be absent.
    asset_roots : sequence of path-like, optional
        Folders to resolve file assets in. By default the folder of ``meta["grammar"]``, then the folders
        of ``meta["asset_roots"]``, if the record has them.
    max_triangles : int
        Refuse to bake more triangles than this (checked before anything is allocated).

    Returns
    -------
    trimesh.Trimesh
        Vertices (instances' first, asset by asset, then the mesh table's) and triangles, unprocessed
        (no vertex merging). ``metadata`` holds plain ints: ``n_instances``, ``n_mesh_faces``,
        ``n_polygons`` (polygons before triangulation, counted as PRT counts faces, see the module
        docstring), ``n_holes`` (hole rings among them), ``face_sizes`` (dict: vertex count ->
        polygons).

    Raises
    ------
    UsageError
        If the mesh would have more than ``max_triangles`` triangles.
    AssetError
        If a used asset cannot be resolved or read.

    Examples
    --------
    >>> record = {"assets": ["builtin:cube"], "asset": np.zeros(1, np.int32),
    ...           "xform": np.array([[[2, 0, 0, 1], [0, 3, 0, 0], [0, 0, 4, 0]]], np.float32)}
    >>> mesh = bake(record)
    >>> len(mesh.faces), float(mesh.area), mesh.bounds.tolist()
    (12, 52.0, [[1.0, 0.0, 0.0], [3.0, 3.0, 4.0]])
    """
    names, asset, xform, mesh, origins = _columns(record)
    return bake_mesh(asset_library(names, record, asset_roots), asset, xform, mesh, max_triangles,
                     origins=origins, lot=record.get("lot"))[0]


def bake_mesh(library: AssetLibrary, asset: np.ndarray, xform: np.ndarray, mesh: MeshChunk, max_triangles: int,
              uv: np.ndarray | None = None, origins: LotOrigins | None = None, lot: np.ndarray | None = None):
    """``bake`` of a record's columns, its assets in ``library``; and the source of each triangle (T,) int64:
    its instance's row, or ``len(asset)`` plus its face in the mesh table. The mesh has texture coordinates
    (0 where a vertex has none) where the instances' ``uv`` (``TerminalChunk.uv``) or the mesh table's are
    given. The mesh is in world coordinates: the ``origins`` of the rows' ``lot`` (N,) and of the mesh's
    faces' lots are added (``model.records.LotOrigins``; None: the rows are in world coordinates)."""
    import trimesh

    used = np.bincount(asset, minlength=len(library.names)).astype(np.int64)
    n_triangles = library.triangles(used) + mesh_triangles(mesh)
    if n_triangles > max_triangles:
        raise UsageError(
            f"baking this record makes {n_triangles:,} triangles, more than the limit of "
            f"{max_triangles:,}; raise it (bake(..., max_triangles=N), or GRAMMARC_MAX_TRIANGLES=N for "
            "the mesh writers) or write an instance record (.npz) instead"
        )
    origins = origins if origins is not None else LotOrigins.empty()
    mesh = _world_mesh(mesh, origins)
    assets = np.flatnonzero(used)
    n_vertices = sum(int(used[a]) * len(library[a].vertices) for a in assets) + len(mesh.vertices)
    vertices = np.empty((n_vertices, 3), np.float64)
    faces = np.empty((n_triangles, 3), np.int64)
    source = np.empty(n_triangles, np.int64)
    face_sizes = np.zeros(1, np.int64)
    n_polygons = 0
    v0 = t0 = 0
    order = np.argsort(asset, kind="stable")  # instances grouped by asset, in record order within each
    starts = offsets_from_counts(used)
    texture = None if uv is None and mesh.uv is None else np.zeros((n_vertices, 2), np.float64)
    for a in assets:
        shape = library[a]
        rows = order[starts[a] : starts[a + 1]]
        first = t0
        if texture is not None and uv is not None:  # the instances' maps of their unit box, per vertex
            placed = np.einsum("kij,vj->kvi", uv[rows, :, :3].astype(np.float64), shape.vertices)
            texture[v0 : v0 + placed.shape[0] * placed.shape[1]] = (placed + uv[rows, None, :, 3]).reshape(-1, 2)
        offset = origins.of(lot[rows]) if len(origins.lot) else None
        v0, t0 = _expand(shape, xform, rows, offset, vertices, faces, v0, t0)
        source[first:t0] = np.repeat(rows, (t0 - first) // max(len(rows), 1))
        face_sizes = _add_counts(face_sizes, shape.polygon_sizes, int(used[a]))
        n_polygons += int(used[a]) * shape.n_polygons
    if len(mesh.face_offsets) > 1:
        vertices[v0:] = mesh.vertices
        if texture is not None:
            texture[v0:] = mesh.texture()
        triangles = triangulate_polygons(mesh.vertices, mesh.ring_offsets, mesh.face_offsets)
        faces[t0 : t0 + len(triangles)] = triangles + v0
        vertex_face = segment_of(mesh.face_offsets)[segment_of(mesh.ring_offsets)]
        source[t0 : t0 + len(triangles)] = len(asset) + vertex_face[triangles[:, 0]]
        t0 += len(triangles)
        ring_sizes = np.diff(mesh.ring_offsets)
        face_sizes = _add_counts(face_sizes, ring_sizes, 1)
        n_polygons += len(ring_sizes)
    n_faces = len(mesh.face_offsets) - 1
    metadata = {
        "n_instances": len(asset),
        "n_mesh_faces": int(n_faces),
        "n_polygons": int(n_polygons),
        "n_holes": int(len(mesh.ring_offsets) - 1 - n_faces),
        "face_sizes": {int(k): int(c) for k, c in enumerate(face_sizes) if c},
    }
    visual = None if texture is None else trimesh.visual.TextureVisuals(uv=np.nan_to_num(texture))
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces[:t0], process=False, metadata=metadata, visual=visual)
    return mesh, source[:t0]


def _expand(shape: AssetMesh, xform: np.ndarray, rows: np.ndarray, offset: np.ndarray | None, vertices: np.ndarray,
            faces: np.ndarray, v0: int, t0: int) -> tuple[int, int]:
    """Write the instances ``rows`` of one asset at ``vertices[v0:]``, ``faces[t0:]``, moved by ``offset``
    (len(rows), 3) (their lots' origins) where given; the new ends."""
    nv, nt = len(shape.vertices), len(shape.faces)
    if nv == 0:
        return v0, t0
    block = max(1, _BLOCK_VERTICES // nv)
    for b in range(0, len(rows), block):
        part = xform[rows[b : b + block]].astype(np.float64)  # (n, 3, 4)
        if offset is not None:
            part[:, :, 3] += offset[b : b + block]
        n = len(part)
        out = vertices[v0 : v0 + n * nv].reshape(n, nv, 3)
        # world[k, v, i] = sum_j linear[k, i, j] * p[v, j] + offset[k, i]
        np.einsum("kij,vj->kvi", part[:, :, :3], shape.vertices, out=out)
        out += part[:, None, :, 3]
        tris = faces[t0 : t0 + n * nt].reshape(n, nt, 3)
        np.add(shape.faces[None], (v0 + np.arange(n, dtype=np.int64) * nv)[:, None, None], out=tris)
        mirrored = np.linalg.det(part[:, :, :3]) < 0
        if mirrored.any():
            # A mirroring transform turns the winding inside out: swap two corners of each triangle.
            tris[mirrored] = tris[mirrored][:, :, [0, 2, 1]]
        v0 += n * nv
        t0 += n * nt
    return v0, t0


def _add_counts(histogram: np.ndarray, sizes: np.ndarray, times: int) -> np.ndarray:
    """``histogram`` (k,) int64 of polygon sizes plus ``times`` x the polygons of ``sizes`` (p,)."""
    if len(sizes) == 0 or times == 0:
        return histogram
    counts = np.bincount(sizes) * times
    if len(counts) > len(histogram):
        histogram = np.pad(histogram, (0, len(counts) - len(histogram)))
    histogram[: len(counts)] += counts
    return histogram


def made_triangles(library: AssetLibrary, asset: np.ndarray, mesh: MeshChunk) -> int:
    """The triangles a bake makes of instances of ``asset`` (N,) int of ``library`` and of ``mesh``, the mesh
    table, counted without baking (the assets are loaded)."""
    return library.triangles(np.bincount(asset, minlength=len(library.names))) + mesh_triangles(mesh)


def triangle_limit(max_triangles: int | None) -> int:
    """The most triangles a baked output may have: ``max_triangles``, else ``GRAMMARC_MAX_TRIANGLES``, else
    ``MAX_TRIANGLES``."""
    return max_triangles if max_triangles is not None else int(os.environ.get("GRAMMARC_MAX_TRIANGLES",
                                                                              MAX_TRIANGLES))


def mesh_triangles(mesh: MeshChunk) -> int:
    """Triangles of the mesh table's faces: V + 2R - 4F (each face V_f + 2 H_f - 2, R_f = H_f + 1)."""
    n_faces = len(mesh.face_offsets) - 1
    n_rings = len(mesh.ring_offsets) - 1
    return max(0, int(mesh.ring_offsets[-1]) + 2 * n_rings - 4 * n_faces) if n_faces else 0


def _columns(record: Mapping) -> tuple[list[str], np.ndarray, np.ndarray, MeshChunk, LotOrigins]:
    """Asset names, ``asset`` (N,) int64, ``xform`` (N, 3, 4), the mesh table of a record and the lot origins
    they are relative to (its ``lot_origin``, ``model.records.LotOrigins``)."""
    names = [str(n) for n in np.asarray(record["assets"]).reshape(-1)]
    asset = np.asarray(record.get("asset", np.zeros(0)), np.int64).reshape(-1)
    xform = np.asarray(record.get("xform", np.zeros((0, 3, 4))), np.float32)
    if xform.shape != (len(asset), 3, 4):
        raise ValueError(f"xform: expected ({len(asset)}, 3, 4), got {xform.shape}")
    if len(asset) and (asset.min() < 0 or asset.max() >= len(names)):
        raise ValueError(f"asset: index out of range [0, {len(names)})")
    return names, asset, xform, record_mesh(record) or MeshChunk.empty(), LotOrigins.from_table(record.get("lot_origin"))


def _world_mesh(mesh: MeshChunk, origins: LotOrigins) -> MeshChunk:
    """``mesh`` with its vertices in world coordinates (float64), its lots' ``origins`` added."""
    return replace(mesh, vertices=mesh.world(origins)) if len(origins.lot) else mesh


# -------------------------------------------------------------------------------------------- writers


class BakedWriter(WriterBlock):
    """Collects TerminalChunks and writes them baked into one mesh on close: .obj, .ply, .stl or .glb.

    The interface of ``InstanceWriter``: the format follows the path's extension. OBJ is streamed: each
    chunk is baked as it comes and appended to a temporary file next to ``path`` (its vertices, then its
    triangles indexing them from the vertices written before), so memory holds one chunk's mesh, not the
    city's (four times the size of the OBJ file when kept whole). PLY, STL and GLB need the whole mesh (counts in
    their headers, one buffer), so their chunks are kept until ``close()``, which bakes and exports them
    (PLY and STL with trimesh, GLB with ``io.gltf.baked_glb``). Either way the writer counts the
    triangles chunks will make as they come and refuses a chunk that would pass ``max_triangles``; the
    file is renamed onto ``path`` only when complete (an OBJ's texture folder and ``.mtl`` just before it),
    so ``abort()`` (or an exception inside ``with``) leaves nothing there.

    Parameters
    ----------
    path : str or os.PathLike
        The output file, ``.obj``, ``.ply``, ``.stl`` or ``.glb``. Its directory must exist.
    assets : sequence of str
        Asset names, unique; ``TerminalChunk.asset`` indexes them.
    symbols : sequence of str
        Symbol names (kept for the interface; meshes carry no symbols).
    meta : dict
        Facts about the run; ``meta["grammar"]`` and ``meta["asset_roots"]`` give the asset roots when
        ``asset_roots`` is not given.
    asset_roots : sequence of path-like, optional
        Folders to resolve file assets in.
    max_triangles : int, optional
        The limit; by default ``GRAMMARC_MAX_TRIANGLES`` or ``MAX_TRIANGLES``.
    lod : str, optional
        Level of detail of the assets (``load_asset``).
    bake_origin : (3,) float, optional
        World point subtracted from every baked vertex (``--bake-origin``). By default OBJ (text with every
        digit) is in world coordinates, and the float32 formats (PLY, STL, GLB) are too when the mesh lies
        within ``FLOAT32_EXACT`` of the world's origin, else relative to the middle of its box in whole
        metres (a float32 step is 0.5 m at a UTM northing). The origin is written into the file: OBJ, PLY and
        STL headers say ``origin X Y Z``; a GLB's node is translated to it (JSON numbers are double), so
        viewers place the city in world coordinates.
    """

    FORMATS: ClassVar[dict[str, str]] = {".obj": "obj", ".ply": "ply", ".stl": "stl", ".glb": "glb"}
    #: It writes baked meshes: what ``--bake`` asks for (``grammarc.io.writers``).
    bakes: ClassVar[bool] = True

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str],
                 meta: dict, asset_roots: Sequence[str | os.PathLike] | None = None,
                 max_triangles: int | None = None, lod: str | None = None,
                 bake_origin: Sequence[float] | None = None):
        self.path = Path(path)
        suffix = self.path.suffix.lower()
        if suffix not in self.FORMATS:
            raise UsageError(f"cannot write `{path}` as a mesh: format `{suffix or '(none)'}` is not "
                             f"one of {', '.join(self.FORMATS)}")
        self._file_type = self.FORMATS[suffix]
        names = [str(n) for n in assets]
        if len(set(names)) != len(names):
            raise ValueError("assets: names must be unique")
        self._symbols = list(symbols)
        self._meta = dict(meta)
        self._library = asset_library(names, {"meta": self._meta}, asset_roots, lod)
        self.max_triangles = triangle_limit(max_triangles)
        self._origin = None if bake_origin is None else np.asarray(bake_origin, np.float64).reshape(3)
        self._chunks: list[tuple[TerminalChunk, np.ndarray | None]] = []  # kept for close(), with their looks
        #: The record's materials, and the looks (``_looks``) met so far, each an OBJ material.
        self._materials = MaterialTable()
        self._look_ids: dict[int, int] = {}
        self._triangles = 0
        self._rows = 0
        self._state = "open"
        self._counts: dict = {}
        self._made = {"triangles": 0, "vertices": 0, "polygons": 0, "mesh_faces": 0, "mesh_vertices": 0}
        self._uv_vertices = 0  # vertices of the streamed OBJ with a texture coordinate (vt)
        self._tmpdir: str | None = None
        self._file = None  # the output being written, in _tmpdir: OBJ from the first chunk, else on close
        if self._file_type == "obj":
            self._open_file()
            header = f"grammarc {self._meta.get('grammarc', '')} bake of {self._meta.get('grammar', '')}"
            # an OBJ is in world coordinates unless --bake-origin moved it: it names an origin only then, or
            # for its coordinate system
            origin = self._origin if self._origin is not None else np.zeros(3)
            named = f"# {_origin_text(origin, self._meta.get('crs'))}\n" \
                if self._origin is not None or self._meta.get("crs") else ""
            self._file.write(f"# {' '.join(header.split())}\n{named}mtllib {self._mtl_path.name}\n".encode())

    def write(self, chunk: TerminalChunk) -> None:
        """Bake a chunk into the OBJ, or keep it for ``close()`` (not copied: do not modify it).

        Raises
        ------
        ValueError
            If the writer is not open, or the chunk's columns disagree (shapes, asset index range).
        UsageError
            If the record would pass ``max_triangles``; the writer has aborted.
        AssetError
            If an asset the chunk uses cannot be loaded; the writer has aborted.
        """
        if self._state != "open":
            raise ValueError(f"write to a BakedWriter that is {self._state}")
        asset = np.asarray(chunk.asset)
        if asset.ndim != 1 or np.shape(chunk.xform) != (len(asset), 3, 4):
            raise ValueError(f"TerminalChunk: asset {asset.shape} and xform {np.shape(chunk.xform)} disagree")
        if len(asset) and (asset.min() < 0 or asset.max() >= len(self._library.names)):
            raise ValueError(f"TerminalChunk.asset: index out of range [0, {len(self._library.names)})")
        try:
            triangles = made_triangles(self._library, asset, chunk.mesh)
            if self._triangles + triangles > self.max_triangles:
                raise UsageError(
                    f"{self.path}: the baked mesh passes {self.max_triangles:,} triangles after "
                    f"{self._rows + len(asset):,} instances; raise the limit with --max-triangles N "
                    "(GRAMMARC_MAX_TRIANGLES=N), bake a few lots with --select, or write an instance "
                    "record (.npz) or instanced .glb/.usdc instead"
                )
            looks = self._looks(chunk)
            if self._file is not None:
                mesh, source = bake_mesh(self._library, asset.astype(np.int64, copy=False), chunk.xform, chunk.mesh,
                                         self.max_triangles, chunk.uv, chunk.origins, chunk.lot)
                self._file.write(self._obj_groups(mesh, source, np.concatenate([chunk.lot, chunk.mesh.lot]), looks))
                self._count(mesh, chunk.mesh)
            else:
                self._chunks.append((chunk, looks))
        except BaseException:
            self.abort()
            raise
        self._triangles += triangles
        self._rows += len(asset)

    def _looks(self, chunk: TerminalChunk) -> np.ndarray | None:
        """(n + F,) int64: how each instance, then each face of the mesh table, looks: its material (a row of
        the writer's ``_materials``) times 2^32 plus its RGBA as a uint32; None where the chunk carries
        neither colours nor textures."""
        if chunk.color is None and chunk.materials is None:  # (a joined mesh table is white, not None)
            return None
        rgba = np.concatenate([chunk.colors(), chunk.mesh.colors()]).view(np.uint32).reshape(-1).astype(np.int64)
        if chunk.materials is None:
            return rgba
        return np.concatenate(self._materials.add(chunk)).astype(np.int64) << 32 | rgba

    def _look(self, look: int) -> int:
        """The OBJ material of a look, numbered as met."""
        return self._look_ids.setdefault(look, len(self._look_ids))

    def _obj_groups(self, mesh, source: np.ndarray, lot: np.ndarray, looks: np.ndarray | None) -> bytes:
        """A chunk's vertices and triangles as OBJ, the triangles in a group ``g lot_N`` per lot (the input's
        number), each lot's in one ``usemtl`` run per look when the chunk has colours or textures."""
        lot = lot[source]
        look = looks[source] if looks is not None else np.zeros(len(source), np.int64)
        order = np.lexsort((look, lot))
        lot, look = lot[order], look[order]
        new_lot = np.ones(len(lot), bool)
        new_lot[1:] = lot[1:] != lot[:-1]
        starts = np.flatnonzero(new_lot | np.r_[True, look[1:] != look[:-1]])
        lines = [(f"g lot_{lot[k]}\n" if new_lot[k] else "")
                 + (f"usemtl m{self._look(int(look[k]))}\n" if looks is not None else "") for k in starts.tolist()]
        # with texture coordinates a ``vt`` follows each ``v`` and faces index both, the vt numbers behind the v
        # numbers by the vertices written before without any
        uv = _texture(mesh)
        shift = self._made["vertices"] - self._uv_vertices
        faces = obj_bytes(np.zeros((0, 3)), mesh.faces[order] + self._made["vertices"],
                          uv=None if uv is None else np.zeros((0, 2)), uv_shift=shift)
        self._uv_vertices += len(mesh.vertices) if uv is not None else 0
        vertices = mesh.vertices if self._origin is None else mesh.vertices - self._origin
        return obj_bytes(vertices, np.zeros((0, 3), np.int64), uv=uv) + with_lines(faces, starts, lines)

    def _mtl(self) -> bytes:
        """The OBJ's material library: per look its colour (``Kd``, ``d``) and texture maps, the paths
        resolved in the asset roots and given relative to the OBJ (as written where no root holds them)."""
        materials = self._materials.table()
        lines = [f"# {len(self._look_ids)} materials of {self.path.name}"]
        for look, k in self._look_ids.items():
            rgba = np.array([look & 0xFFFFFFFF], np.uint32).view(np.uint8) / 255.0
            lines += [f"newmtl m{k}", "Kd {:.6g} {:.6g} {:.6g}".format(*rgba[:3]), f"d {rgba[3]:.6g}"]
            for channel, path in zip(MATERIAL_MAPS, materials[look >> 32]):
                if path and channel in MTL_MAPS:
                    lines.append(f"{MTL_MAPS[channel]} {self._texture_path(path)}")
        return ("\n".join(lines) + "\n").encode()

    def _texture_path(self, name: str) -> str:
        """A texture's path as the material library names it: relative to the OBJ where the asset roots
        hold it, in the OBJ's texture folder where it is a rule package's (``io.textures``), else as given."""
        found = locate(name, self._library.roots)
        if found is None:
            return name
        return self._textures.named(found[1], self._textures_path.name, self.path.parent.resolve())

    def _count(self, mesh, table: MeshChunk) -> None:
        made = self._made
        made["triangles"] += len(mesh.faces)
        made["vertices"] += len(mesh.vertices)
        made["polygons"] += int(mesh.metadata["n_polygons"])
        made["mesh_faces"] += int(len(table.face_offsets) - 1)
        made["mesh_vertices"] += len(table.vertices)

    def close(self) -> dict:
        """Bake the chunks, export the mesh next to ``path`` and rename it onto ``path``.

        Returns
        -------
        counts : dict
            ``instances``, ``mesh_faces``, ``mesh_vertices`` (as ``InstanceWriter``), and ``triangles``,
            ``vertices``, ``polygons`` of the baked mesh. Closing again returns the same counts.
        """
        if self._state == "closed":
            return dict(self._counts)
        if self._state == "aborted":
            raise ValueError("close of a BakedWriter that is aborted")
        try:
            if self._file is None:
                self._open_file()
                chunks, self._chunks = self._chunks, []
                mesh_table = MeshChunk.concat([c.mesh for c, _ in chunks])
                origins = LotOrigins.concat([c.origins for c, _ in chunks])
                lot = np.concatenate([c.lot for c, _ in chunks]) if chunks else np.zeros(0, np.int32)
                asset = np.concatenate([c.asset for c, _ in chunks]) if chunks else np.zeros(0, np.int64)
                xform = np.concatenate([c.xform for c, _ in chunks]) if chunks else np.zeros((0, 3, 4), np.float32)
                looks = _joined_looks(chunks)
                uv = None if all(c.uv is None for c, _ in chunks) else np.concatenate([c.texture() for c, _ in chunks])
                del chunks
                mesh, source = bake_mesh(self._library, asset.astype(np.int64, copy=False), xform, mesh_table,
                                         self.max_triangles, uv, origins, lot)
                del asset, xform, lot
                self._count(mesh, mesh_table)
                self._file.write(self._export(mesh, looks[source] if looks is not None else None))
                del mesh
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
            if self._file_type == "obj":
                staged = os.path.join(self._tmpdir, self._mtl_path.name)
                with open(staged, "wb") as mtl:
                    mtl.write(self._mtl())
                self._place_textures()
                os.replace(staged, self._mtl_path)
            os.replace(os.path.join(self._tmpdir, self.path.name), self.path)
        except BaseException:
            self.abort()
            raise
        shutil.rmtree(self._tmpdir, ignore_errors=True)
        self._state = "closed"
        self._counts = {"instances": self._rows, **self._made}
        return dict(self._counts)

    def abort(self) -> None:
        """Drop the chunks and the partial file; a file already at ``path`` is left untouched."""
        if self._state == "open":
            self._state = "aborted"
            self._chunks = []
            if self._file is not None:
                self._file.close()
            if self._tmpdir is not None:
                shutil.rmtree(self._tmpdir, ignore_errors=True)

    def _open_file(self) -> None:
        """The output's file, in a private directory next to it (same filesystem, for the rename), with
        the umask's permissions as the npz writer's output has (mkstemp would give 0600)."""
        self._tmpdir = private_folder(self.path)
        self._textures = PackagedTextures(self._meta, self._library.roots, Path(self._tmpdir) / "textures")
        self._file = open(os.path.join(self._tmpdir, self.path.name), "xb")  # noqa: SIM115 - closed by close/abort

    def _place_textures(self) -> None:
        """The OBJ's texture folder into place, before its material library: the copies of a rule package's
        textures, or no folder (an older build's removed) when the OBJ names none."""
        if self._textures.copied:
            replace_folder(self._textures.into, self._textures_path, Path(self._tmpdir) / "replaced")
        elif self._textures_path.is_dir():
            shutil.rmtree(self._textures_path)

    @property
    def _mtl_path(self) -> Path:
        """The OBJ's material library, beside it: ``city.obj`` -> ``city.mtl``."""
        return self.beside(self.path)[0][0]

    @property
    def _textures_path(self) -> Path:
        """The OBJ's texture folder, beside it: ``city.obj`` -> ``city.obj.textures``."""
        return self.beside(self.path)[1][0]

    @staticmethod
    def beside(path: Path) -> tuple[list[Path], list[Path]]:
        """The files and folders written beside ``path`` (``io.written_paths``): an OBJ's material library
        and its texture folder (``io.textures``)."""
        if path.suffix.lower() != ".obj":
            return [], []
        return [path.with_suffix(".mtl")], [path.with_name(f"{path.name}.textures")]

    def _export(self, mesh, looks: np.ndarray | None) -> bytes:
        """The bytes of a PLY (with vertex colours where the record has colours) or STL (binary), or a GLB
        with a material per look (``io.gltf.baked_glb``); ``looks`` (T,) int64 per triangle (``_looks``).
        The vertices are moved to the bake origin (the class docstring) first."""
        origin = self._origin if self._origin is not None else float32_origin(mesh.vertices)
        mesh.vertices = mesh.vertices - origin
        if self._file_type == "glb":
            materials = self._materials.table()
            return baked_glb(mesh.vertices, mesh.faces, looks, materials, self._library.roots, self._meta,
                             _texture(mesh), origin=origin)
        if self._file_type == "ply" and looks is not None:
            import trimesh

            colors = np.full((len(mesh.vertices), 4), 255, np.uint8)
            rgba = (looks & 0xFFFFFFFF).astype(np.uint32).view(np.uint8).reshape(-1, 4)
            colors[mesh.faces.reshape(-1)] = np.repeat(rgba, 3, axis=0)
            mesh.visual = trimesh.visual.ColorVisuals(mesh, vertex_colors=colors)
        mesh.metadata = {}
        if self._file_type == "stl":
            data = bytearray(mesh.export(file_type="stl"))
            data[:80] = f"grammarc {_origin_text(origin, self._meta.get('crs'))}".encode().ljust(80)[:80]  # free text
            return bytes(data)
        data = mesh.export(file_type=self._file_type)
        # a comment line in the header, after the format line (PLY allows comments anywhere in the header)
        head, _, rest = data.partition(b"\n")
        return head + f"\ncomment grammarc {_origin_text(origin, self._meta.get('crs'))}".encode() + b"\n" + rest


#: Metres from the world's origin within which float32 coordinates keep a step of 1 mm or less (2^13).
FLOAT32_EXACT = 8192.0


def float32_origin(vertices: np.ndarray) -> np.ndarray:
    """(3,) float64: where float32 vertices keep millimetres: 0 when all lie within ``FLOAT32_EXACT`` of the
    world's origin, else the middle of their box in whole metres."""
    if not len(vertices) or np.abs(vertices).max() <= FLOAT32_EXACT:
        return np.zeros(3)
    return np.round((vertices.min(axis=0) + vertices.max(axis=0)) / 2)


def _origin_text(origin: np.ndarray, crs: str | None) -> str:
    """``origin X Y Z``: the world point a baked file's coordinates are relative to, and ``crs NAME``, the
    coordinate system of its world, where the lots had one with a short name (an EPSG code)."""
    text = "origin " + " ".join(f"{v:.17g}" for v in np.asarray(origin, np.float64))
    return text + (f" crs {crs}" if crs and len(crs) <= 32 and "\n" not in crs else "")


def _joined_looks(chunks: list) -> np.ndarray | None:
    """The looks of kept chunks (``BakedWriter._looks``), instances then faces as ``MeshChunk.concat`` and
    ``_bake`` order them; white without texture for chunks without any; None when no chunk has any."""
    if all(lk is None for _, lk in chunks):
        return None
    white = np.int64(0xFFFFFFFF)
    looks = [np.full(len(c.asset) + len(c.mesh.lot), white) if lk is None else lk for c, lk in chunks]
    counts = [len(c.asset) for c, _ in chunks]
    return np.concatenate([lk[:n] for lk, n in zip(looks, counts)] + [lk[n:] for lk, n in zip(looks, counts)])


#: The OBJ material statement of each texture channel that MTL has (``norm``, ``map_Pr``, ``map_Pm`` and
#: ``map_Ke`` are the PBR extension of MTL that Blender and others read).
MTL_MAPS = {"colormap": "map_Kd", "bumpmap": "map_bump", "specularmap": "map_Ks", "opacitymap": "map_d",
            "normalmap": "norm", "emissivemap": "map_Ke", "roughnessmap": "map_Pr", "metallicmap": "map_Pm"}


def _texture(mesh) -> np.ndarray | None:
    """A baked mesh's texture coordinates (V, 2), None when it has none."""
    return getattr(mesh.visual, "uv", None)


#: The extensions this module writes (``grammarc.io.writers``): all baked.
WRITERS = dict.fromkeys(BakedWriter.FORMATS, BakedWriter)
