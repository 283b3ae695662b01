"""Partitions of a lots file read, each by itself, the lots that reading the whole file gives."""

import itertools
import json

import numpy as np
import pytest
from lot_features import FEATURES as BASE_FEATURES

from grammarc.errors import LotsError
from grammarc.io.lot_partitions import count_lots, partition_lots, read_partition
from grammarc.io.lots import read_lots

FEATURES = [
    *BASE_FEATURES,
    *({"type": "Feature", "properties": {"h": float(k)},
       "geometry": {"type": "Polygon", "coordinates": [[[0, 50 + 10 * k], [8, 50 + 10 * k], [8, 58 + 10 * k],
                                                        [0, 58 + 10 * k], [0, 50 + 10 * k]]]}}
      for k in range(9)),
]


def _files(tmp_path):
    """The features as one GeoJSON document, as a GeoJSON sequence (RFC 8142's record separators on
    some lines) and as GeoParquet in row groups of 2 rows."""
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq
    import shapely

    whole = tmp_path / "lots.geojson"
    whole.write_text(json.dumps({"type": "FeatureCollection", "features": FEATURES}))
    sequence = tmp_path / "lots.geojsonl"
    sequence.write_text("".join(("\x1e" if k % 3 == 0 else "") + json.dumps(f) + "\n" + ("\n" if k == 4 else "")
                                for k, f in enumerate(FEATURES)))
    table = pa.table({
        "id": [f.get("id") for f in FEATURES],
        "h": pa.array([f["properties"]["h"] for f in FEATURES], type=pa.float64()),
        "streetWidth": [f["properties"].get("streetWidth") for f in FEATURES],
        "geometry": shapely.to_wkb([shapely.from_geojson(json.dumps(f["geometry"])) for f in FEATURES]),
    }).replace_schema_metadata({"geo": json.dumps({"primary_column": "geometry",
                                                   "columns": {"geometry": {"encoding": "WKB"}}})})
    parquet = tmp_path / "lots.parquet"
    pq.write_table(table, parquet, row_group_size=2)
    return whole, sequence, parquet


def _gis_file(tmp_path):
    """The features as a GeoPackage (a layer of mixed geometry types), written through GDAL."""
    raw = pytest.importorskip("pyogrio.raw")
    import shapely

    path = tmp_path / "lots.gpkg"
    fields = ["name", "h", "streetWidth"]
    data = [np.array([f.get("id") for f in FEATURES], dtype=object),
            np.array([f["properties"]["h"] for f in FEATURES], dtype=float),
            np.array([json.dumps(f["properties"]["streetWidth"]) if "streetWidth" in f["properties"] else None
                      for f in FEATURES], dtype=object)]
    geometry = shapely.to_wkb([shapely.from_geojson(json.dumps(f["geometry"])) for f in FEATURES])
    raw.write(path, geometry, data, fields, geometry_type="Unknown", driver="GPKG", crs="EPSG:32633")
    return path


def _read_in_parts(path, size):
    parts = partition_lots(path, size)
    counts = [count_lots(p) for p in parts]
    firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)
    return parts, [read_partition(p, int(f)) for p, f in zip(parts, firsts)]


@pytest.mark.parametrize("kind", ["geojson", "sequence", "parquet", "gpkg"])
@pytest.mark.parametrize("size", [1, 3, 5, 100])
def test_partitions_together_are_the_whole_file(tmp_path, kind, size):
    path = _gis_file(tmp_path) if kind == "gpkg" else \
        dict(zip(["geojson", "sequence", "parquet"], _files(tmp_path)))[kind]
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


def test_a_gis_file_reads_as_its_features(tmp_path):
    """GeoPackage through GDAL: the lots, ids, MultiPolygon parts, street edges and bad lots of the
    GeoJSON (`streetWidth` is JSON text in a GeoPackage field, which has no lists)."""
    whole = read_lots(_files(tmp_path)[0])
    gis = read_lots(_gis_file(tmp_path))
    assert gis.ids.tolist()[:3] == ["a", "m:0", "m:1"] and gis.index.tolist() == whole.index.tolist()
    assert gis.bad == whole.bad and [b.id for b in gis.bad] == ["line", "bad-width"]
    np.testing.assert_allclose(gis.vertices, whole.vertices)
    np.testing.assert_array_equal(gis.street, whole.street)
    np.testing.assert_array_equal(gis.attrs["h"].astype(float), whole.attrs["h"].astype(float))


def test_a_sequence_reads_as_its_feature_collection(tmp_path):
    whole, sequence, _ = _files(tmp_path)
    a, b = read_lots(whole), read_lots(sequence)
    assert a.ids.tolist() == b.ids.tolist() and a.index.tolist() == b.index.tolist() and a.bad == b.bad
    np.testing.assert_array_equal(a.vertices, b.vertices)


def test_parquet_partitions_follow_row_groups_near_their_size(tmp_path):
    parquet = _files(tmp_path)[2]  # row groups of 2 rows, 13 rows
    assert [(p.start, p.stop) for p in partition_lots(parquet, 3)] == [(0, 2), (2, 4), (4, 6), (6, 8), (8, 10),
                                                                        (10, 13)]
    assert [(p.start, p.stop) for p in partition_lots(parquet, 6)] == [(0, 6), (6, 12), (12, 13)]


def test_a_bad_line_of_a_sequence_is_named(tmp_path):
    path = tmp_path / "lots.geojsonl"
    path.write_text(json.dumps(FEATURES[0]) + "\n{not json\n")
    with pytest.raises(LotsError, match=r"lots.geojsonl:2: not valid JSON"):
        read_lots(path)
    parts = partition_lots(path, 1)
    assert count_lots(parts[0]) == 1
    with pytest.raises(LotsError, match=r"lots.geojsonl:2:"):
        count_lots(parts[1])


def test_a_sequence_is_cut_at_line_ends_without_reading_it_whole(tmp_path):
    """Partitions of a sequence are byte ranges found by scanning for line ends, in blocks."""
    from grammarc.io import lot_partitions

    _, sequence, _ = _files(tmp_path)
    lot_partitions_block = lot_partitions._SCAN_BLOCK
    try:
        lot_partitions._SCAN_BLOCK = 7  # line ends across block boundaries
        parts = partition_lots(sequence, 4)
    finally:
        lot_partitions._SCAN_BLOCK = lot_partitions_block
    data = sequence.read_bytes()
    assert parts[0].offset == 0 and parts[-1].end == len(data)
    assert all(a.end == b.offset and data[b.offset - 1:b.offset] == b"\n" for a, b in itertools.pairwise(parts))
