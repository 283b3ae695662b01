"""What the derivation of one chunk knows as it applies rules: the ``Context`` every operation is given.

An operation is a function ``f(ctx, shapes, op)`` (``backend.operations``). What it needs beyond its shapes and
its node is here: the plan, the chunk being derived (stores, outputs, counters), the limits, the worklist of
pending batches per symbol, the occluder bookkeeping, and the symbol whose rule is being applied (its name goes
into messages, its id onto leaves). The helpers every operation uses are the context's methods: ``env`` for
expressions, ``fail`` and ``fail_negative`` to report bad lots, ``count`` and its kin for the shape limits.
"""

from __future__ import annotations

import weakref
from collections import defaultdict
from collections.abc import Callable

import numpy as np

from grammarc.backend.chunk import Chunk
from grammarc.backend.evaluate import Env
from grammarc.backend.kernels.order import tally
from grammarc.backend.kernels.split import MAX_COUNT
from grammarc.backend.plan import Plan
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL, Limits
from grammarc.errors import AssetError, ChunkTooLarge, LotFailure
from grammarc.geometry.meshes import is_mesh
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_op

#: ``tally``'s weights when every row is one shape.
_NO_WEIGHTS = np.zeros(0, dtype=np.int64)


class Context:
    """Deriving one chunk of lots with a plan: the state the operations share."""

    __slots__ = ("_asset_meshes", "chunk", "chunk_budget", "limits", "pending", "plan", "symbol", "taken_apart")

    def __init__(self, plan: Plan, chunk: Chunk, limits: Limits, chunk_budget: int) -> None:
        self.plan = plan
        self.chunk = chunk
        self.limits = limits
        #: Shapes a chunk may make in all before it is halved (``ChunkTooLarge``).
        self.chunk_budget = chunk_budget
        #: Symbol id -> the batches waiting for its rules: shapes, or records of a leaf-insert symbol made
        #: ahead of its turn (``backend.leaf_parts``).
        self.pending: defaultdict[int, list] = defaultdict(list)
        #: The occluder ids of shapes taken apart (``occlusion.take_apart``): a shape split by two component
        #: splits (``Comp("sideface", 0){ a } Comp("sideface", 2){ a }``) is one occluder, not two of which
        #: each split's faces would see the other as a neighbour.
        self.taken_apart: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
        #: The symbol whose rule is being applied (``execute.apply_pending`` sets it for each batch).
        self.symbol = plan.start
        self._asset_meshes: dict[int, object] = {}

    def env(self, shapes: Shapes) -> Env:
        """What expressions on ``shapes`` read."""
        return Env(shapes, self.chunk, self.plan)

    # ------------------------------------------------------------------------------------------- failures
    def fail(self, shapes: Shapes, bad: np.ndarray, message: str, span) -> None:
        """Report the lots of shapes ``bad`` (n,) bool as failed: raises ``LotFailure``."""
        self.fail_lots(shapes.lot[bad], message, span)

    def fail_lots(self, lots: np.ndarray, message: str, span) -> None:
        """Report ``lots`` (chunk-local numbers, repeats allowed) as failed in the rule being applied, at
        ``span`` (None: a symbol without rules, whose leaves are being emitted): raises ``LotFailure``."""
        raise LotFailure(f"{message}{self._where(span)}", np.unique(lots))

    def fail_each(self, shapes: Shapes, bad: np.ndarray, describe: Callable[[int], str], span) -> None:
        """Report the lots of shapes ``bad`` (n,) bool as failed, each lot with the message ``describe(i)`` of
        its own first failing shape i (``fail_quoting``)."""
        rows = np.flatnonzero(bad)
        self.fail_quoting(shapes.lot[rows], lambda k: describe(int(rows[k])), span)

    def fail_quoting(self, lots: np.ndarray, quote: Callable[[int], str], span) -> None:
        """Report the lots of rows whose lots are ``lots`` (one a row, repeats allowed) as failed, each with
        the message ``quote(row)`` of its own first row: a lot's reason quotes its own value, whatever
        other lots share its chunk (the records and reasons do not depend on the chunking)."""
        failed, first = np.unique(lots, return_index=True)
        reasons = [f"{quote(int(row))}{self._where(span)}" for row in first]
        raise LotFailure(reasons[0], failed, reasons)

    def _where(self, span) -> str:
        """`` in rule `X` at file:line:col`` of the rule being applied."""
        rule = self.plan.symbols[self.symbol].name
        return f" in rule `{rule}`" + (f" at {span}" if span is not None else "")

    def fail_negative(self, shapes: Shapes, values: np.ndarray, message: str, span) -> None:
        """Fail the shapes whose sizes (n, k), or (1, k) for all, are negative or NaN, each lot quoting its
        first."""
        fine = values >= 0  # False for NaN too
        if fine.all():
            return
        bad = np.broadcast_to(~fine.all(axis=1), (len(shapes),))
        if bad.any():
            sizes = np.broadcast_to(values, (len(shapes), values.shape[1]))
            self.fail_each(shapes, bad, lambda i: f"{message} ({', '.join(f'{v:g}' for v in sizes[i])})", span)

    def refuse_meshes(self, op: ir.Op, shapes: Shapes) -> None:
        """Fail the roofs (meshes) among ``shapes``: ``op`` does not take them (``Operation.meshes``)."""
        mesh = is_mesh(shapes.geom)
        if mesh.any():
            name = print_op(op).split("(")[0]
            self.fail(shapes, mesh, f"`{name}` of a roof is not supported yet (split the roof into faces "
                      "with comp(f) first)", op.span)

    def refuse_far(self, op: ir.Op, made) -> None:
        """Fail the lots of the shapes ``op`` made (``Shapes``, or ``Parts``' shapes) whose scope it sized or
        placed beyond any coordinate (``Tol.far``; NaN is left to the operations that read it)."""
        shapes = getattr(made, "shapes", made)
        if not len(shapes):
            return
        # the usual case: the columns' greatest and least values, four reductions and no copy of np.abs's
        if any(bound > TOL.far for column in (shapes.size, shapes.origin) for bound in (column.max(), -column.min())):
            size, origin = np.abs(shapes.size), np.abs(shapes.origin)
            far = (size > TOL.far).any(axis=1) | (origin > TOL.far).any(axis=1)
            self.fail_each(shapes, far, lambda i: "a scope sized or placed beyond any coordinate "
                           f"({max(size[i].max(), origin[i].max()):g})", op.span)

    # ------------------------------------------------------------------------------------------ the limits
    def count(self, shapes: Shapes, span) -> None:
        """Add new shapes to the per-lot counters and enforce the shape limits."""
        self.count_lots(shapes.lot, span)

    def count_lots(self, lot: np.ndarray, span, per_row: np.ndarray | None = None) -> None:
        """``count`` of new shapes given by their lots (n,), ``per_row`` (n,) int64 shapes each (default 1).

        The per-lot counts are checked against --max-shapes only once the chunk has made more shapes than
        the limit in all (no lot can be over before): a small batch costs its own length, not the chunk's
        number of lots."""
        chunk = self.chunk
        chunk.shape_total += tally(chunk.shape_count, lot, _NO_WEIGHTS if per_row is None else per_row)
        if chunk.shape_total > self.limits.max_shapes:
            self.check_shape_limit(chunk.shape_count, span)
        if chunk.shape_total > self.chunk_budget and len(chunk.shape_count) > 1:
            raise ChunkTooLarge()

    def check_fan_out(self, shapes: Shapes, counts: np.ndarray, span) -> None:
        """Refuse a fan-out of ``counts`` (n,) children per shape (int64, or float64 where a count may be
        beyond int64) that would take a lot over --max-shapes, before allocating them."""
        # summed as floats: two counts of ``MAX_COUNT`` overflow int64 to a negative sum, which passed
        if self.chunk.shape_total + counts.sum(dtype=np.float64) <= self.limits.max_shapes:  # NaN: check
            return
        per_lot = np.bincount(shapes.lot, weights=counts, minlength=len(self.chunk.shape_count))
        self.check_shape_limit(per_lot + self.chunk.shape_count, span)

    def check_shape_limit(self, counts: np.ndarray, span) -> None:
        """Fail the lots whose shape count (L,), made or about to be, exceeds --max-shapes (``LotFailure``,
        each lot's message with its own count): the other lots of the chunk derive."""
        over = ~(counts <= self.limits.max_shapes)  # a NaN count (an inf - inf fan-out) is over too
        if over.any():
            lots = np.flatnonzero(over)
            rule = self.plan.symbols[self.symbol].name
            limit = f"{self.limits.max_shapes:,}"
            reasons = [f"more than {limit} shapes ({_count(c)}) in rule `{rule}` at {span}: a runaway "
                       "grammar? Raise the limit with --max-shapes N." for c in counts[lots]]
            raise LotFailure(reasons[0], lots, reasons)

    def check_depth(self, shapes: Shapes, span) -> None:
        """Fail the lots of ``shapes`` that reached --max-depth rule applications on one path (a runaway
        recursion): their shapes are still pending, the other lots derive."""
        deep = shapes.depth >= self.limits.max_depth
        if deep.any():
            rule = self.plan.symbols[self.symbol].name
            raise LotFailure(f"reached --max-depth {self.limits.max_depth} in rule `{rule}` at {span}: a runaway "
                             "recursion? Raise the limit with --max-depth N.", np.unique(shapes.lot[deep]))

    # -------------------------------------------------------------------------------------------- assets
    def asset_mesh(self, asset: int):
        """The ``AssetMesh`` of asset id ``asset`` for trimming and the insert modes that keep its size
        (``Plan.load_asset``), None for an asset that cannot be loaded; each loaded once per chunk."""
        if asset not in self._asset_meshes:
            grammar = self.plan.grammar
            try:
                mesh = self.plan.load_asset(grammar.assets[asset], grammar.asset_roots)
            except AssetError as error:
                mesh = error  # asset_problem tells why
            self._asset_meshes[asset] = mesh
        mesh = self._asset_meshes[asset]
        return None if isinstance(mesh, AssetError) else mesh

    def asset_problem(self, asset: int) -> str:
        """Why ``asset_mesh(asset)`` is None (after it was asked)."""
        return str(self._asset_meshes[asset])


def _count(value: float) -> str:
    """A shape count for a message: exact while it is a float's integer, in powers of ten beyond, and
    "beyond counting" where a fan-out's count overflowed (``kernels.split.MAX_COUNT``: a size of almost
    nothing, a non-finite one)."""
    if value < 2.0**53:
        return f"{int(value):,}"
    return f"{value:.3g}" if value < MAX_COUNT else "beyond counting"
