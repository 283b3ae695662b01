"""GeoParquet lots (``.parquet``, the ``parquet`` extra: pyarrow): a city's footprints read as columns.

GeoJSON makes a Python object of every coordinate: reading 10^5 lots takes seconds and most of a build's
memory. A GeoParquet file holds the footprints as WKB in one column and the properties as typed columns,
which become lots as any Arrow table of WKB footprints does (``io.arrow_lots``): the same lots, ids,
properties, street edges and bad lots as the GeoJSON's. A file is cut into partitions of rows at its row
groups where one is near, and a partition reads only the row groups that hold its rows.
``write_geoparquet`` writes lots back (``grammarc lots IN --to OUT.parquet`` converts a GeoJSON once).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import shapely

from grammarc.atomic import replacing
from grammarc.errors import LotsError
from grammarc.io.arrow_lots import import_pyarrow, lots_from_table, table_lot_numbers
from grammarc.io.crs import CRS84, projjson
from grammarc.io.lot_builder import STREET_WIDTH, LotBuilder
from grammarc.io.lot_format import NO_OPTIONS, LotsFormat, LotsOptions, Partition, partitions_at
from grammarc.model.lots import Lots

__all__ = [
    "FORMAT", "count_geoparquet", "geoparquet_partitions", "read_geoparquet", "read_geoparquet_partition",
    "write_geoparquet",
]

#: Rows per row group that ``write_geoparquet`` writes.
ROW_GROUP = 16384


def read_geoparquet(path: Path, options: LotsOptions = NO_OPTIONS) -> Lots:
    """All lots of a GeoParquet file; a ``LotsError`` if it cannot be read, has no WKB geometry column, or
    holds no polygon."""
    builder, attrs = _lots(path, None, 0, options.id_field)
    return builder.finish_file(attrs, path, options)


def geoparquet_partitions(path: Path, size: int) -> list[Partition]:
    """Partitions of about ``size`` rows, cut at the row groups nearest to it (``_aligned``)."""
    return partitions_at(path, "parquet", _aligned(_row_group_bounds(path), size))


def count_geoparquet(part: Partition) -> int:
    """The lot numbers the rows of a partition take (``arrow_lots.table_lot_numbers``); only the geometry
    column is read."""
    table = _read_table(part.path, (part.start, part.stop), geometry_only=True)
    return table_lot_numbers(table, _geometry_column(table, part.path), part.path)


def read_geoparquet_partition(part: Partition, first_index: int, options: LotsOptions = NO_OPTIONS) -> Lots:
    """The lots of a partition's rows (only the row groups that hold them are read), the first numbered
    ``first_index``."""
    builder, attrs = _lots(part.path, (part.start, part.stop), first_index, options.id_field)
    return builder.finish(attrs, part.path, options)


def _lots(path: str | os.PathLike, rows: tuple[int, int] | None, first_index: int,
          id_field: str | None) -> tuple[LotBuilder, dict[str, np.ndarray]]:
    """The lots of a GeoParquet file or of its rows ``(start, stop)``, to finish, and their properties; the
    coordinate system is the geometry column's ``crs`` (PROJJSON; absent: OGC:CRS84 where the coordinates
    are degrees, the specification's default; null: none)."""
    table = _read_table(path, rows)
    column = _geometry_column(table, path)
    builder, attrs = lots_from_table(table, column, path, rows[0] if rows else 0, first_index, id_field)
    described = json.loads((table.schema.metadata or {}).get(b"geo", b"{}")).get("columns", {}).get(column, {})
    if "crs" not in described:
        builder.implied = CRS84
    elif described["crs"] is not None:
        builder.declared = _crs_name(described["crs"])
    return builder, attrs


def _crs_name(crs) -> str:
    """A GeoParquet ``crs`` as ``AUTHORITY:CODE`` where its PROJJSON has an ``id``, else as given (a
    string, or the PROJJSON as JSON text)."""
    if isinstance(crs, str):
        return crs
    code = crs.get("id") if isinstance(crs, dict) else None
    if isinstance(code, dict) and "authority" in code and "code" in code:
        return f"{code['authority']}:{code['code']}"
    return json.dumps(crs)


def _row_group_bounds(path: Path) -> np.ndarray:
    """Where a GeoParquet file's row groups start, and its number of rows last, from its footer."""
    pa, pq = import_pyarrow()
    try:
        meta = pq.ParquetFile(path).metadata
    except (OSError, pa.ArrowInvalid) as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error
    return _group_starts(meta)


def _aligned(bounds: np.ndarray, size: int) -> list[int]:
    """Cuts of rows ``[0, bounds[-1])`` into parts of about ``size``, at the row-group ``bounds`` nearest
    to it where one is within ``size / 2`` (a partition then decodes only its own groups), else at ``size``."""
    n = int(bounds[-1])
    cuts = [0]
    while cuts[-1] < n:
        want = cuts[-1] + size
        later = bounds[bounds > cuts[-1]]
        nearest = int(later[np.argmin(np.abs(later - want))])
        cuts.append(nearest if abs(nearest - want) <= size // 2 else min(want, n))
    return cuts


def _group_starts(meta) -> np.ndarray:
    """From a Parquet footer: where each row group starts, and the number of rows last."""
    return np.cumsum([0] + [meta.row_group(g).num_rows for g in range(meta.num_row_groups)])


def _read_table(path, rows: tuple[int, int] | None, geometry_only: bool = False):
    """The table of a GeoParquet file, or of its rows ``(start, stop)`` (the row groups that hold them)."""
    pa, pq = import_pyarrow()
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


def write_geoparquet(lots: Lots, path: str | os.PathLike) -> None:
    """Write lots as GeoParquet (WKB polygons in map coordinates, ids, properties, street widths 1/0),
    atomically. Its ``crs`` is the lots' as PROJJSON, or null where they have none (metres of a local
    scene): a GeoParquet without ``crs`` would mean longitude and latitude."""
    pa, pq = import_pyarrow()
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
           "columns": {"geometry": {"encoding": "WKB", "geometry_types": ["Polygon"], "crs": projjson(lots.crs)}}}
    table = pa.table(columns).replace_schema_metadata({"geo": json.dumps(geo)})
    with replacing(path) as tmp:
        # row groups of 2^14 lots: a partition of a cluster build reads only the groups that hold its rows
        pq.write_table(table, tmp, row_group_size=ROW_GROUP)


FORMAT = LotsFormat(kind="parquet", suffixes=(".parquet",), title=None, read=read_geoparquet,
                    partitions=geoparquet_partitions, count=count_geoparquet,
                    read_partition=read_geoparquet_partition)
