"""What the lots tests share: features of every kind a lots file holds (a polygon with street widths, a line,
a MultiPolygon with a hole, bad street widths), those features written in every format, the PRT kit's
footprints, and helpers that look at lots' rings."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

FEATURES = [
    {"type": "Feature", "id": "a", "properties": {"kind": "house", "h": 12, "streetWidth": [8, 0, 0, 0]},
     "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [20, 0], [20, 15], [0, 15], [0, 0]]]}},
    {"type": "Feature", "id": "line", "properties": {"kind": "x", "h": None},
     "geometry": {"type": "LineString", "coordinates": [[0, 0], [5, 5]]}},
    {"type": "Feature", "id": "m", "properties": {"kind": "court", "h": 7.5},
     "geometry": {"type": "MultiPolygon", "coordinates": [
         [[[40, 0], [80, 0], [80, 40], [40, 40], [40, 0]], [[50, 10], [50, 30], [70, 30], [70, 10], [50, 10]]],
         [[[100, 0], [110, 0], [110, 10], [100, 0]]]]}},
    {"type": "Feature", "id": "bad-width", "properties": {"kind": "house", "h": 3, "streetWidth": [1, 2]},
     "geometry": {"type": "Polygon", "coordinates": [[[0, 30], [10, 30], [10, 40], [0, 40], [0, 30]]]}},
]
#: ``FEATURES`` and nine squares after them: enough features to cut into partitions.
MANY_FEATURES = [
    *FEATURES,
    *({"type": "Feature", "properties": {"h": float(k)},
       "geometry": {"type": "Polygon", "coordinates": [[[0, 50 + 10 * k], [8, 50 + 10 * k], [8, 58 + 10 * k],
                                                        [0, 58 + 10 * k], [0, 50 + 10 * k]]]}}
      for k in range(9)),
]

SQUARE = [[0, 0], [10, 0], [10, 10], [0, 10]]  # counter-clockwise on the map
BOWTIE = [[0, 0], [2, 2], [2, 0], [0, 2]]

# the PRT kit sits next to the repository: ../shared/prt from its root
PRT_FOOTPRINTS = Path(__file__).resolve().parents[3] / "shared" / "prt" / "footprints"
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


def feature(coords, kind="Polygon", **extra) -> dict:
    return {"type": "Feature", "geometry": {"type": kind, "coordinates": coords}, **extra}


def write_geojson(tmp_path: Path, features: list[dict], name: str = "lots.geojson") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def lot_files(tmp_path: Path) -> tuple[Path, Path, Path]:
    """``MANY_FEATURES`` as one GeoJSON document, as a GeoJSON sequence (RFC 8142's record separators on
    some lines, an empty line) and as GeoParquet in row groups of 2 rows."""
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq
    import shapely

    whole = write_geojson(tmp_path, MANY_FEATURES)
    sequence = tmp_path / "lots.geojsonl"
    sequence.write_text("".join(("\x1e" if k % 3 == 0 else "") + json.dumps(f) + "\n" + ("\n" if k == 4 else "")
                                for k, f in enumerate(MANY_FEATURES)))
    table = pa.table({
        "id": [f.get("id") for f in MANY_FEATURES],
        "h": pa.array([f["properties"]["h"] for f in MANY_FEATURES], type=pa.float64()),
        "streetWidth": [f["properties"].get("streetWidth") for f in MANY_FEATURES],
        "geometry": shapely.to_wkb([shapely.from_geojson(json.dumps(f["geometry"])) for f in MANY_FEATURES]),
    }).replace_schema_metadata({"geo": json.dumps({"primary_column": "geometry",
                                                   "columns": {"geometry": {"encoding": "WKB"}}})})
    parquet = tmp_path / "lots.parquet"
    pq.write_table(table, parquet, row_group_size=2)
    return whole, sequence, parquet


def gis_file(tmp_path: Path) -> Path:
    """``MANY_FEATURES`` as a GeoPackage (a layer of mixed geometry types), written through GDAL."""
    raw = pytest.importorskip("pyogrio.raw")
    import shapely

    path = tmp_path / "lots.gpkg"
    fields = ["name", "h", "streetWidth"]
    data = [np.array([f.get("id") for f in MANY_FEATURES], dtype=object),
            np.array([f["properties"]["h"] for f in MANY_FEATURES], dtype=float),
            np.array([json.dumps(f["properties"]["streetWidth"]) if "streetWidth" in f["properties"] else None
                      for f in MANY_FEATURES], dtype=object)]
    geometry = shapely.to_wkb([shapely.from_geojson(json.dumps(f["geometry"])) for f in MANY_FEATURES])
    raw.write(path, geometry, data, fields, geometry_type="Unknown", driver="GPKG", crs="EPSG:32633")
    return path


def rings(lots, i: int) -> list[np.ndarray]:
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


def lot_area(lots, i: int) -> float:
    return sum(map_area(ring) for ring in rings(lots, i))
