"""Tolerances and limits, each with the reason for its value.

``Tol`` holds geometric epsilons; ``Limits`` holds the defaults that stop runaway grammars. A user raises
the limits with ``--max-depth`` and ``--max-shapes``; the tolerances are not user settings.
"""

from __future__ import annotations

import os
from dataclasses import dataclass


@dataclass(frozen=True)
class Tol:
    #: Lengths below this are zero: a scope axis of this size is a flat axis (a face or an edge).
    #: Footprints come in metres; 1e-9 m is far below any modelled feature and above float64 noise
    #: of coordinates up to ~1e6 m.
    zero: float = 1e-9
    #: PRT's length limit: lot ring edges shorter than this collapse (near-duplicate points in GIS data),
    #: and CityEngine's ``split`` makes no part this long or shorter (PRT drops a 0.799 mm part and keeps
    #: a 0.805 mm one, on a 0.79 m window and on a 30 m facade alike).
    merge: float = 8e-4
    #: Lots with a smaller area (m^2) are reported as bad lots: they cannot carry a building.
    area_floor: float = 1e-6
    #: A footprint is its own scope rectangle when its area differs from sx*sz by less than this
    #: relative amount; such lots take the box fast path. Map coordinates far from the origin carry
    #: ~1e-11 relative rounding, which a long thin lot's lever arm multiplies by its aspect ratio.
    rect: float = 1e-7
    #: Probabilities of a stochastic rule must sum to 1 within this.
    probability: float = 1e-6
    #: Lot coordinates (metres, or degrees before reprojection) beyond this in magnitude are no place on
    #: Earth (its circumference is 4e7 m): such a lot is bad, before squares of its lengths overflow.
    coordinate: float = 1e8
    #: A scope size or position beyond this (float32's largest number) makes no record, and GEOS's
    #: arithmetic overflows on it (``extrude(1e308)`` then ``offset``): the operation that makes such a
    #: scope fails its lot, as ``offset`` and ``setback`` fail a lot they would move an outline that far.
    far: float = 3.4028234663852886e38
    #: Two edges turned by less than this (degrees) from each other are parallel: the neighbours of an edge
    #: a setback folds (``geometry.setback``), and an edge facing the moved line that swept it
    #: (``geometry.clip``). Real lots' were 0.01-0.7 degrees apart; an edge between neighbours 11 degrees
    #: apart moves in PRT (a concave lot of the replay's, whose tier it sweeps).
    parallel: float = 2.0


@dataclass(frozen=True)
class Limits:
    #: Rule applications along one derivation path. Real grammars nest a few dozen levels (the Puuc
    #: moldings are ~12); a non-branching runaway recursion reaches this in well under a second.
    max_depth: int = 256
    #: Shapes created from one lot. The largest buildings of the example grammars make ~10^5
    #: shapes; a doubling runaway (`grow ~> grow grow`) reaches this after 21 rounds, long
    #: before memory is at risk (a shape costs ~100 bytes).
    max_shapes: int = 2_000_000

    #: Triangles of a baked mesh (``--max-triangles``): 50 million are ~3 GB of float64 vertices and
    #: int64 faces, what a development machine holds next to the record; an instance record of the same
    #: city is ~60 bytes a row whatever the assets. ``GRAMMARC_MAX_TRIANGLES`` overrides it for the writers.
    max_triangles: int = 50_000_000
    #: Edge (metres) of the tiles of the instanced outputs (``--tile-size``): float32 positions relative
    #: to a 500 m tile's corner are exact to about 30 micrometres (``io.instancing``).
    tile_size: float = 500.0
    #: Edge (metres) of the leaves of a 3D Tiles output (``io.tiles3d``): a browser loads a leaf at a time,
    #: and a 250 m square of a dense town is about 10^4 instances, under a megabyte.
    leaf_size: float = 250.0


TOL = Tol()
LIMITS = Limits()

#: Invariant checks too slow to ship (axes orthonormal, offsets monotone, child counts). The test suite
#: sets GRAMMARC_STRICT=1.
STRICT = os.environ.get("GRAMMARC_STRICT", "") not in ("", "0")

#: Features of the lots file per task of a cluster build (``--partition-size``, ``grammarc.cluster``): a
#: task of seconds, far above Dask's per-task overhead of about a millisecond.
PARTITION_SIZE = 20_000
