"""Tests of grammarc.io.crs: lots in longitude/latitude reach metres, and every file says its coordinate system.

A block of four buildings in Lausanne, written as an OpenStreetMap-like GeoJSON (longitude/latitude), a
GeoPackage in EPSG:4326 and one in the Swiss national grid (EPSG:2056), builds to the same buildings.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import shapely

from grammarc.build import BuildOptions, build
from grammarc.errors import LotsError
from grammarc.io.crs import georeference, looks_like_degrees
from grammarc.io.lot_format import LotsOptions
from grammarc.io.lots import partition_lots, read_lots, read_partition
from grammarc.io.npz import read_instances
from grammarc.model.records import world_columns

pyproj = pytest.importorskip("pyproj")

#: Four 15 x 16 m footprints in Lausanne (longitude, latitude), 23 m apart.
LON, LAT, WIDE, DEEP = 6.6323, 46.5197, 0.0002, 0.000144
RINGS = [[(LON + k * 0.0003 + dx, LAT + dy) for dx, dy in ((0, 0), (WIDE, 0), (WIDE, DEEP), (0, DEEP))]
         for k in range(4)]
GRAMMAR = """version "2023.0"
attr height = 5
Lot --> extrude(height) comp(f){ side : Wall | top : Roof. }
Wall --> split(y){ 3 : Floor }*
Floor --> split(x){ ~2 : Tile }*
Tile --> i("builtin:cube") Tile.
"""


def geojson(path, rings, crs_member=None):
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"b{k}", "properties": {"height": 10.0 + k},
         "geometry": {"type": "Polygon", "coordinates": [[*map(list, ring), list(ring[0])]]}}
        for k, ring in enumerate(rings)]}
    if crs_member is not None:
        doc["crs"] = {"type": "name", "properties": {"name": crs_member}}
    path.write_text(json.dumps(doc))
    return path


def geopackage(path, rings, crs):
    import pyogrio.raw

    polygons = [shapely.Polygon(ring) for ring in rings]
    pyogrio.raw.write(path, shapely.to_wkb(polygons), field_data=[np.array([f"b{k}" for k in range(4)]),
                                                                 10.0 + np.arange(4)],
                      fields=["id", "height"], geometry_type="Polygon", crs=crs, driver="GPKG")
    return path


def swiss(rings):
    to_grid = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:2056", always_xy=True)
    return [list(zip(*to_grid.transform(*np.array(ring).T))) for ring in rings]


def test_degrees_are_told_from_metres_by_the_lots_extent():
    counts = np.array([4, 4])
    assert looks_like_degrees(np.array([r for ring in RINGS[:2] for r in ring]), counts)
    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]] * 2, float)
    assert not looks_like_degrees(square, counts)  # a 10 m lot near the origin is metres
    assert not looks_like_degrees(square + [500_000, 5_000_000], counts)
    assert not looks_like_degrees(square, np.array([4, 4, 0]))  # a lot without a vertex (an empty ring)


def test_lon_lat_geojson_is_reprojected_to_the_utm_zone_of_its_centre(tmp_path):
    lots = read_lots(geojson(tmp_path / "osm.geojson", RINGS))
    assert lots.crs == "EPSG:32632"
    assert lots.crs_note == "OGC:CRS84 (longitude/latitude), reprojected to EPSG:32632 (WGS 84 / UTM zone 32N)"
    want = pyproj.Transformer.from_crs("OGC:CRS84", "EPSG:32632", always_xy=True).transform(*RINGS[0][0])
    np.testing.assert_allclose(lots.vertices[0], [want[0], 0.0, -want[1]], atol=1e-6)
    width = lots.vertices[1, 0] - lots.vertices[0, 0]
    assert 15.0 < width < 15.5  # 0.0002 degrees of longitude at 46.5 degrees north


def test_geojson_sequence_and_south_of_the_equator(tmp_path):
    south = [[(lon - 65, -lat) for lon, lat in ring[::-1]] for ring in RINGS]
    path = tmp_path / "lots.geojsonl"
    path.write_text("\n".join(json.dumps({"type": "Feature", "properties": {}, "geometry": {
        "type": "Polygon", "coordinates": [[*map(list, r), list(r[0])]]}})
                              for r in south))
    assert read_lots(path).crs == "EPSG:32721"  # UTM zone 21S: longitude -58.4


def test_three_files_of_one_block_build_the_same_buildings(tmp_path):
    (tmp_path / "g.cga").write_text(GRAMMAR)
    files = [geojson(tmp_path / "osm.geojson", RINGS),
             geopackage(tmp_path / "wgs84.gpkg", RINGS, "EPSG:4326"),
             geopackage(tmp_path / "lv95.gpkg", swiss(RINGS), "EPSG:2056")]
    worlds = []
    for k, path in enumerate(files):
        out = tmp_path / f"city{k}.npz"
        build(tmp_path / "g.cga", out, lots_path=path, options=BuildOptions(lots=LotsOptions(crs="EPSG:2056")))
        record = read_instances(out)
        assert record["meta"]["crs"] == "EPSG:2056"
        assert np.isfinite(record["lot_origin"]).all()
        worlds.append(world_columns(record)[0])
    assert len(worlds[0]) > 300
    for other in worlds[1:]:
        np.testing.assert_allclose(other, worlds[0], atol=0.01, rtol=0)
    assert 2_537_000 < worlds[0][0, 0, 3] < 2_539_000  # LV95 eastings, in world x


def test_a_projected_file_stays_in_its_coordinate_system(tmp_path):
    lots = read_lots(geojson(tmp_path / "lv95.geojson", swiss(RINGS), "urn:ogc:def:crs:EPSG::2056"))
    assert lots.crs == "urn:ogc:def:crs:EPSG::2056" and lots.crs_note is None
    assert lots.vertices[0, 0] == pytest.approx(swiss(RINGS)[0][0][0])
    local = read_lots(geojson(tmp_path / "local.geojson", [[(0, 0), (30, 0), (30, 20), (0, 20)]]))
    assert local.crs is None and local.crs_note is None  # metres of a local scene, as ever


def test_degrees_without_a_coordinate_system_are_an_error_that_says_how(tmp_path):
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    geo = {"version": "1.0.0", "primary_column": "geometry",
           "columns": {"geometry": {"encoding": "WKB", "geometry_types": ["Polygon"], "crs": None}}}
    table = pa.table({"geometry": shapely.to_wkb([shapely.Polygon(r) for r in RINGS])})
    pq.write_table(table.replace_schema_metadata({"geo": json.dumps(geo)}), tmp_path / "lots.parquet")
    with pytest.raises(LotsError, match="look like longitude/latitude degrees but the file names no coordinate "
                                        "system: declare it with --lots-crs"):
        read_lots(tmp_path / "lots.parquet")
    assert read_lots(tmp_path / "lots.parquet", LotsOptions(lots_crs="EPSG:4326")).crs == "EPSG:32632"


def test_lots_that_say_degrees_but_are_metres_are_an_error(tmp_path):
    with pytest.raises(LotsError, match="name EPSG:4326 .* but their coordinates are not degrees"):
        read_lots(geojson(tmp_path / "x.geojson", swiss(RINGS), "EPSG:4326"))
    with pytest.raises(LotsError, match="unknown coordinate system `EPSG:99999999`"):
        read_lots(geojson(tmp_path / "y.geojson", RINGS, "EPSG:99999999"))


def test_a_target_that_is_not_metric_is_refused():
    from grammarc.errors import UsageError

    xy = np.array(RINGS[0], float)
    with pytest.raises(UsageError, match="--crs EPSG:4258: .* is not in metres"):
        georeference(xy, np.array([4]), "EPSG:4326", None, LotsOptions(crs="EPSG:4258"), "x")


def test_geoparquet_written_by_grammarc_names_its_coordinate_system(tmp_path):
    pytest.importorskip("pyarrow")
    from grammarc.io.geoparquet import write_geoparquet

    lots = read_lots(geojson(tmp_path / "osm.geojson", RINGS))
    write_geoparquet(lots, tmp_path / "utm.parquet")
    again = read_lots(tmp_path / "utm.parquet")
    assert again.crs == "EPSG:32632" and again.crs_note is None
    np.testing.assert_allclose(again.vertices, lots.vertices)
    local = read_lots(geojson(tmp_path / "local.geojson", [[(0, 0), (30, 0), (30, 20), (0, 20)]]))
    write_geoparquet(local, tmp_path / "local.parquet")
    import pyarrow.parquet as pq

    geo = json.loads(pq.read_schema(tmp_path / "local.parquet").metadata[b"geo"])
    assert geo["columns"]["geometry"]["crs"] is None  # unknown, not the default longitude/latitude


def test_a_partitioned_build_of_lon_lat_lots_needs_a_crs(tmp_path):
    path = tmp_path / "lots.geojsonl"
    path.write_text("\n".join(json.dumps({"type": "Feature", "properties": {}, "geometry": {
        "type": "Polygon", "coordinates": [[*map(list, r), list(r[0])]]}})
                              for r in RINGS))
    part = partition_lots(path, 2)[0]
    with pytest.raises(LotsError, match="a partitioned build needs --crs"):
        read_partition(part, 0)
    assert read_partition(part, 0, LotsOptions(crs="EPSG:2056")).crs == "EPSG:2056"


def test_the_build_says_how_it_reprojected_even_when_quiet(tmp_path):
    (tmp_path / "g.cga").write_text(GRAMMAR)
    geojson(tmp_path / "osm.geojson", RINGS)
    done = subprocess.run([sys.executable, "-m", "grammarc.cli", "build", str(tmp_path / "g.cga"), "--lots",
                           str(tmp_path / "osm.geojson"), "--emit", str(tmp_path / "c.npz"), "--quiet"],
                          capture_output=True, text=True, check=True)
    assert done.stderr == ("grammarc: lots in OGC:CRS84 (longitude/latitude), reprojected to EPSG:32632 "
                           "(WGS 84 / UTM zone 32N)\n")
    info = subprocess.run([sys.executable, "-m", "grammarc.cli", "info", str(tmp_path / "c.npz")],
                          capture_output=True, text=True, check=True).stdout
    assert "  crs         EPSG:32632" in info


@pytest.mark.parametrize("suffix", [".ply", ".stl", ".obj"])
def test_baked_meshes_name_their_coordinate_system(tmp_path, suffix):
    (tmp_path / "g.cga").write_text(GRAMMAR)
    out = tmp_path / f"city{suffix}"
    build(tmp_path / "g.cga", out, lots_path=geojson(tmp_path / "osm.geojson", RINGS))
    head = out.read_bytes()[:300]
    assert b" crs EPSG:32632" in head and b"origin " in head


def test_instanced_outputs_name_their_coordinate_system(tmp_path):
    (tmp_path / "g.cga").write_text(GRAMMAR)
    lots = geojson(tmp_path / "osm.geojson", RINGS)
    build(tmp_path / "g.cga", tmp_path / "city.glb", lots_path=lots)
    gltf = json.loads((tmp_path / "city.glb").read_bytes()[20:20 + int.from_bytes(
        (tmp_path / "city.glb").read_bytes()[12:16], "little")])
    assert gltf["asset"]["extras"]["crs"] == "EPSG:32632" and gltf["asset"]["extras"]["origin"] == [0, 0, 0]
    pxr = pytest.importorskip("pxr")
    build(tmp_path / "g.cga", tmp_path / "city.usdc", lots_path=lots)
    layer = pxr.Sdf.Layer.FindOrOpen(str(tmp_path / "city.usdc"))
    assert layer.customLayerData["grammarc:crs"] == "EPSG:32632"
