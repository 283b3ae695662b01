"""Lots of an Arrow table of WKB footprints: what a GeoParquet file (``io.geoparquet``) and a GIS file read
through GDAL (``io.gis``) both are once read.

The footprints are decoded with shapely (GEOS, vectorized) and their rings taken as ragged arrays
(``shapely.to_ragged_array``), so no Python object is made per lot but its id. The lots are the same as a
GeoJSON's (``io.lot_builder.parse_features``): a Polygon is a lot, a MultiPolygon a lot per polygon (ids
``"<id>:<k>"``), any other geometry a bad lot; the id is the ``id`` column, else ``name``, else the row
number; the other columns are properties (numbers as float64 with nan for nulls, the rest as text), and a
list column ``streetWidth`` (or its JSON text, in formats without lists) marks street edges.
"""

from __future__ import annotations

import json

import numpy as np
import shapely

from grammarc.errors import LotsError, UsageError
from grammarc.io.lot_builder import STREET_WIDTH, LotBuilder, id_text, property_column, street_flags

__all__ = ["import_pyarrow", "lots_from_table", "table_lot_numbers"]

_POLYGON, _MULTIPOLYGON = 3, 6


def import_pyarrow():
    """``pyarrow`` and ``pyarrow.parquet``, imported when a columnar file is read (the ``parquet`` extra);
    a ``UsageError`` says how to install them."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as error:
        raise UsageError("GeoParquet lots need pyarrow: pip install 'grammarc[parquet]' (or pip install "
                         "pyarrow)") from error
    return pa, pq


def lots_from_table(table, column: str, path, first_row: int = 0, first_index: int = 0,
                    id_field: str | None = None) -> tuple[LotBuilder, dict[str, np.ndarray]]:
    """The lots of an Arrow table with WKB footprints in ``column``.

    Parameters
    ----------
    table : pyarrow.Table
      The rows of a file, or of a partition of it.
    column : str
      The WKB geometry column.
    path : str or os.PathLike
      The file, for messages.
    first_row : int
      The file's row number of the table's first row (a lot without an id is named by its row).
    first_index : int
      The lot number of the table's first polygon.

    Returns
    -------
    builder : LotBuilder
      The lots, to ``finish``.
    attrs : dict of str to (L,) float64 or object
      The property columns over the builder's lots.
    """
    pa, _ = import_pyarrow()
    geometry, unreadable = _geometry(table, column)
    n = len(geometry)
    names = [c for c in table.column_names if c != column]
    ids = _ids(table, names, n, first_row, id_field)
    kind, good, parts, feature, per_feature = _parts(geometry)
    first = np.cumsum(per_feature) - per_feature + first_index
    k = np.arange(len(parts)) - np.searchsorted(feature, feature)  # part number within its feature
    index = first[feature] + k
    multi = kind[feature] == _MULTIPOLYGON
    lot_ids = [f"{ids[f]}:{j}" if m else ids[f] for f, j, m in zip(feature.tolist(), k.tolist(), multi.tolist())]

    builder = LotBuilder(world=False)
    for f in np.flatnonzero(~good):
        what = "empty polygon" if kind[f] in (_POLYGON, _MULTIPOLYGON) else f"not a polygon ({_type_name(kind[f])})"
        builder.reject(int(first[f]), ids[f], unreadable.get(int(f), what))
    columns = {name: _column(table.column(name), pa) for name in names if name not in ("id", STREET_WIDTH)}
    widths = [_text_list(w) for w in table.column(STREET_WIDTH).to_pylist()] if STREET_WIDTH in names else None
    if widths is not None:  # only files with street widths pay a loop over their lots
        exterior = shapely.get_num_coordinates(shapely.get_exterior_ring(parts))
        keep = np.ones(len(parts), dtype=bool)
        for lot in range(len(parts)):
            value = widths[feature[lot]]
            problem = street_flags(value, np.zeros((exterior[lot], 2))) if value is not None else None
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
        builder.add_block(index, lot_ids, coords[:, :3], np.diff(ring_offsets), np.diff(lot_offsets), street)
    return builder, attrs


def table_lot_numbers(table, column: str, path) -> int:
    """The lot numbers the rows of a table take: a polygon one, a multipolygon one per part, anything else
    one (a bad lot)."""
    return int(_parts(_geometry(table, column)[0])[4].sum())


def _geometry(table, column: str) -> tuple[np.ndarray, dict[int, str]]:
    """The rows' geometries (None where null or unreadable), and why each unreadable row's WKB is (by row
    of the table): such a row is a bad lot, as a GeoJSON feature whose geometry is not one."""
    values = table.column(column)
    present = ~values.is_null().to_numpy(zero_copy_only=False)
    if hasattr(values.type, "storage_type"):  # an extension type (geoarrow.wkb): its WKB bytes
        values = [chunk.storage for chunk in values.chunks]
        values = np.concatenate([v.to_numpy(zero_copy_only=False) for v in values]) if values else np.zeros(0, object)
    else:
        values = values.to_numpy(zero_copy_only=False)
    geometry = shapely.from_wkb(values, on_invalid="ignore")
    return geometry, {int(row): f"bad WKB in column {column!r}: {_wkb_error(values[row])}"
                      for row in np.flatnonzero(present & shapely.is_missing(geometry))}


def _wkb_error(value) -> str:
    """What GEOS says of one unreadable WKB value."""
    try:
        shapely.from_wkb(value)
    except (shapely.errors.GEOSException, TypeError, ValueError) as error:
        return str(error)
    return "unreadable"


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
    """A property column as GeoJSON's are typed (``io.lot_builder.property_column``): numbers float64 with
    nan for nulls, anything else text (object, None for nulls); read by type, not value by value."""
    kind = values.type
    if pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_null(kind):
        return values.cast(pa.float64()).to_numpy(zero_copy_only=False).astype(np.float64)
    if pa.types.is_string(kind) or pa.types.is_large_string(kind):
        return values.to_numpy(zero_copy_only=False).astype(object)
    return property_column(values.to_pylist())


def _ids(table, names: list[str], n: int, first_row: int, id_field: str | None) -> list[str]:
    """The rows' ids: column ``id_field`` where given (``--id-field``), else ``id``, else ``name``; a row
    without one is its number."""
    if id_field is not None and id_field not in names:
        raise LotsError(f"--id-field {id_field}: the lots have no such field (they have {', '.join(names) or 'none'})")
    for name in (id_field,) if id_field is not None else ("id", "name"):
        if name in names:
            values = table.column(name).to_pylist()
            return [id_text(v) if v is not None else str(i) for i, v in enumerate(values, first_row)]
    return [str(i) for i in range(first_row, first_row + n)]


def _type_name(type_id: int) -> str:
    return {0: "Point", 1: "LineString", 2: "LinearRing", 4: "MultiPoint", 5: "MultiLineString",
            7: "GeometryCollection"}.get(int(type_id), "null geometry")
