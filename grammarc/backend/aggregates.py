"""The values of a whole design that a search reads: aggregates over its shapes, goal, prune, heuristic.

A search state is a lot derived with fixed choices (``backend.choices``). Its design is its leaves: the
shapes that end under a symbol no rule of which applies to them. Its aggregates (``count("room")``,
``min(Scope.sx of "room")``, ``area("room")``) are over the leaves of one symbol, taken as they are emitted
(``collect``: one evaluation per batch, summed per lot with ``bincount``), so that a partial state's
aggregates are those of the leaves made so far. ``judge`` evaluates the search statements
once the derivation stops, on the lots' own shapes: ``Scope`` there is the lot's.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.choices import Choices
from grammarc.backend.env import Env
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import fold_groups
from grammarc.ir import nodes as ir


def collect(choices: Choices, env: Env, symbol: str) -> None:
    """Add the leaves ``env.shapes`` of ``symbol`` to the aggregates over it, per lot."""
    shapes = env.shapes
    live = ~choices.stopped[shapes.lot]
    lot = shapes.lot[live]
    for i, aggregate in enumerate(choices.aggregates):
        if aggregate.symbol != symbol or not len(lot):
            continue
        if aggregate.func == "area":
            values = shapes.size[live, 0] * shapes.size[live, 2]
        elif aggregate.func == "volume":
            values = np.prod(shapes.size[live], axis=1)
        elif aggregate.value is None:  # count
            values = np.ones(len(lot))
        else:
            values = evaluate_array(aggregate.value, env, dtype=bool if aggregate.func == "count" else np.float64)
            values = values[live].astype(np.float64)
        fold_groups(lot, values, choices.total[i], choices.counted[i], choices.low[i], choices.high[i])


def judge(module: ir.Module, choices: Choices, env: Env) -> None:
    """Evaluate the goal, prune and heuristic of the lots (``env.shapes``: one per lot, the lots' own)."""
    for kind, dtype in (("goal", bool), ("prune", bool), ("heuristic", np.float64)):
        expr = module.objective(kind)
        if expr is not None:
            setattr(choices, kind, evaluate_array(expr, env, dtype=dtype))
