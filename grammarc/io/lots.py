"""Lots in: the table of lots formats by suffix, and the entry points that read a file whole or in partitions.

Each format is one module describing itself with a ``LotsFormat`` (``io.lot_format``), as trimesh's
``exchange`` modules do; ``FORMATS`` lists them and every entry point dispatches on the file's suffix:

- ``.geojson``, ``.json``: a GeoJSON document, or a PRT initial shape as JSON (``io.geojson``);
- ``.obj``: a face per lot (``io.obj_lots``);
- ``.parquet``: GeoParquet, the fast way for 10^5 lots and more (``io.geoparquet``, the ``parquet`` extra);
- ``.geojsonl``, ``.geojsons``, ``.geojsonseq``, ``.jsonl``, ``.ndjson``: a GeoJSON sequence, a Feature or
  a geometry per line (``io.geojson_sequence``);
- ``.gpkg``, ``.shp``, ``.fgb``, ...: a GIS file read through GDAL (``io.gis``, the ``gis`` extra).

All of them give the same lots for the same footprints, cleaned, validated and oriented as CityEngine takes
them (``io.lot_builder``). A bad lot (self-intersecting, zero area, not a polygon, a wall) is data, not an
exception: it is listed in ``Lots.bad`` and the other lots load. Only a file that cannot be read at all
raises :class:`~grammarc.errors.LotsError`.

A country's footprints do not fit in one process's memory, nor should they cross a cluster's scheduler
(``grammarc.cluster``). ``partition_lots`` cuts a file into ``Partition``s that workers read themselves:
rows of GeoParquet (at row groups), features of a GIS file, lines of a GeoJSON sequence; a file of any
other format fits in memory by construction and is read whole, once per worker process, a partition being
its lots numbered ``[start, stop)``. A lot's number (``Lots.index``) is its place among the file's polygons,
and it seeds the lot's random stream, so a partition must know the number of its first polygon:
``count_lots`` gives the numbers each partition takes (a MultiPolygon takes one per part), a pass the
cluster runs before deriving, and ``read_partition`` reads a partition with its first number. The lots then
equal those of ``read_lots`` on the whole file, numbers, ids, properties and bad lots alike (tests), and so
do their records.
"""

from __future__ import annotations

import contextlib
import functools
import gc
import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from grammarc.errors import LotsError
from grammarc.io import geojson, geojson_sequence, geoparquet, gis, obj_lots
from grammarc.io.lot_builder import STREET_WIDTH, LotBuilder, property_column
from grammarc.io.lot_format import NO_OPTIONS, LotsFormat, LotsOptions, Partition, partitions_at
from grammarc.model.lots import Lots

__all__ = [
    "FORMATS", "Partition", "count_lots", "default_lot", "file_stamp", "lots_from_polygons",
    "partition_lots", "read_lots", "read_partition",
]

#: The lots formats, in the order an unknown suffix's error lists them.
FORMATS: tuple[LotsFormat, ...] = (
    geojson.FORMAT, obj_lots.FORMAT, geoparquet.FORMAT, geojson_sequence.FORMAT, gis.FORMAT,
)
_BY_SUFFIX = {suffix: form for form in FORMATS for suffix in form.suffixes}
_BY_KIND = {form.kind: form for form in FORMATS}


def read_lots(path: str | os.PathLike, options: LotsOptions | None = None) -> Lots:
    """Read all lots of a file, of any format of ``FORMATS`` (by its suffix; see the format's module).

    Parameters
    ----------
    path : str or os.PathLike
      The lots file.
    options : LotsOptions, optional
      What the user asks of the file: ``--lots-crs`` and ``--crs`` (lots in longitude/latitude are
      reprojected, ``io.crs``), ``--id-field``, ``--min-area``.

    Returns
    -------
    lots : Lots
      The good lots, oriented and validated; the bad ones in ``lots.bad``.

    Raises
    ------
    LotsError
      The file is missing, unreadable, not valid JSON, of an unknown suffix, or holds no polygon; or its
      lots look like degrees and name no coordinate system.
    UsageError
      The format needs an extra that is not installed (pyarrow, pyogrio).
    """
    path = Path(path)
    if not path.is_file():
        raise LotsError(f"lots file not found: {path}")
    form = _BY_SUFFIX.get(path.suffix.lower())
    if form is None:
        raise LotsError(f"unknown lots file type {path.suffix.lower()!r} (expected {_expected()}): {path}")
    with _no_cycle_collection():
        return form.read(path, options or NO_OPTIONS)


def partition_lots(path: str | os.PathLike, size: int, options: LotsOptions | None = None) -> list[Partition]:
    """The partitions of a lots file, about ``size`` features each (GeoParquet's follow its row groups).

    Returns
    -------
    partitions : list of Partition
      In file order, numbered from 0; the first starts at 0 and each ends where the next starts. A file
      read whole is cut into lot numbers (kind ``"whole"``).
    """
    path = Path(path)
    if not path.is_file():
        raise LotsError(f"lots file not found: {path}")
    form = _BY_SUFFIX.get(path.suffix.lower())
    if form is not None and form.partitions is not None:
        return form.partitions(path, size)
    lots = _whole(str(path), *file_stamp(path), options)
    n = 1 + max([int(lots.index.max()) if len(lots) else -1, *(b.index for b in lots.bad)])
    return partitions_at(path, "whole", [*range(0, n, size), n])


def count_lots(part: Partition) -> int:
    """The lot numbers the features of ``part`` take (see the module docstring)."""
    if part.kind == "whole":
        return part.stop - part.start
    return _BY_KIND[part.kind].count(part)


def read_partition(part: Partition, first_index: int, options: LotsOptions | None = None) -> Lots:
    """The lots of ``part``, the first numbered ``first_index`` (``count_lots`` of the partitions before;
    ignored for a file read whole, whose lots keep their numbers).

    Raises ``LotsError`` for lots in longitude/latitude without ``options.crs``: each partition would
    reproject them to the UTM zone of its own lots, not of the file's."""
    if part.kind != "whole":
        with _no_cycle_collection():
            lots = _BY_KIND[part.kind].read_partition(part, first_index, options or NO_OPTIONS)
        if lots.crs_note is not None and (options is None or options.crs is None):
            raise LotsError(f"{part.path}: its lots are {lots.crs_note.split(',')[0]}: a partitioned build "
                            "needs --crs to reproject them (e.g. the UTM zone or national grid of the city)")
        return lots
    lots = _whole(part.path, *file_stamp(Path(part.path)), options)
    inside = (lots.index >= part.start) & (lots.index < part.stop)
    return replace(lots.take(np.flatnonzero(inside)),
                   bad=tuple(b for b in lots.bad if part.start <= b.index < part.stop))


def file_stamp(path: Path) -> tuple[int, int]:
    """What tells a file's contents apart cheaply: its modification time and size."""
    info = path.stat()
    return info.st_mtime_ns, info.st_size


def lots_from_polygons(
    polygons: list[list[np.ndarray]],
    *,
    ids=None,
    attrs=None,
    street=None,
    source: str = "<memory>",
) -> Lots:
    """Make lots in memory from map-coordinate polygons, cleaned and validated as GeoJSON lots are.

    Parameters
    ----------
    polygons : list of list of (k, 2) float
      Per lot, the exterior ring then its holes, in map coordinates (x, y); any winding, closed or not.
    ids : sequence of str, optional
      One id per lot; default ``"0"``, ``"1"``, ...
    attrs : dict of str to sequence, optional
      Per-lot property columns of length ``len(polygons)``; typed as GeoJSON properties are (numbers and
      None become float64 with nan, anything else ``str`` with None).
    street : sequence, optional
      Per lot, None or CityEngine's ``streetWidth``: a number per edge of the exterior ring, > 0 where
      the edge faces a street.
    source : str
      Recorded in ``Lots.source``.

    Returns
    -------
    lots : Lots
      The good lots; bad ones (lot numbers = positions in ``polygons``) in ``lots.bad``.

    Examples
    --------
    >>> lots = lots_from_polygons([[np.array([[0, 0], [4, 0], [4, 3], [0, 3]])]], ids=["a"])
    >>> lots.vertices[:2].tolist()
    [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0]]
    >>> lots_from_polygons([[np.array([[0, 0], [1, 1], [2, 2]])]]).bad
    (BadLot(index=0, id='0', reason='zero area'),)
    """
    ids = [str(i) for i in range(len(polygons))] if ids is None else [str(i) for i in ids]
    attrs = {} if attrs is None else dict(attrs)
    lengths = {"ids": len(ids), **{f"attrs[{name!r}]": len(values) for name, values in attrs.items()}}
    for name, length in lengths.items():
        if length != len(polygons):
            raise ValueError(f"{name} has {length} entries for {len(polygons)} polygons")
    builder = LotBuilder(world=False)
    street = [None] * len(polygons) if street is None else street
    for index, (lot_id, rings, widths) in enumerate(zip(ids, polygons, street)):
        builder.add_positions(index, lot_id, rings, {} if widths is None else {STREET_WIDTH: list(widths)})
    return builder.finish({name: property_column(list(values)) for name, values in attrs.items()}, source)


#: ``Lots.source`` of ``default_lot``: what a build without lots says it built.
DEFAULT_LOT = "one built-in 30 x 20 m lot"


def default_lot() -> Lots:
    """One 30 x 20 m rectangle, id ``"default"``: map corners (0, 0), (30, 0), (30, 20), (0, 20).

    Returns
    -------
    lots : Lots
      A single lot whose first edge runs 30 m along world +x.
    """
    rectangle = np.array([[0.0, 0.0], [30.0, 0.0], [30.0, 20.0], [0.0, 20.0]])
    return lots_from_polygons([[rectangle]], ids=["default"], source=DEFAULT_LOT)


def _expected() -> str:
    """The suffixes ``read_lots`` takes, for its error: a format with a title as one item (``a GIS file
    (.gpkg, ...)``), the others' suffixes each by itself; the last item after "or"."""
    items = [item for form in FORMATS
             for item in ([f"{form.title} ({', '.join(form.suffixes)})"] if form.title else form.suffixes)]
    return f"{', '.join(items[:-1])} or {items[-1]}"


@contextlib.contextmanager
def _no_cycle_collection():
    """The cyclic garbage collector off while a file is parsed: JSON makes millions of dicts and lists (a
    tree, no cycles, freed by reference counting), and each collection would walk them all again, which on
    a city's file costs about as much as the parsing itself."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


@functools.lru_cache(maxsize=1)
def _whole(path: str, mtime_ns: int, size: int, options: LotsOptions | None) -> Lots:
    """A lots file read whole, once per process while it is unchanged (its stamp is in the key)."""
    return read_lots(path, options)
