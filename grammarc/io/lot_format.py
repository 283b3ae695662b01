"""What a lots format module gives the table of formats (``io.lots``), and what a partition of a file is.

Each lots format is one module that describes itself with a ``LotsFormat``: the suffixes it reads and how
to read a whole file. A format whose files may be larger than a process's memory (GeoParquet rows, GIS
features, GeoJSON-sequence lines) also says how to cut a file into ``Partition``s, how many lot numbers
a partition's features take, and how to read one partition; a cluster's workers each read their own
partitions (``grammarc.cluster``). Files of the other formats are read whole.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from grammarc.errors import LotsError

if TYPE_CHECKING:  # for annotations only: this module is imported before the lots are read (``io.lots_reading``)
    from grammarc.model.lots import Lots

__all__ = ["NO_OPTIONS", "LotsFormat", "LotsOptions", "Partition", "partitions_at", "read_text"]


@dataclass(frozen=True)
class LotsOptions:
    """What the user asks of a lots file beyond what it holds.

    Attributes
    ----------
    lots_crs : str, optional
        The file's coordinate system where it names none or the wrong one (``--lots-crs``, any text pyproj
        reads: ``EPSG:4326``, WKT, PROJJSON; ``io.crs``).
    crs : str, optional
        The metric coordinate system to reproject lots in longitude/latitude to (``--crs``), instead of the
        UTM zone of their centre.
    id_field : str, optional
        The property that holds the lots' ids (``--id-field``, e.g. OpenStreetMap's ``osm_id``), instead
        of a feature's ``id``, else its ``id`` or ``name`` property, else its number. A lot without a value
        there is numbered.
    min_area : float, optional
        Lots of a smaller area (square metres, after any reprojection) are bad (``--min-area``): slivers.
    """

    lots_crs: str | None = None
    crs: str | None = None
    id_field: str | None = None
    min_area: float | None = None


#: What a lots file is read with when the user asks nothing of it.
NO_OPTIONS = LotsOptions()


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


@dataclass(frozen=True)
class LotsFormat:
    """A lots format, as its module describes it to ``io.lots``.

    Attributes
    ----------
    kind : str
      The format's name; a partition's ``kind`` for a format that partitions.
    suffixes : tuple of str
      The file suffixes it reads, lower-case with the dot.
    title : str or None
      How the error for an unknown suffix names the format, before its suffixes (``"a GIS file"``);
      None lists the suffixes alone.
    read : callable (Path, LotsOptions or None) -> Lots
      All lots of a file, which exists, in metres (``io.crs``), as the user's ``LotsOptions`` ask; a
      ``LotsError`` if the file cannot be read or holds no polygon.
    partitions : callable (Path, int) -> list of Partition, or None
      The partitions of a file, about ``size`` features each, their features in file order; None: the
      file is read whole.
    count : callable (Partition) -> int, or None
      The lot numbers a partition's features take (a MultiPolygon takes one per part).
    read_partition : callable (Partition, int, LotsOptions or None) -> Lots, or None
      A partition's lots, the first numbered as given (the ``count`` of the partitions before it).
    """

    kind: str
    suffixes: tuple[str, ...]
    title: str | None
    read: Callable[[Path], Lots]
    partitions: Callable[[Path, int], list[Partition]] | None = None
    count: Callable[[Partition], int] | None = None
    read_partition: Callable[[Partition, int], Lots] | None = None


def partitions_at(path: Path, kind: str, cuts: list[int],
                  byte_starts: np.ndarray | None = None) -> list[Partition]:
    """The partitions of a file between consecutive ``cuts`` (feature numbers from 0, the count last).

    Parameters
    ----------
    path : Path
      The file.
    kind : str
      Its format's ``kind``.
    cuts : list of int
      Where partitions start, increasing from 0, and the number of features last.
    byte_starts : (n + 1,) int64, optional
      Where each feature starts in the file, and its size last: the partitions' bytes ``[offset, end)``.
    """
    return [Partition(k, str(path), kind, int(a), int(b),
                      *((int(byte_starts[a]), int(byte_starts[b])) if byte_starts is not None else ()))
            for k, (a, b) in enumerate(itertools.pairwise(cuts))]


def read_text(path: Path) -> str:
    """A text lots file's contents (UTF-8); a ``LotsError`` if it cannot be read."""
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise LotsError(f"cannot read lots file {path}: {error}") from error
