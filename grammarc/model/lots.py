"""Lots: the footprints a city is derived from, as flat ragged arrays, and the lots that were skipped.

Every lot becomes an initial shape, and the backend derives shapes in batches of arrays, so lots are held
as flat ragged arrays (Arrow-style offsets that start at 0, as in shapely's ``from_ragged_array``) rather
than as one object per lot. The readers (``grammarc.io.lots``) make them; the geometry and the backend take
them. A bad lot (self-intersecting, zero area, not a polygon, a wall) is data, not an exception: it is
listed in ``Lots.bad`` with its number, its id and a reason, and the other lots load.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from grammarc.errors import UsageError
from grammarc.ragged import ragged_take

__all__ = ["BadLot", "Lots"]


@dataclass(frozen=True)
class BadLot:
    """A lot that was skipped: its number in the input, its id and why."""

    index: int
    id: str
    reason: str


@dataclass(frozen=True, eq=False)
class Lots:
    """Footprints in world coordinates (y up), rings as Arrow-style ragged arrays (offsets start at 0).

    Attributes
    ----------
    ids : (L,) object
      Lot identifiers, ``str``.
    index : (L,) int64
      Each lot's number in the input; bad lots keep theirs, so the good lots' numbers are stable.
    vertices : (V, 3) float64
      Ring vertices in world coordinates.
    ring_offsets : (R + 1,) int64
      Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r + 1]]``, open (first vertex not repeated),
      at least 3 vertices. Exterior rings have a +Y Newell normal, holes a -Y one.
    lot_offsets : (L + 1,) int64
      Lot ``i`` is rings ``lot_offsets[i]:lot_offsets[i + 1]``, the exterior ring first, then its holes.
    street : (V,) bool
      Whether the edge from each vertex to the next of its ring faces a street: CityEngine's
      ``streetWidth`` object attribute (one number per edge of the exterior ring, > 0 for a street).
    attrs : dict of str to (L,) float64 or object
      Per-lot property columns: float64 with nan for missing values, or object with ``str`` values and
      None for missing ones.
    bad : tuple of BadLot
      Lots of the input that were skipped, ordered by ``index``.
    source : str
      The path read, or ``"<memory>"``.
    crs : str or None
      The coordinate system of the vertices (``EPSG:<code>``, WKT or PROJJSON, as read or reprojected to;
      ``io.crs``); None: metres with no coordinate system.
    crs_note : str or None
      How the lots came to ``crs`` where they were reprojected, for the build to say.
    """

    ids: np.ndarray
    index: np.ndarray
    vertices: np.ndarray
    ring_offsets: np.ndarray
    lot_offsets: np.ndarray
    street: np.ndarray
    attrs: dict[str, np.ndarray]
    bad: tuple[BadLot, ...]
    source: str
    crs: str | None = None
    crs_note: str | None = None

    def __len__(self) -> int:
        return len(self.ids)

    def take(self, sel: np.ndarray | slice) -> Lots:
        """A subset of the lots, in the order of ``sel``.

        Parameters
        ----------
        sel : (k,) int, (L,) bool or slice
          The lots to keep.

        Returns
        -------
        lots : Lots
          The selected lots with rebased offsets and sliced attrs; ``bad`` and ``source`` are kept as is.
        """
        if isinstance(sel, slice) and sel.indices(len(self))[2] == 1:
            return self._span(*sel.indices(len(self))[:2])
        lot = np.arange(*sel.indices(len(self))) if isinstance(sel, slice) else np.atleast_1d(np.arange(len(self))[sel])
        ring, lot_offsets = ragged_take(self.lot_offsets, lot)
        vertex, ring_offsets = ragged_take(self.ring_offsets, ring)
        return Lots(
            ids=self.ids[lot],
            index=self.index[lot],
            vertices=self.vertices[vertex],
            ring_offsets=ring_offsets,
            lot_offsets=lot_offsets,
            street=self.street[vertex],
            attrs={name: column[lot] for name, column in self.attrs.items()},
            bad=self.bad,
            source=self.source,
            crs=self.crs,
            crs_note=self.crs_note,
        )

    def _span(self, first: int, stop: int) -> Lots:
        """``take`` of the lots ``first:stop`` (a chunk of a build): views of these arrays, read-only, but
        for the offsets (rebased); a gather of every column cost a build's parent ~0.2 s of CPU over
        pompeii x100's 35 chunks, beside its workers."""
        stop = max(stop, first)
        rings, vertices = self.lot_offsets[[first, stop]], self.ring_offsets[self.lot_offsets[[first, stop]]]
        return Lots(
            ids=_read_only(self.ids[first:stop]),
            index=_read_only(self.index[first:stop]),
            vertices=_read_only(self.vertices[vertices[0]:vertices[1]]),
            ring_offsets=self.ring_offsets[rings[0]:rings[1] + 1] - vertices[0],
            lot_offsets=self.lot_offsets[first:stop + 1] - rings[0],
            street=_read_only(self.street[vertices[0]:vertices[1]]),
            attrs={name: _read_only(column[first:stop]) for name, column in self.attrs.items()},
            bad=self.bad,
            source=self.source,
            crs=self.crs,
            crs_note=self.crs_note,
        )

    def select(self, ids) -> Lots:
        """The lots of these ids (``--select``), in input order; bad lots not among them are dropped.

        Raises
        ------
        UsageError
            If an id names no lot of the input.
        """
        wanted = {str(i) for i in ids}
        ids = self.ids.astype(str)
        unknown = sorted(wanted - set(ids.tolist()) - {b.id for b in self.bad})
        if unknown:
            raise UsageError(f"--select: no lot has the id {', '.join(map(repr, unknown[:10]))}"
                             + (f" (and {len(unknown) - 10} more)" if len(unknown) > 10 else ""))
        keep = np.isin(ids, sorted(wanted))
        return replace(self.take(keep), bad=tuple(b for b in self.bad if b.id in wanted))


def _read_only(view: np.ndarray) -> np.ndarray:
    """``view`` marked read-only: a write into a chunk's lots would be a write into every lot's."""
    view.flags.writeable = False
    return view
