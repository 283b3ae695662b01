"""GeoParquet lots read as the same lots as the GeoJSON they were converted from, bad ones included."""

import json

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
import pyarrow.parquet as pq
import shapely
from lot_features import FEATURES, lot_files

from grammarc.cli import main
from grammarc.io.geoparquet import write_geoparquet
from grammarc.io.lots import partition_lots, read_lots


def same(a, b, numbers=True):
    assert list(a.ids) == list(b.ids)
    assert a.index.tolist() == b.index.tolist() or not numbers
    for key in ("vertices", "ring_offsets", "lot_offsets", "street"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
    assert list(a.attrs) == list(b.attrs)
    for name in a.attrs:
        assert a.attrs[name].dtype == b.attrs[name].dtype
        assert a.attrs[name].astype(str).tolist() == b.attrs[name].astype(str).tolist()


@pytest.mark.parametrize("line", [True, False])
def test_a_parquet_file_gives_the_lots_of_its_geojson(tmp_path, line):
    """Written from the features directly (a GIS tool's GeoParquet): the same lots, the same bad lots; read
    through shapely where a row is a line, else by the WKB kernel (``io.wkb``)."""
    features = [f for f in FEATURES if line or f["id"] != "line"]
    path = tmp_path / "lots.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    geometry = [shapely.from_geojson(json.dumps(f["geometry"])) for f in features]
    table = pa.table({
        "id": [f["id"] for f in features],
        "kind": [f["properties"]["kind"] for f in features],
        "h": pa.array([f["properties"]["h"] for f in features], type=pa.float64()),
        "streetWidth": [f["properties"].get("streetWidth") for f in features],
        "geometry": shapely.to_wkb(geometry),
    }).replace_schema_metadata({"geo": json.dumps({"primary_column": "geometry",
                                                   "columns": {"geometry": {"encoding": "WKB"}}})})
    pq.write_table(table, tmp_path / "lots.parquet")
    geojson, parquet = read_lots(path), read_lots(tmp_path / "lots.parquet")
    same(geojson, parquet)
    assert parquet.ids.tolist() == ["a", "m:0", "m:1"] and parquet.street.sum() == 1
    assert parquet.bad == geojson.bad and [b.id for b in parquet.bad] == ["line", "bad-width"][0 if line else 1:]


def test_lots_command_converts_and_the_conversion_reads_back(tmp_path, capsys):
    path = tmp_path / "lots.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": FEATURES}))
    assert main(["lots", str(path), "--to", str(tmp_path / "out.parquet")]) == 0
    assert "3 lots, 2 bad" in capsys.readouterr().out
    same(read_lots(path), read_lots(tmp_path / "out.parquet"), numbers=False)  # the bad lots are left out
    assert main(["lots", str(path), "--to", str(tmp_path / "out.json")]) == 2


def test_write_geoparquet_round_trips_a_city(tmp_path):
    city = read_lots(__import__("pathlib").Path(__file__).parents[2] / "examples" / "city" / "city.geojson")
    write_geoparquet(city, tmp_path / "city.parquet")
    back = read_lots(tmp_path / "city.parquet")
    assert back.ids.tolist() == city.ids.tolist()
    np.testing.assert_allclose(back.vertices, city.vertices)


def test_a_parquet_file_without_footprints_is_refused_by_name(tmp_path):
    from grammarc.errors import LotsError

    pq.write_table(pa.table({"id": ["a"], "height": [3.0]}), tmp_path / "plain.parquet")
    with pytest.raises(LotsError, match="plain.parquet: no WKB geometry column"):
        read_lots(tmp_path / "plain.parquet")
    (tmp_path / "broken.parquet").write_bytes(b"PAR1 not a parquet file")
    with pytest.raises(LotsError, match="broken.parquet"):
        read_lots(tmp_path / "broken.parquet")


def test_a_bad_row_is_a_bad_lot_by_its_number_and_id_and_the_other_rows_are_read(tmp_path, capsys):
    """Unreadable WKB (garbage, cut short), a null geometry and a point: four bad lots, one good."""
    square = shapely.to_wkb(shapely.box(0, 0, 10, 10))
    pq.write_table(pa.table({"id": ["a", "b", "c", "d", "e"], "geometry": [
        square, b"not wkb", None, shapely.to_wkb(shapely.Point(1, 2)), square[:10]]}), tmp_path / "rows.parquet")
    lots = read_lots(tmp_path / "rows.parquet")
    assert lots.ids.tolist() == ["a"] and lots.index.tolist() == [0]
    assert [(b.index, b.id) for b in lots.bad] == [(1, "b"), (2, "c"), (3, "d"), (4, "e")]
    assert [b.reason.split(":")[0] for b in lots.bad] == ["bad WKB in column 'geometry'", "not a polygon (null geometry)",
                                                         "not a polygon (Point)", "bad WKB in column 'geometry'"]
    assert main(["lots", str(tmp_path / "rows.parquet")]) == 0
    assert "lot b (#1) is bad: bad WKB in column 'geometry': ParseException" in capsys.readouterr().err


def test_parquet_partitions_follow_row_groups_near_their_size(tmp_path):
    parquet = lot_files(tmp_path)[2]  # row groups of 2 rows, 13 rows
    assert [(p.start, p.stop) for p in partition_lots(parquet, 3)] == [(0, 2), (2, 4), (4, 6), (6, 8), (8, 10),
                                                                        (10, 13)]
    assert [(p.start, p.stop) for p in partition_lots(parquet, 6)] == [(0, 6), (6, 12), (12, 13)]



@pytest.mark.parametrize("ids", [[7, None, -3], ["a", None, "c"], [True, None, False]])
def test_ids_of_every_column_type_are_their_text_and_a_null_is_the_row_number(tmp_path, ids):
    """Text and whole numbers are converted as columns, other types value by value: the same text."""
    squares = shapely.to_wkb([shapely.box(20 * k, 0, 20 * k + 10, 10) for k in range(3)])
    geo = {"primary_column": "geometry", "columns": {"geometry": {"encoding": "WKB", "crs": None}}}
    table = pa.table({"id": ids, "geometry": squares}).replace_schema_metadata({"geo": json.dumps(geo)})
    pq.write_table(table, tmp_path / "ids.parquet")
    assert read_lots(tmp_path / "ids.parquet").ids.tolist() == [str(i) if i is not None else "1" for i in ids]
