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
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import draw, draws
from grammarc.ir import nodes as ir


@operation(ir.Case, ir.Stochastic, meshes=True, consumes=True)
def branch(ctx: Context, cursor: Shapes, op: ir.Case | ir.Stochastic) -> Parts:
    """``case`` and ``p%`` blocks: each shape runs one branch, the default when none is taken."""
    env = ctx.env(cursor)
    n = len(cursor)
    taken = np.full(n, len(op.branches), dtype=np.int64)
    sequential = ctx.plan.sequential_random
    if isinstance(op, ir.Case) and sequential and any(draws(cond) for cond, _ in op.branches):
        taken = _taken_in_order(ctx, cursor, op)
    elif isinstance(op, ir.Case):
        for i in range(len(op.branches) - 1, -1, -1):
            holds = evaluate_array(op.branches[i][0], env, dtype=bool)
            taken[holds] = i
    else:
        percent = np.stack([evaluate_array(c, env) for c, _ in op.branches], axis=1)
        cumulative = np.cumsum(percent, axis=1) / 100.0
        u = draw(sequential, cursor.key, op.site)
        taken = (u[:, None] >= cumulative).sum(axis=1)
    bodies = [body for _, body in op.branches] + [op.default]
    order, offsets = group_by(taken, len(bodies))
    if np.count_nonzero(np.diff(offsets)) == 1:  # one branch for every shape: they stay in their order
        return Parts(tuple(bodies), cursor, offsets)
    return Parts(tuple(bodies), cursor.take(order), offsets)


def _taken_in_order(ctx: Context, cursor: Shapes, op: ir.Case) -> np.ndarray:
    """The branch (n,) int64 each shape takes, its conditions evaluated in order and each only on the
    shapes no earlier one took, as PRT evaluates them: conditions that draw then draw only there, and the
    draws they made stay in ``cursor.key``."""
    taken = np.full(len(cursor), len(op.branches), dtype=np.int64)
    open_rows = np.arange(len(cursor))
    for i, (cond, _) in enumerate(op.branches):
        if not len(open_rows):
            break
        undecided = cursor.take(open_rows)
        holds = np.broadcast_to(evaluate_array(cond, ctx.env(undecided), dtype=bool), open_rows.shape)
        cursor.key[open_rows] = undecided.key
        taken[open_rows[holds]] = i
        open_rows = open_rows[~holds]
    return taken
