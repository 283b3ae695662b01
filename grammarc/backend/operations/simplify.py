"""CityEngine's ``reduceGeometry(tolerance)``: polygons with fewer vertices (``geometry.reduce``).

A polygon or a prism of the polygon store loses the share ``tolerance`` of its rings' vertices, the
scope unchanged. A scope box or rectangle is left as it is, as a ring of four vertices is (collapsing a
rectangle's edges would make it another shape, not a simpler one); a roof or another mesh, and an inserted asset, are refused: their
faces share edges that removing vertices face by face would tear open. Reads: the scope's ``size``,
``geom`` and what the tolerance reads. Writes: ``geom``.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes
from grammarc.geometry.meshes import is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.geometry.reduce import reduce_rings
from grammarc.ir import nodes as ir
from grammarc.ragged import offsets_from_counts, segment_of, segment_reduce


@operation(ir.ReduceGeometry, writes=("geom",))
def reduce_geometry(ctx: Context, cursor: Shapes, op: ir.ReduceGeometry) -> Shapes:
    geom = cursor.geom
    bad = geom < -1
    if bad.any():
        ctx.fail(cursor, bad, "`reduceGeometry` of an inserted asset is not supported yet", op.span)
    tolerance = np.broadcast_to(evaluate_array(op.tolerance, ctx.env(cursor)), (len(cursor),))
    rows = np.flatnonzero(is_polygon(geom) & (tolerance > 0))
    if not len(rows):
        return cursor
    store = ctx.chunk.polygons
    coords, ring_offsets, poly_offsets = store.gather(geom[rows])
    plane = store.plane[geom[rows]]
    ring_poly = segment_of(poly_offsets)
    vertex_poly = ring_poly[segment_of(ring_offsets)]
    size = cursor.size[rows]
    at = np.arange(len(rows))
    scale = np.stack([size[at, PLANE_U[plane]], size[at, PLANE_V[plane]]], axis=1)[vertex_poly]
    keep = reduce_rings(coords * scale, ring_offsets, np.minimum(tolerance[rows], 1.0)[ring_poly])
    if keep.all():
        return cursor
    kept = segment_reduce(np.add, keep.astype(np.int64), ring_offsets, 0)
    new = geom.copy()
    new[rows] = store.add(coords[keep], offsets_from_counts(kept), poly_offsets, plane)
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, new)
