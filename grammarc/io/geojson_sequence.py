"""Lots of a GeoJSON sequence: a Feature or a bare geometry per line (RFC 8142's record separators, or
newline-delimited GeoJSON), read whole or in partitions of lines.

A sequence's features become lots as a FeatureCollection's do (``io.lot_builder.parse_features``). Unlike
one GeoJSON document, a sequence can be cut without being parsed: a partition is lines ``[start, stop)``
and their bytes ``[offset, end)`` of the file, found by one scan for line ends in blocks, so a file larger
than memory is fine. A line that is not JSON is an error naming its line number.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import orjson

from grammarc.errors import LotsError
from grammarc.io.crs import CRS84
from grammarc.io.lot_builder import parse_features, property_columns
from grammarc.io.lot_format import NO_OPTIONS, LotsFormat, LotsOptions, Partition, partitions_at
from grammarc.model.lots import Lots

__all__ = [
    "FORMAT", "SUFFIXES", "count_sequence", "read_sequence", "read_sequence_partition", "sequence_partitions",
]

#: Suffixes of GeoJSON sequences.
SUFFIXES = (".geojsonl", ".geojsons", ".geojsonseq", ".jsonl", ".ndjson")
#: Bytes read at a time while looking for line ends.
_SCAN_BLOCK = 1 << 26


def read_sequence(path: Path, options: LotsOptions = NO_OPTIONS) -> Lots:
    """All lots of a GeoJSON sequence; a ``LotsError`` if it cannot be read, has a line that is not JSON,
    or holds no polygon. Longitude and latitude where the coordinates are degrees (RFC 8142)."""
    builder = parse_features(_features(path, 0, 0, path.stat().st_size), 0, options.id_field)
    builder.implied = CRS84
    return builder.finish_file(property_columns(builder.props), path, options)


def sequence_partitions(path: Path, size: int) -> list[Partition]:
    """Partitions of ``size`` lines (the last may be shorter), cut at line ends."""
    starts = _line_starts(path)
    n = len(starts) - 1
    return partitions_at(path, "sequence", [*range(0, n, size), n], starts)


def count_sequence(part: Partition) -> int:
    """The lot numbers the features of a partition take (a MultiPolygon one per part)."""
    return parse_features(_features(Path(part.path), part.start, part.offset, part.end), 0).end


def read_sequence_partition(part: Partition, first_index: int, options: LotsOptions = NO_OPTIONS) -> Lots:
    """The lots of a partition, the first numbered ``first_index``."""
    builder = parse_features(_features(Path(part.path), part.start, part.offset, part.end), first_index,
                             options.id_field)
    builder.implied = CRS84
    return builder.finish(property_columns(builder.props), part.path, options)


def _features(path: Path, first_line: int, offset: int, end: int) -> list:
    """The features of bytes ``[offset, end)`` of a sequence, whose first line is ``first_line`` (from
    0); a line that is not JSON is an error naming it."""
    try:
        with open(path, "rb") as file:
            file.seek(offset)
            data = file.read(end - offset)
    except OSError as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error
    features = []
    for number, line in enumerate(data.split(b"\n"), first_line + 1):
        line = line.strip(b"\x1e \t\r")
        if not line:
            continue
        try:
            features.append(orjson.loads(line))
        except orjson.JSONDecodeError as error:
            raise LotsError(f"{path}:{number}: not valid JSON: {error.msg}") from error
    return features


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


FORMAT = LotsFormat(kind="sequence", suffixes=SUFFIXES, title="a GeoJSON sequence", read=read_sequence,
                    partitions=sequence_partitions, count=count_sequence,
                    read_partition=read_sequence_partition)
