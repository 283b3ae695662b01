"""3D Tiles 1.1 (``--emit city.3dtiles``): the tileset and every tile's GLB keep the specifications
(``tiles3d_checks``; the Khronos glTF validator where npm's is installed), the leaves hold the record's
instances at their places with their lots' features, coarser tiles stand above them, the root is placed
on the Earth where the lots have a coordinate system, and the folder appears whole."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from conftest import in_world
from tiles3d_checks import box_bounds, check_content, check_tileset, property_tables, read_accessor, tiles
from writers_city import GRAMMAR

from grammarc.build import BuildOptions, build
from grammarc.errors import UsageError
from grammarc.io import OutputOptions, written_paths
from grammarc.io.gltf import _read_part
from grammarc.io.instancing import compose
from grammarc.io.npz import read_instances
from grammarc.io.tiles3d import TilesetWriter, read_tileset, write_record

VIEWER = Path(__file__).resolve().parents[2] / "viewer"
PROPERTIES = [{"height": 9.5, "roof-type": "hip"}, {"height": 12.0}, {"height": 7.25, "roof-type": "flat"}]


def built(tmp_path: Path, corner=(12_000.0, 300.0), crs: str | None = None, **options):
    """(the npz record in world coordinates, the tileset folder, the writer's counts) of three lots with
    attributes, ``corner`` their map corner, ``crs`` their coordinate system (GeoJSON's ``crs`` member)."""
    x0, y0 = corner
    lots = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{k}", "properties": PROPERTIES[k],
         "geometry": {"type": "Polygon", "coordinates": [[[x, y], [x + w, y], [x + w, y + 12], [x, y + 12], [x, y]]]}}
        for k, (x, y, w) in enumerate([(x0, y0, 14), (x0 + 20, y0, 10), (x0 + 700, y0 + 10, 20)])]}
    if crs is not None:
        lots["crs"] = {"type": "name", "properties": {"name": crs}}
    (tmp_path / "lots.geojson").write_text(json.dumps(lots))
    (tmp_path / "g.cga").write_text(GRAMMAR)
    build(tmp_path / "g.cga", tmp_path / "city.npz", lots_path=tmp_path / "lots.geojson")
    result = build(tmp_path / "g.cga", tmp_path / "city.3dtiles", lots_path=tmp_path / "lots.geojson",
                   output_options=OutputOptions(**options))
    return in_world(read_instances(tmp_path / "city.npz")), tmp_path / "city.3dtiles", result.counts


def leaf_instances(folder: Path, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World transforms (n, 3, 4), lot numbers and symbols of every instance of the leaves."""
    xforms, lots, symbols = [], [], []
    for path in sorted(folder.glob("tiles/tile_*.glb")):
        tree, blob = _read_part(path)
        lot_table = property_tables(tree, blob)[0]
        for root in tree["scenes"][0]["nodes"]:
            corner = np.array(tree["nodes"][root]["translation"]) + reference
            for child in tree["nodes"][root]["children"]:
                attributes = tree["nodes"][child].get("extensions", {}).get("EXT_mesh_gpu_instancing", {})
                if not attributes:
                    continue
                attributes = attributes["attributes"]
                t, r, s = (read_accessor(tree, blob, attributes[k]) for k in ("TRANSLATION", "ROTATION", "SCALE"))
                xforms.append(compose(t.astype(np.float64) + corner, r, s))
                rows = read_accessor(tree, blob, attributes["_FEATURE_ID_0"]).astype(np.int64)
                lots.append(np.array(lot_table["number"])[rows])
                symbols.append(read_accessor(tree, blob, attributes["_FEATURE_ID_1"]).astype(np.int64))
    return np.concatenate(xforms), np.concatenate(lots), np.concatenate(symbols)


def test_the_tileset_and_every_tile_keep_the_specifications(tmp_path):
    record, folder, counts = built(tmp_path)
    tileset = check_tileset(folder)
    contents = sorted(folder.glob("tiles/*.glb"))
    assert len(contents) == counts["contents"] == sum("content" in t for t, _ in tiles(tileset["root"]))
    for path in contents:
        check_content(path)
    assert counts["instances"] == len(record["asset"])
    assert written_paths(folder) == ([], [folder])


def test_the_leaves_hold_the_records_instances_at_their_places_with_their_lots_and_symbols(tmp_path):
    record, folder, _ = built(tmp_path)
    reference = np.array(json.loads((folder / "tileset.json").read_text())["extras"]["reference"])
    xform, lot, symbol = leaf_instances(folder, reference)
    assert len(xform) == len(record["xform"])

    def ordered(xform, lot, symbol):
        order = np.lexsort((*np.round(xform[:, :, 3].T, 2), symbol, lot))
        return xform[order], lot[order], symbol[order]

    got, want = ordered(xform, lot, symbol), ordered(record["xform"], record["lot"], record["symbol"])
    np.testing.assert_array_equal(got[1], want[1])
    np.testing.assert_array_equal(got[2], want[2])
    np.testing.assert_allclose(got[0], want[0], atol=2e-4)  # float32 relative to a tile 12 km out


def test_the_features_name_each_lot_its_attributes_and_the_symbols(tmp_path):
    record, folder, _ = built(tmp_path)
    rows = {}
    for path in folder.glob("tiles/tile_*.glb"):
        tree, blob = _read_part(path)
        lot_table, symbol_table = property_tables(tree, blob)
        assert symbol_table["name"] == [str(s) for s in record["symbols"]]
        classes = tree["extensions"]["EXT_structural_metadata"]["schema"]["classes"]
        assert classes["lot"]["properties"]["roof_type"]["name"] == "roof-type"
        for k, number in enumerate(lot_table["number"]):
            rows[number] = {key: values[k] for key, values in lot_table.items()}
    assert rows[0] == {"id": "lot0", "number": 0, "height": 9.5, "roof_type": "hip"}
    assert rows[1] == {"id": "lot1", "number": 1, "height": 12.0, "roof_type": ""}
    assert rows[2] == {"id": "lot2", "number": 2, "height": 7.25, "roof_type": "flat"}


def test_coarser_levels_stand_for_the_lots_with_errors_that_grow_towards_the_root(tmp_path):
    record, folder, counts = built(tmp_path, tile_size=8.0)
    tileset = check_tileset(folder)
    assert counts["levels"] >= 5  # 720 m of 8 m leaves: 2^7 leaves across
    by_level: dict[float, list[dict]] = {}
    for tile, _ in tiles(tileset["root"]):
        by_level.setdefault(tile["geometricError"], []).append(tile)
    errors = sorted(by_level)
    assert errors[0] == 0 and all(t["content"]["uri"].startswith("tiles/tile_") for t in by_level[0])
    assert errors[1:] == [8.0 * 2 ** k / 32 for k in range(1, len(errors))]
    # level 1: a box per lot, with the lot's features; above: merged masses, with their own
    boxes = 0
    for tile in (t for t in by_level[errors[1]] if "content" in t):  # a node may hold no lot's centre
        tree, _ = check_content(folder / tile["content"]["uri"])
        node = tree["nodes"][0]
        assert "EXT_instance_features" in node["extensions"]
        boxes += tree["accessors"][node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"]]["count"]
    assert boxes == len(np.unique(record["lot"]))
    top, blob = check_content(folder / tileset["root"]["content"]["uri"])
    (masses,) = property_tables(top, blob)
    assert top["extensions"]["EXT_structural_metadata"]["propertyTables"][0]["class"] == "mass"
    assert sum(masses["lots"]) == len(np.unique(record["lot"]))
    assert tileset["geometricError"] > tileset["root"]["geometricError"]


def test_a_georeferenced_city_is_placed_on_the_earth_by_its_root_transform(tmp_path):
    pyproj = pytest.importorskip("pyproj")
    _, folder, _ = built(tmp_path, corner=(500_000.0, 5_000_000.0), crs="EPSG:32632")
    tileset = check_tileset(folder)
    matrix = np.array(tileset["root"]["transform"]).reshape(4, 4).T
    reference = np.array(tileset["extras"]["reference"])
    to_map = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:32632", always_xy=True)
    for tile, _ in tiles(tileset["root"]):
        centre = np.array(tile["boundingVolume"]["box"][:3])
        ecef = matrix @ np.r_[centre, 1.0]
        easting, northing, _ = to_map.transform(*ecef[:3])
        # within a kilometre of the reference point the plane of the transform leaves the map by millimetres
        np.testing.assert_allclose([easting, northing], [reference[0] + centre[0], -reference[2] + centre[1]],
                                   atol=5e-3)


def test_a_local_city_has_no_transform(tmp_path):
    _, folder, _ = built(tmp_path)
    assert "transform" not in check_tileset(folder)["root"]


def test_the_folder_appears_whole_or_not_at_all(tmp_path):
    _, folder, _ = built(tmp_path)
    before = {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    writer = TilesetWriter(folder, assets=["builtin:cube"], symbols=["A"], meta={})
    writer.abort()
    assert {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()} == before
    (folder / "tiles" / "stale.glb").write_bytes(b"old")
    with TilesetWriter(folder, assets=["builtin:cube"], symbols=["A"], meta={}):
        pass  # an empty city
    assert sorted(p.name for p in folder.iterdir()) == ["tiles", "tileset.json"]
    assert not list((folder / "tiles").iterdir())
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    with pytest.raises(UsageError, match=r"\.3dtiles"):
        TilesetWriter(tmp_path / "city.tiles", assets=[], symbols=[], meta={})


@pytest.mark.skipif(shutil.which("node") is None or not (VIEWER / "node_modules" / "gltf-validator").is_dir(),
                    reason="the glTF validator is not installed: npm ci --prefix viewer")
def test_the_khronos_gltf_validator_finds_no_error_nor_warning_in_any_tile(tmp_path):
    _, folder, _ = built(tmp_path, tile_size=50.0)
    paths = sorted(str(p) for p in folder.glob("tiles/*.glb"))
    out = subprocess.run(["node", str(VIEWER / "scripts" / "validate-glb.mjs"), *paths], capture_output=True,
                         text=True, check=True).stdout
    reports = [json.loads(line) for line in out.splitlines()]
    assert len(reports) == len(paths)
    assert all(r["errors"] == 0 and r["warnings"] == 0 for r in reports), [r for r in reports if r["messages"]]


def test_coarse_boxes_span_their_lots(tmp_path):
    record, folder, _ = built(tmp_path, tile_size=8.0)
    tileset = check_tileset(folder)
    reference = np.array(tileset["extras"]["reference"])
    level1 = [t for t, _ in tiles(tileset["root"]) if t["geometricError"] == 0.5 and "content" in t]
    assert level1
    for tile in level1:
        tree, blob = _read_part(folder / tile["content"]["uri"])
        attributes = tree["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]
        low = read_accessor(tree, blob, attributes["TRANSLATION"]) + reference
        high = low + read_accessor(tree, blob, attributes["SCALE"])
        numbers = np.array(property_tables(tree, blob)[0]["number"])[
            read_accessor(tree, blob, attributes["_FEATURE_ID_0"]).astype(int)]
        for k, lot in enumerate(numbers):
            centres = record["xform"][record["lot"] == lot][:, :, 3]
            assert (centres >= low[k] - 1e-3).all() and (centres <= high[k] + 1e-3).all()
        # the tile's bounding box (z up: x, -z, y) holds its boxes
        box_low, box_high = box_bounds(tile["boundingVolume"]["box"])
        local_low, local_high = low - reference, high - reference
        assert (box_low <= np.c_[local_low[:, 0], -local_high[:, 2], local_low[:, 1]] + 1e-3).all()
        assert (box_high >= np.c_[local_high[:, 0], -local_low[:, 2], local_high[:, 1]] - 1e-3).all()


def test_a_record_written_again_as_a_tileset_has_the_same_instances_and_lot_numbers(tmp_path):
    record, _, _ = built(tmp_path)
    counts = write_record(read_instances(tmp_path / "city.npz"), tmp_path / "again.3dtiles")
    tileset = check_tileset(tmp_path / "again.3dtiles")
    assert counts["instances"] == len(record["asset"])
    xform, lot, _ = leaf_instances(tmp_path / "again.3dtiles", np.array(tileset["extras"]["reference"]))
    assert sorted(lot.tolist()) == sorted(record["lot"].tolist())
    np.testing.assert_allclose(np.sort(xform[:, :, 3], axis=0), np.sort(record["xform"][:, :, 3], axis=0), atol=2e-4)
    tree, blob = _read_part(next((tmp_path / "again.3dtiles").glob("tiles/tile_*.glb")))
    lots = property_tables(tree, blob)[0]
    assert lots["id"] == [f"lot{n}" for n in lots["number"]]  # no lots file: a lot is its number


def test_the_tileset_does_not_depend_on_the_chunking(tmp_path):
    _, folder, _ = built(tmp_path, tile_size=50.0)
    again = tmp_path / "chunked.3dtiles"
    build(tmp_path / "g.cga", again, lots_path=tmp_path / "lots.geojson", options=BuildOptions(chunk_size=1),
          output_options=OutputOptions(tile_size=50.0))

    def files(root: Path) -> dict:
        return {p.relative_to(root): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}

    assert files(again) == files(folder)


def test_read_back_a_tileset_is_the_record_by_leaf(tmp_path):
    record, folder, _ = built(tmp_path)
    back = read_tileset(folder)
    assert [str(s) for s in back["symbols"]] == [str(s) for s in record["symbols"]]
    names = sorted(str(n) for n in record["assets"])

    def order(r: dict) -> np.ndarray:
        """Rows by asset name, lot, symbol and place: the same order whatever the file's grouping."""
        asset = np.searchsorted(names, [str(r["assets"][a]) for a in r["asset"]])
        return np.lexsort((*np.round(r["xform"][:, :, 3].T, 2), r["symbol"], r["lot"], asset))

    got, want = order(back), order(record)
    np.testing.assert_array_equal(back["lot"][got], record["lot"][want])
    np.testing.assert_array_equal(back["symbol"][got], record["symbol"][want])
    np.testing.assert_allclose(back["xform"][got], record["xform"][want], atol=2e-4)
    # the mesh table as triangles, each with its face's lot and symbol
    faces = len(back["mesh_face_offsets"]) - 1
    assert faces >= len(record["mesh_face_offsets"]) - 1 and len(back["mesh_lot"]) == faces
    assert set(back["mesh_lot"].tolist()) == set(record["mesh_lot"].tolist())
    assert set(back["mesh_symbol"].tolist()) == set(record["mesh_symbol"].tolist())
