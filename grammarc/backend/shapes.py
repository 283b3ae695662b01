"""Shapes as columns: a batch of n shapes is a set of arrays, never a list of objects.

A ``Shapes`` batch holds, per shape:

- ``origin`` (n, 3) float64: the scope's position P in world coordinates;
- ``size`` (n, 3) float64: the scope's size S along its own axes;
- ``frame`` (n,) int32: the scope's axes, as an index into the chunk's frame table (``Frames``) - most
  operations keep the axes, so shapes share frames instead of copying 3x3 matrices;
- ``geom`` (n,) int32: -1 when the shape's geometry is its scope box or rectangle, else a polygon in the
  chunk's ``PolygonStore``, or from ``MESH_BASE`` up a mesh (a roof) in its ``MeshStore``;
- ``lot`` (n,) int32: the lot, as an index into the chunk's lots;
- ``key`` (n,) uint64: the random-stream key (``backend.random``);
- ``depth`` (n,) int32: rule applications on the path from the lot;
- ``params`` tuple of (n,) arrays: the values of the symbol's parameters (float64, or int32 string ids);
- ``dynamic`` tuple of (n,) arrays: the attributes that rules ``set`` (``Plan.dynamic`` numbers them),
  inherited by children.

``geom`` < -1 means the shape's geometry is an inserted asset fitted to its scope (CityEngine's ``i()``),
possibly mirrored along scope axes (``mirror``) and turned z-up (``i(asset, zUp)``): ``asset_geom`` and
``asset_of`` encode and decode it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

#: The bit of an asset's ``geom`` code for an asset inserted ``zUp``: its z is the scope's y (it is turned
#: -90 degrees about x before it is fitted, and before any mirror).
Z_UP = 8


def asset_geom(asset: np.ndarray, mirrored: np.ndarray | int = 0) -> np.ndarray:
    """The ``geom`` code (int32) of asset ids, with mirror bits (1: x, 2: y, 4: z) and ``Z_UP``."""
    return (-2 - (np.asarray(asset, dtype=np.int64) * 16 + mirrored)).astype(np.int32)


def face_axes(axes: np.ndarray, size: np.ndarray, flat_axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Flat scopes' axes (n, 3, 3) (rows) and sizes (n, 3) reordered so that their two extents come
    first and their flat axis ``flat_axis`` (n,) last, keeping the turn: a face's x, y and normal."""
    cols = np.stack([(flat_axis + 1) % 3, (flat_axis + 2) % 3, flat_axis], axis=1)
    rows = np.arange(len(flat_axis))[:, None]
    return axes[rows, cols], size[rows, cols]


def asset_of(geom: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Asset ids and mirror bits (with ``Z_UP``) of asset ``geom`` codes (< -1)."""
    code = -2 - geom.astype(np.int64)
    return code // 16, code % 16


@dataclass(frozen=True, eq=False)
class Shapes:
    origin: np.ndarray
    size: np.ndarray
    frame: np.ndarray
    geom: np.ndarray
    lot: np.ndarray
    key: np.ndarray
    depth: np.ndarray
    params: tuple[np.ndarray, ...] = ()
    dynamic: tuple[np.ndarray, ...] = ()

    def __len__(self) -> int:
        return len(self.lot)

    def take(self, index: np.ndarray) -> Shapes:
        """The shapes at ``index`` (integer or boolean array, or a slice), in that order.

        A mask is turned into row numbers first: one pass over it, where indexing each column by the mask
        would pass over it once per column, ten times for a batch's ten columns. A mask that
        keeps every shape gives the batch itself: columns are never changed in place (``with_scope`` and
        the operations make new ones), so nothing need be copied, and guards and leaf kinds often keep all.
        Row numbers gather with ``np.take``, which copies each row of ``origin`` and ``size`` as one block,
        where indexing (``origin[index]``) copies it element by element through numpy's general indexing,
        several times slower on rows this short.
        """
        if not isinstance(index, slice):
            index = np.asarray(index)
            if index.dtype == bool:
                if index.all():
                    return self
                index = np.flatnonzero(index)
            elif not len(index):  # ``take([])``: no rows (the empty list is float64 as an array)
                index = index.astype(np.int64)
        return Shapes(*(_rows(getattr(self, f), index) for f in _ARRAYS),
                      tuple(_rows(p, index) for p in self.params), tuple(_rows(d, index) for d in self.dynamic))

    def with_scope(self, origin, size, frame, geom) -> Shapes:
        return replace(self, origin=origin, size=size, frame=frame, geom=geom)

    @staticmethod
    def merge(batches: list[Shapes], rows: list[np.ndarray]) -> Shapes:
        """Batches whose shapes stand for ``rows`` (one index array per batch) together in row order:
        the batch an operation treated in parts, whole again."""
        return Shapes.concat(batches).take(np.argsort(np.concatenate(rows), kind="stable"))

    @staticmethod
    def concat(batches: list[Shapes]) -> Shapes:
        if len(batches) == 1:
            return batches[0]
        first = batches[0]
        return Shapes(
            *(np.concatenate([getattr(b, f) for b in batches]) for f in
              ("origin", "size", "frame", "geom", "lot", "key", "depth")),
            params=tuple(np.concatenate([b.params[i] for b in batches]) for i in range(len(first.params))),
            dynamic=tuple(np.concatenate([b.dynamic[i] for b in batches]) for i in range(len(first.dynamic))),
        )


#: The names of a batch's columns, in order: the arrays, then the tuples of them (``params``, ``dynamic``).
COLUMNS = tuple(f.name for f in fields(Shapes))
_ARRAYS = COLUMNS[:COLUMNS.index("params")]


def _rows(column: np.ndarray, index: np.ndarray | slice) -> np.ndarray:
    """A column's rows ``index``: a view of a slice, else a copy by ``take`` (the method: ``np.take`` wraps it
    in another Python call, paid for each of a batch's some thirty columns in a chunk's hundreds of gathers)."""
    return column[index] if isinstance(index, slice) else column.take(index, axis=0)
