"""Tests of grammarc.io.lots: GeoJSON / OBJ / in-memory lots, cleanup, orientation, validation, take."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.errors import LotsError
from grammarc.io.lots import BadLot, Lots, default_lot, lots_from_polygons, read_lots

# the PRT kit sits next to the repository: ../shared/prt from its root
PRT_FOOTPRINTS = Path(__file__).resolve().parents[3] / "shared" / "prt" / "footprints"

SQUARE = [[0, 0], [10, 0], [10, 10], [0, 10]]  # counter-clockwise on the map
BOWTIE = [[0, 0], [2, 2], [2, 0], [0, 2]]


# ---------------------------------------------------------------------------------------------- helpers


def rings(lots: Lots, i: int) -> list[np.ndarray]:
    """The rings of lot i, (k, 3) world coordinates each."""
    o = lots.ring_offsets
    return [lots.vertices[o[r] : o[r + 1]] for r in range(lots.lot_offsets[i], lots.lot_offsets[i + 1])]


def normal_y(ring: np.ndarray) -> float:
    """Newell normal's y component of a world ring (twice its area seen from above)."""
    nxt = np.roll(ring, -1, axis=0)
    return float(np.sum((ring[:, 2] - nxt[:, 2]) * (ring[:, 0] + nxt[:, 0])))


def map_area(ring: np.ndarray) -> float:
    """Shoelace signed area of a world ring in map coordinates (x, -z)."""
    x, y = ring[:, 0], -ring[:, 2]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def lot_area(lots: Lots, i: int) -> float:
    return sum(map_area(ring) for ring in rings(lots, i))


def feature(coords, kind="Polygon", **extra) -> dict:
    return {"type": "Feature", "geometry": {"type": kind, "coordinates": coords}, **extra}


def write_geojson(tmp_path: Path, features: list[dict], name: str = "lots.geojson") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def write_obj(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "lots.obj"
    path.write_text(text)
    return path


# ---------------------------------------------------------------------------------------------- GeoJSON


def test_ccw_square_maps_to_world_with_up_normal(tmp_path):
    lots = read_lots(write_geojson(tmp_path, [feature([SQUARE + [SQUARE[0]]], id="a")]))
    assert len(lots) == 1 and lots.ids.tolist() == ["a"] and lots.bad == ()
    expected = [[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]]
    np.testing.assert_array_equal(lots.vertices, expected)
    assert not np.signbit(lots.vertices[lots.vertices == 0]).any()  # map y = 0 gives z = +0.0, not -0.0
    assert normal_y(lots.vertices) > 0
    assert lots.ring_offsets.tolist() == [0, 4] and lots.lot_offsets.tolist() == [0, 1]
    assert lots.index.dtype == np.int64 and lots.ring_offsets.dtype == np.int64
    assert lots.vertices.dtype == np.float64 and lots.ids.dtype == object
    assert lots.source == str(tmp_path / "lots.geojson")


def test_clockwise_ring_is_reversed_keeping_its_first_vertex(tmp_path):
    cw = [[0, 0], [0, 10], [10, 10], [10, 0]]
    lots = read_lots(write_geojson(tmp_path, [feature([cw])]))
    # v0, v3, v2, v1 of the input
    expected = [[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]]
    np.testing.assert_array_equal(lots.vertices, expected)
    assert normal_y(lots.vertices) > 0


def test_hole_gets_down_normal_and_exterior_up_normal(tmp_path):
    outer_cw = [[0, 0], [0, 40], [40, 40], [40, 0]]
    hole_ccw = [[10, 10], [30, 10], [30, 30], [10, 30]]  # wrong for a hole (RFC 7946 wants clockwise)
    lots = read_lots(write_geojson(tmp_path, [feature([outer_cw, hole_ccw])]))
    outer, hole = rings(lots, 0)
    assert normal_y(outer) > 0 and normal_y(hole) < 0
    np.testing.assert_array_equal(outer[0], [0, 0, 0])
    np.testing.assert_array_equal(hole[:2], [[10, 0, -10], [10, 0, -30]])
    assert lot_area(lots, 0) == pytest.approx(1200.0)


def street_edges(lots: Lots, i: int) -> list[list[list[float]]]:
    """The street edges of lot i's exterior ring as [start, end] map points."""
    ring = rings(lots, i)[0]
    flags = lots.street[lots.ring_offsets[lots.lot_offsets[i]]:][:len(ring)]
    ends = [(ring[k], ring[(k + 1) % len(ring)]) for k in np.flatnonzero(flags)]
    return [[[a[0], -a[2]], [b[0], -b[2]]] for a, b in ends]


def test_street_width_marks_edges_through_reversal_closing_and_merged_points(tmp_path):
    """CityEngine's streetWidth: a number per edge, > 0 for a street. The edge keeps its mark when its
    ring is reversed, given closed, or has a duplicated point."""
    ccw = feature([SQUARE + [SQUARE[0]]], id="ccw", properties={"streetWidth": [0, 8, 0, 0]})
    cw = feature([[[0, 0], [0, 10], [10, 10], [10, 0]]], id="cw", properties={"streetWidth": [0, 0, 8, 0]})
    doubled = feature([[[0, 0], [10, 0], [10, 0], [10, 10], [0, 10]]], id="dup",
                      properties={"streetWidth": [0, 0, 5, 0, 0], "h": 3})
    lots = read_lots(write_geojson(tmp_path, [ccw, cw, doubled]))
    assert lots.bad == () and "streetWidth" not in lots.attrs and lots.attrs["h"][2] == 3
    assert street_edges(lots, 0) == [[[10, 0], [10, 10]]]
    assert street_edges(lots, 1) == [[[10, 0], [10, 10]]]  # the east edge, run the other way now
    assert street_edges(lots, 2) == [[[10, 0], [10, 10]]]


def test_a_street_width_that_does_not_fit_the_ring_is_a_bad_lot(tmp_path):
    lots = read_lots(write_geojson(tmp_path, [
        feature([SQUARE], id="short", properties={"streetWidth": [1, 0]}),
        feature([SQUARE], id="text", properties={"streetWidth": "front"}),
        feature([SQUARE], id="ok")]))
    assert lots.ids.tolist() == ["ok"]
    assert [b.reason for b in lots.bad] == ["streetWidth has 2 values for 4 edges",
                                            "streetWidth is not a list of numbers"]


def test_multipolygon_gives_one_lot_per_polygon_with_shared_properties(tmp_path):
    far = [[p[0] + 100, p[1]] for p in SQUARE]
    multi = feature([[SQUARE], [far]], kind="MultiPolygon", id="blk", properties={"height": 12})
    lots = read_lots(write_geojson(tmp_path, [feature([SQUARE]), multi]))
    assert lots.ids.tolist() == ["0", "blk:0", "blk:1"]
    assert lots.index.tolist() == [0, 1, 2]
    assert lots.lot_offsets.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(lots.attrs["height"], [np.nan, 12.0, 12.0])
    assert rings(lots, 2)[0][0].tolist() == [100.0, 0.0, 0.0]


def test_lot_ids_come_from_feature_id_then_property_id_then_name_then_index(tmp_path):
    features = [
        feature([SQUARE], id=7, properties={"id": "p", "name": "n"}),
        feature([SQUARE], properties={"id": "p", "name": "n"}),
        feature([SQUARE], properties={"name": "n"}),
        feature([SQUARE], properties=None),
    ]
    assert read_lots(write_geojson(tmp_path, features)).ids.tolist() == ["7", "p", "n", "3"]


def test_properties_become_float_and_string_columns_with_missing_values(tmp_path):
    props = [
        {"height": 10, "use": "office", "flag": True, "mixed": 1, "tags": ["a", "b"]},
        {"height": 2.5, "flag": False, "mixed": "x"},
        {"use": None, "tags": {"k": 1}},
    ]
    lots = read_lots(write_geojson(tmp_path, [feature([SQUARE], properties=p) for p in props]))
    assert list(lots.attrs) == ["height", "use", "flag", "mixed", "tags"]
    height, flag = lots.attrs["height"], lots.attrs["flag"]
    assert height.dtype == np.float64 and flag.dtype == np.float64
    np.testing.assert_array_equal(height, [10.0, 2.5, np.nan])
    np.testing.assert_array_equal(flag, [1.0, 0.0, np.nan])
    assert lots.attrs["use"].dtype == object and lots.attrs["use"].tolist() == ["office", None, None]
    assert lots.attrs["mixed"].tolist() == ["1", "x", None]
    assert lots.attrs["tags"].tolist() == ['["a", "b"]', None, '{"k": 1}']


def test_bad_lots_are_reported_and_the_others_keep_their_numbers(tmp_path):
    features = [
        feature([SQUARE], id="ok0"),
        feature([BOWTIE], id="bowtie"),
        feature([[[0, 0], [5, 0], [10, 0]]], id="flat"),
        feature([SQUARE], id="ok3", properties={"h": 3}),
    ]
    lots = read_lots(write_geojson(tmp_path, features))
    assert lots.ids.tolist() == ["ok0", "ok3"]
    assert lots.index.tolist() == [0, 3]
    np.testing.assert_array_equal(lots.attrs["h"], [np.nan, 3.0])
    bowtie, flat = lots.bad
    assert (bowtie.index, bowtie.id, flat) == (1, "bowtie", BadLot(2, "flat", "zero area"))
    assert bowtie.reason == "self-intersection at (1.0, 1.0)"


def test_tiny_triangle_is_zero_area_and_hole_outside_shell_is_invalid(tmp_path):
    tiny = [[0, 0], [1e-4, 0], [0, 1e-4]]
    outside = [SQUARE, [[20, 20], [20, 21], [21, 21], [21, 20]]]
    lots = read_lots(write_geojson(tmp_path, [feature([tiny]), feature(outside), feature([SQUARE])]))
    assert lots.index.tolist() == [2]
    assert lots.bad[0] == BadLot(0, "0", "zero area")
    assert lots.bad[1].index == 1 and lots.bad[1].reason.startswith("hole lies outside shell")


def test_non_polygon_features_are_reported(tmp_path):
    features = [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 2]}, "id": "pt"},
        {"type": "Feature", "geometry": None},
        feature([SQUARE]),
    ]
    lots = read_lots(write_geojson(tmp_path, features))
    assert lots.index.tolist() == [2]
    assert lots.bad == (
        BadLot(0, "pt", "not a polygon (Point)"),
        BadLot(1, "1", "not a polygon (null geometry)"),
    )


def test_single_feature_and_bare_geometry_files(tmp_path):
    single = tmp_path / "one.json"
    single.write_text(json.dumps(feature([SQUARE], properties={"name": "x"})))
    assert read_lots(single).ids.tolist() == ["x"]
    bare = tmp_path / "bare.geojson"
    bare.write_text(json.dumps({"type": "MultiPolygon", "coordinates": [[SQUARE], [SQUARE]]}))
    assert read_lots(bare).ids.tolist() == ["0:0", "0:1"]


def test_third_coordinate_is_ignored(tmp_path):
    square_3d = [[x, y, 99.0] for x, y in SQUARE]
    lots = read_lots(write_geojson(tmp_path, [feature([square_3d])]))
    assert np.all(lots.vertices[:, 1] == 0) and lot_area(lots, 0) == pytest.approx(100.0)


def test_duplicate_and_closing_vertices_are_removed(tmp_path):
    ring = [[0, 0], [0, 0], [10, 0], [10, 1e-8], [10, 10], [0, 10], [0, 10], [0, 0]]
    lots = read_lots(write_geojson(tmp_path, [feature([ring])]))
    np.testing.assert_array_equal(lots.vertices, [[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]])


def test_run_of_near_duplicates_wrapping_around_the_end_belongs_to_the_first_vertex():
    ring = np.array([[0, 0], [10, 0], [10, 10], [0, 10], [5e-8, 0], [0, 5e-8], [0, 0]])
    lots = lots_from_polygons([[ring]])
    np.testing.assert_array_equal(lots.vertices[:, [0, 2]], [[0, 0], [10, 0], [10, -10], [0, -10]])


def test_fewer_than_three_distinct_vertices_is_bad():
    lots = lots_from_polygons([[np.array([[0, 0], [1, 0], [1, 0], [0, 0]])], [np.array(SQUARE)]])
    assert lots.bad == (BadLot(0, "0", "fewer than 3 distinct vertices"),)
    assert lots.ids.tolist() == ["1"]


def test_empty_and_malformed_polygons_are_reported(tmp_path):
    features = [
        feature([]),
        feature([], kind="MultiPolygon"),
        feature([[[0, 0], [1, "x"], [1, 1]]]),
        feature([SQUARE]),
    ]
    lots = read_lots(write_geojson(tmp_path, features))
    assert [(b.index, b.reason) for b in lots.bad] == [
        (0, "empty polygon"),
        (1, "empty polygon"),
        (2, "malformed coordinates"),
    ]
    assert lots.index.tolist() == [3]


def test_missing_file_raises(tmp_path):
    with pytest.raises(LotsError, match="lots file not found: .*nope.geojson"):
        read_lots(tmp_path / "nope.geojson")


def test_bad_json_raises_with_line_and_column(tmp_path):
    path = tmp_path / "broken.geojson"
    path.write_text('{"type": "FeatureCollection",\n "features": [,]}')
    with pytest.raises(LotsError, match=r"broken.geojson:2:15: not valid JSON"):
        read_lots(path)


def test_file_without_polygons_raises(tmp_path):
    point = {"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 2]}}
    path = write_geojson(tmp_path, [point])
    with pytest.raises(LotsError, match=f"no polygon in lots file {path}"):
        read_lots(path)
    with pytest.raises(LotsError, match="no polygon"):
        read_lots(write_geojson(tmp_path, [], name="empty.json"))


def test_unknown_suffix_raises(tmp_path):
    path = tmp_path / "lots.dwg"
    path.write_bytes(b"\0")
    with pytest.raises(LotsError, match="unknown lots file type '.dwg'.*lots.dwg"):
        read_lots(path)


def test_a_broken_gis_file_raises(tmp_path):
    pytest.importorskip("pyogrio")
    path = tmp_path / "lots.shp"
    path.write_bytes(b"\0")
    with pytest.raises(LotsError, match="cannot read lots file .*lots.shp"):
        read_lots(path)


# -------------------------------------------------------------------------------------------------- OBJ


def test_obj_faces_with_negative_and_slashed_indices(tmp_path):
    text = """# two footprints
o lots
v 0 1 0
v 0 1 20
v 30 1 20
v 30 1 0
vt 0 0
vn 0 1 0
f 1/1/1 2//1 3/1 4
v 50 0 0
v 60 0 0
v 60 0 -10
f -3 -1 -2
"""
    lots = read_lots(write_obj(tmp_path, text))
    assert lots.ids.tolist() == ["face0", "face1"] and lots.index.tolist() == [0, 1]
    first, second = rings(lots, 0)[0], rings(lots, 1)[0]
    np.testing.assert_array_equal(first, [[0, 1, 0], [0, 1, 20], [30, 1, 20], [30, 1, 0]])  # y kept
    # -3 -1 -2 is clockwise from above: reversed keeping (50, 0, 0) first
    np.testing.assert_array_equal(second, [[50, 0, 0], [60, 0, 0], [60, 0, -10]])
    assert normal_y(first) > 0 and normal_y(second) > 0


def test_obj_wall_face_and_bad_index_are_reported(tmp_path):
    text = "v 0 0 0\nv 10 0 0\nv 10 3 0\nv 0 3 0\nv 0 0 -10\nf 1 2 3 4\nf 1 2 5\nf 1 2 9\n"
    lots = read_lots(write_obj(tmp_path, text))
    assert lots.ids.tolist() == ["face1"]
    assert lots.bad == (
        BadLot(0, "face0", "not a footprint: face normal is not vertical"),
        BadLot(2, "face2", "vertex index out of range"),
    )


def test_obj_malformed_line_raises_with_line_number(tmp_path):
    with pytest.raises(LotsError, match=r"lots.obj:2: bad 'v' line"):
        read_lots(write_obj(tmp_path, "v 0 0 0\nv 1 zero 0\n"))
    with pytest.raises(LotsError, match="no polygon"):
        read_lots(write_obj(tmp_path, "v 0 0 0\n"))


# --------------------------------------------------------------------------------------- in memory


def test_default_lot():
    lot = default_lot()
    assert lot.ids.tolist() == ["default"] and lot.bad == ()
    np.testing.assert_array_equal(lot.vertices, [[0, 0, 0], [30, 0, 0], [30, 0, -20], [0, 0, -20]])


def test_lots_from_polygons_checks_lengths():
    with pytest.raises(ValueError, match="ids has 2 entries for 1 polygons"):
        lots_from_polygons([[np.array(SQUARE)]], ids=["a", "b"])
    with pytest.raises(ValueError, match="attrs\\['h'\\] has 0 entries"):
        lots_from_polygons([[np.array(SQUARE)]], attrs={"h": []})


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(3, 12),
    seed=st.integers(0, 2**32 - 1),
    clockwise=st.booleans(),
    offset=st.sampled_from([0.0, 5e5]),
)
def test_star_polygons_keep_first_vertex_and_area(n, seed, clockwise, offset):
    """Star-shaped rings (simple by construction) at any winding, also far from the origin."""
    rng = np.random.default_rng(seed)
    # one vertex per sector of 2 pi / n, gaps below pi: the ring is simple, star-shaped about the origin
    angles = 2 * np.pi * (np.arange(n) + rng.uniform(0, 0.4, n)) / n
    radii = rng.uniform(1, 10, n)
    ring = offset + np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    if clockwise:
        ring = ring[::-1]
    lots = lots_from_polygons([[ring]])
    (out,) = rings(lots, 0)
    np.testing.assert_array_equal(out[0, [0, 2]], [ring[0, 0], -ring[0, 1]])
    assert normal_y(out - out[0]) > 0
    x, y = ring[:, 0] - ring[0, 0], ring[:, 1] - ring[0, 1]
    area = 0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    assert map_area(out - out[0]) == pytest.approx(area, rel=1e-9)


# ------------------------------------------------------------------------------------------- PRT kit

prt = pytest.mark.skipif(not PRT_FOOTPRINTS.is_dir(), reason="PRT kit (../shared/prt) not present")
PRT_AREAS = {
    "rect_30x20": 600.0,
    "rect_12x8": 96.0,
    "L_30x20": 400.0,
    "U_40x30": 900.0,
    "courtyard_40x40": 1200.0,
    "rotated_25x15": 375.0,
    "triangle": 150.0,
    "octagon": 407.29,
}


@prt
def test_prt_geojson_loads_with_areas_and_up_normals():
    lots = read_lots(PRT_FOOTPRINTS / "all.geojson")
    assert lots.bad == () and lots.ids.tolist() == list(PRT_AREAS)
    for i, name in enumerate(lots.ids):
        assert lot_area(lots, i) == pytest.approx(PRT_AREAS[name], abs=0.01), name
        assert normal_y(rings(lots, i)[0]) > 0
    courtyard = rings(lots, lots.ids.tolist().index("courtyard_40x40"))
    assert len(courtyard) == 2 and normal_y(courtyard[1]) < 0
    # the rings start at the same vertex as the OBJ files: rect_30x20 runs (0,0,0) -> (0,0,20) first
    np.testing.assert_array_equal(rings(lots, 0)[0][:2], [[0, 0, 0], [0, 0, 20]])


@prt
@pytest.mark.parametrize("name", [n for n in PRT_AREAS if n != "courtyard_40x40"])
def test_prt_obj_footprints_load_unchanged(name):
    path = PRT_FOOTPRINTS / f"{name}.obj"
    lots = read_lots(path)
    assert len(lots) == 1 and lots.bad == ()
    assert lot_area(lots, 0) == pytest.approx(PRT_AREAS[name], abs=0.01)
    # already +Y: the vertex order of the file is kept
    file_vertices = [line.split()[1:] for line in path.read_text().splitlines() if line.startswith("v ")]
    np.testing.assert_allclose(lots.vertices, np.array(file_vertices, dtype=float))


@prt
def test_prt_initial_shape_json_with_hole():
    lots = read_lots(PRT_FOOTPRINTS / "courtyard_40x40.json")
    assert lots.ids.tolist() == ["face0"] and lots.lot_offsets.tolist() == [0, 2]
    assert lot_area(lots, 0) == pytest.approx(1200.0)
    np.testing.assert_array_equal(rings(lots, 0)[0][:2], [[0, 0, 0], [0, 0, 40]])
