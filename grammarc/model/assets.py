"""Asset meshes: what an inserted asset looks like, in its unit box, for every layer that draws or writes it.

An instance of the record is an asset name and the affine map of the asset's unit box [0, 1]^3 into the
world. The derivation (which trims inserted geometry), the renderer and every mesh writer need the asset's
triangles, loaded the same way: so they live on the model floor, below all of them.

Assets, each an ``AssetMesh`` in the unit box [0, 1]^3:

* ``builtin:cube``: the unit cube, 8 vertices, 12 triangles, normals outward;
* ``builtin:quad``: the unit square on z = 0, normal +z, 2 triangles;
* ``builtin:cylinder``: axis along y through (0.5, ., 0.5), radius 0.5, y in [0, 1], 16 sides, capped
  (60 triangles); ``builtin:cylinderN`` the same with N sides;
* ``builtin:coneN``: the cone over the N-sided base of ``cylinderN``, apex at (0.5, 1, 0.5);
* ``builtin:sphereNxM``: the sphere in the unit box, N segments around y and M from pole to pole;
* ``builtin:L``, ``H``, ``U``, ``T``: the paper's mass-model blocks, prisms over outlines with wings a
  third of the box thick;
* a file, resolved in the asset roots as the compiler resolves it (``resolve_asset``), read by the reader
  of its format (``READERS``), then mapped from its bounding box onto [0, 1]^3 as CityEngine fits an
  inserted asset to the scope. An axis along which the asset is flat stays flat (at 0): there is nothing
  to stretch.

Formats, and how their axes and units are read. CityEngine is y-up and places an asset as its file
declares it; ``i(asset, zUp)`` turns a file that declares nothing but was made z-up (the insert's work,
not the loader's). Every reader returns y-up vertices:

* OBJ (``model.obj``): no up axis nor unit in the format: y-up, as written;
* glTF and GLB (trimesh): y-up metres by the glTF specification; a scene's nodes are concatenated with
  their transforms applied;
* Collada ``.dae`` (trimesh, with pycollada): scaled to metres by ``<unit meter>`` and turned y-up from
  ``<up_axis>`` (``Z_UP``: -90 degrees about x, as ``zUp``; ``X_UP``: +90 degrees about z);
* FBX and 3DS (the Open Asset Import Library through ``assimp-py``, an optional package): assimp applies
  the node transforms and turns FBX's declared axes and 3DS's z-up to y-up; sizes stay in the file's
  units (assimp-py does not expose assimp's unit conversion). Without the package they are an error
  ``unsupported asset format: FBX`` (``ir.asset_names.unsupported_format``), at the insert when the
  grammar compiles;
* any other ending trimesh reads (PLY, STL, OFF...): as trimesh reads it.

Polygon counts. Conformance compares face counts with PRT, whose encoder returns polygons, not triangles,
so an ``AssetMesh`` keeps the polygons it was triangulated from (``polygon_sizes``):

* a built-in counts its faces: cube 6 quads, quad 1, cylinder 16 quads and two 16-gons;
* an OBJ asset counts its ``f`` lines (trimesh triangulates faces as it loads them, and keeps no count
  of them), each a polygon of as many vertices as the line has; other formats count triangles (their
  readers triangulate).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache, lru_cache
from pathlib import Path

import numpy as np

from grammarc.errors import AssetError
from grammarc.ir.asset_names import builtin_segments, resolve_asset, unsupported_format
from grammarc.model.obj import ObjError, read_obj

__all__ = ["LOD_STAND_IN", "AssetLibrary", "AssetMesh", "asset_library", "builtin_mesh", "load_asset",
           "record_roots"]

#: ``--lod builtin``: a built-in cube stands in for an asset file that is missing.
LOD_STAND_IN = "builtin"
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
    bounds : (2, 3) float64
        The lowest and highest corner of the asset's bounding box in its own coordinates and units, before
        it was fitted to the unit box (what ``assetInfo`` reports and ``keepSizeAndPosition`` keeps); the
        unit box for a built-in.
    """

    vertices: np.ndarray
    faces: np.ndarray
    polygon_sizes: np.ndarray
    bounds: np.ndarray

    @property
    def n_triangles(self) -> int:
        return len(self.faces)

    @property
    def n_polygons(self) -> int:
        return len(self.polygon_sizes)


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
        return _frozen(vertices, np.array([[0, 1, 2], [0, 2, 3]]), np.array([4]), ((0.0, 0.0, 0.0), (1.0, 1.0, 0.0)))
    if bare in BLOCKS:
        return _prism(np.array(BLOCKS[bare], dtype=np.float64) / 3.0)
    segmented = ("cylinder", (CYLINDER_SIDES,)) if bare == "cylinder" else builtin_segments(bare)
    if segmented is not None:
        kind, counts = segmented
        if kind == "cylinder":
            return _prism(_circle(counts[0]))
        if kind == "cone":
            return _cone(_circle(counts[0]))
        return _sphere(*counts)
    raise AssetError(f"unknown built-in asset `{name}` (built-ins: cube, quad, cylinder, cylinderN, coneN, "
                     "sphereNxM, L, H, U, T)")


def _circle(k: int) -> np.ndarray:
    """The regular k-gon inscribed in the unit square, (k, 2) as (x, z) counter-clockwise seen from +y:
    angle 0 and pi put vertices on x = 0 and 1."""
    angle = 2 * np.pi * np.arange(k) / k
    return np.stack([0.5 + 0.5 * np.cos(angle), 0.5 - 0.5 * np.sin(angle)], axis=1)


def _cone(outline: np.ndarray) -> AssetMesh:
    """The cone over ``outline`` (``_circle``) from its base on y = 0 to its apex (0.5, 1, 0.5): a
    triangle per side, and the base."""
    k = len(outline)
    base = np.stack([outline[:, 0], np.zeros(k), outline[:, 1]], axis=1)
    vertices = np.concatenate([base, [[0.5, 1.0, 0.5]]])
    i = np.arange(k)
    sides = np.stack([i, (i + 1) % k, np.full(k, k)], axis=1)
    # the base faces -y: counter-clockwise from +y is clockwise from below; a fan from vertex 0
    bottom = np.stack([np.zeros(k - 2, np.int64), i[2:], i[1:-1]], axis=1)
    return _frozen(_fitted(vertices), np.concatenate([sides, bottom]), np.array([3] * k + [k]))


def _sphere(sides: int, divisions: int) -> AssetMesh:
    """The UV sphere fitted to the unit box: ``sides`` segments around y, ``divisions`` from the south pole
    (y = 0) to the north pole; triangles at the poles, quads between."""
    ring = _circle(sides) - 0.5
    polar = np.pi * np.arange(1, divisions) / divisions  # from the south pole
    rings = [np.stack([ring[:, 0] * np.sin(t), np.full(sides, -0.5 * np.cos(t)), ring[:, 1] * np.sin(t)], axis=1)
             for t in polar]
    vertices = np.concatenate([[[0.0, -0.5, 0.0]], *rings, [[0.0, 0.5, 0.0]]]) + 0.5
    north = len(vertices) - 1
    i = np.arange(sides)
    j = (i + 1) % sides
    first = 1 + (divisions - 2) * sides  # the first vertex of the last ring
    south = np.stack([np.zeros(sides, np.int64), j + 1, i + 1], axis=1)
    top = np.stack([first + i, first + j, np.full(sides, north)], axis=1)
    quads = np.concatenate([np.stack([1 + r * sides + i, 1 + r * sides + j, 1 + (r + 1) * sides + j,
                                      1 + (r + 1) * sides + i], axis=1) for r in range(divisions - 2)]
                           or [np.empty((0, 4), np.int64)])
    faces = np.concatenate([south, _quads_to_triangles(quads), top]).astype(np.int64)
    sizes = [3] * sides + [4] * len(quads) + [3] * sides
    return _frozen(_fitted(vertices), faces, np.array(sizes))


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
    """A file asset, cached by path and modification time (a city uses a few assets many times), read by
    the reader of its format (``READERS``) and turned y-up in its file's units."""
    suffix = path.suffix.lower()
    reader = READERS.get(suffix, _read_trimesh)
    try:
        vertices, faces, sizes = reader(path)
    except AssetError:
        raise
    except Exception as error:  # each reader's own errors: a broken file is the asset's problem
        raise AssetError(f"cannot read asset `{path}`: {error}") from error
    return _from_own_coordinates(vertices, faces, sizes)


def _read_obj(path: Path):
    """OBJ by ``model.obj`` (geometry only: materials would need Pillow), polygons fanned into triangles;
    OBJ has no up axis or unit: y-up, as CityEngine reads it."""
    try:
        vertices, polygons = read_obj(path.read_text(encoding="utf-8", errors="replace"), str(path))
    except (OSError, ObjError) as error:
        raise AssetError(f"cannot read asset `{path}`: {error}") from error
    polygons = [f for f in polygons if len(f) >= 3 and (f >= 0).all() and (f < len(vertices)).all()]
    sizes = np.array([len(f) for f in polygons], np.int64)
    faces = np.concatenate([np.stack([np.full(len(f) - 2, f[0]), f[1:-1], f[2:]], axis=1)
                            for f in polygons]) if polygons else np.zeros((0, 3), np.int64)
    return vertices, faces, sizes


def _read_trimesh(path: Path):
    """glTF and GLB (y-up metres by the glTF specification) and any other format trimesh reads: a scene's
    meshes concatenated with their node transforms applied (``force="mesh"``)."""
    import trimesh

    mesh = trimesh.load(path, force="mesh", process=False)
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), np.float64).reshape(-1, 3)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), np.int64).reshape(-1, 3)
    return vertices, faces, np.full(len(faces), 3, np.int64)


def _read_collada(path: Path):
    """Collada through trimesh (which needs pycollada), then scaled to metres by the file's
    ``<unit meter=...>`` and turned y-up from its ``<up_axis>``: CityEngine places a Collada asset as its
    author declared it, where trimesh only notes both."""
    try:
        import collada  # noqa: F401  (trimesh's Collada reader)
    except ImportError as error:
        raise AssetError(f"cannot read Collada asset `{path}`: pycollada is not installed "
                         "(pip install pycollada)") from error
    vertices, faces, sizes = _read_trimesh(path)
    meter, up = _collada_unit_and_up(path)
    return _y_up(vertices * meter, up), faces, sizes


def _collada_unit_and_up(path: Path) -> tuple[float, str]:
    """A Collada file's ``<asset><unit meter>`` (1 when absent) and ``<up_axis>`` (``Y_UP`` when absent)."""
    from xml.etree import ElementTree

    meter, up = 1.0, "Y_UP"
    for element in ElementTree.parse(path).getroot().iter():
        tag = element.tag.rsplit("}", 1)[-1]
        if tag == "unit" and element.get("meter"):
            meter = float(element.get("meter"))
        elif tag == "up_axis" and element.text:
            up = element.text.strip().upper()
        elif tag in ("library_geometries", "library_visual_scenes", "scene"):
            break  # the document's <asset> comes first
    return meter, up


def _y_up(vertices: np.ndarray, up: str) -> np.ndarray:
    """Vertices of a file whose up axis is ``up`` (``X_UP``, ``Y_UP``, ``Z_UP``) turned y-up, right-handed:
    Z_UP turns -90 degrees about x (CityEngine's ``zUp``), X_UP +90 degrees about z."""
    x, y, z = vertices.T
    if up == "Z_UP":
        return np.stack([x, z, -y], axis=1)
    if up == "X_UP":
        return np.stack([-y, x, z], axis=1)
    return vertices


def _read_assimp(path: Path):
    """FBX and 3DS through the Open Asset Import Library (``assimp-py``), which applies the node transforms
    and an FBX file's declared axes (the result is y-up), triangulated. Their sizes are in the file's units
    (an FBX in centimetres stays in centimetres): assimp-py does not expose the unit conversion."""
    try:
        import assimp_py
    except ImportError as error:
        raise AssetError(unsupported_format(path) or f"cannot read asset `{path}`: {error}") from error
    scene = assimp_py.import_file(str(path), assimp_py.Process_Triangulate | assimp_py.Process_PreTransformVertices)
    vertices, faces, start = [], [], 0
    for mesh in scene.meshes:
        points = np.asarray(mesh.vertices, np.float64).reshape(-1, 3)
        triangles = np.asarray(mesh.indices, np.int64).reshape(-1, 3)
        vertices.append(points)
        faces.append(triangles + start)
        start += len(points)
    vertices = np.concatenate(vertices) if vertices else np.zeros((0, 3))
    faces = np.concatenate(faces) if faces else np.zeros((0, 3), np.int64)
    return vertices, faces, np.full(len(faces), 3, np.int64)


#: Readers by file ending; any other ending goes through trimesh. Each returns vertices (v, 3) y-up,
#: triangles (t, 3) and the polygon sizes (p,) they came from.
READERS = {".obj": _read_obj, ".glb": _read_trimesh, ".gltf": _read_trimesh, ".dae": _read_collada,
           ".fbx": _read_assimp, ".3ds": _read_assimp}


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


def _from_own_coordinates(vertices, faces, sizes) -> AssetMesh:
    """A file asset: its vertices fitted to the unit box, its bounds in its own coordinates kept."""
    bounds = np.array([vertices.min(axis=0), vertices.max(axis=0)]) if len(vertices) else np.zeros((2, 3))
    return _frozen(_fitted(vertices), faces, sizes, bounds)


def _quads_to_triangles(quads: np.ndarray) -> np.ndarray:
    """(2q, 3) triangles of (q, 4) quads, each split along its diagonal 0-2, in quad order."""
    return np.stack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]], axis=1).reshape(-1, 3)


def _frozen(vertices, faces, sizes, bounds=((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))) -> AssetMesh:
    arrays = [np.array(vertices, np.float64), np.array(faces, np.int64), np.array(sizes, np.int64),
              np.array(bounds, np.float64)]
    for array in arrays:
        array.flags.writeable = False  # cached and shared: nobody may change them
    return AssetMesh(*arrays)


class AssetLibrary:
    """Asset meshes of a record's asset names, loaded when first used: ``library[a]`` is the mesh of asset
    index ``a`` (an ``AssetError`` if it cannot be loaded), ``names`` the record's asset names."""

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


def asset_library(names: Sequence[str], record: Mapping, asset_roots=None, lod: str | None = None) -> AssetLibrary:
    """The meshes of asset ``names``, loaded when first used from ``asset_roots`` or the roots that the
    record's meta names (the grammar's folder, then its ``asset_roots``), at level of detail ``lod``."""
    return AssetLibrary(names, record_roots(record, asset_roots), lod)


def record_roots(record: Mapping, asset_roots=None) -> list[Path]:
    """``asset_roots``, or the roots a record's meta names: the grammar's folder, then ``asset_roots``
    (a rule package's own folders are not among them: ``io.rpk.record_asset_roots`` adds them)."""
    if asset_roots is not None:
        return [Path(r) for r in asset_roots]
    meta = record.get("meta")
    if not isinstance(meta, Mapping):
        return []
    roots = [Path(meta["grammar"]).parent] if meta.get("grammar") else []
    return roots + [Path(r) for r in meta.get("asset_roots", ())]
