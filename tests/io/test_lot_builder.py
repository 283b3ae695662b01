"""Tests of grammarc.io.lot_builder: GeoJSON features to lots, their cleanup, orientation and validation,
street flags and property columns (read from GeoJSON files, and made in memory)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lot_features import BOWTIE, SQUARE, feature, lot_area, map_area, normal_y, rings, write_geojson

from grammarc.io.lots import lots_from_polygons, read_lots
from grammarc.model.lots import BadLot, Lots


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
    assert height.dtype == np.float64 and flag.dtype == object
    np.testing.assert_array_equal(height, [10.0, 2.5, np.nan])
    # a boolean is no number (an attribute of numbers given one makes its lot bad): its JSON text
    assert flag.tolist() == ["true", "false", None]
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


def test_a_lot_with_a_coordinate_that_is_no_place_on_earth_is_bad(tmp_path):
    """Squares of its lengths would overflow: the lot is bad, named with the reason, the others build."""
    huge = [[0, 0], [1, 0], [1, 1e308], [0, 1e308]]
    lots = read_lots(write_geojson(tmp_path, [feature([huge]), feature([SQUARE])]))
    assert lots.index.tolist() == [1]
    assert lots.bad == (BadLot(0, "0", "a coordinate is not finite or beyond 1e+08"),)
    not_finite = np.array([[0, 0], [1, 0], [1, np.nan], [0, 1]])
    high = np.array([[0, 0, 0], [1, 0, 0], [1, 1, np.inf], [0, 1, 0]])
    lots = lots_from_polygons([[not_finite], [np.array(SQUARE, float)], [high]])
    assert lots.index.tolist() == [1]
    assert [(b.index, b.reason) for b in lots.bad] == [(i, "a coordinate is not finite or beyond 1e+08") for i in (0, 2)]


def test_tiny_triangle_is_zero_area_and_hole_outside_shell_is_invalid(tmp_path):
    tiny = [[0, 0], [1.2e-3, 0], [0, 1.2e-3]]  # edges over 0.8 mm (they stay), 0.72 mm^2
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


def test_an_elevation_is_the_lots_base_height_its_lowest_corner(tmp_path):
    """A 3D footprint (draped on terrain) stands flat on its lowest corner; positions without an elevation
    do not count, and a lot without any stands at 0."""
    draped = [[x, y, 99.0 + k] for k, (x, y) in enumerate(SQUARE)]
    mixed = [[x + 20, y, 7.5] if k == 2 else [x + 20, y] for k, (x, y) in enumerate(SQUARE)]
    flat = [[x + 40, y] for x, y in SQUARE]
    lots = read_lots(write_geojson(tmp_path, [feature([draped]), feature([mixed]), feature([flat])]))
    heights = [np.unique(lots.vertices[lots.ring_offsets[k]:lots.ring_offsets[k + 1], 1]).tolist() for k in range(3)]
    assert heights == [[99.0], [7.5], [0.0]] and lot_area(lots, 0) == pytest.approx(100.0)
    empty = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [[]]}}
    lots = read_lots(write_geojson(tmp_path, [feature([draped]), empty]))  # the last lot without a vertex
    assert lots.index.tolist() == [0] and lots.bad == (BadLot(1, "1", "fewer than 3 distinct vertices"),)


def test_duplicate_and_closing_vertices_are_removed(tmp_path):
    ring = [[0, 0], [0, 0], [10, 0], [10, 1e-8], [10, 10], [0, 10], [0, 10], [0, 0]]
    lots = read_lots(write_geojson(tmp_path, [feature([ring])]))
    np.testing.assert_array_equal(lots.vertices, [[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]])


def test_a_run_of_near_duplicates_around_the_end_collapses_into_the_first_edge_as_in_prt():
    """PRT (genattrs, whose second box goes 50 m along the first edge) keeps this lot's first edge along
    +x: the run (5e-8, 0), (0, 5e-8), (0, 0) and the first vertex collapse into one vertex that starts
    the ring."""
    ring = np.array([[0, 0], [10, 0], [10, 10], [0, 10], [5e-8, 0], [0, 5e-8], [0, 0]])
    lots = lots_from_polygons([[ring]])
    np.testing.assert_allclose(lots.vertices[:, [0, 2]], [[0, 0], [10, 0], [10, -10], [0, -10]], atol=1e-7)


def test_short_edges_collapse_as_in_prt():
    """Edges under 0.8 mm lose the end whose removal changes the ring less, as PRT does (measured with
    extrude_color: face counts and bounding boxes), and the lot starts where its first vertex went."""
    def collapsed(ring):
        return lots_from_polygons([[np.array(ring)]]).vertices[:, [0, 2]]

    # a collinear vertex on an edge of 0.7999 mm goes, one of 0.8 mm stays
    assert len(collapsed([[0, 0], [7.999e-4, 0], [10, 0], [10, 10], [0, 10]])) == 4
    assert len(collapsed([[0, 0], [8e-4, 0], [10, 0], [10, 10], [0, 10]])) == 5
    # the first vertex lies on the line of its neighbours: it goes, its successor starts the ring
    np.testing.assert_allclose(collapsed([[0, 0], [0, -5e-4], [10, 0], [10, 10], [0, 10]])[0], [0, 5e-4])
    # the last vertex sticks out: it stays and starts the ring
    np.testing.assert_allclose(collapsed([[0, 0], [10, 0], [10, 10], [0, 10], [-5e-4, 0]])[0], [-5e-4, 0])
    # a spike of 0.5 mm goes, whichever side of the corner it is
    assert collapsed([[0, 0], [10, 0], [10, 10], [10 + 5e-4, 10 + 1e-4], [0, 10]]).max() == 10
    np.testing.assert_allclose(collapsed([[0, 0], [10, 0], [10 + 5e-4, 10 + 1e-4], [10, 10], [0, 10]]),
                               [[0, 0], [10, 0], [10 + 5e-4, -10 - 1e-4], [0, -10]])
    # three on a line 0.5 mm apart: the middle one goes, the far one stays (1 mm from the first)
    assert collapsed([[0, 0], [0, -5e-4], [0, -1e-3], [10, 0], [10, 10], [0, 10]]).tolist()[:2] == [
        [0, 0], [0, 1e-3]]


def test_an_arc_of_short_edges_loses_every_other_vertex():
    angle = np.linspace(0, 2 * np.pi, 100_000, endpoint=False)
    circle = np.column_stack([10 * np.cos(angle), 10 * np.sin(angle)])  # edges of 0.63 mm
    lots = lots_from_polygons([[circle]])
    assert not lots.bad and len(lots.vertices) == 50_000


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


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), offset=st.sampled_from([200.0, 5e5]))
def test_lots_that_skip_geos_validity_are_those_it_finds_valid(seed, offset):
    """Rings of 3-7 vertices on a coarse grid (convex, concave, bow-ties, collinear runs, slivers, rings
    that wind twice), some with a hole: the same lots and bad lots as when GEOS checks every lot, and
    every lot it is not asked about is one it finds valid. (The offsets keep x beyond 180: tiny lots
    near the origin would look like degrees, which the reader refuses without a coordinate system.)"""
    import shapely

    from grammarc.io import lot_builder

    rng = np.random.default_rng(seed)
    polygons = []
    for _ in range(40):
        n = rng.integers(3, 8)
        ring = offset + rng.integers(0, 4, (n, 2)) * rng.choice([1.0, 1e-4])
        if rng.random() < 0.3:  # a convex polygon, maybe wound twice (a pentagram's order)
            angles = np.sort(rng.uniform(0, 2 * np.pi, n))
            ring = offset + np.column_stack([np.cos(angles), np.sin(angles)]) * rng.uniform(1e-3, 50)
            if n == 5 and rng.random() < 0.5:
                ring = ring[[0, 2, 4, 1, 3]]
        polygons.append([ring] if rng.random() < 0.8 else [ring, offset + np.array([[1, 1], [1.5, 1], [1, 1.5]])])
    fast = lots_from_polygons(polygons)
    convex = lot_builder._plainly_convex(fast)
    assert shapely.is_valid(lot_builder._map_polygons(fast)[convex]).all()
    original = lot_builder._plainly_convex
    try:
        lot_builder._plainly_convex = lambda lots: np.zeros(len(lots), dtype=bool)
        slow = lots_from_polygons(polygons)
    finally:
        lot_builder._plainly_convex = original
    assert fast.bad == slow.bad
    np.testing.assert_array_equal(fast.vertices, slow.vertices)


@pytest.mark.parametrize("min_area", [None, 0.5, 2.0])
def test_lots_near_the_least_area_are_judged_by_geos_as_before(min_area):
    """Convex lots skip GEOS only where their area is plainly more than the least a lot may have (the
    area floor, ``--min-area``): squares just over and under either are the bad lots, with the reasons
    and areas, of the check that asks GEOS about every lot."""
    from grammarc.io import lot_builder
    from grammarc.io.lot_format import LotsOptions

    sides = [np.sqrt(a) for a in (1e-6 * 0.9999, 1e-6 * 1.0001, 1e-6 * 1.01, 0.5 * 0.9999, 0.5 * 1.0001,
                                  2.0 * 0.99999, 2.0 * 1.00001, 2.0 * 1.002, 100.0)]

    def read():
        builder = lot_builder.LotBuilder(world=False)
        for k, side in enumerate(sides):
            square = 5e5 + np.array([[0, 0], [side, 0], [side, side], [0, side]])
            builder.add_positions(k, f"s{k}", [square], {})
        return builder.finish({}, "<memory>", LotsOptions(min_area=min_area))

    fast = read()
    original = lot_builder._plainly_convex
    try:
        lot_builder._plainly_convex = lambda lots: np.zeros(len(lots), dtype=bool)
        slow = read()
    finally:
        lot_builder._plainly_convex = original
    assert fast.bad == slow.bad and fast.ids.tolist() == slow.ids.tolist()
    least = {None: 0, 0.5: 4, 2.0: 6}[min_area]
    assert [b.index for b in fast.bad] == list(range(max(least, 1)))


@pytest.mark.parametrize(("values", "want"), [
    ([1, 2.5, None], [1.0, 2.5, np.nan]),
    ([2**53 + 1, -3], [float(2**53 + 1), -3.0]),
    ([1, True], ["1", "true"]),
    ([1.5, "2"], ["1.5", "2"]),
    ([None, None], [np.nan, np.nan]),
])
def test_a_property_column_is_numbers_only_where_every_value_is_a_number(values, want):
    """JSON's numbers take one pass in C; a boolean or a string among them makes a column of text."""
    from grammarc.io.lot_builder import property_column

    column = property_column(values)
    if isinstance(want[0], float):
        assert column.dtype == np.float64
        np.testing.assert_array_equal(column, want)
    else:
        assert column.dtype == object and column.tolist() == want
