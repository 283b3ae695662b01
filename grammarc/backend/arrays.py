"""CityEngine's array values, one array per shape, computed on a whole batch at once.

An array value of a batch of n shapes is ``Arrays``: a ragged column, the elements of every shape's
array in one flat array (row by row), offsets saying where each shape's array starts, and each array's
number of columns (its rows are its size over its columns). Ragged, not a dense (n, rows, cols) block,
because the size of an array is often known only per shape: a lot's array attribute comes from its own
GeoJSON property, a range ``[0 : n]`` or a logical index ``a[a .> 2]`` has a length per shape. One form
for every array keeps each operation written once; a constant array (a literal of constants) is
repeated for the batch, which costs little as arrays in rules are short.

Every operation here is numpy over the flat elements (the shape of each element is ``owner``, its place
in its array ``position``), or a numba kernel where a shape's elements must be ordered together
(``sort_row_indices``): no Python per shape. Elements are float64, bool, or int32 ids of interned
strings, as scalar values are (``backend.evaluate``). Where CityEngine would stop, because two arrays of
one shape cannot be combined (rows of different lengths in ``[a ; b]``), the functions return a mask of
the shapes that fail, for the evaluator to report their lots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

#: The most elements one array may hold (CityEngine's default limit of the Procedural Runtime).
MAX_ELEMENTS = 100_000


@dataclass(frozen=True, eq=False)
class Arrays:
    """One array per shape of a batch.

    Attributes
    ----------
    values : (E,) float64, bool or int32
      The elements of all arrays, shape by shape, each array row by row.
    offsets : (n + 1,) int64
      Shape ``s``'s array is ``values[offsets[s]:offsets[s + 1]]``.
    columns : (n,) int64
      Each array's number of columns; an empty array has 0.
    """

    values: np.ndarray
    offsets: np.ndarray
    columns: np.ndarray

    def __len__(self) -> int:
        return len(self.columns)

    @property
    def sizes(self) -> np.ndarray:
        """(n,) int64 number of elements per shape."""
        return np.diff(self.offsets)

    @property
    def rows(self) -> np.ndarray:
        """(n,) int64 number of rows per shape (0 for an empty array)."""
        return self.sizes // np.maximum(self.columns, 1)

    def owner(self) -> np.ndarray:
        """(E,) int64 the shape of each element."""
        return np.repeat(np.arange(len(self)), self.sizes)

    def position(self) -> np.ndarray:
        """(E,) int64 each element's place in its own array."""
        return np.arange(len(self.values)) - np.repeat(self.offsets[:-1], self.sizes)

    def take(self, which: np.ndarray) -> Arrays:
        """The arrays of shapes ``which`` (k,) int, in that order (a lot's array for each of its shapes)."""
        sizes = self.sizes[which]
        offsets = _offsets(sizes)
        source = np.repeat(self.offsets[:-1][which] - offsets[:-1], sizes) + np.arange(offsets[-1])
        return Arrays(self.values[source], offsets, self.columns[which])


def _offsets(sizes: np.ndarray) -> np.ndarray:
    offsets = np.zeros(len(sizes) + 1, dtype=np.int64)
    np.cumsum(sizes, out=offsets[1:])
    return offsets


def _column(value, n: int) -> np.ndarray:
    """A scalar value (a Python scalar or an (n,) array) as an (n,) array."""
    value = np.asarray(value)
    return np.broadcast_to(value, (n,)) if value.ndim == 0 else value


def from_scalars(value, n: int, dtype) -> Arrays:
    """Per shape the 1x1 array of its value of ``value`` (a Python scalar or (n,) array)."""
    return Arrays(np.array(_column(value, n), dtype=dtype), np.arange(n + 1, dtype=np.int64),
                  np.ones(n, dtype=np.int64))


def concatenate_row(pieces: list[Arrays]) -> tuple[Arrays, np.ndarray]:
    """``[a, b, ...]``: the pieces side by side, per shape; empty pieces are left out.

    Returns the arrays and (n,) bool the shapes whose non-empty pieces differ in their rows.
    """
    rows = np.max([np.where(p.sizes > 0, p.rows, 0) for p in pieces], axis=0)
    bad = np.any([(p.sizes > 0) & (p.rows != rows) for p in pieces], axis=0)
    width = np.sum([p.columns for p in pieces], axis=0)
    out = _offsets(rows * width)
    values = np.empty(out[-1], dtype=pieces[0].values.dtype)
    start = np.zeros(len(rows), dtype=np.int64)  # the first column of the piece, per shape
    for p in pieces:
        owner, position = p.owner(), p.position()
        columns = np.maximum(p.columns, 1)[owner]
        dest = out[:-1][owner] + position // columns * width[owner] + start[owner] + position % columns
        ok = ~bad[owner]
        values[dest[ok]] = p.values[ok]
        start = start + p.columns
    return Arrays(values, out, np.where(rows > 0, width, 0)), bad


def stack_rows(rows: list[Arrays]) -> tuple[Arrays, np.ndarray]:
    """``[a ; b ; ...]``: the rows of each one below those of the one before, per shape; empty arrays are
    left out. Returns the arrays and (n,) bool the shapes whose non-empty arrays differ in columns."""
    width = np.max([np.where(r.sizes > 0, r.columns, 0) for r in rows], axis=0)
    bad = np.any([(r.sizes > 0) & (r.columns != width) for r in rows], axis=0)
    sizes = np.sum([r.sizes for r in rows], axis=0)
    out = _offsets(np.where(bad, 0, sizes))
    values = np.empty(out[-1], dtype=rows[0].values.dtype)
    start = np.zeros(len(width), dtype=np.int64)  # where the array goes in the shape's result
    for r in rows:
        owner = r.owner()
        ok = ~bad[owner]
        values[(out[:-1][owner] + start[owner] + r.position())[ok]] = r.values[ok]
        start = start + r.sizes
    return Arrays(values, out, width), bad


def colon(base, step, limit, n: int) -> tuple[Arrays, np.ndarray]:
    """``[base : step : limit]`` per shape: base, base + step, ... not beyond ``limit``; empty when
    ``step`` is 0 or leads away from ``limit``. Returns the arrays and (n,) bool the shapes whose range
    would exceed ``MAX_ELEMENTS`` (a range to infinity, or of a step too small for a float's count, too)."""
    base, step, limit = (np.asarray(_column(v, n), dtype=np.float64) for v in (base, step, limit))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        count = np.floor((limit - base) / step) + 1
    count = np.where((step != 0) & (count > 0), count, 0)  # NaN is not > 0
    bad = count > MAX_ELEMENTS
    sizes = np.where(bad, 0, count).astype(np.int64)
    offsets = _offsets(sizes)
    owner = np.repeat(np.arange(n), sizes)
    position = np.arange(offsets[-1]) - offsets[:-1][owner]
    return Arrays(base[owner] + step[owner] * position, offsets, sizes.copy()), bad


# ------------------------------------------------------------------------------------------------ indexing


def item(array: Arrays, index, default) -> np.ndarray:
    """``a[i]`` with a number ``i`` per shape: the element at linear index ``floor(i)`` (row by row), or
    ``default`` where it is out of range. Returns (n,) of the elements' dtype."""
    k = np.floor(np.asarray(_column(index, len(array)), dtype=np.float64))
    valid = (k >= 0) & (k < array.sizes)
    at = np.where(valid, array.offsets[:-1] + np.where(valid, k, 0).astype(np.int64), 0)
    return np.where(valid, array.values[at] if len(array.values) else default, default)


def cell(array: Arrays, row, column, default) -> np.ndarray:
    """``a[i, j]`` with numbers per shape: the element at row i, column j, or ``default`` out of range."""
    r = np.floor(np.asarray(_column(row, len(array)), dtype=np.float64))
    c = np.floor(np.asarray(_column(column, len(array)), dtype=np.float64))
    valid = (r >= 0) & (r < array.rows) & (c >= 0) & (c < array.columns)
    at = array.offsets[:-1] + np.where(valid, r * array.columns + c, 0).astype(np.int64)
    return np.where(valid, array.values[np.where(valid, at, 0)] if len(array.values) else default, default)


def _picks(index: Arrays) -> Arrays:
    """An index array as the indices it selects: numbers as they are (floored), a bool array as the
    positions of its true elements (logical indexing is linear), in one row."""
    if index.values.dtype != np.bool_:
        return Arrays(np.floor(index.values), index.offsets, index.columns)
    owner = index.owner()
    sizes = np.bincount(owner[index.values], minlength=len(index)).astype(np.int64)
    return Arrays(index.position()[index.values].astype(np.float64), _offsets(sizes), sizes)


def gather(array: Arrays, index: Arrays, default) -> Arrays:
    """``a[indices]``: the elements at the linear indices, shaped as the index array (bool arrays: one
    row of the elements where it is true); ``default`` for indices out of range."""
    picks = _picks(index)
    owner = picks.owner()
    valid = (picks.values >= 0) & (picks.values < array.sizes[owner])
    at = array.offsets[:-1][owner] + np.where(valid, picks.values, 0).astype(np.int64)
    values = np.where(valid, array.values[np.where(valid, at, 0)] if len(array.values) else default, default)
    return Arrays(values.astype(array.values.dtype), picks.offsets, picks.columns)


def gather_cells(array: Arrays, rows: Arrays, columns: Arrays, default) -> Arrays:
    """``a[rows, columns]`` with index arrays (a number is a 1x1 array): the rows x columns cells, each
    list taken linearly; ``default`` for cells out of range."""
    rows, columns = _picks(rows), _picks(columns)
    nr, nc = rows.sizes, columns.sizes
    offsets = _offsets(nr * nc)
    owner = np.repeat(np.arange(len(array)), nr * nc)
    position = np.arange(offsets[-1]) - offsets[:-1][owner]
    width = np.maximum(nc, 1)[owner]
    r = rows.values[rows.offsets[:-1][owner] + position // width]
    c = columns.values[columns.offsets[:-1][owner] + position % width]
    valid = (r >= 0) & (r < array.rows[owner]) & (c >= 0) & (c < array.columns[owner])
    at = array.offsets[:-1][owner] + np.where(valid, r * array.columns[owner] + c, 0).astype(np.int64)
    values = np.where(valid, array.values[np.where(valid, at, 0)] if len(array.values) else default, default)
    return Arrays(values.astype(array.values.dtype), offsets, np.where(nr * nc > 0, nc, 0))


# ----------------------------------------------------------------------------------------------- functions


def transpose(array: Arrays) -> Arrays:
    """Rows become columns."""
    owner, position = array.owner(), array.position()
    rows = array.rows[owner]
    source = array.offsets[:-1][owner] + position % np.maximum(rows, 1) * array.columns[owner] \
        + position // np.maximum(rows, 1)
    return Arrays(array.values[source], array.offsets, array.rows)


def sort_keys(array: Arrays, ranks: np.ndarray | None) -> np.ndarray:
    """The elements as sort keys: numbers as they are, string ids as the rank of their text (``ranks``)."""
    return array.values if ranks is None else ranks[array.values]


def sort_indices(array: Arrays, ranks: np.ndarray | None) -> Arrays:
    """``sortIndices``: each row's linear indices in the order of its sorted values, equal values in
    their order; shaped as ``array``."""
    owner, position = array.owner(), array.position()
    columns = np.maximum(array.columns, 1)[owner]
    row_start = position - position % columns  # linear index of the element's row's first element
    order = np.lexsort((position, sort_keys(array, ranks), row_start, owner))
    return Arrays(position[order].astype(np.float64), array.offsets, array.columns)


def sort_row_indices(array: Arrays, ranks: np.ndarray | None) -> Arrays:
    """``sortRowIndices``: the row indices in the order of the sorted rows (compared element by element),
    equal rows in their order; one row of ``nRows`` values."""
    rows = array.rows
    offsets = _offsets(rows)
    out = _sort_rows(np.asarray(sort_keys(array, ranks), dtype=np.float64), array.offsets, array.columns,
                     offsets)
    return Arrays(out, offsets, rows.copy())


@njit(cache=True, nogil=True)
def _sort_rows(keys, offsets, columns, out_offsets):
    """Per array, a stable insertion sort of its row indices by their rows' keys."""
    out = np.empty(out_offsets[-1], dtype=np.float64)
    for s in range(len(columns)):
        start, width, first = offsets[s], columns[s], out_offsets[s]
        count = out_offsets[s + 1] - first
        for i in range(count):
            j = i
            while j > 0:
                a = int(out[first + j - 1])
                less = False  # whether row i sorts before row a
                for k in range(width):
                    x, y = keys[start + i * width + k], keys[start + a * width + k]
                    if x != y:
                        less = x < y
                        break
                if not less:
                    break
                out[first + j] = out[first + j - 1]
                j -= 1
            out[first + j] = i
    return out


def find_first(array: Arrays, value, epsilon=None) -> np.ndarray:
    """``findFirst``: (n,) float64 the linear index of the first element equal to the shape's ``value``
    (within ``epsilon`` for numbers when given), -1 where there is none."""
    owner = array.owner()
    wanted = _column(value, len(array))[owner]
    if epsilon is None:
        found = array.values == wanted
    else:
        found = np.abs(array.values - wanted) <= _column(epsilon, len(array))[owner]
    first = np.full(len(array), -1.0)
    shapes, at = np.unique(owner[found], return_index=True)
    first[shapes] = array.position()[found][at]
    return first


def equal(left: Arrays, right: Arrays) -> np.ndarray:
    """``a == b`` per shape: (n,) bool, equal dimensions and equal elements."""
    same = (left.sizes == right.sizes) & (left.columns == right.columns)
    owner = left.owner()
    ok = same[owner]
    source = right.offsets[:-1][owner] + left.position()
    differ = np.zeros(len(left.values), dtype=bool)
    differ[ok] = left.values[ok] != right.values[source[ok]]
    return same & (np.bincount(owner[differ], minlength=len(left)) == 0)


def choose(condition, then: Arrays, other: Arrays) -> Arrays:
    """``case c : a else : b`` per shape: ``then``'s array where ``condition`` (n,) bool holds."""
    pick = np.asarray(_column(condition, len(then)), dtype=bool)
    sizes = np.where(pick, then.sizes, other.sizes)
    offsets = _offsets(sizes)
    owner = np.repeat(np.arange(len(then)), sizes)
    position = np.arange(offsets[-1]) - offsets[:-1][owner]
    chosen = pick[owner]
    values = np.empty(offsets[-1], dtype=then.values.dtype)
    values[chosen] = then.values[then.offsets[:-1][owner[chosen]] + position[chosen]]
    values[~chosen] = other.values[other.offsets[:-1][owner[~chosen]] + position[~chosen]]
    return Arrays(values, offsets, np.where(pick, then.columns, other.columns))
