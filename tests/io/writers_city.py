"""A small city for the instanced writers' tests: built with ``grammarc build`` into an npz record and
into the format under test, from lots far from the origin (x 12 km), with flat faces (quads), a mirrored
split, colours and a polygon of the mesh table."""

from __future__ import annotations

import json
import zlib
from pathlib import Path

import numpy as np
from conftest import in_world

from grammarc.build import build
from grammarc.io import OutputOptions
from grammarc.io.npz import read_instances
from grammarc.model.records import world_columns

GRAMMAR = """
Lot --> extrude(9) comp(f){ side : Facade | top : Roof }
Facade --> split(y){ 3 : Floor }*
Floor --> split(x){ ~2 : Tile }*
Tile --> case split.index % 2 == 0 : color("#c04020") Window. else : mirror(true, false, false) Wall
Wall --> i("builtin:cube")
Roof --> roofHip(25)
"""


def city(tmp_path: Path, output: str, **options) -> tuple[dict, Path, dict]:
    """(the npz record in world coordinates, the output path, the writer's counts) of the city written as
    ``output``."""
    lots = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{k}", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [[[x, y], [x + w, y], [x + w, y + 12], [x, y + 12],
                                                          [x, y]]]}}
        for k, (x, y, w) in enumerate([(12_000, 300, 14), (12_020, 300, 10), (12_700, 310, 20)])]}
    (tmp_path / "lots.geojson").write_text(json.dumps(lots))
    (tmp_path / "g.cga").write_text(GRAMMAR)
    build(tmp_path / "g.cga", tmp_path / "city.npz", lots_path=tmp_path / "lots.geojson")
    result = build(tmp_path / "g.cga", tmp_path / output, lots_path=tmp_path / "lots.geojson",
                   output_options=OutputOptions(**options))
    return in_world(read_instances(tmp_path / "city.npz")), tmp_path / output, result.counts


def world(position, orientation_xyzw, scale) -> np.ndarray:
    """(n, 3, 4) affine maps of translation, rotation and scale, the record's convention."""
    from scipy.spatial.transform import Rotation

    rotation = Rotation.from_quat(np.asarray(orientation_xyzw, float)).as_matrix()
    linear = rotation * np.asarray(scale, float)[:, None, :]
    return np.concatenate([linear, np.asarray(position, float)[:, :, None]], axis=2)


def glb_city(tmp_path: Path, output: str) -> tuple[dict, Path, int]:
    """(the npz record, the output path, the asset's triangles) of a mast inserted on three lots from a
    GLB made here: a z-up export (a 1 x 1 x 6 m post and a 2 m vane on top, two nodes) inserted
    ``i("mast.glb", zUp, keepSizeAlignPosition)`` on each lot's centre, standing 6 m tall."""
    import trimesh
    from trimesh.transformations import translation_matrix

    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box(extents=(1, 1, 6)), transform=translation_matrix((0, 0, 3)))
    scene.add_geometry(trimesh.creation.cylinder(radius=0.1, height=2.0, sections=6),
                       transform=translation_matrix((0.5, 0, 5)) @ trimesh.transformations.rotation_matrix(
                           np.pi / 2, [0, 1, 0]))
    (tmp_path / "mast.glb").write_bytes(scene.export(file_type="glb"))
    (tmp_path / "g.cga").write_text("Lot --> t('0.5, 0, '0.5) s(0, 0, 0) "
                                    'i("mast.glb", zUp, keepSizeAlignPosition) Mast.\n')
    lots = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{k}", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [[[x, 0], [x + 8, 0], [x + 8, 8], [x, 8], [x, 0]]]}}
        for k, x in enumerate([0, 10, 20])]}
    (tmp_path / "lots.geojson").write_text(json.dumps(lots))
    build(tmp_path / "g.cga", tmp_path / "city.npz", lots_path=tmp_path / "lots.geojson")
    build(tmp_path / "g.cga", tmp_path / output, lots_path=tmp_path / "lots.geojson")
    return in_world(read_instances(tmp_path / "city.npz")), tmp_path / output, len(scene.to_geometry().faces)


#: A red roof and half transparent green walls, on two lots; a textured facade.
COLOURED = """version "2023.0"
Lot --> extrude(6) comp(f){ top : color(1, 0, 0) Roof. | side : Facade }
Facade --> color("#00ff00") set(material.opacity, 0.5) Wall.
"""
TEXTURED = """version "2023.0"
Lot --> extrude(6) comp(f){ top : Roof. | side : texture("tex/wall.png") Wall. }
"""
#: Textured lots whose leaves are polygons (the mesh table: rings with a hole) in 4 m by 3 m tiles of
#: their texture.
TEXTURED_GROUND = """version "2023.0"
Lot --> setupProjection(0, scope.xz, 4, 3) projectUV(0) texture("tex/wall.png") offset(-2) comp(f){ border : Ground. }
"""
RED, SEE_THROUGH_GREEN = [255, 0, 0, 255], [0, 255, 0, 128]


def _png(width: int, height: int) -> bytes:
    """A grey RGB PNG image."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return len(data).to_bytes(4, "big") + kind + data + zlib.crc32(kind + data).to_bytes(4, "big")
    rows = b"".join(b"\0" + b"\x80" * 3 * width for _ in range(height))
    header = width.to_bytes(4, "big") + height.to_bytes(4, "big") + bytes([8, 2, 0, 0, 0])
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")


PNG = _png(2, 2)


def nearest_uv(record, points: np.ndarray) -> np.ndarray:
    """(n, 2): the texture coordinates of the record's mesh vertices nearest to world ``points`` (n, 3)."""
    vertices = world_columns(record)[1]
    nearest = np.argmin(((points[:, None, :] - vertices[None]) ** 2).sum(axis=2), axis=1)
    return record["mesh_uv"][nearest].astype(float)


def textured_city(tmp_path: Path, text: str, suffix: str, bake: bool = False) -> Path:
    """``text`` (a colour or texture grammar, its texture ``tex/wall.png``) derived on two lots and written
    as ``city{suffix}``, baked if ``bake``."""
    (tmp_path / "tex").mkdir(exist_ok=True)
    (tmp_path / "tex" / "wall.png").write_bytes(PNG)
    (tmp_path / "g.cga").write_text(text)
    squares = [[[30 * k, 0], [30 * k + 12, 0], [30 * k + 12, 9], [30 * k, 9], [30 * k, 0]] for k in range(2)]
    (tmp_path / "lots.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [ring]}}
        for ring in squares]}))
    out = tmp_path / f"city{suffix}"
    build(tmp_path / "g.cga", out, lots_path=tmp_path / "lots.geojson", output_options=OutputOptions(bake=bake))
    return out
