"""GeoParquet lots (the ``parquet`` extra, pyarrow): a city's footprints read as columns.

GeoJSON makes a Python object of every coordinate: reading 10^5 lots takes seconds and most of a build's
memory. A GeoParquet file holds the footprints as WKB in one column and the properties as typed columns;
``read_geoparquet`` decodes the WKB with shapely (GEOS, vectorized) and takes the rings as ragged arrays
(``shapely.to_ragged_array``), so no Python object is made per lot but its id.

The lots are the same as the GeoJSON's (``io.lots.read_lots``): a Polygon is a lot, a MultiPolygon a lot
per polygon (ids ``"<id>:<k>"``), any other geometry a bad lot; the id is the ``id`` column, else
``name``, else the row number; the other columns are properties (numbers as float64 with nan for
nulls, the rest as text), and a list column ``streetWidth`` marks street edges as in GeoJSON.
``write_geoparquet`` writes lots back (``grammarc lots IN OUT.parquet`` converts a GeoJSON once).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import shapely

from grammarc.errors import LotsError, UsageError
from grammarc.io.atomic import replacing
from grammarc.io.lots import STREET_WIDTH, Lots, _Builder, _street_flags
from grammarc.io.lots import _column as json_column

__all__ = ["read_geoparquet", "write_geoparquet"]

_POLYGON, _MULTIPOLYGON = 3, 6
#: Rows per row group that ``write_geoparquet`` writes.
ROW_GROUP = 16384


def _parquet():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as error:
        raise UsageError("GeoParquet lots need pyarrow: pip install 'grammarc[parquet]' (or pip install "
                         "pyarrow)") from error
    return pa, pq


def read_geoparquet(path: str | os.PathLike, rows: tuple[int, int] | None = None,
                    first_index: int = 0) -> tuple[_Builder, dict[str, np.ndarray]]:
    """The lots of a GeoParquet file, for ``_Builder.finish``: the builder and the property columns.

    ``rows`` (start, stop) reads only those rows (a partition, ``io.lot_partitions``; only the row groups
    that hold them are read), whose first polygon is lot number ``first_index`` of the file.
    """
    table = _read_table(path, rows)
    return lots_from_table(table, _geometry_column(table, path), path, rows[0] if rows else 0, first_index)


def lots_from_table(table, column: str, path, first_row: int = 0,
                    first_index: int = 0) -> tuple[_Builder, dict[str, np.ndarray]]:
    """The lots of an Arrow table with WKB footprints in ``column`` (GeoParquet's, or a GIS file's read by
    ``io.gis``), its first row being row ``first_row`` of the file and its first polygon lot number
    ``first_index``: the builder and the property columns."""
    pa, _ = _parquet()
    geometry = _geometry(table, column, path)
    n = len(geometry)
    names = [c for c in table.column_names if c != column]
    ids = _ids(table, names, n, first_row)
    kind, good, parts, feature, per_feature = _parts(geometry)
    first = np.cumsum(per_feature) - per_feature + first_index
    k = np.arange(len(parts)) - np.searchsorted(feature, feature)  # part number within its feature
    index = first[feature] + k
    multi = kind[feature] == _MULTIPOLYGON
    lot_ids = [f"{ids[f]}:{j}" if m else ids[f] for f, j, m in zip(feature.tolist(), k.tolist(), multi.tolist())]

    builder = _Builder(world=False)
    for f in np.flatnonzero(~good):
        what = "empty polygon" if kind[f] in (_POLYGON, _MULTIPOLYGON) else f"not a polygon ({_type_name(kind[f])})"
        builder.reject(int(first[f]), ids[f], what)
    columns = {name: _column(table.column(name), pa) for name in names if name not in ("id", STREET_WIDTH)}
    widths = [_text_list(w) for w in table.column(STREET_WIDTH).to_pylist()] if STREET_WIDTH in names else None
    if widths is not None:  # only files with street widths pay a loop over their lots
        exterior = shapely.get_num_coordinates(shapely.get_exterior_ring(parts))
        keep = np.ones(len(parts), dtype=bool)
        for lot in range(len(parts)):
            value = widths[feature[lot]]
            problem = _street_flags(value, np.zeros((exterior[lot], 2))) if value is not None else None
            if isinstance(problem, str):
                keep[lot] = False
                builder.reject(int(index[lot]), lot_ids[lot], problem)
        parts, feature, index = parts[keep], feature[keep], index[keep]
        lot_ids = [i for i, kept in zip(lot_ids, keep) if kept]
    attrs = {name: values[feature] for name, values in columns.items()}
    if len(parts):
        _, coords, (ring_offsets, lot_offsets) = shapely.to_ragged_array(parts)
        street = np.zeros(len(coords), dtype=bool)
        if widths is not None:
            for lot, start in enumerate(ring_offsets[lot_offsets[:-1]].tolist()):
                value = widths[feature[lot]]
                if value is not None:
                    street[start:start + len(value)] = np.asarray(value, dtype=np.float64) > 0
        builder.add_block(index, lot_ids, coords[:, :2], np.diff(ring_offsets), np.diff(lot_offsets), street)
    return builder, attrs


def count_polygons(path: str | os.PathLike, rows: tuple[int, int]) -> int:
    """The lot numbers that ``rows`` of a GeoParquet file take (``table_lot_numbers``). Only the geometry
    column is read."""
    table = _read_table(path, rows, geometry_only=True)
    return table_lot_numbers(table, _geometry_column(table, path), path)


def table_lot_numbers(table, column: str, path) -> int:
    """The lot numbers the rows of a table take: a polygon one, a multipolygon one per part, anything else
    one (a bad lot)."""
    return int(_parts(_geometry(table, column, path))[4].sum())


def row_group_bounds(path: str | os.PathLike) -> np.ndarray:
    """Where a GeoParquet file's row groups start, and its number of rows last, from its footer."""
    pa, pq = _parquet()
    try:
        meta = pq.ParquetFile(path).metadata
    except (OSError, pa.ArrowInvalid) as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error
    return _group_starts(meta)


def _group_starts(meta) -> np.ndarray:
    """From a Parquet footer: where each row group starts, and the number of rows last."""
    return np.cumsum([0] + [meta.row_group(g).num_rows for g in range(meta.num_row_groups)])


def _read_table(path, rows: tuple[int, int] | None, geometry_only: bool = False):
    """The table of a GeoParquet file, or of its rows ``(start, stop)`` (the row groups that hold them)."""
    pa, pq = _parquet()
    try:
        if rows is None:
            return pq.read_table(path)
        file = pq.ParquetFile(path)
        columns = [_geometry_column(file.schema_arrow, path)] if geometry_only else None
        starts = _group_starts(file.metadata)
        groups = [g for g in range(len(starts) - 1) if starts[g] < rows[1] and starts[g + 1] > rows[0]]
        table = file.read_row_groups(groups, columns=columns) if groups else file.schema_arrow.empty_table()
        first = int(starts[groups[0]]) if groups else 0
        return table.slice(rows[0] - first, rows[1] - rows[0])
    except (OSError, pa.ArrowInvalid) as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error


def _geometry_column(table, path) -> str:
    """The WKB column GeoParquet's ``geo`` metadata names (of a table or a schema)."""
    schema = getattr(table, "schema", table)
    geo = json.loads((schema.metadata or {}).get(b"geo", b"{}"))
    column = geo.get("primary_column", "geometry")
    encoding = geo.get("columns", {}).get(column, {}).get("encoding", "WKB")
    if column not in schema.names or encoding.upper() != "WKB":
        raise LotsError(f"{path}: no WKB geometry column (GeoParquet's `geo` metadata names "
                        f"{column!r}, encoding {encoding!r})")
    return column


def _geometry(table, column: str, path) -> np.ndarray:
    values = table.column(column)
    if hasattr(values.type, "storage_type"):  # an extension type (geoarrow.wkb): its WKB bytes
        values = [chunk.storage for chunk in values.chunks]
        values = np.concatenate([v.to_numpy(zero_copy_only=False) for v in values]) if values else np.zeros(0, object)
    else:
        values = values.to_numpy(zero_copy_only=False)
    try:
        return shapely.from_wkb(values)
    except shapely.errors.GEOSException as error:
        raise LotsError(f"{path}: bad WKB in column {column!r}: {error}") from error


def _parts(geometry: np.ndarray):
    """Each feature's kind and goodness, the polygons of the good ones with their feature, and the lot
    numbers each feature takes (lots are numbered in file order: a feature's parts, then the next's)."""
    kind = shapely.get_type_id(geometry)
    good = np.isin(kind, (_POLYGON, _MULTIPOLYGON)) & ~shapely.is_empty(geometry)
    parts, feature = shapely.get_parts(geometry[good], return_index=True)
    feature = np.flatnonzero(good)[feature]
    per_feature = np.where(good, 0, 1)  # a bad feature takes one number, as in GeoJSON
    np.add.at(per_feature, feature, 1)
    return kind, good, parts, feature, per_feature


def _text_list(value):
    """A ``streetWidth`` value; text (GIS formats have no list fields) is read as a JSON list."""
    if not isinstance(value, str):
        return value
    try:
        return json.loads(value)
    except ValueError:
        return value  # refused by name as "not a list of numbers"


def _column(values, pa) -> np.ndarray:
    """A property column as GeoJSON's are typed (``io.lots._column``): numbers and booleans float64 with
    nan for nulls, anything else text (object, None for nulls); read by type, not value by value."""
    kind = values.type
    if pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_boolean(kind) or pa.types.is_null(kind):
        return values.cast(pa.float64()).to_numpy(zero_copy_only=False).astype(np.float64)
    if pa.types.is_string(kind) or pa.types.is_large_string(kind):
        return values.to_numpy(zero_copy_only=False).astype(object)
    return json_column(values.to_pylist())


def _ids(table, names: list[str], n: int, first_row: int) -> list[str]:
    for name in ("id", "name"):
        if name in names:
            values = table.column(name).to_pylist()
            return [str(v) if v is not None else str(i) for i, v in enumerate(values, first_row)]
    return [str(i) for i in range(first_row, first_row + n)]


def _type_name(type_id: int) -> str:
    return {0: "Point", 1: "LineString", 2: "LinearRing", 4: "MultiPoint", 5: "MultiLineString",
            7: "GeometryCollection"}.get(int(type_id), "null geometry")


def write_geoparquet(lots: Lots, path: str | os.PathLike) -> None:
    """Write lots as GeoParquet (WKB polygons in map coordinates, ids, properties, street widths 1/0),
    atomically."""
    pa, pq = _parquet()
    path = Path(path)
    xy = np.column_stack([lots.vertices[:, 0], np.subtract(0.0, lots.vertices[:, 2])])
    # closed rings, as WKB has them
    counts = np.diff(lots.ring_offsets)
    starts = lots.ring_offsets[:-1]
    at = np.insert(np.arange(len(xy)), lots.ring_offsets[1:], starts)
    closed = xy[at]
    ring_offsets = np.concatenate([[0], np.cumsum(counts + 1)])
    polygons = shapely.from_ragged_array(shapely.GeometryType.POLYGON, closed, (ring_offsets, lots.lot_offsets))
    exterior = lots.ring_offsets[lots.lot_offsets[:-1]]
    ends = lots.ring_offsets[lots.lot_offsets[:-1] + 1]
    widths = [lots.street[a:b].astype(float).tolist() for a, b in zip(exterior.tolist(), ends.tolist())]
    columns = {"id": pa.array([str(i) for i in lots.ids]),
               "geometry": pa.array(shapely.to_wkb(polygons), type=pa.binary())}
    for name, values in lots.attrs.items():
        columns[name] = pa.array(values.tolist())
    if lots.street.any():
        columns[STREET_WIDTH] = pa.array(widths, type=pa.list_(pa.float64()))
    geo = {"version": "1.0.0", "primary_column": "geometry",
           "columns": {"geometry": {"encoding": "WKB", "geometry_types": ["Polygon"]}}}
    table = pa.table(columns).replace_schema_metadata({"geo": json.dumps(geo)})
    with replacing(path) as tmp:
        # row groups of 2^14 lots: a partition of a cluster build reads only the groups that hold its rows
        pq.write_table(table, tmp, row_group_size=ROW_GROUP)
