"""CityEngine's ``resetGeometry()``: a shape's geometry, scope and pivot its lot's initial shape's again.

The reference's example sets a lot back again and again by growing distances, each time from the lot
itself; what a rule ``set`` (colour, material, attributes), its texture space and its place in the
derivation (``comp.index``...) stay, the trim planes a ``comp(f)`` gave it go. The initial shapes are the
chunk's (``Chunk.lot_shapes``), gathered by each shape's lot. Reads: ``lot``. Writes: the scope,
``geom``, the trim planes' id and the mark of inserted geometry (``dynamic``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes
from grammarc.backend.terminals import marked_inserted
from grammarc.ir import nodes as ir


@operation(ir.ResetGeometry, writes=("origin", "size", "frame", "geom", "dynamic"), meshes=True)
def reset_geometry(ctx: Context, cursor: Shapes, op: ir.ResetGeometry) -> Shapes:
    """Each shape with its lot's initial scope and geometry (its own, not inserted), and no trim planes."""
    size, frame, geom = ctx.chunk.lot_shapes
    lot = cursor.lot
    dynamic = list(cursor.dynamic)
    if ctx.plan.trim_slot is not None:  # the chunk's ``TrimPlanes`` row 0: none
        dynamic[ctx.plan.trim_slot] = np.zeros(len(cursor), dtype=np.int32)
    reset = replace(cursor, origin=ctx.chunk.lot_origin[lot], size=size[lot], frame=frame[lot], geom=geom[lot],
                    dynamic=tuple(dynamic))
    return marked_inserted(ctx.plan, reset, False)
