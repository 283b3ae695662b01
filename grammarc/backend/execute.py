"""Rules and successor bodies executed on whole batches of shapes.

``apply_pending`` takes every pending shape of one symbol: guards partition the batch (the first rule
whose guard holds applies, in source order), one uniform draw per shape picks a stochastic alternative,
and each alternative's body runs on its shapes at once. A body is a sequence of operations on a *cursor*:
a ``Shapes`` batch whose columns the operations replace as they go (``T``, ``S``, ``R``, ``[ ]``), each
looked up in ``operations.OPERATIONS``. Successor symbols are queued for later rounds; splits give back
their parts' shapes, whose bodies run here at once, one call per part. Python cost is per operation and
batch, never per shape.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend import terminals
from grammarc.backend.choices import consequent
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.fusion.fused import FusedBatch
from grammarc.backend.fusion.fused import derive as derive_fused
from grammarc.backend.occlusion import add_occluders
from grammarc.backend.operations import OPERATIONS, Parts
from grammarc.backend.operations.scope import center
from grammarc.backend.operations.table import check_writes
from grammarc.backend.pivot import aligned, sets_pivot
from grammarc.backend.plan import SymbolPlan
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import bracket, draw
from grammarc.constants import STRICT, TOL
from grammarc.ir import nodes as ir
from grammarc.ragged import rank_within

#: Operations after which a body's shape is not the body's to emit: it was replaced by successors, split
#: into parts, deleted, or handed to case branches (which emit their own leaves).
_CONSUMING = frozenset(node for node, entry in OPERATIONS.items() if entry.consumes)


def apply_pending(ctx: Context, sym: SymbolPlan, batches: list) -> None:
    """``apply`` to a symbol's pending batches, in order: shapes, and records of a leaf-insert symbol
    made ahead of its turn (``leaf_parts``) or by a fused kernel (``fusion.FusedBatch``), emitted now,
    where its rule would have emitted them."""
    ctx.symbol = sym.id
    shapes: list[Shapes] = []
    for batch in [*batches, None]:
        if isinstance(batch, Shapes):
            shapes.append(batch)
            continue
        if shapes:
            apply(ctx, sym, Shapes.concat(shapes))
            shapes = []
        if isinstance(batch, FusedBatch):
            batch.emit(ctx)
        elif batch is not None:
            terminals.append_records(ctx, batch.xform, batch.lot, ctx.plan.leaf_inserts[sym.id].asset, sym.id,
                                     None)


def apply(ctx: Context, sym: SymbolPlan, shapes: Shapes) -> None:
    """Apply the rules of ``sym`` to all of ``shapes``; shapes no rule applies to become leaves.

    A symbol whose rules split on snap planes (``Repeat("YS", ...)``) takes a lot's shapes one after
    the other, as the paper derives: its first shape's snaps are there when its second one splits
    (the front volume's floors set the levels of the wings'). All lots still go together: the k-th
    shape of every lot in one batch. A symbol that roots a fused region is derived by its kernels
    (``backend.fusion``) unless they decline the batch. In a search, the shapes of the states stopped at
    a choice go no further, by either way.
    """
    shapes = _going_on(ctx, shapes)
    if not len(shapes):
        return
    region = ctx.plan.fused.get(sym.id)
    if region is not None and derive_fused(ctx, region, shapes):
        return
    if sym.id in ctx.plan.snapping and len(shapes) > 1:
        rank = rank_within(shapes.lot)
        if rank.max() > 0:
            for k in range(int(rank.max()) + 1):
                apply_all(ctx, sym, shapes.take(rank == k))
            return
    apply_all(ctx, sym, shapes)


def apply_all(ctx: Context, sym: SymbolPlan, shapes: Shapes) -> None:
    """``apply`` on all of ``shapes`` at once (a snapping symbol's k-th shapes: a choice met by the
    ones before may have stopped their state)."""
    shapes = _going_on(ctx, shapes)
    if not len(shapes):
        return
    ctx.check_depth(shapes, sym.rules[0].span)
    remaining = shapes
    for rule in sym.rules:
        if rule.guard is not None:
            holds = evaluate_array(rule.guard, ctx.env(remaining), dtype=bool)
            if not holds.all():
                if holds.any():
                    apply_rule(ctx, rule, remaining.take(holds))
                remaining = remaining.take(~holds)  # all of them, uncopied, where none holds
                continue
        apply_rule(ctx, rule, remaining)
        return
    terminals.emit_leaves(ctx, remaining, sym.id)


def _going_on(ctx: Context, shapes: Shapes) -> Shapes:
    """``shapes`` but, in a search, those of the states stopped at a choice."""
    choices = ctx.chunk.choices
    return shapes if choices is None else shapes.take(~choices.stopped[shapes.lot])


def apply_rule(ctx: Context, rule: ir.Rule, shapes: Shapes) -> None:
    """Run ``rule`` on ``shapes``: its body, or each shape's stochastic alternative."""
    alts = rule.alternatives
    if ctx.chunk.choices is not None:
        _charge(ctx, rule, shapes)
    if len(alts) == 1:
        run(ctx, alts[0].body, shapes, leaf_at_end=True)
        return
    if alts[0].choice:  # a set of consequents: the state's, or one drawn, all equally likely
        choice = consequent(ctx.chunk.choices, ctx.plan.sequential_random, shapes.lot, shapes.key, rule.site,
                            len(alts))
        for i, alt in enumerate(alts):
            picked = shapes.take(choice == i)
            if len(picked):
                run(ctx, alt.body, picked, leaf_at_end=True)
        return
    env = ctx.env(shapes)
    probs = np.stack([evaluate_array(a.prob, env) for a in alts], axis=1)
    bad = (np.abs(probs.sum(axis=1) - 1.0) > TOL.probability) | (probs < 0).any(axis=1)
    if bad.any():
        ctx.fail(shapes, bad, "probabilities do not sum to 1", rule.span)
    cumulative = np.cumsum(probs, axis=1)
    u = draw(ctx.plan.sequential_random, shapes.key, rule.site)
    choice = np.minimum((u[:, None] >= cumulative).sum(axis=1), len(alts) - 1)
    for i, alt in enumerate(alts):
        picked = shapes.take(choice == i)
        if len(picked):
            run(ctx, alt.body, picked, leaf_at_end=True)


def _charge(ctx: Context, rule: ir.Rule, shapes: Shapes) -> None:
    """A search state pays the grammar's ``cost:`` (1 where it states none) for each rule application."""
    expr = ctx.plan.grammar.module.objective("cost")
    cost = np.ones(len(shapes)) if expr is None else evaluate_array(expr, ctx.env(shapes))
    bad = ~(cost >= 0)
    if bad.any():
        ctx.fail_each(shapes, bad, lambda i: f"a negative cost ({cost[i]:g})", rule.span)
    ctx.chunk.choices.charge(shapes.lot, cost)


def run(ctx: Context, body: ir.Body, cursor: Shapes, leaf_at_end: bool = False) -> None:
    """Execute ``body`` on ``cursor``; operations replace its columns as they go.

    With CityEngine semantics and ``leaf_at_end`` (a rule's body, a split part, a case branch), a
    body that makes no successor leaves its shape as a leaf of the rule's symbol.
    """
    stack: list[tuple] = []
    base = (cursor.origin, cursor.size, cursor.frame)  # what `center` centres on
    for op in body:
        if isinstance(op, ir.Push):
            # the whole shape: its scope, its geometry and the attributes `set` gives it; with PRT's
            # stream, the copy is a new shape whose state is a child's (in place: the batch stays the
            # object it was) and the shape that waits for `]` has moved on
            stack.append((cursor, base, bracket(ctx.plan.sequential_random, cursor.key)))
            base = (cursor.origin, cursor.size, cursor.frame)
        elif isinstance(op, ir.Pop):
            if stack:
                cursor, base, waiting = stack.pop()
                if waiting is not None:
                    cursor.key[:] = waiting
        elif not len(cursor):
            if not stack:
                return
            # nothing left inside the brackets (an offset's inside of a small face): the shapes come
            # back at their `]`
        elif isinstance(op, ir.Center):
            cursor = center(ctx, cursor, op, base)
        else:
            entry = OPERATIONS[type(op)]
            if not entry.meshes and len(ctx.chunk.meshes):
                ctx.refuse_meshes(op, cursor)
            # an operation changes the cursor (returns it), makes shapes for its parts, or neither
            made = entry.function(ctx, cursor, op)
            if made is not None:
                ctx.refuse_far(op, made)
            if type(made) is Parts:
                run_parts(ctx, _pivoted(ctx, op, made))
            elif made is not None:
                if STRICT:
                    check_writes(op, entry.writes, cursor, made)
                cursor = _pivoted(ctx, op, made)
    if leaf_at_end and ctx.plan.leaf_bodies and len(cursor) and not any(type(op) in _CONSUMING for op in body):
        if ctx.plan.occluders:
            add_occluders(ctx.chunk, cursor)  # a leaf solid occludes
        terminals.emit_leaves(ctx, cursor, ctx.symbol)


def _pivoted(ctx: Context, op: ir.Op, made):
    """``made`` (shapes or ``Parts``) with their scopes as their pivots where ``op`` sets the pivot and the
    grammar keeps one (``backend.pivot``)."""
    slot = ctx.plan.pivot_slot
    if slot is None or not sets_pivot(op):
        return made
    if type(made) is Parts:
        return replace(made, shapes=aligned(slot, made.shapes))
    return aligned(slot, made)


def run_parts(ctx: Context, parts: Parts) -> None:
    """Run each part's body on its shapes, in order; a leaf-insert part's records go to its symbol's
    pending batches instead, counted as the successors they stand for (``backend.leaf_parts``)."""
    offsets = parts.offsets
    for i, body in enumerate(parts.bodies):
        leaf = parts.leaves[i] if parts.leaves else None
        if leaf is not None:
            records = leaf.records(ctx.chunk.frames.data, ctx.chunk.lot_origin)
            ctx.count_lots(records.lot, body[0].span)
            ctx.pending[records.symbol].append(records)
        elif offsets[i + 1] > offsets[i]:
            run(ctx, body, parts.shapes.take(slice(offsets[i], offsets[i + 1])), leaf_at_end=True)
