"""Branches inside a body: CityEngine's ``case`` blocks and ``p%`` stochastic blocks.

Each shape runs one branch, the default when none is taken: the branches' bodies come back as ``Parts``,
each running on its shapes. Reads: ``key`` (the draw) and what the conditions read. Writes: no column.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.random import uniform
from grammarc.backend.shapes import Shapes
from grammarc.ir import nodes as ir


@operation(ir.Case, ir.Stochastic, meshes=True, consumes=True)
def branch(ctx: Context, cursor: Shapes, op: ir.Case | ir.Stochastic) -> Parts:
    """``case`` and ``p%`` blocks: each shape runs one branch, the default when none is taken."""
    env = ctx.env(cursor)
    n = len(cursor)
    taken = np.full(n, len(op.branches), dtype=np.int64)
    if isinstance(op, ir.Case):
        for i in range(len(op.branches) - 1, -1, -1):
            holds = evaluate_array(op.branches[i][0], env, dtype=bool)
            taken[holds] = i
    else:
        percent = np.stack([evaluate_array(c, env) for c, _ in op.branches], axis=1)
        cumulative = np.cumsum(percent, axis=1) / 100.0
        draw = uniform(cursor.key, op.site)
        taken = (draw[:, None] >= cumulative).sum(axis=1)
    bodies = [body for _, body in op.branches] + [op.default]
    order, offsets = group_by(taken, len(bodies))
    return Parts(tuple(bodies), cursor.take(order), offsets)
