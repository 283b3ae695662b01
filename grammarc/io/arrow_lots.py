"""Lots of an Arrow table of WKB footprints: what a GeoParquet file (``io.geoparquet``) and a GIS file read
through GDAL (``io.gis``) both are once read.

The footprints are decoded into ragged arrays by a kernel straight from the column's buffers (``io.wkb``)
where every row is a plain polygon or multipolygon, else by shapely (GEOS, vectorized, then
``shapely.to_ragged_array``), which says what each odd row is; no Python object is made per lot but its
id. The lots are the same as a
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
from grammarc.io.wkb import Polygons, decode_polygons
from grammarc.ragged import ragged_take

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
    rows, unreadable = _polygons(table, column)
    names = [c for c in table.column_names if c != column]
    ids = _ids(table, names, len(rows.kinds), first_row, id_field)
    good = rows.parts > 0
    per_feature = np.where(good, rows.parts, 1)  # a bad feature takes one number, as in GeoJSON
    first = np.cumsum(per_feature) - per_feature + first_index
    feature = np.repeat(np.arange(len(rows.parts)), rows.parts)
    k = np.arange(len(feature)) - np.searchsorted(feature, feature)  # part number within its feature
    index = first[feature] + k
    lot_ids = ids[feature]
    multi = np.flatnonzero(rows.kinds[feature] == _MULTIPOLYGON)
    lot_ids[multi] = lot_ids[multi] + ":" + k[multi].astype(str).astype(object)

    builder = LotBuilder(world=False)
    for f in np.flatnonzero(~good):
        what = "empty polygon" if rows.kinds[f] in (_POLYGON, _MULTIPOLYGON) else \
            f"not a polygon ({_type_name(rows.kinds[f])})"
        builder.reject(int(first[f]), ids[f], unreadable.get(int(f), what))
    columns = {name: _column(table.column(name), pa) for name in names if name not in ("id", STREET_WIDTH)}
    coords, ring_offsets, part_offsets = rows.coords, rows.ring_offsets, rows.part_offsets
    street = np.zeros(len(coords), dtype=bool)
    if STREET_WIDTH in names:  # only files with street widths pay a loop over their lots
        widths = [_text_list(w) for w in table.column(STREET_WIDTH).to_pylist()]
        keep = np.ones(len(feature), dtype=bool)
        for lot, (start, stop) in enumerate(zip(ring_offsets[part_offsets[:-1]].tolist(),
                                                _exterior_ends(ring_offsets, part_offsets).tolist())):
            value = widths[feature[lot]]
            flags = street_flags(value, np.zeros((stop - start, 2))) if value is not None else None
            if isinstance(flags, str):
                keep[lot] = False
                builder.reject(int(index[lot]), lot_ids[lot], flags)
            elif flags is not None:
                street[start:stop] = flags
        if not keep.all():
            rings, part_offsets = ragged_take(part_offsets, np.flatnonzero(keep))
            points, ring_offsets = ragged_take(ring_offsets, rings)
            coords, street = coords[points], street[points]
            feature, index, lot_ids = feature[keep], index[keep], lot_ids[keep]
    attrs = {name: values[feature] for name, values in columns.items()}
    if len(feature):
        builder.add_block(index, lot_ids, coords[:, :3], np.diff(ring_offsets), np.diff(part_offsets), street)
    return builder, attrs


def _exterior_ends(ring_offsets: np.ndarray, part_offsets: np.ndarray) -> np.ndarray:
    """Where each polygon's exterior ring ends in the positions (where it starts: a polygon without rings,
    an empty part of a multipolygon)."""
    starts = ring_offsets[part_offsets[:-1]]
    has = np.diff(part_offsets) > 0
    return np.where(has, ring_offsets[np.minimum(part_offsets[:-1] + 1, len(ring_offsets) - 1)], starts)


def table_lot_numbers(table, column: str, path) -> int:
    """The lot numbers the rows of a table take: a polygon one, a multipolygon one per part, anything else
    one (a bad lot)."""
    return int(np.maximum(_polygons(table, column)[0].parts, 1).sum())


def _polygons(table, column: str) -> tuple[Polygons, dict[int, str]]:
    """The rows' polygons (``io.wkb``; a bad row, not a polygon or multipolygon or an empty one, has no
    parts), and why each unreadable row's WKB is (by row of the table): such a row is a bad lot, as a
    GeoJSON feature whose geometry is not one. Decoded in one pass where every row is a plain polygon or
    multipolygon, else through shapely (GEOS), which says what each odd row is."""
    values = table.column(column)
    decoded = decode_polygons(values)
    if decoded is not None:
        return decoded, {}
    present = ~values.is_null().to_numpy(zero_copy_only=False)
    if hasattr(values.type, "storage_type"):  # an extension type (geoarrow.wkb): its WKB bytes
        values = [chunk.storage for chunk in values.chunks]
        values = np.concatenate([v.to_numpy(zero_copy_only=False) for v in values]) if values else np.zeros(0, object)
    else:
        values = values.to_numpy(zero_copy_only=False)
    geometry = shapely.from_wkb(values, on_invalid="ignore")
    unreadable = {int(row): f"bad WKB in column {column!r}: {_wkb_error(values[row])}"
                  for row in np.flatnonzero(present & shapely.is_missing(geometry))}
    kinds = shapely.get_type_id(geometry).astype(np.int64)
    good = np.isin(kinds, (_POLYGON, _MULTIPOLYGON)) & ~shapely.is_empty(geometry)
    parts, feature = shapely.get_parts(geometry[good], return_index=True)
    counts = np.zeros(len(geometry), dtype=np.int64)
    counts[good] = np.bincount(feature, minlength=int(good.sum()))
    if len(parts):
        _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(parts)
    else:
        coords, ring_offsets, part_offsets = np.zeros((0, 2)), np.zeros(1, np.int64), np.zeros(1, np.int64)
    return Polygons(kinds, counts, coords, ring_offsets, part_offsets), unreadable


def _wkb_error(value) -> str:
    """What GEOS says of one unreadable WKB value."""
    try:
        shapely.from_wkb(value)
    except (shapely.errors.GEOSException, TypeError, ValueError) as error:
        return str(error)
    return "unreadable"


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


def _ids(table, names: list[str], n: int, first_row: int, id_field: str | None) -> np.ndarray:
    """(N,) object: the rows' ids, column ``id_field`` where given (``--id-field``), else ``id``, else
    ``name``; a row without one is its number."""
    if id_field is not None and id_field not in names:
        raise LotsError(f"--id-field {id_field}: the lots have no such field (they have {', '.join(names) or 'none'})")
    rows = np.arange(first_row, first_row + n)
    for name in (id_field,) if id_field is not None else ("id", "name"):
        if name in names:
            return _id_texts(table.column(name), rows)
    return rows.astype(str).astype(object)


def _id_texts(values, rows: np.ndarray) -> np.ndarray:
    """(N,) object: an id column as text (``lot_builder.id_text``), a null its row's number. Text and whole
    numbers are converted as a column (their text is Arrow's, the same as Python's); other types (floats
    among them: ``3.0`` is ``"3"``) value by value."""
    pa, _ = import_pyarrow()
    kind = values.type
    if pa.types.is_string(kind) or pa.types.is_large_string(kind) or pa.types.is_integer(kind):
        texts = values.cast(pa.string()).to_numpy(zero_copy_only=False).astype(object)
    else:
        texts = np.array([id_text(v) if v is not None else None for v in values.to_pylist()] + [None],
                         dtype=object)[:-1]  # [None]: one object per row, whatever the values are
    missing = values.is_null().to_numpy(zero_copy_only=False)
    texts[missing] = rows[missing].astype(str)
    return texts


def _type_name(type_id: int) -> str:
    return {0: "Point", 1: "LineString", 2: "LinearRing", 4: "MultiPoint", 5: "MultiLineString",
            7: "GeometryCollection"}.get(int(type_id), "null geometry")
