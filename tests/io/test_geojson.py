"""Tests of grammarc.io.geojson: GeoJSON documents of every shape, and PRT initial shapes as JSON."""

from __future__ import annotations

import json

import numpy as np
import pytest
from lot_features import (
    PRT_AREAS,
    PRT_FOOTPRINTS,
    SQUARE,
    feature,
    lot_area,
    normal_y,
    prt,
    rings,
    write_geojson,
)

from grammarc.errors import LotsError
from grammarc.io.lots import read_lots


def test_single_feature_and_bare_geometry_files(tmp_path):
    single = tmp_path / "one.json"
    single.write_text(json.dumps(feature([SQUARE], properties={"name": "x"})))
    assert read_lots(single).ids.tolist() == ["x"]
    bare = tmp_path / "bare.geojson"
    bare.write_text(json.dumps({"type": "MultiPolygon", "coordinates": [[SQUARE], [SQUARE]]}))
    assert read_lots(bare).ids.tolist() == ["0:0", "0:1"]


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
def test_prt_initial_shape_json_with_hole():
    lots = read_lots(PRT_FOOTPRINTS / "courtyard_40x40.json")
    assert lots.ids.tolist() == ["face0"] and lots.lot_offsets.tolist() == [0, 2]
    assert lot_area(lots, 0) == pytest.approx(1200.0)
    np.testing.assert_array_equal(rings(lots, 0)[0][:2], [[0, 0, 0], [0, 0, 40]])

