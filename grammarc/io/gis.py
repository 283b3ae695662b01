"""Lots from GIS files through GDAL (the ``gis`` extra: pyogrio, pyarrow): GeoPackage, shapefiles,
FlatGeobuf and the other vector formats GDAL reads (``SUFFIXES``).

pyogrio reads a layer into an Arrow table (WKB footprints and typed fields), which becomes lots as a
GeoParquet file's table does (``io.arrow_lots``): the same ids (``id``, else ``name``, else the feature's
number), properties, MultiPolygon parts and bad lots. A partition is features ``[start, stop)`` of the
first layer, read alone (``skip_features``/``max_features``), which is how a cluster's workers read their
partitions of a file larger than memory. Coordinates are taken as metres as they are: reproject a
longitude/latitude layer first (``ogr2ogr -t_srs EPSG:32633``).
"""

from __future__ import annotations

import os
from pathlib import Path

from grammarc.errors import LotsError, UsageError
from grammarc.io.arrow_lots import lots_from_table, table_lot_numbers
from grammarc.io.lot_format import NO_OPTIONS, LotsFormat, LotsOptions, Partition, partitions_at
from grammarc.model.lots import Lots

__all__ = ["FORMAT", "SUFFIXES", "count_gis", "gis_partitions", "read_gis", "read_gis_partition"]

#: Suffixes of the GIS files read through GDAL.
SUFFIXES = (".gpkg", ".shp", ".fgb", ".gml", ".kml", ".sqlite", ".tab")


def _pyogrio():
    try:
        import pyogrio
        import pyogrio.raw
    except ImportError as error:
        raise UsageError("GIS lots files need pyogrio: pip install 'grammarc[gis]'") from error
    return pyogrio


def read_gis(path: Path, options: LotsOptions = NO_OPTIONS) -> Lots:
    """All lots of a GIS file's first layer, in the coordinate system GDAL gives it; a ``LotsError`` if GDAL
    cannot read it, it has no geometry, or it holds no polygon."""
    table, column, declared = _table(path, None)
    builder, attrs = lots_from_table(table, column, path, id_field=options.id_field)
    builder.declared = declared
    return builder.finish_file(attrs, path, options)


def gis_partitions(path: Path, size: int) -> list[Partition]:
    """Partitions of ``size`` features of the first layer (the last may be shorter)."""
    n = _features(path)
    return partitions_at(path, "gis", [*range(0, n, size), n])


def count_gis(part: Partition) -> int:
    """The lot numbers a partition's features take (``arrow_lots.table_lot_numbers``); no fields read."""
    table, column, _ = _table(part.path, (part.start, part.stop), columns=[])
    return table_lot_numbers(table, column, part.path)


def read_gis_partition(part: Partition, first_index: int, options: LotsOptions = NO_OPTIONS) -> Lots:
    """The lots of a partition's features, the first numbered ``first_index``."""
    table, column, declared = _table(part.path, (part.start, part.stop))
    builder, attrs = lots_from_table(table, column, part.path, part.start, first_index,
                                     options.id_field)
    builder.declared = declared
    return builder.finish(attrs, part.path, options)


def _features(path: str | os.PathLike) -> int:
    """The features of the file's first layer."""
    pyogrio = _pyogrio()
    try:
        return int(pyogrio.read_info(path, force_feature_count=True)["features"])
    except Exception as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error


def _table(path, rows, columns=None):
    """The first layer's features ``rows`` (all for None) as an Arrow table, its geometry column and its
    coordinate system (GDAL's name for it, None without one)."""
    pyogrio = _pyogrio()
    skip, count = (rows[0], rows[1] - rows[0]) if rows else (0, None)
    try:
        meta, table = pyogrio.raw.read_arrow(path, columns=columns, skip_features=skip, max_features=count)
    except Exception as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error
    column = meta.get("geometry_name") or "wkb_geometry"
    if column not in table.column_names:
        raise LotsError(f"{path}: no geometry in its first layer")
    return table, column, meta.get("crs")


FORMAT = LotsFormat(kind="gis", suffixes=SUFFIXES, title="a GIS file", read=read_gis,
                    partitions=gis_partitions, count=count_gis, read_partition=read_gis_partition)
