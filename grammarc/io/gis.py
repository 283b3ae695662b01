"""Lots from GIS files through GDAL (the ``gis`` extra: pyogrio, pyarrow): GeoPackage, shapefiles,
FlatGeobuf and the other vector formats GDAL reads (``GIS_SUFFIXES``).

pyogrio reads a layer into an Arrow table (WKB footprints and typed fields), which becomes lots as a
GeoParquet file's table does (``geoparquet.lots_from_table``): the same ids (``id``, else ``name``, else
the feature's number), properties, MultiPolygon parts and bad lots. ``rows`` reads only those features
(``skip_features``/``max_features``), which is how a cluster's workers read their partitions of a file
larger than memory (``io.lot_partitions``). Coordinates are taken as metres as they are: reproject a
longitude/latitude layer first (``ogr2ogr -t_srs EPSG:32633``).
"""

from __future__ import annotations

import os

from grammarc.errors import LotsError, UsageError
from grammarc.io.lots import GIS_SUFFIXES

__all__ = ["GIS_SUFFIXES", "count_gis", "gis_features", "read_gis"]


def _pyogrio():
    try:
        import pyogrio
        import pyogrio.raw
    except ImportError as error:
        raise UsageError("GIS lots files need pyogrio: pip install 'grammarc[gis]'") from error
    return pyogrio


def gis_features(path: str | os.PathLike) -> int:
    """The features of the file's first layer."""
    pyogrio = _pyogrio()
    try:
        return int(pyogrio.read_info(path, force_feature_count=True)["features"])
    except Exception as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error


def read_gis(path: str | os.PathLike, rows: tuple[int, int] | None = None, first_index: int = 0):
    """The lots of a GIS file (its features ``rows``, the first numbered ``first_index``), for
    ``_Builder.finish``: the builder and the property columns."""
    from grammarc.io.geoparquet import lots_from_table

    table, column = _table(path, rows)
    return lots_from_table(table, column, path, rows[0] if rows else 0, first_index)


def count_gis(path: str | os.PathLike, rows: tuple[int, int]) -> int:
    """The lot numbers the features ``rows`` take (``geoparquet.table_lot_numbers``); no fields read."""
    from grammarc.io.geoparquet import table_lot_numbers

    table, column = _table(path, rows, columns=[])
    return table_lot_numbers(table, column, path)


def _table(path, rows, columns=None):
    pyogrio = _pyogrio()
    skip, count = (rows[0], rows[1] - rows[0]) if rows else (0, None)
    try:
        meta, table = pyogrio.raw.read_arrow(path, columns=columns, skip_features=skip, max_features=count)
    except Exception as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error
    column = meta.get("geometry_name") or "wkb_geometry"
    if column not in table.column_names:
        raise LotsError(f"{path}: no geometry in its first layer")
    return table, column
