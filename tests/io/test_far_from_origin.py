"""A city at a UTM northing of 5.75 million metres is the city at the origin moved, in every writer.

float32 has steps of 0.5 m there: records, tiles and bakes keep their float32 numbers near a float64 origin
(``model.records.LotOrigins``, the tiles' corners, the bake origin), so positions agree to 1 mm after the
offset is taken away.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from conftest import in_world
from writers_city import GRAMMAR

from grammarc.build import build
from grammarc.io import OutputOptions
from grammarc.io.gltf import read_glb
from grammarc.io.npz import read_instances
from grammarc.model.records import world_columns
from grammarc.render.picture import render

#: Map offset (easting, northing) of the far city, and the same in world coordinates (z = -map y).
OFFSET = (487_000.0, 5_750_000.0)
SHIFT = np.array([OFFSET[0], 0.0, -OFFSET[1]])
MM = 1e-3


def build_at(tmp_path, offset, output: str, **options):
    """The writers' test city (three lots with facades, a mirrored split and hip roofs) with its lots moved
    by ``offset`` (map x, y), written as ``output`` in a folder of its own; the output's path."""
    folder = tmp_path / ("far" if offset[1] else "near")
    folder.mkdir(exist_ok=True)
    dx, dy = offset
    lots = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{k}", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [[[x + dx, y + dy], [x + w + dx, y + dy],
                                                          [x + w + dx, y + 12 + dy], [x + dx, y + 12 + dy],
                                                          [x + dx, y + dy]]]}}
        for k, (x, y, w) in enumerate([(0, 0, 14), (20, 0, 10), (700, 10, 20)])]}
    (folder / "lots.geojson").write_text(json.dumps(lots))
    (folder / "g.cga").write_text(GRAMMAR)
    build(folder / "g.cga", folder / output, lots_path=folder / "lots.geojson", output_options=OutputOptions(**options))
    return folder / output


def both(tmp_path, output: str, **options):
    return build_at(tmp_path, (0.0, 0.0), output, **options), build_at(tmp_path, OFFSET, output, **options)


def by_position(xform: np.ndarray) -> np.ndarray:
    """``xform`` (n, 3, 4) in the order of its rows' positions (the writers group rows by tile and asset)."""
    return xform[np.lexsort(np.round(xform[:, :, 3], 2).T)]


def test_the_record_keeps_millimetres_and_says_where_its_lots_are(tmp_path):
    near, far = (read_instances(p) for p in both(tmp_path, "city.npz"))
    assert far["lot_origin"].dtype == np.float64 and far["lot_origin"].shape == (3, 3)
    np.testing.assert_allclose(far["lot_origin"] - near["lot_origin"], np.tile(SHIFT, (3, 1)), atol=1e-6)
    # rows relative to their lot: the same numbers wherever the city lies
    assert np.abs(far["xform"] - near["xform"]).max() < MM
    assert np.abs(far["mesh_vertices"] - near["mesh_vertices"]).max() < MM
    (near_x, near_v), (far_x, far_v) = world_columns(near), world_columns(far)
    np.testing.assert_allclose(far_x[:, :, 3] - SHIFT, near_x[:, :, 3], atol=MM, rtol=0)
    np.testing.assert_allclose(far_v - SHIFT, near_v, atol=MM, rtol=0)
    assert np.abs(far_x[:, :, 3] - SHIFT).max() > 700  # the lots are spread, not stacked at an origin


def test_instanced_gltf_tiles_are_placed_in_double_precision(tmp_path):
    near, far = (in_world(read_glb(p)) for p in both(tmp_path, "city.glb"))
    moved = far["xform"].copy()
    moved[:, :, 3] -= SHIFT
    assert len(moved) == len(near["xform"]) > 100
    np.testing.assert_allclose(by_position(moved), by_position(near["xform"]), atol=MM, rtol=1e-6)
    np.testing.assert_allclose(np.sort(far["mesh_vertices"] - SHIFT, axis=0), np.sort(near["mesh_vertices"], axis=0),
                               atol=MM, rtol=0)


def test_usd_tiles_are_placed_in_double_precision(tmp_path):
    pytest.importorskip("pxr")
    from grammarc.io.usd import read_usd

    near, far = (read_usd(p) for p in both(tmp_path, "city.usdc"))
    moved = far["xform"].copy()
    moved[:, :, 3] -= SHIFT
    # USD orientations are half-precision quaternions: the linear part agrees to 2e-3 of the sizes
    np.testing.assert_allclose(by_position(moved)[:, :, 3], by_position(near["xform"])[:, :, 3], atol=MM, rtol=0)
    np.testing.assert_allclose(np.sort(far["mesh_vertices"] - SHIFT, axis=0), np.sort(near["mesh_vertices"], axis=0),
                               atol=MM, rtol=0)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl", ".glb"])
def test_baked_meshes_keep_millimetres_and_say_their_origin(tmp_path, suffix):
    options = {"bake": True} if suffix == ".glb" else {}
    near, far = both(tmp_path, "city" + suffix, **options)
    a, b = (trimesh.load(p, force="mesh", process=False) for p in (near, far))
    if suffix == ".obj" or suffix == ".glb":  # text with every digit: world coordinates
        moved = b.vertices - SHIFT
    else:  # float32 near the origin the header names
        text = far.read_bytes()[:400].decode("latin-1")
        origin = np.array(text.split("origin ")[1].split()[:3], float)
        assert np.abs(origin - SHIFT).max() < 1000
        moved = b.vertices + origin - SHIFT
    assert len(a.faces) == len(b.faces) > 100
    np.testing.assert_allclose(np.sort(moved, axis=0), np.sort(a.vertices, axis=0), atol=MM, rtol=0)


def test_a_bake_origin_chosen_by_the_user_is_subtracted_and_named(tmp_path):
    near = build_at(tmp_path, (0.0, 0.0), "city.ply")
    far = build_at(tmp_path, OFFSET, "city.ply", bake_origin=tuple(SHIFT))
    assert b"comment grammarc origin 487000 0 -5750000\n" in far.read_bytes()[:300]
    a, b = (trimesh.load(p, process=False) for p in (near, far))
    np.testing.assert_allclose(np.sort(b.vertices, axis=0), np.sort(a.vertices, axis=0), atol=MM, rtol=0)


def test_cityjson_keeps_millimetres_in_its_integers(tmp_path):
    near, far = (json.loads(p.read_text()) for p in both(tmp_path, "city.city.json"))
    a, b = ((np.array(d["vertices"]) * d["transform"]["scale"] + d["transform"]["translate"]) for d in (near, far))
    shift = np.array([OFFSET[0], OFFSET[1], 0.0])  # easting, northing, height
    assert len(a) == len(b) > 100
    np.testing.assert_allclose(np.sort(b - shift, axis=0), np.sort(a, axis=0), atol=MM, rtol=0)


def test_the_far_city_renders_as_the_city_at_the_origin(tmp_path):
    near, far = (read_instances(p) for p in both(tmp_path, "city.npz"))
    render(near, tmp_path / "near.png", size=(320, 200))
    render(far, tmp_path / "far.png", size=(320, 200))
    assert (tmp_path / "near.png").read_bytes() == (tmp_path / "far.png").read_bytes()
