"""``render``: a shaded picture of an instance record, drawn on the CPU and written as a PNG.

``render`` takes the record's columns, a mapping (the command line reads the file with ``io.npz``):
drawing knows no file format. The record's instances are drawn by ``raster.draw_instances`` in record
order, each as a splat, a box or its asset's triangles by its size on screen (see ``raster``), then the
mesh table's polygons, triangulated by ``geometry.triangulation`` as the mesh writers triangulate them.
Asset meshes come from ``model.assets``, loaded as the writers load them; a file asset that cannot be
found or read is drawn as its instances' boxes and named in the result, so a record moved away from its
grammar still gives a picture.

Colours: ``"material"`` is the record's colour of each instance and face (CityEngine's ``color``, white by
default); ``"symbol"`` and ``"asset"`` colour by the symbol or asset index from ``palette`` (mesh faces,
which have no asset, are ``MESH_GREY`` then). The alpha channel is ignored; the background is ``SKY``.

The picture depends on the record and the options only (no clock, no threads), and Pillow writes no time
into the PNG, so the same record gives the same bytes.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from grammarc.atomic import replacing
from grammarc.errors import AssetError, UsageError
from grammarc.geometry.triangulation import triangulate_polygons
from grammarc.model.assets import asset_library, builtin_mesh
from grammarc.model.records import record_mesh, world_columns
from grammarc.ragged import segment_of
from grammarc.render.camera import VIEWS, Camera, fit_camera
from grammarc.render.raster import draw_instances, draw_triangles

__all__ = ["COLORS", "SKY", "palette", "parse_size", "png_path", "render"]

#: The colourings ``render`` takes.
COLORS = ("material", "symbol", "asset")
#: Background: a light sky blue (RGB).
SKY = (172, 200, 230)
#: Colour of mesh faces in the ``"asset"`` colouring (they are polygons, not instances of an asset).
MESH_GREY = (190, 190, 190)
#: Instances smaller than this on screen (pixels) are splats.
SPLAT_PX = 2.0
#: Assets of more triangles than this are drawn as their box while smaller than ``DETAIL_PX`` on screen.
HEAVY_TRIANGLES = 64
DETAIL_PX = 24.0
#: The largest picture side: a z-buffer of 16384^2 is 2 GB already.
MAX_SIDE = 16384


def render(record: Mapping, path, *, size: tuple[int, int] = (1600, 1000), view: str = "oblique",
           color: str = "material", asset_roots: Sequence[str | os.PathLike] = ()) -> dict:
    """Draw the city of an instance record and write it to ``path`` as a PNG.

    Parameters
    ----------
    record : mapping
        The record's columns: ``assets`` (A,) str, ``asset`` (N,) int, ``xform`` (N, 3, 4) float, and
        where the record has them ``color`` (N, 4) uint8, ``symbol`` (N,) int, ``meta`` (dict), the mesh
        table (``mesh_vertices`` (V, 3), ``mesh_ring_offsets`` (R+1,), ``mesh_face_offsets`` (F+1,),
        ``mesh_color`` (F, 4), ``mesh_symbol`` (F,)): the dict of ``io.npz.read_instances``.
    path : path-like
        The picture, a ``.png`` in an existing folder (``png_path``); written to a temporary file beside it
        and moved into place, so it is complete or unchanged.
    size : (int, int)
        Width and height in pixels.
    view : str
        ``"oblique"``: perspective from the south-south-east, looking down at the city; ``"top"``:
        orthographic from above, north up. Either way the city's bounding box fills the picture.
    color : str
        ``"material"``, ``"symbol"`` or ``"asset"`` (see the module docstring).
    asset_roots : sequence of path-like
        Folders to find file assets in; by default the folder of the record's grammar, then the record's
        ``meta["asset_roots"]``.

    Returns
    -------
    dict
        ``instances`` and ``mesh_faces`` drawn; ``splats``, ``boxes``, ``meshes``: how many instances were
        drawn each way; ``missing_assets``: names of file assets drawn as boxes because they could not
        be loaded, ``asset_problems`` why (each an ``AssetError``'s message).

    Raises
    ------
    UsageError
        If the record's columns are missing or disagree, an option is wrong, or ``path`` is not a ``.png``
        in an existing folder.
    """
    width, height = _checked_size(size)
    if view not in VIEWS:
        raise UsageError(f"view must be one of {', '.join(VIEWS)}, got `{view}`")
    if color not in COLORS:
        raise UsageError(f"color must be one of {', '.join(COLORS)}, got `{color}`")
    out = png_path(path)
    record = _columns(record)
    names, asset, xform = record["assets"], record["asset"], record["xform"]
    vertices, ring_offsets, face_offsets = record["mesh"]

    camera = fit_camera(*_bounds(xform, vertices), (width, height), view)
    image = np.empty((height, width, 3), np.uint8)
    image[:] = SKY
    depth = np.full((height, width), -np.inf)
    light = camera.light()

    library = asset_library(names, record, [Path(r) for r in asset_roots or ()] or None)
    meshes, missing, problems = [], [], []
    for a in np.flatnonzero(np.bincount(asset, minlength=len(names))):
        try:
            meshes.append((a, library[a]))
        except AssetError as error:
            missing.append(names[a])
            problems.append(str(error))
    counts = _draw_instances(asset, xform, _instance_colors(record, color), meshes, len(names), camera,
                             light, image, depth)
    if len(face_offsets) > 1:
        triangles = triangulate_polygons(vertices, ring_offsets, face_offsets)
        # The face of each triangle: its first vertex's ring, that ring's face.
        ring = np.searchsorted(ring_offsets, triangles[:, 0], side="right") - 1
        face = np.searchsorted(face_offsets, ring, side="right") - 1
        draw_triangles(camera.to_camera(vertices), camera.project(vertices), triangles,
                       _face_colors(record, color)[face], camera.lens[3], camera.perspective, light, image,
                       depth)
    _write_png(image, out)
    return {
        "instances": len(asset),
        "mesh_faces": len(face_offsets) - 1,
        "splats": int(counts[0]),
        "boxes": int(counts[1]),
        "meshes": int(counts[2]),
        "missing_assets": missing,
        "asset_problems": problems,
    }


def png_path(path: str | os.PathLike) -> Path:
    """``path`` as the picture's path, checked: a ``.png`` in an existing folder, else a UsageError (the
    command line checks it before it reads the record)."""
    out = Path(path)
    if out.suffix.lower() != ".png":
        raise UsageError(f"cannot write `{out}`: the picture is a PNG, name it `.png`")
    if not out.parent.is_dir():
        raise UsageError(f"cannot write `{out}`: folder `{out.parent}` does not exist")
    return out


def parse_size(text: str) -> tuple[int, int]:
    """``"1600x1000"`` -> (1600, 1000); a UsageError for anything else.

    Examples
    --------
    >>> parse_size("800x600")
    (800, 600)
    """
    width, sep, height = text.lower().partition("x")
    if not (sep and width.strip().isdigit() and height.strip().isdigit()):
        raise UsageError(f"size must be WIDTHxHEIGHT in pixels (1600x1000), got `{text}`")
    return _checked_size((int(width), int(height)))


def palette(n: int) -> np.ndarray:
    """(n, 3) uint8: n distinct colours, the same for every n (colour k does not depend on n).

    Hues step by the golden ratio of a turn, so neighbouring indices differ strongly; saturation and
    value stay where a shaded face still shows its hue.

    Examples
    --------
    >>> palette(3).tolist()
    [[235, 117, 117], [117, 152, 235], [186, 235, 117]]
    """
    hue = (np.arange(n) * 0.6180339887498949) % 1.0
    saturation, value = 0.5, 0.92
    # HSV to RGB: channel c is v (1 - s clip(min(k, 4 - k), 0, 1)), k = (c_offset + 6 h) mod 6.
    k = (np.array([5.0, 3.0, 1.0]) + 6.0 * hue[:, None]) % 6.0
    rgb = value * (1.0 - saturation * np.clip(np.minimum(k, 4.0 - k), 0.0, 1.0))
    return np.round(rgb * 255).astype(np.uint8)


def _checked_size(size) -> tuple[int, int]:
    width, height = (int(s) for s in size)
    if not (0 < width <= MAX_SIDE and 0 < height <= MAX_SIDE):
        raise UsageError(f"size must be 1 to {MAX_SIDE} pixels a side, got {width}x{height}")
    return width, height


def _columns(record: Mapping) -> dict:
    """The columns ``render`` draws, checked: ``assets`` (list of str), ``asset`` (N,) int32, ``xform``
    (N, 3, 4) float32, ``mesh`` (vertices (V, 3) float64, ring and face offsets int64), both moved from world
    coordinates by the same whole metres to the city's middle (the picture does not change), ``meta``, and
    ``color``, ``symbol``, ``symbols``, ``mesh_color``, ``mesh_symbol`` where the record has them."""
    if not isinstance(record, Mapping):
        raise TypeError(f"render takes a record's columns (a mapping, as io.npz.read_instances returns), "
                        f"not {type(record).__name__}")
    missing = [key for key in ("assets", "asset", "xform") if key not in record]
    if missing:
        raise UsageError(f"not an instance record: no {', '.join(missing)}")
    out = dict(record)
    out["assets"] = [str(n) for n in np.asarray(record["assets"]).reshape(-1)]
    out["asset"] = np.ascontiguousarray(record["asset"], np.int32).reshape(-1)
    n = len(out["asset"])
    if np.shape(record["xform"]) != (n, 3, 4):
        raise UsageError(f"not an instance record: xform is {np.shape(record['xform'])}, expected ({n}, 3, 4)")
    if n and (out["asset"].min() < 0 or out["asset"].max() >= len(out["assets"])):
        raise UsageError(f"not an instance record: asset index out of range [0, {len(out['assets'])})")
    # drawn around the middle of the city, where float32 keeps its detail wherever the city lies
    xform, vertices = world_columns(record)
    if isinstance(record.get("meta"), Mapping) and "search" in record["meta"]:
        xform, vertices = _side_by_side(record, xform, vertices)
    middle = np.round(_middle(xform, vertices))
    xform[:, :, 3] -= middle
    out["xform"] = np.ascontiguousarray(xform, np.float32)
    mesh = record_mesh(record)
    out["mesh"] = (vertices - middle, mesh.ring_offsets, mesh.face_offsets) if mesh is not None else \
        (np.zeros((0, 3)), np.zeros(1, np.int64), np.zeros(1, np.int64))
    return out


def _side_by_side(record: Mapping, xform: np.ndarray, vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A search's solutions (``grammarc search``: the record's lots are solutions, which lie on their
    lots, one over the other) laid out on a grid in the order found, rows of ``ceil(sqrt(n))`` from
    west to east, then north to south, a fifth of a solution apart."""
    lot = np.asarray(record.get("lot", np.zeros(0, np.int32)), np.int64)
    mesh = record_mesh(record)
    vertex_lot = np.zeros(0, np.int64)
    if mesh is not None and len(vertices):
        vertex_lot = np.asarray(mesh.lot, np.int64)[segment_of(mesh.face_offsets)[segment_of(mesh.ring_offsets)]]
    n = int(max(lot.max(initial=-1), vertex_lot.max(initial=-1))) + 1
    if n < 2:
        return xform, vertices
    # each solution's own box, its lower corner moved to its cell's (solutions of several lots alike)
    low, high = np.full((n, 3), np.inf), np.full((n, 3), -np.inf)
    corner_low, corner_high = _boxes(xform)
    for rows, low_rows, high_rows in ((lot, corner_low, corner_high), (vertex_lot, vertices, vertices)):
        np.minimum.at(low, rows, low_rows)
        np.maximum.at(high, rows, high_rows)
    low, high = np.where(np.isfinite(low), low, 0.0), np.where(np.isfinite(high), high, 0.0)
    cell = (high - low).max(axis=0) * 1.2
    columns = int(np.ceil(np.sqrt(n)))
    shift = -low
    shift[:, 0] += (np.arange(n) % columns) * cell[0]
    shift[:, 2] += (np.arange(n) // columns) * cell[2]
    xform = xform.copy()
    xform[:, :, 3] += shift[lot]
    return xform, vertices + shift[vertex_lot]


def _middle(xform: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """(3,) float64: the middle of the instances' origins and the mesh vertices (0 for an empty record)."""
    points = np.concatenate([xform[:, :, 3], vertices])
    return (points.min(axis=0) + points.max(axis=0)) / 2 if len(points) else np.zeros(3)


def _boxes(xform: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each instance's world box (low, high), (N, 3) each."""
    # An instance's box spans origin + sum over its axes of [min(0, axis), max(0, axis)], per coordinate;
    # column by column, as (N, 3) sums: a (N, 3, 3) temporary would cost more than the sums.
    low, high = xform[:, :, 3].copy(), xform[:, :, 3].copy()
    for j in range(3):
        low += np.minimum(xform[:, :, j], 0)
        high += np.maximum(xform[:, :, j], 0)
    return low, high


def _bounds(xform: np.ndarray, vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The world bounding box (low, high) float64 of every instance's box and every mesh vertex."""
    low, high = _boxes(xform)
    low, high = np.concatenate([low, vertices]), np.concatenate([high, vertices])
    if not len(low):
        return np.zeros(3), np.zeros(3)
    return low.min(axis=0).astype(np.float64), high.max(axis=0).astype(np.float64)


def _draw_instances(asset, xform, rgb, meshes, n_assets, camera: Camera, light, image, depth) -> np.ndarray:
    """Lay the loaded asset meshes out as the ragged tables of ``draw_instances`` and draw; an asset
    absent from ``meshes`` (not used, or not loaded) has no triangles, so it is always its box."""
    cube = builtin_mesh("builtin:cube")
    vertex_counts = np.zeros(n_assets + 1, np.int64)
    face_counts = np.zeros(n_assets + 1, np.int64)
    detail_px = np.full(n_assets + 1, np.inf)  # no triangles: the box at every size
    vertices, faces = [], []
    for a, mesh in meshes:
        vertex_counts[a], face_counts[a] = len(mesh.vertices), len(mesh.faces)
        detail_px[a] = DETAIL_PX if mesh.n_triangles > HEAVY_TRIANGLES else 0.0
        vertices.append(mesh.vertices)
        faces.append(mesh.faces)
    vertex_counts[-1], face_counts[-1] = len(cube.vertices), len(cube.faces)
    vertex_offsets = np.concatenate([[0], np.cumsum(vertex_counts)])
    face_offsets = np.concatenate([[0], np.cumsum(face_counts)])
    return draw_instances(xform, rgb, asset, vertex_offsets, face_offsets,
                          np.concatenate([*vertices, cube.vertices]).astype(np.float64),
                          np.concatenate([*faces, cube.faces]).astype(np.int64), detail_px, SPLAT_PX,
                          camera.view, camera.lens, camera.perspective, light, image, depth)


def _instance_colors(record: dict, color: str) -> np.ndarray:
    """(N, 3 or 4) uint8: each instance's colour in the colouring ``color`` (RGB first)."""
    n = len(record["asset"])
    if color == "material":
        return _rgba(record, "color", n)
    return _by_index(record, color, n)


def _face_colors(record: dict, color: str) -> np.ndarray:
    """(F, 3 or 4) uint8: each mesh face's colour in the colouring ``color``."""
    n = len(record["mesh"][2]) - 1
    if color == "asset":
        return np.broadcast_to(np.array(MESH_GREY, np.uint8), (n, 3))
    if color == "symbol":
        return _by_index(record, "mesh_symbol", n)
    return _rgba(record, "mesh_color", n)


def _by_index(record: dict, key: str, n: int) -> np.ndarray:
    """(n, 3) uint8: the palette colour of each row's index in column ``key`` (0 if the record has none)."""
    index = np.asarray(record[key], np.int64).reshape(n) if key in record else np.zeros(n, np.int64)
    return palette(int(index.max(initial=0)) + 1)[index]


def _rgba(record: dict, key: str, n: int) -> np.ndarray:
    """Colour column ``key`` as (n, 4) uint8, white if the record has none."""
    if key not in record:
        return np.full((n, 4), 255, np.uint8)
    return np.ascontiguousarray(record[key], np.uint8).reshape(n, 4)


def _write_png(image: np.ndarray, path: Path) -> None:
    """Write ``image`` (h, w, 3) uint8 as a PNG to a private folder beside ``path``, fsync it and move it
    onto ``path``; the folder is removed whatever happens."""
    from PIL import Image

    with replacing(path) as tmp:
        Image.fromarray(image).save(tmp, format="PNG")
