"""Tests of grammarc.io.lots: the table of formats, and partitions of every kind that read together as the
whole file."""

from __future__ import annotations

import itertools
import subprocess
import sys

import numpy as np
import pytest
from lot_features import SQUARE, gis_file, lot_files

from grammarc.errors import LotsError
from grammarc.io.lots import (
    FORMATS,
    count_lots,
    default_lot,
    lots_from_polygons,
    partition_lots,
    read_lots,
    read_partition,
)


def test_missing_file_raises(tmp_path):
    with pytest.raises(LotsError, match="lots file not found: .*nope.geojson"):
        read_lots(tmp_path / "nope.geojson")
    with pytest.raises(LotsError, match="lots file not found: .*nope.parquet"):
        partition_lots(tmp_path / "nope.parquet", 10)


def test_unknown_suffix_raises(tmp_path):
    path = tmp_path / "lots.dwg"
    path.write_bytes(b"\0")
    with pytest.raises(LotsError, match="unknown lots file type '.dwg'.*lots.dwg"):
        read_lots(path)
    with pytest.raises(LotsError) as error:
        read_lots(path)
    assert str(error.value) == (
        "unknown lots file type '.dwg' (expected .geojson, .json, .obj, .parquet, a GeoJSON sequence (.geojsonl, "
        ".geojsons, .geojsonseq, .jsonl, .ndjson) or a GIS file (.gpkg, .shp, .fgb, .gml, .kml, .sqlite, .tab)): "
        f"{path}")


def test_each_suffix_names_one_format_and_partitioning_is_all_or_nothing():
    suffixes = [suffix for form in FORMATS for suffix in form.suffixes]
    assert len(suffixes) == len(set(suffixes)) and all(s == s.lower() and s.startswith(".") for s in suffixes)
    assert len({form.kind for form in FORMATS} | {"whole"}) == len(FORMATS) + 1
    for form in FORMATS:
        parts = (form.partitions, form.count, form.read_partition)
        assert all(p is None for p in parts) or all(callable(p) for p in parts), form.kind


def test_the_optional_readers_are_imported_only_when_their_format_is_read():
    code = "import sys, grammarc.io.lots; print(sorted(m for m in ('pyarrow', 'pyogrio') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_default_lot():
    lot = default_lot()
    assert lot.ids.tolist() == ["default"] and lot.bad == ()
    np.testing.assert_array_equal(lot.vertices, [[0, 0, 0], [30, 0, 0], [30, 0, -20], [0, 0, -20]])


def test_lots_from_polygons_checks_lengths():
    with pytest.raises(ValueError, match="ids has 2 entries for 1 polygons"):
        lots_from_polygons([[np.array(SQUARE)]], ids=["a", "b"])
    with pytest.raises(ValueError, match="attrs\\['h'\\] has 0 entries"):
        lots_from_polygons([[np.array(SQUARE)]], attrs={"h": []})


# ------------------------------------------------------------------------------------------- partitions


def _read_in_parts(path, size):
    parts = partition_lots(path, size)
    counts = [count_lots(p) for p in parts]
    firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)
    return parts, [read_partition(p, int(f)) for p, f in zip(parts, firsts)]


@pytest.mark.parametrize("kind", ["geojson", "sequence", "parquet", "gpkg"])
@pytest.mark.parametrize("size", [1, 3, 5, 100])
def test_partitions_together_are_the_whole_file(tmp_path, kind, size):
    path = gis_file(tmp_path) if kind == "gpkg" else \
        dict(zip(["geojson", "sequence", "parquet"], lot_files(tmp_path)))[kind]
    whole = read_lots(path)
    parts, lots = _read_in_parts(path, size)
    assert parts[0].start == 0 and all(a.stop == b.start for a, b in itertools.pairwise(parts))
    assert np.concatenate([p.index for p in lots]).tolist() == whole.index.tolist()
    assert np.concatenate([p.ids for p in lots]).tolist() == whole.ids.tolist()
    np.testing.assert_array_equal(np.concatenate([p.vertices for p in lots]), whole.vertices)
    np.testing.assert_array_equal(np.concatenate([p.street for p in lots]), whole.street)
    assert tuple(b for p in lots for b in p.bad) == whole.bad
    heights = np.concatenate([p.attrs.get("h", np.full(len(p), np.nan)) for p in lots])
    np.testing.assert_array_equal(heights.astype(float), whole.attrs["h"].astype(float))
    assert {p.kind for p in parts} == {"whole" if kind == "geojson" else "gis" if kind == "gpkg" else kind}


def test_id_field_picks_the_ids_in_every_format(tmp_path):
    """``--id-field h``: the property ``h`` names the lots (as text); a lot without a value is numbered, and a
    columnar file without the field is an error that lists the fields it has."""
    from grammarc.io.lot_format import LotsOptions

    options = LotsOptions(id_field="h")
    whole, sequence, parquet = lot_files(tmp_path)
    ids = [read_lots(path, options).ids.tolist() for path in (whole, sequence, parquet)]
    assert ids[0] == ids[1] == ids[2] and ids[0][:3] == ["12", "7.5:0", "7.5:1"]
    with pytest.raises(LotsError, match=r"--id-field osm_id: the lots have no such field \(they have id, h,"):
        read_lots(parquet, LotsOptions(id_field="osm_id"))


def test_elevations_of_a_columnar_file_are_base_heights_too(tmp_path):
    pa = pytest.importorskip("pyarrow")
    import json

    import pyarrow.parquet as pq
    import shapely

    polygons = [shapely.Polygon([(0, 0, 12.0), (10, 0, 12.5), (10, 10, 13.0), (0, 10, 12.0)]),
                shapely.Polygon([(20, 0), (30, 0), (30, 10), (20, 10)])]
    geo = {"version": "1.0.0", "primary_column": "geometry", "columns": {"geometry": {"encoding": "WKB"}}}
    table = pa.table({"geometry": shapely.to_wkb(polygons)}).replace_schema_metadata({"geo": json.dumps(geo)})
    pq.write_table(table, tmp_path / "lots.parquet")
    lots = read_lots(tmp_path / "lots.parquet")
    assert lots.vertices[:4, 1].tolist() == [12.0] * 4 and lots.vertices[4:, 1].tolist() == [0.0] * 4
