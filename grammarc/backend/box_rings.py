"""Where a scope box's ring starts: a rectangle kept as its scope box keeps its polygon's vertex order.

A shape whose geometry is its scope box or rectangle (``geom`` -1) has an implicit ring, its plane's
rectangle (``geometry.components.RECT_RINGS``). PRT keeps a polygon's vertex order whatever its scope: a
rectangle whose scope ``rotateScope`` or ``alignScopeToAxes`` turned still starts at the vertex it started
at, so its edges keep their numbers (``comp(fe)``, per-edge ``setback``, ``shapeL/U/O``) and the pieces cut
from it start where PRT starts them. grammarc keeps such a rectangle as its box (its records stay
``builtin:quad``) and notes the corner its ring starts at: an index into the implicit ring's corners, in
one ``Shapes.dynamic`` column (``slots.RING_START``) that the plan adds only where a grammar both turns
scopes and numbers edges or cuts faces (``plan.renumbers_boxes``). Elsewhere every box starts at corner 0,
as it did before.

Every consumer of a box's ring takes it from ``geometry.components.rect_rings`` with the box's corner
(``outlines.polygons_of``, ``setback``'s faces, component splits, ``alignScopeToGeometry``'s edges), and
every operation that makes a box from a polygon or a piece notes where the polygon's ring started
(``geometry.components.rect_corners``): ``backend.reframing``, the pieces of splits, setbacks and offsets,
the caps of component splits. A split cuts a box whose ring starts elsewhere than corner 0 as its polygon
(``as_polygons``), so that its pieces start where PRT's do.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry.components import rect_corners, rect_plane, rect_rings

if TYPE_CHECKING:
    from grammarc.backend.chunk import Chunk
    from grammarc.backend.plan import Plan


def corners(plan: Plan, shapes: Shapes) -> np.ndarray | None:
    """The corner each shape's box ring starts at (n,) int64, None where the grammar keeps no corners."""
    if plan.ring_slot is None:
        return None
    return shapes.dynamic[plan.ring_slot].astype(np.int64)


def with_corners(plan: Plan, shapes: Shapes, corner: np.ndarray | int) -> Shapes:
    """``shapes`` whose box rings start at ``corner`` ((n,) or one for all); unchanged where the grammar
    keeps no corners."""
    if plan.ring_slot is None:
        return shapes
    dynamic = list(shapes.dynamic)
    dynamic[plan.ring_slot] = np.broadcast_to(np.asarray(corner, dtype=np.float64), (len(shapes),)).copy()
    return replace(shapes, dynamic=tuple(dynamic))


def piece_corners(pieces) -> np.ndarray:
    """The corners (k,) that pieces (``geometry.clip.Clipped``) kept as boxes start their rings at (0 for
    the others): where each rectangle's ring starts, as cutting or moving it in left it."""
    first = pieces.coords[pieces.ring_offsets[pieces.poly_offsets[:-1]]]
    return np.where(pieces.is_rect, rect_corners(first, pieces.plane), 0)


def as_polygons(plan: Plan, chunk: Chunk, shapes: Shapes, axis: int) -> Shapes:
    """``shapes`` with each box whose ring starts elsewhere than corner 0 and that a split along ``axis``
    cuts across its ring given that ring as a stored polygon, so that its pieces start where PRT's do."""
    corner = corners(plan, shapes)
    if corner is None:
        return shapes
    plane = rect_plane(shapes.size, TOL.zero)
    rows = np.flatnonzero((shapes.geom == -1) & (corner != 0) & (plane != axis))
    if not len(rows):
        return shapes
    plane = plane[rows]
    geom = shapes.geom.copy()
    geom[rows] = chunk.polygons.add(rect_rings(plane, corner[rows]),
                                    np.arange(0, 4 * len(rows) + 1, 4, dtype=np.int64),
                                    np.arange(len(rows) + 1, dtype=np.int64), plane)
    return replace(shapes, geom=geom)
