"""CityEngine's primitives: ``primitiveCube/Quad/Disk/Cylinder/Sphere/Cone`` make the shape's geometry a
box, a rectangle, a regular polygon or a built-in mesh, fitted to the scope or given its own size.

What each becomes decides what may follow it: a cube is the scope box and a quad the scope rectangle, a
disk a polygon of the polygon store (shared by every shape of the batch: it is normalized to the scope),
so ``comp``, ``split``, ``extrude``, ``offset``, ``setback`` and roofs take them as they take a lot or a mass;
a cylinder, sphere or cone is the built-in asset ``builtin:cylinderN``, ``sphereNxM``, ``coneN``, inserted as
``i()`` inserts (an instance in the record; what refuses an inserted asset refuses it).

With sizes, the scope takes the primitive's size (a radius gives a diameter) and is centred on the old
scope in x and z, standing on its y = 0, as CityEngine's reference says. A quad or disk lies in the plane
of its scope's flat axis (``rect_plane``: y for a volume, whose y size becomes 0), its sizes along the
plane's two axes in order, centred in that plane. CityEngine also gives a zero scope size of a 3D
primitive a size from its other two; grammarc keeps it flat, as ``i()`` does.

A primitive is inserted geometry, as an asset is: a leaf cube is cut at its trim planes, where a box
``extrude`` made is not (``slots.TRIM_INSERTED``).

Reads: the scope (``origin``, ``size``, ``frame``) and what the sizes read. Writes: ``origin``, ``size``,
``geom`` and the mark as inserted (``dynamic``).
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate
from grammarc.backend.operations.inserts import scope_at
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes, asset_geom
from grammarc.backend.terminals import marked_inserted
from grammarc.constants import TOL
from grammarc.geometry.components import rect_plane
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.ir import nodes as ir
from grammarc.ir.asset_names import primitive_asset, segment_counts

#: The kinds that lie in a plane of their scope.
FLAT = ("quad", "disk")


@operation(ir.Primitive, writes=("origin", "size", "geom", "dynamic"), meshes=True)
def primitive(ctx: Context, cursor: Shapes, op: ir.Primitive) -> Shapes:
    n = len(cursor)
    plane = rect_plane(cursor.size, TOL.zero) if op.kind in FLAT else np.ones(n, dtype=np.int8)
    rows = np.arange(n)
    size = cursor.size.copy()
    if op.kind in FLAT:
        size[rows, plane] = 0.0
    # along which axes the new size is centred on the old scope: x and z, or the plane's two axes
    centred = np.ones((n, 3))
    centred[rows, plane] = 0.0
    if op.sizes is not None:
        env = ctx.env(cursor)
        given = np.stack([np.broadcast_to(np.asarray(evaluate(s, env), np.float64), (n,)) for s in op.sizes],
                         axis=1)
        ctx.fail_negative(cursor, given, f"`primitive{op.kind.title()}` has a negative or NaN size", op.span)
        size = _sizes(op.kind, given, plane)
    geom = np.full(n, -1, dtype=np.int32)
    if op.segments:
        geom = _segmented(ctx, cursor, op, plane)
    return marked_inserted(ctx.plan, scope_at(ctx, cursor, (cursor.size - size) * 0.5 * centred, size, geom), True)


def _segmented(ctx: Context, cursor: Shapes, op: ir.Primitive, plane: np.ndarray) -> np.ndarray:
    """The ``geom`` (n,) of disks and built-in meshes, per distinct segment counts of the batch (an
    attribute a lot overrides may change them): a mesh whose counts the grammar never names fails."""
    env = ctx.env(cursor)
    values = np.stack([np.broadcast_to(np.asarray(evaluate(s, env), np.float64), (len(cursor),))
                       for s in op.segments], axis=1)
    distinct, inverse = np.unique(values, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    geom = np.empty(len(cursor), dtype=np.int32)
    for k, row in enumerate(distinct):
        mine = inverse == k
        counts = segment_counts(row)
        if op.kind == "disk":
            geom[mine] = _disks(ctx, plane[mine], counts[0])
            continue
        asset = ctx.plan.grammar.asset_ids.get(primitive_asset(op.kind, counts), -1)
        if asset < 0:
            ctx.fail(cursor, mine, f"`primitive{op.kind.title()}` with {' x '.join(map(str, counts))} segments: "
                     "only the counts the grammar declares are built", op.span)
        geom[mine] = asset_geom(np.full(int(mine.sum()), asset, dtype=np.int32))
    return geom


def _sizes(kind: str, given: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """The scope sizes (n, 3) of primitives of ``kind`` from their size arguments ``given`` (n, k)."""
    if kind == "cube":
        return given
    diameter = 2.0 * given[:, 0]
    if kind in ("cylinder", "cone"):
        return np.stack([diameter, given[:, 1], diameter], axis=1)
    if kind == "sphere":
        return np.repeat(diameter[:, None], 3, axis=1)
    extents = given if kind == "quad" else np.stack([diameter, diameter], axis=1)
    size = np.zeros((len(given), 3))
    rows = np.arange(len(given))
    size[rows, PLANE_U[plane]] = extents[:, 0]
    size[rows, PLANE_V[plane]] = extents[:, 1]
    return size


def _disks(ctx: Context, plane: np.ndarray, sides: int) -> np.ndarray:
    """The ``geom`` (n,) of disks of ``sides`` vertices in the planes ``plane`` (n,): one stored polygon per
    plane, fitted to the unit square and wound counter-clockwise around the plane's normal."""
    angle = 2 * np.pi * np.arange(sides) / sides
    ring = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    ring = (ring - ring.min(axis=0)) / (ring.max(axis=0) - ring.min(axis=0))
    geom = np.empty(len(plane), dtype=np.int32)
    for p in np.unique(plane).tolist():
        # (u, v) of plane y run along (x, z): counter-clockwise around +y is clockwise in (u, v)
        coords = ring[::-1] if p == 1 else ring
        made = ctx.chunk.polygons.add(np.ascontiguousarray(coords), np.array([0, sides], dtype=np.int64),
                                      np.array([0, 1], dtype=np.int64), np.array([p], dtype=np.int8))
        geom[plane == p] = made[0]
    return geom
