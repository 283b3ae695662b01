"""Baking an instance record into one triangle mesh, and the mesh writers (.obj, .ply, .stl, .glb).

A record (README, "The record") holds instances (an asset and the affine map of its unit box) and leaf
polygons (the mesh table). Baking expands every instance into the asset's triangles and triangulates the
polygons, so that the city can be looked at, exported, or measured against PRT (``grammarc.conform``).

Assets, each an ``AssetMesh`` in the unit box [0, 1]^3:

* ``builtin:cube``: the unit cube, 8 vertices, 12 triangles, normals outward;
* ``builtin:quad``: the unit square on z = 0, normal +z, 2 triangles;
* ``builtin:cylinder``: axis along y through (0.5, ., 0.5), radius 0.5, y in [0, 1], 16 sides, capped
  (60 triangles); ``builtin:cylinderN`` the same with N sides;
* ``builtin:L``, ``H``, ``U``, ``T``: the paper's mass-model blocks, prisms over outlines with wings a
  third of the box thick;
* a file (OBJ, or any mesh format trimesh reads), resolved in the asset roots as the compiler resolves it
  (``grammarc.io.assets.resolve_asset``) and loaded with trimesh, then mapped from its bounding box onto
  [0, 1]^3 as CityEngine fits an inserted asset to the scope. An axis along which the asset is flat stays
  flat (at 0): there is nothing to stretch.

Instances are expanded per asset, all instances of one asset at once: ``einsum`` of the (n, 3, 3) linear
parts with the asset's (v, 3) vertices, faces offset by ``arange(n) * v``. An instance whose transform
mirrors (negative determinant) gets its triangles reversed, so a mirrored cube still faces outward; a flat
transform (a quad's zero column) keeps the asset's winding, whose normal is then ``col0 x col1``, the
face's normal by the record's convention.

Polygons of the mesh table are triangulated in the plane of their outline's Newell normal: a convex face
without holes as a fan (vectorized over all such faces), any other face with mapbox-earcut (one call per
face), triangles turned to face along the normal.

Polygon counts. Conformance compares face counts with PRT, whose encoder returns polygons, not triangles,
so ``bake`` also counts the polygons before triangulation, in the mesh's ``metadata``:

* a built-in counts its faces: cube 6 quads, quad 1, cylinder 16 quads and two 16-gons;
* an OBJ asset counts its ``f`` lines (trimesh triangulates faces as it loads them, and keeps no count
  of them), each a polygon of as many vertices as the line has; other formats count triangles;
* a face of the mesh table counts each of its rings, outline and holes, as PRT's encoder returns them
  (README of the PRT kit: "a face with holes comes back as its outer ring plus one face per hole ring").

Memory: the baked mesh holds ~60 bytes a triangle (float64 vertices, int64 faces), so ``bake`` counts the
triangles before it allocates anything and refuses a record beyond ``max_triangles``.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache, lru_cache
from pathlib import Path
from typing import ClassVar

import numpy as np

from grammarc.constants import LIMITS
from grammarc.errors import AssetError, UsageError
from grammarc.io import WriterBlock
from grammarc.io.assets import builtin_name, resolve_asset
from grammarc.io.obj import ObjError, obj_bytes, read_obj
from grammarc.model.records import MeshChunk, TerminalChunk
from grammarc.ragged import fan_out, offsets_from_counts, segment_reduce

__all__ = [
    "LOD_STAND_IN",
    "MAX_TRIANGLES",
    "AssetMesh",
    "BakedWriter",
    "asset_library",
    "bake",
    "builtin_mesh",
    "count_triangles",
    "load_asset",
    "triangulate_polygons",
]

#: Default limit of ``bake`` (``constants.Limits.max_triangles``).
MAX_TRIANGLES = LIMITS.max_triangles
#: ``--lod builtin``: a built-in cube stands in for an asset file that is missing.
LOD_STAND_IN = "builtin"
#: Vertices expanded per einsum call: bounds the float64 temporaries of a block of instances (~50 MB).
_BLOCK_VERTICES = 1 << 21
#: Sides of ``builtin:cylinder``.
CYLINDER_SIDES = 16
#: The paper's mass-model blocks (section 3.1, after Schmitt): outlines in thirds of the unit square, as
#: (x, z) counter-clockwise seen from +y; wings one third thick.
BLOCKS = {
    "L": [(0, 0), (0, 3), (3, 3), (3, 2), (1, 2), (1, 0)],
    "U": [(0, 0), (0, 3), (3, 3), (3, 0), (2, 0), (2, 2), (1, 2), (1, 0)],
    "T": [(1, 0), (1, 2), (0, 2), (0, 3), (3, 3), (3, 2), (2, 2), (2, 0)],
    "H": [(0, 0), (0, 3), (1, 3), (1, 2), (2, 2), (2, 3), (3, 3), (3, 0), (2, 0), (2, 1), (1, 1), (1, 0)],
}
#: An asset's extent below this (in its own units) is a flat axis, mapped to 0 rather than stretched.
_FLAT = 1e-12
#: A polygon's turn at a vertex counts as convex above ``-_CONVEX * |e_prev| |e_next| |n|`` (collinear
#: vertices, and rounding of float32 world coordinates, are not concavities).
_CONVEX = 1e-7


@dataclass(frozen=True, eq=False)
class AssetMesh:
    """An asset's triangles in its unit box, and the polygons they came from.

    Attributes
    ----------
    vertices : (v, 3) float64
        In [0, 1]^3; the bounding box of a non-flat asset is exactly the unit box.
    faces : (t, 3) int64
        Triangles, counter-clockwise seen from outside.
    polygon_sizes : (p,) int64
        Vertex count of each polygon before triangulation (see the module docstring).
    """

    vertices: np.ndarray
    faces: np.ndarray
    polygon_sizes: np.ndarray

    @property
    def n_triangles(self) -> int:
        return len(self.faces)

    @property
    def n_polygons(self) -> int:
        return len(self.polygon_sizes)


# --------------------------------------------------------------------------------------------- assets


@cache
def builtin_mesh(name: str) -> AssetMesh:
    """The mesh of a built-in asset: ``"cube"``, ``"quad"`` or ``"cylinder"`` (``builtin:`` optional).

    Examples
    --------
    >>> cube = builtin_mesh("builtin:cube")
    >>> cube.vertices.shape, cube.faces.shape, cube.n_polygons
    ((8, 3), (12, 3), 6)
    """
    bare = name.removeprefix("builtin:")
    if bare == "cube":
        # vertex i has coordinates (i & 1, i >> 1 & 1, i >> 2 & 1); each face's quad counter-clockwise
        # seen from outside, split along its first diagonal.
        vertices = np.array([[i & 1, i >> 1 & 1, i >> 2 & 1] for i in range(8)], np.float64)
        quads = np.array([
            [0, 4, 6, 2],  # x = 0
            [1, 3, 7, 5],  # x = 1
            [0, 1, 5, 4],  # y = 0
            [2, 6, 7, 3],  # y = 1
            [0, 2, 3, 1],  # z = 0
            [4, 5, 7, 6],  # z = 1
        ])  # fmt: skip
        return _frozen(vertices, _quads_to_triangles(quads), np.full(6, 4))
    if bare == "quad":
        vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float64)
        return _frozen(vertices, np.array([[0, 1, 2], [0, 2, 3]]), np.array([4]))
    if bare in BLOCKS:
        return _prism(np.array(BLOCKS[bare], dtype=np.float64) / 3.0)
    if builtin_name(bare) and bare.startswith("cylinder"):
        k = int(bare.removeprefix("cylinder") or CYLINDER_SIDES)
        # a = 0 and pi put vertices on x = 0 and 1; increasing a turns counter-clockwise seen from +y
        angle = 2 * np.pi * np.arange(k) / k
        return _prism(np.stack([0.5 + 0.5 * np.cos(angle), 0.5 - 0.5 * np.sin(angle)], axis=1))
    raise AssetError(f"unknown built-in asset `{name}` (built-ins: cube, quad, cylinder, cylinderN, L, H, U, T)")


def _prism(outline: np.ndarray) -> AssetMesh:
    """The prism over ``outline`` ((k, 2) as (x, z), counter-clockwise seen from +y) from y = 0 to 1,
    fitted to the unit box: side quads, then the top and bottom caps (earcut: the blocks are concave)."""
    import mapbox_earcut

    k = len(outline)
    ring = np.stack([outline[:, 0], np.zeros(k), outline[:, 1]], axis=1)
    vertices = np.concatenate([ring, ring + [0.0, 1.0, 0.0]])
    i = np.arange(k)
    j = (i + 1) % k
    sides = np.stack([i, j, j + k, i + k], axis=1)  # outward: bottom i, bottom j, top j, top i
    cap = mapbox_earcut.triangulate_float64(outline, np.array([k], dtype=np.uint32)).reshape(-1, 3)
    # the top faces +y: counter-clockwise from +y is clockwise in (x, z); the bottom the other way
    a, b, c = outline[cap[:, 0]], outline[cap[:, 1]], outline[cap[:, 2]]
    turn = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    top = np.where((turn < 0)[:, None], cap, cap[:, ::-1])
    top, bottom = top + k, top[:, ::-1]
    faces = np.concatenate([_quads_to_triangles(sides), top, bottom]).astype(np.int64)
    return _frozen(_fitted(vertices), faces, np.array([4] * k + [k, k]))


def load_asset(name: str, asset_roots: Sequence[str | os.PathLike] = (), lod: str | None = None) -> AssetMesh:
    """Load an asset by its record name: a built-in, or a file resolved in ``asset_roots``.

    Parameters
    ----------
    name : str
        As in the record's ``assets``: ``builtin:cube`` or a path relative to an asset root.
    asset_roots : sequence of path-like
        Folders searched in order (the grammar's folder, ``--assets`` folders, a rule package's
        ``asset_roots``).
    lod : str, optional
        A level of detail: ``window.obj`` is replaced by ``window.<lod>.obj`` beside it where that file
        exists (the paper's Pompeii had high, middle and low LoD assets). ``builtin`` gives the built-in
        cube as a stand-in for an asset file that no root holds, where otherwise that is an error.

    Returns
    -------
    AssetMesh
        The asset mapped from its bounding box onto [0, 1]^3.

    Raises
    ------
    AssetError
        If the name is refused (absolute, leaves the roots), no root holds it, or trimesh cannot read it.
    """
    if name.startswith("builtin:"):
        return builtin_mesh(name)
    roots = [Path(r) for r in asset_roots]
    resolved = resolve_asset(name, roots)
    if resolved.problem:
        raise AssetError(resolved.problem)
    if resolved.path is None:
        if lod == LOD_STAND_IN:
            return builtin_mesh("builtin:cube")
        shown = ", ".join(str(r) for r in asset_roots) or "(no asset roots given)"
        raise AssetError(f"asset `{name}` not found in {shown} (--lod {LOD_STAND_IN} puts a cube in its place)")
    path = resolved.path
    if lod and lod != LOD_STAND_IN:
        substitute = path.with_name(f"{path.stem}.{lod}{path.suffix}")
        path = substitute if substitute.is_file() else path
    return _load_file(path, path.stat().st_mtime_ns)


@lru_cache(maxsize=64)
def _load_file(path: Path, mtime_ns: int) -> AssetMesh:
    """A file asset, cached by path and modification time (a city uses a few assets many times).

    OBJ files are read by ``io.obj`` (geometry only: their materials would need Pillow), their polygons
    fanned into triangles; other formats go through trimesh.
    """
    if path.suffix.lower() == ".obj":
        try:
            vertices, polygons = read_obj(path.read_text(encoding="utf-8", errors="replace"), str(path))
        except (OSError, ObjError) as error:
            raise AssetError(f"cannot read asset `{path}`: {error}") from error
        polygons = [f for f in polygons if len(f) >= 3 and (f >= 0).all() and (f < len(vertices)).all()]
        sizes = np.array([len(f) for f in polygons], np.int64)
        faces = np.concatenate([np.stack([np.full(len(f) - 2, f[0]), f[1:-1], f[2:]], axis=1)
                                for f in polygons]) if polygons else np.zeros((0, 3), np.int64)
        return _frozen(_fitted(vertices), faces, sizes)
    import trimesh

    try:
        mesh = trimesh.load(path, force="mesh", process=False)
    except Exception as error:
        raise AssetError(f"cannot read asset `{path}`: {error}") from error
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), np.float64).reshape(-1, 3)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), np.int64).reshape(-1, 3)
    return _frozen(_fitted(vertices), faces, np.full(len(faces), 3, np.int64))


def _fitted(vertices: np.ndarray) -> np.ndarray:
    """Vertices mapped from their bounding box onto [0, 1]^3, as CityEngine fits an asset to a scope;
    a flat axis maps to 0."""
    if not len(vertices):
        return vertices
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    extent = high - low
    flat = extent <= _FLAT * max(1.0, float(np.abs(vertices).max()))
    scale = np.divide(1.0, extent, out=np.zeros(3), where=~flat)  # a flat axis maps to 0
    return (vertices - low) * scale


def _quads_to_triangles(quads: np.ndarray) -> np.ndarray:
    """(2q, 3) triangles of (q, 4) quads, each split along its diagonal 0-2, in quad order."""
    return np.stack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]], axis=1).reshape(-1, 3)


def _frozen(vertices, faces, sizes) -> AssetMesh:
    arrays = [np.array(vertices, np.float64), np.array(faces, np.int64), np.array(sizes, np.int64)]
    for array in arrays:
        array.flags.writeable = False  # cached and shared: nobody may change them
    return AssetMesh(*arrays)


class _Library:
    """Asset meshes of a record's asset names, loaded when first used."""

    def __init__(self, names: Sequence[str], roots: Sequence[str | os.PathLike], lod: str | None = None):
        self.names = [str(n) for n in names]
        self.roots = [Path(r) for r in roots]
        self.lod = lod
        self._meshes: dict[int, AssetMesh] = {}

    def __getitem__(self, index: int) -> AssetMesh:
        if index not in self._meshes:
            self._meshes[index] = load_asset(self.names[index], self.roots, self.lod)
        return self._meshes[index]

    def triangles(self, used: np.ndarray) -> int:
        """Triangles of ``used[a]`` instances of each asset ``a``, ``used`` (A,) int64."""
        return sum(int(used[a]) * self[a].n_triangles for a in np.flatnonzero(used))


# ---------------------------------------------------------------------------------------- the record


def asset_library(names: Sequence[str], record: Mapping, asset_roots=None, lod: str | None = None) -> _Library:
    """The meshes of asset ``names``, loaded when first used from ``asset_roots`` or the roots that the
    record's meta names (the grammar's folder, then its ``asset_roots``), at level of detail ``lod``."""
    return _Library(names, _roots(record, asset_roots), lod)


def count_triangles(record: Mapping, asset_roots: Sequence[str | os.PathLike] | None = None,
                    lod: str | None = None) -> int:
    """The number of triangles ``bake`` makes of ``record`` at most, without baking it.

    Loads the assets the record uses (not the mesh). Faces of the mesh table count ``V + 2H - 2``
    triangles (V vertices in all rings, H holes), what earcut makes of a simple polygon.
    """
    names, asset, _, mesh = _columns(record)
    library = asset_library(names, record, asset_roots, lod)
    return library.triangles(np.bincount(asset, minlength=len(names))) + _mesh_triangles(mesh)


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
    names, asset, xform, mesh = _columns(record)
    return _bake(asset_library(names, record, asset_roots), asset, xform, mesh, max_triangles)


def _bake(library: _Library, asset: np.ndarray, xform: np.ndarray, mesh: MeshChunk, max_triangles: int):
    """``bake`` of a record's columns, its assets in ``library``."""
    import trimesh

    used = np.bincount(asset, minlength=len(library.names)).astype(np.int64)
    n_triangles = library.triangles(used) + _mesh_triangles(mesh)
    if n_triangles > max_triangles:
        raise UsageError(
            f"baking this record makes {n_triangles:,} triangles, more than the limit of "
            f"{max_triangles:,}; raise it (bake(..., max_triangles=N), or GRAMMARC_MAX_TRIANGLES=N for "
            "the mesh writers) or write an instance record (.npz) instead"
        )
    assets = np.flatnonzero(used)
    n_vertices = sum(int(used[a]) * len(library[a].vertices) for a in assets) + len(mesh.vertices)
    vertices = np.empty((n_vertices, 3), np.float64)
    faces = np.empty((n_triangles, 3), np.int64)
    face_sizes = np.zeros(1, np.int64)
    n_polygons = 0
    v0 = t0 = 0
    order = np.argsort(asset, kind="stable")  # instances grouped by asset, in record order within each
    starts = offsets_from_counts(used)
    for a in assets:
        shape = library[a]
        rows = order[starts[a] : starts[a + 1]]
        v0, t0 = _expand(shape, xform, rows, vertices, faces, v0, t0)
        face_sizes = _add_counts(face_sizes, shape.polygon_sizes, int(used[a]))
        n_polygons += int(used[a]) * shape.n_polygons
    if len(mesh.face_offsets) > 1:
        vertices[v0:] = mesh.vertices
        triangles = triangulate_polygons(mesh.vertices, mesh.ring_offsets, mesh.face_offsets)
        faces[t0 : t0 + len(triangles)] = triangles + v0
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
    return trimesh.Trimesh(vertices=vertices, faces=faces[:t0], process=False, metadata=metadata)


def _expand(shape: AssetMesh, xform: np.ndarray, rows: np.ndarray, vertices: np.ndarray,
            faces: np.ndarray, v0: int, t0: int) -> tuple[int, int]:
    """Write the instances ``rows`` of one asset at ``vertices[v0:]``, ``faces[t0:]``; the new ends."""
    nv, nt = len(shape.vertices), len(shape.faces)
    if nv == 0:
        return v0, t0
    block = max(1, _BLOCK_VERTICES // nv)
    for b in range(0, len(rows), block):
        part = xform[rows[b : b + block]].astype(np.float64)  # (n, 3, 4)
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


def _mesh_triangles(mesh: MeshChunk) -> int:
    """Triangles of the mesh table's faces: V + 2R - 4F (each face V_f + 2 H_f - 2, R_f = H_f + 1)."""
    n_faces = len(mesh.face_offsets) - 1
    n_rings = len(mesh.ring_offsets) - 1
    return max(0, int(mesh.ring_offsets[-1]) + 2 * n_rings - 4 * n_faces) if n_faces else 0


def _columns(record: Mapping) -> tuple[list[str], np.ndarray, np.ndarray, MeshChunk]:
    """Asset names, ``asset`` (N,) int64, ``xform`` (N, 3, 4) and the mesh table of a record."""
    names = [str(n) for n in np.asarray(record["assets"]).reshape(-1)]
    asset = np.asarray(record.get("asset", np.zeros(0)), np.int64).reshape(-1)
    xform = np.asarray(record.get("xform", np.zeros((0, 3, 4))), np.float32)
    if xform.shape != (len(asset), 3, 4):
        raise ValueError(f"xform: expected ({len(asset)}, 3, 4), got {xform.shape}")
    if len(asset) and (asset.min() < 0 or asset.max() >= len(names)):
        raise ValueError(f"asset: index out of range [0, {len(names)})")
    mesh = record.get("mesh")
    if mesh is None and "mesh_face_offsets" in record:
        mesh = MeshChunk(
            vertices=np.asarray(record["mesh_vertices"]),
            ring_offsets=np.asarray(record["mesh_ring_offsets"], np.int64),
            face_offsets=np.asarray(record["mesh_face_offsets"], np.int64),
            lot=np.asarray(record.get("mesh_lot", np.zeros(0, np.int32))),
            symbol=np.asarray(record.get("mesh_symbol", np.zeros(0, np.int32))),
        )
    if mesh is None:
        mesh = MeshChunk.empty()
    return names, asset, xform, mesh


def _roots(record: Mapping, asset_roots) -> list[Path]:
    """``asset_roots``, or the roots a record's meta names: the grammar's folder, then ``asset_roots``."""
    if asset_roots is not None:
        return [Path(r) for r in asset_roots]
    meta = record.get("meta")
    if not isinstance(meta, Mapping):
        return []
    roots = [Path(meta["grammar"]).parent] if meta.get("grammar") else []
    return roots + [Path(r) for r in meta.get("asset_roots", ())]


# ------------------------------------------------------------------------------------------ polygons


def triangulate_polygons(vertices: np.ndarray, ring_offsets: np.ndarray,
                         face_offsets: np.ndarray) -> np.ndarray:
    """Triangles of planar polygons with holes, facing along each outline's Newell normal.

    Parameters
    ----------
    vertices : (V, 3) float
        Ring vertices, ring after ring.
    ring_offsets : (R+1,) int64
        Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r+1]]``.
    face_offsets : (F+1,) int64
        Face ``f`` is rings ``face_offsets[f]:face_offsets[f+1]``: its outline, then its holes.

    Returns
    -------
    (T, 3) int64
        Indices into ``vertices``; the convex faces without holes first (fans), then the others
        (mapbox-earcut), each group in face order. A face whose outline has no area gives none.

    Examples
    --------
    >>> square = np.array([[0, 0, 0], [0, 0, 4], [4, 0, 4], [4, 0, 0],   # outline, normal +y
    ...                    [1, 0, 1], [3, 0, 1], [3, 0, 3], [1, 0, 3]], float)  # hole
    >>> triangulate_polygons(square, np.array([0, 4, 8]), np.array([0, 2])).shape
    (8, 3)
    """
    vertices = np.asarray(vertices, np.float64)
    ring_offsets = np.asarray(ring_offsets, np.int64)
    face_offsets = np.asarray(face_offsets, np.int64)
    n_faces = len(face_offsets) - 1
    if n_faces == 0:
        return np.zeros((0, 3), np.int64)
    ring_counts = np.diff(ring_offsets)
    n_rings = len(ring_counts)
    ring = np.repeat(np.arange(n_rings), ring_counts)  # (V,) ring of each vertex
    start = ring_offsets[:-1][ring]
    at = np.arange(len(vertices))
    after = np.where(at + 1 < start + ring_counts[ring], at + 1, start)  # successor in the ring
    before = np.where(at > start, at - 1, start + ring_counts[ring] - 1)
    local = vertices - vertices[start]  # relative to each ring's first vertex: no loss far from 0
    newell = segment_reduce(np.add, np.cross(local, local[after]), ring_offsets, 0.0)  # (R, 3)
    outline = face_offsets[:-1]  # (F,) the outline ring of each face
    normal = newell[outline]  # (F, 3), twice the outline's vector area
    face_of_ring = np.repeat(np.arange(n_faces), np.diff(face_offsets))
    has_area = np.linalg.norm(normal, axis=1) > 0

    # Convex: every turn of the outline is to the left of the normal (or straight).
    e_in = vertices[at] - vertices[before]
    e_out = vertices[after] - vertices[at]
    n_vertex = normal[face_of_ring[ring]]
    turn = np.einsum("vi,vi->v", np.cross(e_in, e_out), n_vertex)
    slack = _CONVEX * np.linalg.norm(e_in, axis=1) * np.linalg.norm(e_out, axis=1)
    slack *= np.linalg.norm(n_vertex, axis=1)
    concave_ring = segment_reduce(np.add, (turn < -slack).astype(np.int64), ring_offsets, 0) > 0
    single = np.diff(face_offsets) == 1
    fan = has_area & single & ~concave_ring[outline] & (ring_counts[outline] >= 3)
    triangles = [_fans(ring_offsets[outline[fan]], ring_counts[outline[fan]])]

    rest = np.flatnonzero(has_area & ~fan)
    if len(rest):
        triangles.append(_earcut_faces(vertices, ring_offsets, face_offsets, normal, rest))
    return np.concatenate(triangles)


def _fans(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(sum(counts - 2), 3) int64 fan triangles (s, s+i+1, s+i+2) of rings at ``starts``, ``counts``."""
    parent, index = fan_out(counts - 2)
    first = starts[parent]
    return np.stack([first, first + index + 1, first + index + 2], axis=1)


def _earcut_faces(vertices: np.ndarray, ring_offsets: np.ndarray, face_offsets: np.ndarray,
                  normal: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Triangles of ``faces`` (k,) by mapbox-earcut, in each face's plane, turned along its normal."""
    try:
        import mapbox_earcut
    except ImportError as error:
        raise UsageError("triangulating concave polygons and polygons with holes needs mapbox-earcut: "
                         "pip install mapbox-earcut") from error
    unit = normal[faces] / np.linalg.norm(normal[faces], axis=1, keepdims=True)  # (k, 3)
    # In-plane axes u, v with u x v = n: cross n with the world axis it is least aligned with.
    helper = np.eye(3)[np.argmin(np.abs(unit), axis=1)]
    u = np.cross(unit, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(unit, u)
    out = []
    for k, f in enumerate(faces):
        first, last = ring_offsets[face_offsets[f]], ring_offsets[face_offsets[f + 1]]
        points = vertices[first:last] - vertices[first]
        plane = np.stack([points @ u[k], points @ v[k]], axis=1)
        ends = (ring_offsets[face_offsets[f] + 1 : face_offsets[f + 1] + 1] - first).astype(np.uint32)
        tris = mapbox_earcut.triangulate_float64(plane, ends).astype(np.int64).reshape(-1, 3)
        a, b, c = plane[tris[:, 0]], plane[tris[:, 1]], plane[tris[:, 2]]
        clockwise = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
        tris[clockwise] = tris[clockwise][:, [0, 2, 1]]
        out.append(tris + first)
    return np.concatenate(out)


# -------------------------------------------------------------------------------------------- writers


class BakedWriter(WriterBlock):
    """Collects TerminalChunks and writes them baked into one mesh on close: .obj, .ply, .stl or .glb.

    The interface of ``InstanceWriter``: the format follows the path's extension. OBJ is streamed: each
    chunk is baked as it comes and appended to a temporary file next to ``path`` (its vertices, then its
    triangles indexing them from the vertices written before), so memory holds one chunk's mesh (candler
    x500, 2.1 GB of OBJ, took 8.4 GB when kept whole). PLY, STL and GLB need the whole mesh (counts in
    their headers, one buffer), so their chunks are kept until ``close()``, which bakes and exports them
    with trimesh. Either way the writer counts the triangles chunks will make as they come and refuses a
    chunk that would pass ``max_triangles``; the file is renamed onto ``path`` only when complete, so
    ``abort()`` (or an exception inside ``with``) leaves nothing there.

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
    """

    FORMATS: ClassVar[dict[str, str]] = {".obj": "obj", ".ply": "ply", ".stl": "stl", ".glb": "glb"}

    def __init__(self, path: str | os.PathLike, *, assets: Sequence[str], symbols: Sequence[str],
                 meta: dict, asset_roots: Sequence[str | os.PathLike] | None = None,
                 max_triangles: int | None = None, lod: str | None = None):
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
        if max_triangles is None:
            max_triangles = int(os.environ.get("GRAMMARC_MAX_TRIANGLES", MAX_TRIANGLES))
        self.max_triangles = max_triangles
        self._chunks: list[tuple[np.ndarray, np.ndarray, MeshChunk]] = []
        self._triangles = 0
        self._rows = 0
        self._state = "open"
        self._counts: dict = {}
        self._made = {"triangles": 0, "vertices": 0, "polygons": 0, "mesh_faces": 0, "mesh_vertices": 0}
        self._tmpdir: str | None = None
        self._file = None  # the output being written, in _tmpdir: OBJ from the first chunk, else on close
        if self._file_type == "obj":
            self._open_file()
            header = f"grammarc {self._meta.get('grammarc', '')} bake of {self._meta.get('grammar', '')}"
            self._file.write(f"# {' '.join(header.split())}\n".encode())

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
        xform = np.asarray(chunk.xform)
        if asset.ndim != 1 or xform.shape != (len(asset), 3, 4):
            raise ValueError(f"TerminalChunk: asset {asset.shape} and xform {xform.shape} disagree")
        if len(asset) and (asset.min() < 0 or asset.max() >= len(self._library.names)):
            raise ValueError(f"TerminalChunk.asset: index out of range [0, {len(self._library.names)})")
        try:
            used = np.bincount(asset, minlength=len(self._library.names))
            triangles = self._library.triangles(used) + _mesh_triangles(chunk.mesh)
            if self._triangles + triangles > self.max_triangles:
                raise UsageError(
                    f"{self.path}: the baked mesh passes {self.max_triangles:,} triangles after "
                    f"{self._rows + len(asset):,} instances; raise the limit with --max-triangles N "
                    "(GRAMMARC_MAX_TRIANGLES=N), bake a few lots with --select, or write an instance "
                    "record (.npz) or instanced .glb/.usdc instead"
                )
            if self._file is not None:
                mesh = _bake(self._library, asset.astype(np.int64, copy=False), xform, chunk.mesh,
                             self.max_triangles)
                self._file.write(obj_bytes(mesh.vertices, mesh.faces + self._made["vertices"]))
                self._count(mesh, chunk.mesh)
            else:
                self._chunks.append((asset, xform, chunk.mesh))
        except BaseException:
            self.abort()
            raise
        self._triangles += triangles
        self._rows += len(asset)

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
                mesh_table = MeshChunk.concat([c[2] for c in chunks])
                asset = np.concatenate([c[0] for c in chunks]) if chunks else np.zeros(0, np.int64)
                xform = np.concatenate([c[1] for c in chunks]) if chunks else np.zeros((0, 3, 4), np.float32)
                del chunks
                mesh = _bake(self._library, asset.astype(np.int64, copy=False), xform, mesh_table,
                             self.max_triangles)
                del asset, xform
                self._count(mesh, mesh_table)
                self._file.write(self._export(mesh))
                del mesh
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
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
        self._tmpdir = tempfile.mkdtemp(prefix=f".{self.path.name}.tmp", dir=self.path.parent)
        self._file = open(os.path.join(self._tmpdir, self.path.name), "xb")  # noqa: SIM115 - closed by close/abort

    def _export(self, mesh) -> bytes:
        """The bytes of a PLY or STL (binary), or a GLB as trimesh writes a scene of one mesh."""
        mesh.metadata = {}  # glb writes metadata as extras; keep the file to geometry
        data = mesh.export(file_type=self._file_type)
        return data if isinstance(data, bytes) else data.encode("utf-8")

