"""What a body hands on: successor symbols, queued for their rules or emitted as leaves, and the operations
that leave nothing (``ε``, ``NIL``, and those accepted without effect on the record).

Reads: every column (a successor is the cursor's shape, one rule application deeper, with a new key and
its own parameters). Writes: no column of the cursor, but for the state of a sequential stream, which a
successor and ``NIL`` move on in place (``backend.streams``).
"""

from __future__ import annotations

import numpy as np

from grammarc.backend import terminals
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.occlusion import add_occluders, occluder_label
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import skip, successor_keys
from grammarc.ir import nodes as ir


@operation(ir.Symbol, meshes=True, consumes=True)
def successor(ctx: Context, cursor: Shapes, op: ir.Symbol) -> None:
    """The shapes become shapes of ``op``'s symbol: pending for its rules, or leaves (a terminal, ``X.``)."""
    plan = ctx.plan
    sym = plan.symbols[plan.symbol_ids[op.name]]
    env = ctx.env(cursor)
    params = tuple(
        evaluate_array(arg, env, dtype=np.int32 if t is ir.Type.STR else np.float64)
        for arg, t in zip(op.args, sym.param_types)
    )
    shapes = Shapes(cursor.origin, cursor.size, cursor.frame, cursor.geom, cursor.lot,
                    successor_keys(plan.sequential_random, cursor.key, op.site), cursor.depth + 1, params,
                    cursor.dynamic)
    ctx.count(shapes, op.span)
    if plan.makes_leaves(op):
        if plan.occluders:
            add_occluders(ctx.chunk, shapes, occluder_label(plan, sym.id))  # a leaf solid occludes
        terminals.emit_leaves(ctx, shapes, sym.id)
    else:
        ctx.pending[sym.id].append(shapes)


@operation(ir.Empty, meshes=True, consumes=True)
@operation(ir.NotApplied, meshes=True)
def nothing(ctx: Context, cursor: Shapes, op: ir.Empty | ir.NotApplied) -> None:
    """``ε``, ``NIL``, and operations without effect on the record; ``NIL`` moves PRT's stream on."""
    if isinstance(op, ir.Empty):
        skip(ctx.plan.sequential_random, cursor.key)
