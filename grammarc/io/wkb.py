"""Polygons and multipolygons of a WKB column decoded straight from its Arrow buffers, as ragged arrays.

A GeoParquet file of 10^5-10^6 footprints holds each as a WKB value. Decoding them with shapely makes a
Python ``bytes`` object and a GEOS geometry of every row, and ``to_ragged_array`` walks the geometries again
for their coordinates: most of the time it takes to read such a file. Here one numba kernel walks the
column's bytes twice (counting, then copying the coordinates), and no object is made per row.

Only what a lots file is made of is decoded: rows that are each a polygon or a multipolygon, in either byte
order, with x and y or x, y and z (ISO WKB or PostGIS's EWKB flag), every polygon with rings, every ring
closed and of 4 positions or more, as GEOS reads them. Anything else in a column (a null, another type, an
empty polygon, a measure, an SRID, a value cut short or with bytes left over) makes ``decode_polygons``
return None, and the caller reads the column with shapely, which says what each odd row is.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np
from numba import njit

from grammarc.ragged import offsets_from_counts

__all__ = ["Polygons", "decode_polygons"]

_POLYGON, _MULTIPOLYGON = 3, 6
_ISO_Z = 1000  # ISO WKB: 1003 is a polygon with z
_EWKB_Z = 0x80000000  # PostGIS's extended WKB: the high bit says z
_NATIVE_LITTLE = sys.byteorder == "little"


@dataclass(frozen=True)
class Polygons:
    """The rows of a WKB column as ragged arrays (``grammarc.ragged``), the layout of
    ``shapely.to_ragged_array`` of their polygons.

    kinds : (N,) int64
      Each row's geometry type, as shapely numbers them: 3 a polygon, 6 a multipolygon (other types, and
      -1 for none, in a column read through shapely).
    parts : (N,) int64
      Polygons per row: 1 for a polygon, 0 for a row that is none (read through shapely: another type, a
      null, an empty or unreadable geometry).
    coords : (V, 3) float64
      The positions of every ring, closed as WKB has them; z is NaN where a row has none.
    ring_offsets : (R + 1,) int64
      Each ring's positions in ``coords``.
    part_offsets : (P + 1,) int64
      Each polygon's rings (its exterior, then its holes), polygons in row order.
    """

    kinds: np.ndarray
    parts: np.ndarray
    coords: np.ndarray
    ring_offsets: np.ndarray
    part_offsets: np.ndarray


def decode_polygons(column) -> Polygons | None:
    """The rows of ``column`` (a pyarrow binary or large binary array or chunked array, or an extension
    type over one, as geoarrow's WKB) as ragged polygons; None where a row is anything but a polygon or a
    multipolygon as described in the module's docstring."""
    import pyarrow as pa  # the column's own library

    chunks = column.chunks if hasattr(column, "chunks") else [column]
    chunks = [chunk.storage if hasattr(chunk.type, "storage_type") else chunk for chunk in chunks]
    if any(chunk.null_count or not (pa.types.is_binary(chunk.type) or pa.types.is_large_binary(chunk.type))
           for chunk in chunks):
        return None
    data, offsets = _bytes(chunks, [pa.types.is_large_binary(chunk.type) for chunk in chunks])
    n = len(offsets) - 1
    kinds = np.zeros(n, dtype=np.int64)
    parts = np.zeros(n, dtype=np.int64)
    empty = np.zeros(0, dtype=np.int64)
    failed, n_parts, n_rings, n_points = _scan(data, offsets, kinds, parts, empty, empty,
                                               np.zeros(0, np.uint8), _NATIVE_LITTLE, False)
    if failed >= 0:
        return None
    rings = np.zeros(n_parts, dtype=np.int64)
    points = np.zeros(n_rings, dtype=np.int64)
    coords = np.full((n_points, 3), np.nan)
    _scan(data, offsets, kinds, parts, rings, points, coords.reshape(-1).view(np.uint8), _NATIVE_LITTLE, True)
    ring_offsets = offsets_from_counts(points)
    first, last = coords[ring_offsets[:-1], :2], coords[ring_offsets[1:] - 1, :2]
    if not (first == last).all():  # GEOS refuses an open ring (compared in x and y only, as here)
        return None
    return Polygons(kinds, parts, coords, ring_offsets, offsets_from_counts(rings))


def _bytes(chunks, large: list[bool]) -> tuple[np.ndarray, np.ndarray]:
    """The values of binary arrays (``large``: of 64-bit offsets) as one buffer of bytes and (N + 1,) int64
    offsets into it."""
    datas, offsets, at = [np.zeros(0, np.uint8)], [np.zeros(1, np.int64)], 0
    for chunk, wide in zip(chunks, large, strict=True):
        if not len(chunk):
            continue
        value_offsets = np.frombuffer(chunk.buffers()[1], np.int64 if wide else np.int32)
        value_offsets = value_offsets[chunk.offset:chunk.offset + len(chunk) + 1].astype(np.int64)
        buffer = chunk.buffers()[2]
        data = np.frombuffer(buffer, np.uint8) if buffer is not None else np.zeros(0, np.uint8)
        start, stop = int(value_offsets[0]), int(value_offsets[-1])
        datas.append(data[start:stop])
        offsets.append(value_offsets[1:] - start + at)
        at += stop - start
    return (datas[1] if len(datas) == 2 else np.concatenate(datas)), np.concatenate(offsets)


@njit(cache=True, nogil=True)
def _count(data, at, end, little):
    """The count (an unsigned 32-bit integer) at byte ``at`` and the byte after it; a count of 0 where the
    value would run past ``end``."""
    if at + 4 > end:
        return np.int64(0), at
    return _u32(data, at, little), at + 4


@njit(cache=True, nogil=True)
def _u32(data, at, little):
    """The unsigned 32-bit integer at byte ``at``."""
    if little:
        return np.int64(data[at]) | np.int64(data[at + 1]) << 8 | np.int64(data[at + 2]) << 16 \
            | np.int64(data[at + 3]) << 24
    return np.int64(data[at + 3]) | np.int64(data[at + 2]) << 8 | np.int64(data[at + 1]) << 16 \
        | np.int64(data[at]) << 24


@njit(cache=True, nogil=True)
def _header(data, at, end):
    """A geometry's byte order and type at ``at``: (next byte, little-endian, kind, dimensions); kind -1
    for anything but a polygon or multipolygon of 2 or 3 dimensions."""
    if at + 5 > end or data[at] > 1:
        return at, False, -1, 0
    little = data[at] == 1
    code = _u32(data, at + 1, little)
    dims = 2
    if code > _ISO_Z and code < _ISO_Z + 10:
        code, dims = code - _ISO_Z, 3
    elif code >= _EWKB_Z and code < _EWKB_Z + 10:
        code, dims = code - _EWKB_Z, 3
    if code != _POLYGON and code != _MULTIPOLYGON:
        return at + 5, little, -1, dims
    return at + 5, little, code, dims


@njit(cache=True, nogil=True)
def _scan(data, offsets, kinds, parts, rings, points, coords, native_little, fill):
    """Walk every row: its kind and polygons into ``kinds`` and ``parts``, and when ``fill``, each polygon's
    rings, each ring's positions and their coordinates' bytes (``coords``: (V * 3 * 8,) uint8 of float64
    in native order, z left as it is for 2D rows). Returns (the first row that is not decoded, else -1, and
    the polygons, rings and positions counted)."""
    p = 0
    r = 0
    v = 0
    for row in range(len(offsets) - 1):
        at, end = offsets[row], offsets[row + 1]
        at, little, kind, dims = _header(data, at, end)
        if kind < 0:
            return row, p, r, v
        n_parts = 1
        if kind == _MULTIPOLYGON:
            n_parts, at = _count(data, at, end, little)
            if n_parts == 0:
                return row, p, r, v
        kinds[row] = kind
        parts[row] = n_parts
        for _ in range(n_parts):
            if kind == _MULTIPOLYGON:
                at, little, part_kind, part_dims = _header(data, at, end)
                if part_kind != _POLYGON or part_dims != dims:
                    return row, p, r, v
            n_rings, at = _count(data, at, end, little)
            if n_rings == 0:
                return row, p, r, v
            if fill:
                rings[p] = n_rings
            p += 1
            for _ in range(n_rings):
                n, at = _count(data, at, end, little)
                if n < 4 or at + n * dims * 8 > end:
                    return row, p, r, v
                if fill:
                    points[r] = n
                    swap = little != native_little
                    for k in range(n):
                        for d in range(dims):
                            source = at + (k * dims + d) * 8
                            target = ((v + k) * 3 + d) * 8
                            for b in range(8):
                                coords[target + b] = data[source + (7 - b if swap else b)]
                r += 1
                v += n
                at += n * dims * 8
        if at != end:
            return row, p, r, v
    return -1, p, r, v
