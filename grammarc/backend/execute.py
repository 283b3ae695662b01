"""Rules and successor bodies executed on whole batches of shapes.

``Executor.apply`` takes every pending shape of one symbol: guards partition the batch (the first rule
whose guard holds applies, in source order), one uniform draw per shape picks a stochastic alternative,
and each alternative's body runs on its shapes at once. A body is a sequence of operations on a *cursor*:
a ``Shapes`` batch whose scope columns the operations replace as they go (``T``, ``S``, ``R``, ``[ ]``).
Successor symbols are queued for later rounds; splits run their parts' bodies on the children at once,
one call per part. Python cost is per operation and batch, never per shape.
"""

from __future__ import annotations

import weakref
from collections import defaultdict
from dataclasses import replace

import numpy as np

from grammarc.backend import terminals
from grammarc.backend.chunk import Chunk
from grammarc.backend.component_operations import ComponentOperations
from grammarc.backend.evaluate import Env, evaluate, evaluate_array
from grammarc.backend.face_operations import FaceOperations
from grammarc.backend.kernels.order import group_by
from grammarc.backend.occlusion import ANCESTORS, add_occluders, with_ancestor
from grammarc.backend.plan import COLOR_SLOT, Plan, SymbolPlan, consumes
from grammarc.backend.random import child_keys, uniform
from grammarc.backend.scope_operations import ScopeOperations
from grammarc.backend.shapes import Shapes, asset_geom
from grammarc.backend.split_operations import SplitOperations
from grammarc.constants import TOL, Limits
from grammarc.errors import ChunkTooLarge, LimitError, LotFailure
from grammarc.geometry.meshes import is_mesh
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_op
from grammarc.ragged import rank_within


class Executor(ScopeOperations, SplitOperations, ComponentOperations, FaceOperations):
    """Derives one chunk: a worklist of pending batches per symbol, and the operations."""

    def __init__(self, plan: Plan, chunk: Chunk, limits: Limits, chunk_budget: int):
        self.plan = plan
        self.chunk = chunk
        self.limits = limits
        self.chunk_budget = chunk_budget
        self.pending: dict[int, list[Shapes]] = defaultdict(list)
        #: The occluder ids of shapes taken apart (``occluding``): a shape split by two component splits
        #: (``Comp("sideface", 0){ a } Comp("sideface", 2){ a }``) is one occluder, not two of which each
        #: split's faces would see the other as a neighbour.
        self.taken_apart: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    # ------------------------------------------------------------------------------------------ helpers
    def env(self, shapes: Shapes) -> Env:
        return Env(shapes, self.chunk, self.plan)

    def fail(self, shapes: Shapes, bad: np.ndarray, message: str, symbol: int, span) -> None:
        """Report the lots of shapes ``bad`` (bool mask) as failed: raises ``LotFailure``."""
        lots = np.unique(shapes.lot[bad])
        rule = self.plan.symbols[symbol].name
        raise LotFailure(f"{message} in rule `{rule}` at {span}", lots)

    def fail_negative(self, shapes: Shapes, values: np.ndarray, message: str, symbol: int, span) -> None:
        """Fail the shapes whose sizes (n, k), or (1, k) for all, are negative or NaN, quoting the first."""
        bad = ~(values >= 0).all(axis=1)
        if bad.any():
            row = values[np.flatnonzero(bad)[0]]
            self.fail(shapes, bad, f"{message} ({', '.join(f'{v:g}' for v in np.atleast_1d(row))})", symbol, span)

    def occluding(self, cursor: Shapes, children: Shapes, parent: np.ndarray, symbol: int) -> Shapes:
        """A component split's solids become occluders; their components carry them as ancestors."""
        if ANCESTORS[0] not in self.plan.dynamic:
            return children
        ident = self.taken_apart.get(cursor)
        if ident is None:
            ident = self.taken_apart[cursor] = add_occluders(self.chunk, cursor, self.occluder_label(symbol),
                                                             active=False)
        return with_ancestor(self.plan, children, ident[parent])

    def occluder_label(self, symbol: int) -> str | None:
        """The label of the occluders a rule of ``symbol`` makes: the paper names a shape by its symbol
        (``Shape.occ("balcony")``); CityEngine labels with ``label()`` only."""
        return None if self.plan.leaf_bodies else self.plan.symbols[symbol].name

    def label(self, op: ir.Label, cursor: Shapes, symbol: int) -> Shapes:
        """``label(name)``: the shape's solid is an occluder with that label, and its own ancestor."""
        return with_ancestor(self.plan, cursor, add_occluders(self.chunk, cursor, op.name))

    def count(self, shapes: Shapes, symbol: int, span) -> None:
        """Add new shapes to the per-lot counters and enforce the shape limits."""
        if len(shapes):
            self.add_counts(np.bincount(shapes.lot, minlength=len(self.chunk.shape_count)), symbol, span)

    def add_counts(self, per_lot: np.ndarray, symbol: int, span) -> None:
        """``count`` of new shapes given as their number per lot (L,) int64."""
        counts = self.chunk.shape_count
        counts += per_lot
        self.check_shape_limit(counts, symbol, span)
        if counts.sum() > self.chunk_budget and len(counts) > 1:
            raise ChunkTooLarge()

    # ---------------------------------------------------------------------------------- rule application
    def apply(self, sym: SymbolPlan, shapes: Shapes) -> None:
        """Apply the rules of ``sym`` to all of ``shapes``; shapes no rule applies to become leaves.

        A symbol whose rules split on snap planes (``Repeat("YS", ...)``) takes a lot's shapes one after
        the other, as the paper derives: its first shape's snaps are there when its second one splits
        (the front volume's floors set the levels of the wings'). All lots still go together: the k-th
        shape of every lot in one batch.
        """
        if sym.id in self.plan.snapping and len(shapes) > 1:
            rank = rank_within(shapes.lot)
            if rank.max() > 0:
                for k in range(int(rank.max()) + 1):
                    self.apply_all(sym, shapes.take(rank == k))
                return
        self.apply_all(sym, shapes)

    def apply_pending(self, sym: SymbolPlan, batches: list) -> None:
        """``apply`` to a symbol's pending batches, in order: shapes, and records of a leaf-insert symbol
        made ahead of its turn (``leaf_parts``), emitted now, where its rule would have emitted them."""
        shapes: list[Shapes] = []
        for batch in [*batches, None]:
            if isinstance(batch, Shapes):
                shapes.append(batch)
                continue
            if shapes:
                self.apply(sym, Shapes.concat(shapes))
                shapes = []
            if batch is not None:
                terminals.append_records(self.chunk, batch.xform, batch.lot, self.plan.leaf_inserts[sym.id].asset,
                                         sym.id, None)

    def apply_all(self, sym: SymbolPlan, shapes: Shapes) -> None:
        """``apply`` on all of ``shapes`` at once."""
        deepest = int(np.argmax(shapes.depth))
        if shapes.depth[deepest] >= self.limits.max_depth:
            rule = sym.rules[0]
            raise LimitError(
                f"derivation of lot {self.chunk.lot_ids[shapes.lot[deepest]]} reached --max-depth "
                f"{self.limits.max_depth} at rule `{sym.name}` ({rule.span}): runaway recursion? "
                "Raise the limit with --max-depth N."
            )
        remaining = shapes
        for rule in sym.rules:
            if rule.guard is not None:
                holds = evaluate_array(rule.guard, self.env(remaining), dtype=bool)
                if not holds.all():
                    if holds.any():
                        self.apply_rule(sym, rule, remaining.take(holds))
                    remaining = remaining.take(~holds)  # all of them, uncopied, where none holds
                    continue
            self.apply_rule(sym, rule, remaining)
            return
        terminals.emit_leaves(self.chunk, remaining, sym.id)

    def apply_rule(self, sym: SymbolPlan, rule: ir.Rule, shapes: Shapes) -> None:
        symbol = sym.id
        alts = rule.alternatives
        if len(alts) == 1:
            self.run(alts[0].body, shapes, symbol, leaf_at_end=True)
            return
        env = self.env(shapes)
        probs = np.stack([evaluate_array(a.prob, env) for a in alts], axis=1)
        bad = (np.abs(probs.sum(axis=1) - 1.0) > TOL.probability) | (probs < 0).any(axis=1)
        if bad.any():
            self.fail(shapes, bad, "probabilities do not sum to 1", symbol, rule.span)
        cumulative = np.cumsum(probs, axis=1)
        draw = uniform(shapes.key, rule.site)
        choice = np.minimum((draw[:, None] >= cumulative).sum(axis=1), len(alts) - 1)
        for i, alt in enumerate(alts):
            picked = shapes.take(choice == i)
            if len(picked):
                self.run(alt.body, picked, symbol, leaf_at_end=True)

    # ------------------------------------------------------------------------------------------- bodies
    def run(self, body: ir.Body, cursor: Shapes, symbol: int, leaf_at_end: bool = False) -> None:
        """Execute ``body`` on ``cursor``; operations replace its scope columns as they go.

        With CityEngine semantics and ``leaf_at_end`` (a rule's body, a split part, a case branch), a
        body that makes no successor leaves its shape as a leaf of ``symbol``.
        """
        stack: list[tuple] = []
        base = (cursor.origin, cursor.size, cursor.frame)  # what `center` centres on
        for op in body:
            if not len(cursor):
                return
            if isinstance(op, ir.Push):
                # the whole shape: its scope, its geometry and the attributes `set` gives it
                stack.append((cursor, base))
                base = (cursor.origin, cursor.size, cursor.frame)
            elif isinstance(op, ir.Pop):
                if stack:
                    cursor, base = stack.pop()
            elif isinstance(op, ir.Center):
                cursor = self.center(op, cursor, base)
            else:
                if type(op) not in _MESH_OPERATIONS and len(self.chunk.meshes):
                    self.refuse_meshes(op, cursor, symbol)
                # an operation either makes shapes (returns None) or changes the cursor (returns it)
                changed = _OPERATIONS[type(op)](self, op, cursor, symbol)
                if changed is not None:
                    cursor = changed
        if leaf_at_end and self.plan.leaf_bodies and len(cursor) and not consumes(body):
            if ANCESTORS[0] in self.plan.dynamic:
                add_occluders(self.chunk, cursor)  # a leaf solid occludes
            terminals.emit_leaves(self.chunk, cursor, symbol)

    def refuse_meshes(self, op: ir.Op, cursor: Shapes, symbol: int) -> None:
        """Roofs take component splits and scope operations; other operations on them are reported."""
        mesh = is_mesh(cursor.geom)
        if mesh.any():
            name = print_op(op).split("(")[0]
            self.fail(cursor, mesh, f"`{name}` of a roof is not supported yet (split the roof into faces "
                      "with comp(f) first)", symbol, op.span)

    def insert(self, op: ir.Insert, cursor: Shapes, symbol: int) -> None:
        """The paper's ``I(name)``: an instance of the asset on the scope (a solid one occludes)."""
        if ANCESTORS[0] in self.plan.dynamic:
            add_occluders(self.chunk, cursor, self.occluder_label(symbol))
        terminals.emit_instances(self.chunk, cursor, self.plan.grammar.asset_ids[op.asset], symbol)

    def nothing(self, op: ir.Empty | ir.NotApplied, cursor: Shapes, symbol: int) -> None:
        """``ε``, ``NIL``, and operations without effect on the record."""

    def successor(self, op: ir.Symbol, cursor: Shapes, symbol: int) -> None:
        sym = self.plan.symbols[self.plan.symbol_ids[op.name]]
        env = self.env(cursor)
        params = tuple(
            evaluate_array(arg, env, dtype=np.int32 if t is ir.Type.STR else np.float64)
            for arg, t in zip(op.args, sym.param_types)
        )
        shapes = Shapes(cursor.origin, cursor.size, cursor.frame, cursor.geom, cursor.lot,
                        child_keys(cursor.key, op.site), cursor.depth + 1, params, cursor.dynamic)
        self.count(shapes, symbol, op.span)
        if sym.terminal or op.leaf:
            if ANCESTORS[0] in self.plan.dynamic:
                add_occluders(self.chunk, shapes, self.occluder_label(sym.id))  # a leaf solid occludes
            terminals.emit_leaves(self.chunk, shapes, sym.id)
        else:
            self.pending[sym.id].append(shapes)

    # ------------------------------------------------------------------------------ CityEngine operations
    def use_asset(self, op: ir.UseAsset, cursor: Shapes, symbol: int) -> Shapes:
        """The geometry becomes the asset fitted to the scope (a cube is the scope box itself)."""
        if op.name is None:
            asset = np.full(len(cursor), self.plan.grammar.asset_ids[op.asset], dtype=np.int32)
        else:
            names = evaluate_array(op.name, self.env(cursor), dtype=np.int32)
            lookup = self.plan.asset_of_string
            asset = np.array([lookup.get(int(s), -1) for s in np.unique(names)], dtype=np.int32)[
                np.unique(names, return_inverse=True)[1].reshape(-1)]
            bad = asset < 0
            if bad.any():
                name = list(self.plan.strings.ids)[int(names[np.flatnonzero(bad)[0]])]
                self.fail(cursor, bad, f"`i` of `{name}`, which is not an asset of the grammar", symbol,
                          op.span)
        geom = np.where(asset == 0, -1, asset_geom(asset)).astype(np.int32)  # asset 0 is builtin:cube
        return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)

    def set_color(self, op: ir.SetColor, cursor: Shapes, symbol: int) -> Shapes:
        """The shape's colour as 0xRRGGBB: from components in [0, 1], or parsed from "#rrggbb"."""
        env = self.env(cursor)
        n = len(cursor)
        if len(op.values) == 3:
            parts = [np.clip(np.round(np.broadcast_to(evaluate_array(v, env), (n,)) * 255), 0, 255)
                     for v in op.values]
            packed = parts[0] * 65536 + parts[1] * 256 + parts[2]
        else:
            ids = np.broadcast_to(evaluate_array(op.values[0], env, dtype=np.int32), (n,))
            names = list(self.plan.strings.ids)
            distinct, inverse = np.unique(ids, return_inverse=True)
            packed = np.array([_hex_color(names[int(i)]) for i in distinct])[inverse.reshape(-1)]
            bad = np.isnan(packed)
            if bad.any():
                text = names[int(ids[np.flatnonzero(bad)[0]])]
                self.fail(cursor, bad, f'color("{text}") is not a colour "#rrggbb"', symbol, op.span)
        index = self.plan.dynamic[COLOR_SLOT]
        dynamic = cursor.dynamic[:index] + (packed.astype(np.float64),) + cursor.dynamic[index + 1:]
        return replace(cursor, dynamic=dynamic)

    def set_attr(self, op: ir.SetAttr, cursor: Shapes, symbol: int) -> Shapes:
        index = self.plan.dynamic[op.name]
        column = cursor.dynamic[index]
        value = evaluate_array(op.value, self.env(cursor), dtype=column.dtype)
        dynamic = cursor.dynamic[:index] + (value,) + cursor.dynamic[index + 1:]
        return Shapes(cursor.origin, cursor.size, cursor.frame, cursor.geom, cursor.lot, cursor.key,
                      cursor.depth, cursor.params, dynamic)

    def report(self, op: ir.Report, cursor: Shapes, symbol: int) -> None:
        env = self.env(cursor)
        key = evaluate_array(op.key, env, dtype=np.int32)
        value = evaluate(op.value, env)
        self.chunk.outputs.reports.append(report_rows(cursor.lot, key, value, len(cursor)))

    def branch(self, op: ir.Case | ir.Stochastic, cursor: Shapes, symbol: int) -> None:
        """``case`` and ``p%`` blocks: each shape runs one branch, the default when none is taken."""
        env = self.env(cursor)
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
        self.run_parts(tuple(bodies), cursor.take(order), offsets, symbol)


#: Operation type -> the Executor method that runs it (``[``, ``]`` and ``center`` are handled in ``run``).
_OPERATIONS = {
    ir.Symbol: Executor.successor, ir.Translate: Executor.translate, ir.Scale: Executor.scale,
    ir.Rotate: Executor.rotate, ir.Insert: Executor.insert, ir.Split: Executor.split,
    ir.Repeat: Executor.repeat, ir.Comp: Executor.comp, ir.Extrude: Executor.extrude,
    ir.AlignScope: Executor.align_scope, ir.Mirror: Executor.mirror, ir.Offset: Executor.offset,
    ir.SetColor: Executor.set_color, ir.UseAsset: Executor.use_asset, ir.SetAttr: Executor.set_attr,
    ir.Report: Executor.report, ir.Case: Executor.branch, ir.Stochastic: Executor.branch,
    ir.GroupSplit: Executor.group_split, ir.CompFaces: Executor.comp_faces, ir.Empty: Executor.nothing,
    ir.NotApplied: Executor.nothing, ir.Setback: Executor.setback, ir.Roof: Executor.roof,
    ir.InnerRectangle: Executor.inner_rectangle, ir.Convexify: Executor.convexify,
    ir.CleanupGeometry: Executor.cleanup_geometry, ir.Snap: Executor.snap, ir.Label: Executor.label,
}
#: Operations that take roofs (meshes): scope changes, component splits, successors, leaves, cleanup.
_MESH_OPERATIONS = frozenset({
    ir.Symbol, ir.Translate, ir.Scale, ir.Rotate, ir.Insert, ir.Comp, ir.CompFaces, ir.Empty, ir.NotApplied,
    ir.SetColor, ir.UseAsset, ir.SetAttr, ir.Report, ir.Case, ir.Stochastic, ir.Split, ir.Repeat, ir.GroupSplit,
    ir.AlignScope, ir.CleanupGeometry, ir.Snap, ir.Label,
})


def _hex_color(text: str) -> float:
    """0xRRGGBB of "#rrggbb" (or "#rgb"), NaN when the text is no such colour."""
    digits = text.strip().lstrip("#")
    if len(digits) == 3:
        digits = "".join(c * 2 for c in digits)
    try:
        return float(int(digits, 16)) if len(digits) == 6 else float("nan")
    except ValueError:
        return float("nan")


def report_rows(lot: np.ndarray, key, value, n: int) -> tuple:
    """One ``report`` call's rows: lot (n,), key ids (n,), values (n,) float64 and the value kind
    ("num", "bool" or "str"; strings as their ids)."""
    key = np.broadcast_to(np.asarray(key, dtype=np.int32), (n,))
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, np.ndarray) and value.dtype == bool):
        kind = "bool"
    elif isinstance(value, (int, np.integer)) or (isinstance(value, np.ndarray) and value.dtype == np.int32):
        kind = "str"
    else:
        kind = "num"
    values = np.broadcast_to(np.asarray(value, dtype=np.float64), (n,))
    return lot, key, values, kind
