"""Lots files cut into partitions that cluster workers read themselves (``grammarc.cluster``).

A country's footprints do not fit in one process's memory, nor should they cross a scheduler. A partition
names a range of a lots file; the worker that derives it reads that range and nothing else:

- GeoParquet (``.parquet``): rows ``[start, stop)``, cut at row-group boundaries where one is near, and
  read from the row groups that hold them (pyarrow);
- a GIS file GDAL reads (``.gpkg``, ``.shp``, ``.fgb``, ...: ``io.gis``): features ``[start, stop)``;
- a GeoJSON sequence (RFC 8142 or newline-delimited: ``.geojsonl``, ``.geojsons``, ``.geojsonseq``,
  ``.jsonl``, ``.ndjson``; a Feature or a geometry per line): lines ``[start, stop)``, bytes
  ``[offset, end)`` of the file, found by one scan for line ends;
- any other lots file (one GeoJSON document, OBJ, a PRT shape) is read whole, once per worker process,
  and a partition is the lots numbered ``[start, stop)``: such a file fits in memory by construction.

A lot's number (``Lots.index``) is its place among the file's polygons, and it seeds the lot's random
stream, so a partition must know the number of its first polygon: ``count_lots`` gives the numbers each
partition takes (a MultiPolygon takes one per part), a pass the cluster runs before deriving, and
``read_partition`` reads a partition with its first number. The lots then equal those of ``read_lots``
on the whole file, numbers, ids, properties and bad lots alike (tests), and so do their records.
"""

from __future__ import annotations

import functools
import itertools
import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import orjson

from grammarc.errors import LotsError
from grammarc.io.lots import (
    GIS_SUFFIXES,
    SEQUENCE_SUFFIXES,
    Lots,
    _columns,
    _no_cycle_collection,
    parse_features,
    read_lots,
)

__all__ = ["SEQUENCE_SUFFIXES", "Partition", "count_lots", "partition_lots", "read_partition", "read_whole"]

#: Bytes read at a time while looking for line ends.
_SCAN_BLOCK = 1 << 26


@dataclass(frozen=True)
class Partition:
    """Part ``number`` of a lots file: its features ``[start, stop)`` (rows, lines, or lot numbers of a
    file read whole, by ``kind``) and, for a sequence, their bytes ``[offset, end)``."""

    number: int
    path: str
    kind: str
    start: int
    stop: int
    offset: int = 0
    end: int = 0


def file_kind(path: str | os.PathLike) -> str:
    """``parquet``, ``gis``, ``sequence``, or ``whole`` (a file read at once)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".parquet":
        return "parquet"
    return "gis" if suffix in GIS_SUFFIXES else "sequence" if suffix in SEQUENCE_SUFFIXES else "whole"


def partition_lots(path: str | os.PathLike, size: int) -> list[Partition]:
    """The partitions of a lots file, about ``size`` features each (GeoParquet's follow its row groups)."""
    path = Path(path)
    if not path.is_file():
        raise LotsError(f"lots file not found: {path}")
    kind = file_kind(path)
    starts = None  # a sequence's line starts: its partitions' byte ranges
    if kind == "parquet":
        from grammarc.io.geoparquet import row_group_bounds

        cuts = _aligned(row_group_bounds(path), size)
    else:
        if kind == "gis":
            from grammarc.io.gis import gis_features

            n = gis_features(path)
        elif kind == "sequence":
            starts = _line_starts(path)
            n = len(starts) - 1
        else:
            lots = _whole(str(path), *file_stamp(path))
            n = 1 + max([int(lots.index.max()) if len(lots) else -1, *(b.index for b in lots.bad)])
        cuts = [*range(0, n, size), n]
    return [Partition(k, str(path), kind, int(a), int(b),
                      *((int(starts[a]), int(starts[b])) if starts is not None else ()))
            for k, (a, b) in enumerate(itertools.pairwise(cuts))]


def count_lots(part: Partition) -> int:
    """The lot numbers the features of ``part`` take (see the module docstring)."""
    if part.kind in ("parquet", "gis"):
        return _columnar(part.kind)[1](part.path, (part.start, part.stop))
    if part.kind == "sequence":
        return parse_features(_features(part), 0).end
    return part.stop - part.start


def read_partition(part: Partition, first_index: int) -> Lots:
    """The lots of ``part``, the first numbered ``first_index`` (``count_lots`` of the partitions before;
    ignored for a file read whole, whose lots keep their numbers)."""
    if part.kind in ("parquet", "gis"):
        with _no_cycle_collection():
            builder, attrs = _columnar(part.kind)[0](part.path, (part.start, part.stop), first_index)
            return builder.finish(attrs, part.path)
    if part.kind == "sequence":
        with _no_cycle_collection():
            builder = parse_features(_features(part), first_index)
            return builder.finish(_columns(builder.props), part.path)
    lots = _whole(part.path, *file_stamp(Path(part.path)))
    inside = (lots.index >= part.start) & (lots.index < part.stop)
    return replace(lots.take(np.flatnonzero(inside)),
                   bad=tuple(b for b in lots.bad if part.start <= b.index < part.stop))


def read_whole(path: Path) -> Lots:
    """All lots of a GeoParquet, GIS or GeoJSON-sequence file (``read_lots`` of these kinds)."""
    kind = file_kind(path)
    with _no_cycle_collection():
        if kind == "sequence":
            builder = parse_features(_features(Partition(0, str(path), kind, 0, 0, 0, path.stat().st_size)), 0)
            attrs = _columns(builder.props)
        else:
            builder, attrs = _columnar(kind)[0](path)
        if builder.polygons == 0:
            raise LotsError(f"no polygon in lots file {path}")
        return builder.finish(attrs, str(path))


def _columnar(kind: str):
    """The reader and the lot counter of a columnar kind: footprints as WKB in an Arrow table, from
    pyarrow (``parquet``) or GDAL (``gis``)."""
    if kind == "parquet":
        from grammarc.io.geoparquet import count_polygons, read_geoparquet

        return read_geoparquet, count_polygons
    from grammarc.io.gis import count_gis, read_gis

    return read_gis, count_gis


def _features(part: Partition) -> list:
    """The features of a sequence's partition; a line that is not JSON is an error naming it."""
    try:
        with open(part.path, "rb") as file:
            file.seek(part.offset)
            data = file.read(part.end - part.offset)
    except OSError as error:
        raise LotsError(f"cannot read lots file {part.path}: {error}") from error
    features = []
    for number, line in enumerate(data.split(b"\n"), part.start + 1):
        line = line.strip(b"\x1e \t\r")
        if not line:
            continue
        try:
            features.append(orjson.loads(line))
        except orjson.JSONDecodeError as error:
            raise LotsError(f"{part.path}:{number}: not valid JSON: {error.msg}") from error
    return features


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


def _line_starts(path: Path) -> np.ndarray:
    """Byte offsets where the file's lines start, and its size last; a scan in blocks, so a file larger
    than memory is fine. A last line without its line end counts."""
    starts = [np.zeros(1, np.int64)]
    size = path.stat().st_size
    with open(path, "rb") as file:
        at = 0
        while block := file.read(_SCAN_BLOCK):
            ends = np.flatnonzero(np.frombuffer(block, np.uint8) == 10) + at + 1
            starts.append(ends[ends < size])
            at += len(block)
    return np.concatenate([*starts, [size]]) if size else np.zeros(1, np.int64)


def file_stamp(path: Path) -> tuple[int, int]:
    """What tells a file's contents apart cheaply: its modification time and size."""
    info = path.stat()
    return info.st_mtime_ns, info.st_size


@functools.lru_cache(maxsize=1)
def _whole(path: str, mtime_ns: int, size: int) -> Lots:
    """A lots file read whole, once per process while it is unchanged (its stamp is in the key)."""
    return read_lots(path)
