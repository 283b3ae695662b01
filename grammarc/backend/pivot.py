"""The pivot: each shape's own coordinate system, as CityEngine keeps it (``pivot.p``, ``pivot.o``).

CityEngine places a shape's scope relative to its pivot: ``scope.t`` and ``scope.r`` are the scope's origin
and angles in the pivot's frame, ``r`` adds to those angles (it is ``rotate(rel, pivot, ...)``), ``rotateScope``
turns about the pivot's axes, and ``convert``, ``translate`` and ``rotate`` take positions and angles in it. A
lot's pivot is its object system (its scope). ``setPivot`` moves it to a corner of the scope and gives the
scope its axes; a component split (``comp``, whose default ``zUp`` aligns pivot and scope),
``alignScopeToAxes``, ``alignScopeToGeometry`` and ``alignScopeToGeometryBBox`` make the new scope the
pivot (``sets_pivot``), as the reference says (after them ``scope.t`` and ``scope.r`` are zero). Every other operation leaves the pivot
where it is, and successors inherit it.

The pivot rides in four ``Shapes.dynamic`` columns (``slots.PIVOT_SLOTS``: its origin in world and its axes as
an id into the chunk's ``Frames``, which a scope aligned with its pivot shares), only where a grammar uses it
(``plan.uses_pivot``): a CityEngine grammar that calls ``setPivot``, reads ``scope.t*``, ``scope.r*`` or ``pivot.*``,
converts from or to the pivot, translates or rotates in it (``set(scope.t*|r*)`` too), or turns with an ``r``
or ``rotateScope`` of more than one angle. Elsewhere grammarc takes the pivot as the object system (the lot's
scope), and an ``r`` turns about the scope's own axes as they were, which is adding to ``scope.r`` where the
scope is aligned with its pivot (on a lot, after a ``comp``); grammars that need neither pay nothing for it.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend import euler
from grammarc.backend.shapes import Shapes
from grammarc.backend.slots import PIVOT_SLOTS
from grammarc.ir import nodes as ir

if TYPE_CHECKING:
    from grammarc.backend.chunk import Chunk

#: ``setPivot``'s corners 0 to 7 as (x, y, z) ends of the scope (0: its origin side, 1: its far side): the
#: bottom ring from the origin along x, then across to z and back, then the same ring at the top. The
#: order follows the Roman rule sets, which pick the corner of one compass direction as their scope turns in
#: quarter turns (index plus one per quarter turn about y).
CORNERS = np.array([(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1), (0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)])
#: ``setPivot``'s axis maps: the old scope axes that become the pivot's x, y and z at corner 0, as the names
#: read (``yzx``: the old y is the new x, the old z the new y). The reference's text gives ``yzx`` what this
#: gives ``zxy`` and the other way round (with a typo in one of them); the names' reading is the one public
#: rule files rely on: the Paphos colonnade extrudes a piece of facade (its scope's y out of the wall, z down
#: from the top) and stands a column's y upright from the ground with ``setPivot(yzx, 3)``.
AXIS_MAPS = {"xyz": (0, 1, 2), "yzx": (1, 2, 0), "zxy": (2, 0, 1)}


def sets_pivot(op) -> bool:
    """Whether operation ``op`` makes each shape's new scope its pivot (``resetGeometry`` gives back the lot's
    scope, which is the lot's pivot)."""
    return isinstance(op, (ir.CompFaces, ir.AlignToGeometry, ir.AlignScopeToBBox, ir.ResetGeometry)) or (
        isinstance(op, ir.AlignScope) and op.mode != "rotate")


def pivot_system(slot: int | None, chunk: Chunk, shapes: Shapes) -> tuple[np.ndarray, np.ndarray]:
    """The pivots' origins (n, 3) and axes (n, 3, 3) (rows, in world): the columns from ``slot`` (the plan's
    ``pivot_slot``), or the lots' scopes where the grammar keeps none (or while the lots' attributes are
    evaluated, before the columns exist)."""
    if slot is None or len(shapes.dynamic) <= slot:
        return chunk.lot_origin[shapes.lot], chunk.lot_axes[shapes.lot]
    columns = shapes.dynamic
    return np.stack(columns[slot:slot + 3], axis=1), chunk.frames[columns[slot + 3]]


def pivot_frames(slot: int | None, shapes: Shapes) -> np.ndarray | None:
    """The pivots' frame ids (n,) int32, None where the shapes carry no pivot."""
    if slot is None or len(shapes.dynamic) <= slot:
        return None
    return shapes.dynamic[slot + 3]


def with_pivot(slot: int, shapes: Shapes, origin: np.ndarray, frame: np.ndarray) -> Shapes:
    """``shapes`` with pivots at ``origin`` (n, 3) float64 with axes ``frame`` (n,) int32 (frame ids)."""
    dynamic = list(shapes.dynamic)
    dynamic[slot:slot + 4] = [*np.ascontiguousarray(origin.T), np.asarray(frame, dtype=np.int32)]
    return replace(shapes, dynamic=tuple(dynamic))


def aligned(slot: int, shapes: Shapes) -> Shapes:
    """``shapes`` with their scopes as their pivots."""
    return with_pivot(slot, shapes, shapes.origin, shapes.frame)


def initial_column(name: str, chunk: Chunk, shapes: Shapes) -> np.ndarray:
    """A lot's starting value of pivot column ``name``: its scope, the object system."""
    k = PIVOT_SLOTS.index(name)
    return shapes.frame.copy() if k == 3 else shapes.origin[:, k].copy()


def relative_angles(frames: np.ndarray, pivot_axes: np.ndarray, aligned_rows: np.ndarray | bool) -> np.ndarray:
    """The angles (n, 3) of scopes with axes ``frames`` (n, 3, 3) in the frames ``pivot_axes`` (their pivots',
    ``scope.r``, or another system's); exactly zero at ``aligned_rows`` (n,) bool (or False: none), the scopes
    that share that frame."""
    angles = euler.angles(np.einsum("nij,nkj->nik", frames, pivot_axes))
    angles[aligned_rows] = 0.0
    return angles


def corner_axes(axis_map: str, corner: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``setPivot(axis_map, corner)``: the corners' ends (n, 3) int (``CORNERS``) and the pivots' axes as
    rows of signed unit vectors in the scopes' frames (n, 3, 3).

    At corner 0 the pivot's x, y and z are the old axes ``AXIS_MAPS[axis_map]``; at another corner each
    points into the scope (reversed where the corner is at that axis's far end), and where that would make
    a left-handed frame its x and z trade places: the frame is a right-handed one turned about its y, the
    reference's "y in the same direction as the original (or negative)".
    """
    ends = CORNERS[np.asarray(corner, dtype=np.int64) % 8]
    inward = 1 - 2 * ends  # +1 from the origin side, -1 from the far side
    bx, ay, cz = AXIS_MAPS[axis_map]
    n = len(ends)
    rows = np.arange(n)
    swap = inward[:, bx] * inward[:, ay] * inward[:, cz] < 0
    x_axis = np.where(swap, cz, bx)
    z_axis = np.where(swap, bx, cz)
    out = np.zeros((n, 3, 3))
    out[rows, 0, x_axis] = inward[rows, x_axis]
    out[rows, 1, ay] = inward[:, ay]
    out[rows, 2, z_axis] = inward[rows, z_axis]
    return ends, out
