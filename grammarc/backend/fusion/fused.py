"""Deriving a region root's pending shapes with its kernels, and emitting the records where the interpreter
would have.

``derive`` runs the kernel over the batch counting, checks what the interpreter would refuse (then it hands
the whole batch back, and the interpreter derives it, failing what it fails), counts the shapes for
--max-shapes as the interpreter does, allocates the records once and runs the kernel again, writing. The
root's own records are emitted at once; those of each inlined symbol wait in that symbol's pending list as a ``FusedBatch`` until the
schedule reaches it, where the interpreter would have run its rules on the shapes handed to it.

Where the grammar's shapes carry per-shape columns (colours, texture channels and coordinates, trim planes,
attributes rules ``set``...: ``Plan.dynamic``), a record or a shape handed off has its root's, but for those
the region wrote on its way (``set``, ``color``: ``regions``): the kernel writes the root's row beside each,
and the values it wrote; its records are placed as the interpreter places them from those columns
(``terminals.place_instances``: cut at trim planes, coloured, textured).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np

from grammarc.backend import terminals
from grammarc.backend.fusion.compiled import compiled_before, handed_columns, kernel, ready
from grammarc.backend.fusion.sites import Block, Emit, Handoff
from grammarc.backend.materials import hex_colors
from grammarc.backend.shapes import Shapes
from grammarc.ir import nodes as ir
from grammarc.ragged import offsets_from_counts


@dataclass(frozen=True, eq=False)
class FusedRecords:
    """The records a region's kernel wrote, by site: site k's are rows ``starts[k]`` to ``starts[k + 1]``; and
    the shapes it handed off (``handed``: origin, size, frame, lot, key, depth, parameters (p, h), root
    rows, written columns (w, h)), hand-off site k's rows ``handoff_starts[k]`` to ``handoff_starts[k + 1]``.
    Where the kernel carries per-shape columns, ``root`` is its batch, ``row`` the root row of each record
    (else None), and ``written`` (w, m) the values of the columns ``slots`` that the region wrote."""

    xform: np.ndarray  # (m, 3, 4) float32
    lot: np.ndarray  # (m,) int32
    starts: np.ndarray  # (sites + 1,) int64
    handed: tuple
    handoff_starts: np.ndarray  # (handoff sites + 1,) int64
    root: Shapes | None = None
    row: np.ndarray | None = None  # (m,) int64
    written: np.ndarray | None = None  # (w, m) float64
    slots: tuple[int, ...] = ()

    def shapes(self, plan, handoff: Handoff) -> Shapes:
        """The shapes of ``handoff``, with their roots' per-shape columns but those the region wrote (their
        geometry inserted where an ``i`` made it)."""
        a, b = self.handoff_starts[handoff.site], self.handoff_starts[handoff.site + 1]
        origin, size, frame, lot, key, depth, values, row, written = self.handed
        types = plan.symbols[handoff.symbol].param_types
        dynamic = () if self.root is None else self._columns(row[a:b], handoff.written, written[:, a:b])
        params = tuple(values[k, a:b].astype(np.int32) if t is ir.Type.STR else values[k, a:b]
                       for k, t in enumerate(types))  # a string as the interpreter holds it: its interned id
        made = Shapes(origin[a:b], size[a:b], frame[a:b], np.full(b - a, handoff.geom, np.int32), lot[a:b],
                      key[a:b], depth[a:b], params, dynamic)
        return terminals.marked_inserted(plan, made, True) if handoff.inserted else made

    def _columns(self, rows: np.ndarray, slots: tuple[int, ...], written: np.ndarray) -> tuple:
        """The per-shape columns of shapes made of the roots ``rows``: their roots', but the ``slots`` the
        region wrote, whose values are the rows of ``written`` (w, m), in the roots' columns' types."""
        columns = [column if k in slots else column[rows] for k, column in enumerate(self.root.dynamic)]
        for slot in slots:
            columns[slot] = written[self.slots.index(slot)].astype(columns[slot].dtype)
        return tuple(columns)

    def emit(self, ctx, event: Emit, a: int, b: int) -> None:
        """Append the records ``a`` to ``b`` of emission site ``event``: placed from their roots' rows, as
        ``terminals.emit_instances`` and ``emit_leaves`` place them, where the kernel carries per-shape
        columns."""
        xform = self.xform[a:b]
        if self.root is None:
            terminals.append_records(ctx, xform, self.lot[a:b], event.asset, event.symbol, None)
            return
        shapes, rows = self.root, self.row[a:b]
        if event.written:  # the records' own columns, the roots' but those the region wrote
            shapes = replace(replace(shapes, dynamic=()).take(rows),
                             dynamic=self._columns(rows, event.written, self.written[:, a:b]))
            rows = np.arange(b - a)
        if event.leaf and event.asset == terminals.QUAD:  # a leaf quad is never cut
            terminals.append_instances(ctx, shapes, rows, xform, event.asset, event.symbol)
            return
        slot = ctx.plan.inserted_slot
        inserted = None
        if event.leaf and not event.inserted and slot is not None:  # a leaf box: cut where its root was inserted
            inserted = shapes.dynamic[slot][rows] == 1
        terminals.place_instances(ctx, shapes, rows, xform, event.asset, event.symbol, event.leaf, inserted)


@dataclass(frozen=True, eq=False)
class FusedBatch:
    """An inlined symbol's share of a region's records, pending until its turn (``emit``)."""

    records: FusedRecords
    block: Block

    def emit(self, ctx) -> None:
        """Append this block's records and queue its symbols' blocks, in the interpreter's order."""
        records, starts, handoff_starts = self.records, self.records.starts, self.records.handoff_starts
        for event in self.block.events:
            if type(event) is Emit:
                a, b = starts[event.site], starts[event.site + 1]
                if b > a:
                    records.emit(ctx, event, a, b)
            elif type(event) is Handoff:
                if handoff_starts[event.site + 1] > handoff_starts[event.site]:
                    ctx.pending[event.symbol].append(records.shapes(ctx.plan, event))
            elif (starts[event.last] > starts[event.first]
                  or handoff_starts[event.last_handoff] > handoff_starts[event.first_handoff]):
                ctx.pending[event.symbol].append(FusedBatch(records, event))


def derive(ctx, region, shapes: Shapes) -> bool:
    """Derive ``shapes`` of ``region``'s root with its kernels; False (nothing done) where the interpreter
    must: a kernel not compiled yet for which too few shapes came, a shape with geometry of its own, a depth within reach of --max-depth, a parameter or attribute
    that is not a column of numbers, or a shape that would fail."""
    chunk, limits = ctx.chunk, ctx.limits
    if not ready(region.source.text, len(shapes), region.compile_at):
        return False  # a few shapes do not pay for compiling a kernel; the interpreter derives them
    if (shapes.geom != -1).any() or int(shapes.depth.max()) + region.source.depth >= limits.max_depth:
        return False
    attrs = [*map(_numbers, shapes.params), *(_attribute(ctx, shapes, name) for name in region.source.attrs)]
    if not all(isinstance(a, np.ndarray) and a.dtype == np.float64 for a in attrs):
        return False
    source = region.source
    derive_batch = kernel(source.text, len(attrs))
    n = len(shapes)
    sites, made, bad = np.zeros(source.sites, np.int64), np.empty(n), np.zeros(n, np.bool_)
    handoffs = np.zeros(source.handoffs, np.int64)
    # contiguous, as the kernel was compiled for (``compiled.kernel``): a copy only where one is not
    hexes = hex_colors(ctx.plan.strings) if source.hexes else np.empty(0)
    columns = (*map(np.ascontiguousarray, (shapes.origin, shapes.size, shapes.frame, shapes.lot, shapes.key,
                                           shapes.depth, chunk.frames.data, *attrs, chunk.lot_origin)),
               hexes, float(limits.max_shapes))
    derive_batch(*columns, False, sites, made, bad, np.empty((0, 3, 4), np.float32), np.empty(0, np.int32),
                 np.empty(0, np.int64), np.empty((0, 0)), handoffs, handed_columns(0, source.params))
    if bad.any() or not _within_limit(ctx, shapes.lot, made):
        return False
    ctx.count_lots(shapes.lot, ctx.plan.symbols[region.root].rules[0].span, made.astype(np.int64))
    starts, handoff_starts = offsets_from_counts(sites), offsets_from_counts(handoffs)
    total = int(starts[-1])
    xform, lot = np.empty((total, 3, 4), np.float32), np.empty(total, np.int32)
    row = np.empty(total if source.carries else 0, np.int64)
    written = np.empty((len(source.written), total))
    handed = handed_columns(int(handoff_starts[-1]), source.params, source.carries, len(source.written))
    derive_batch(*columns, True, starts[:-1].copy(), made, bad, xform, lot, row, written, handoff_starts[:-1].copy(),
                 handed)
    records = FusedRecords(xform, lot, starts, handed, handoff_starts,
                           *((shapes, row, written, source.written) if source.carries else ()))
    FusedBatch(records, source.block).emit(ctx)
    return True


def _attribute(ctx, shapes: Shapes, name: str):
    """The column of attribute ``name`` a kernel reads (``codegen._Writer.attribute``): the shapes' own where
    they carry it (``Plan.dynamic``), by row, else the chunk's, by lot (as ``evaluate`` reads them), in
    numbers (``_numbers``)."""
    slot = ctx.plan.dynamic.get(name)
    return _numbers(shapes.dynamic[slot] if slot is not None else ctx.chunk.attrs.get(name))


def _numbers(column):
    """A column as a kernel reads it: booleans as numbers (true 1.0), which its conditions and arithmetic take
    as numpy does, and strings as their interned ids in numbers (``regions`` says where it reads them)."""
    if isinstance(column, np.ndarray) and column.dtype in (np.bool_, np.int32):
        return column.astype(np.float64)
    return column


def _within_limit(ctx, lot: np.ndarray, made: np.ndarray) -> bool:
    """Whether no lot goes over --max-shapes with ``made`` (n,) more shapes of rows of lots ``lot`` (n,)."""
    chunk, limit = ctx.chunk, ctx.limits.max_shapes
    if chunk.shape_total + made.sum() <= limit:
        return True
    return bool((np.bincount(lot, weights=made, minlength=len(chunk.shape_count)) + chunk.shape_count
                 <= limit).all())


def preload(plan) -> Iterator[None]:
    """Load the machine code of ``plan``'s kernels that an earlier build compiled, one a step (none is
    compiled here), for a build to run while it waits for its lots (``io.lots_reading``): the kernels are
    then loaded when its workers are forked, which would otherwise each load them again as their shapes
    come."""
    for region in plan.fused.values():
        if compiled_before(region.source.text):
            kernel(region.source.text, len(plan.symbols[region.root].param_types) + len(region.source.attrs))
            yield
