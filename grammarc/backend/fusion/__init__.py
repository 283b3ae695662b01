"""Fused derivation: regions of a grammar compiled into numba kernels that write terminals straight into the
records, with no shape columns between their operations ("compile, don't interpret").

``regions`` finds the symbols whose rules need no context (scope operations, splits, repeats, guards,
inserts, leaves: the whitelist) and which of their successors can be derived with them (the others' shapes
are handed off: written out, to wait for their symbol's turn); ``codegen`` writes a
region's kernel (``group_splits`` its CityEngine splits), run in two passes (count the records each site makes; write them at offsets from a
cumulative sum), and the order its records are due in; ``compiled`` keeps the generated modules in the
user's cache folder, so that numba's cache keeps their machine code; ``fused`` derives a root's pending batch
with them.
``backend.plan`` finds the regions (this module: nothing here imports the derivation, which imports the
plan); ``backend.execute`` hands a region root's shapes to ``fused.derive`` and falls back to the interpreter
where it declines; the interpreter derives everything else.

The records are the interpreter's, bit for bit and in the same order. Bits: the kernels do the
interpreter's float64 operations in its order (no operation of a region multiplies frames). Order: records
are sorted by lot (stably), and within a lot come in the order the interpreter emits them: a symbol's rules
run when the schedule reaches its pending batch, and an ``I`` emits for the whole batch at once, so the
records of one emission site (an ``I`` reached through given parts of given splits) come together, in the
order of the batch, which is the order of the root's shapes and, within one, of the children of each split
(a split's part holds its children in their parents' order). The kernel writes site by site in that order;
the records of a site in an inlined symbol's rules are emitted when the schedule reaches that symbol
(``fused.FusedBatch``), where the interpreter would have emitted them; shapes handed off join their symbol's
pending batches at that moment too, where the interpreter's would. ``GRAMMARC_FUSION=off`` derives with
the interpreter alone. A kernel is compiled once (numba's cache keeps it), when enough shapes have come to
pay for its compilation; a compiled one then serves every batch.
"""

from __future__ import annotations

from dataclasses import dataclass

from grammarc.backend.fusion.codegen import Source, generate
from grammarc.backend.fusion.regions import Fusible, compile_at, grammar_allows

__all__ = ["Region", "fused_regions"]


@dataclass(frozen=True)
class Region:
    """A fused region: its root symbol, its generated kernel (``codegen.Source``), and how many shapes of its
    root a process meets before it compiles the kernel if it is not yet (``regions.COMPILE_AT``)."""

    root: int
    source: Source
    compile_at: int


def fused_regions(plan) -> dict[int, Region]:
    """The regions of ``plan`` by root symbol id: every symbol ``regions.Fusible`` accepts whose shapes fan
    out (none where fusion is off or the grammar needs what no kernel carries)."""
    threshold = compile_at()
    if threshold is None or not grammar_allows(plan):
        return {}
    fusible = Fusible(plan)
    return {sym.id: Region(sym.id, generate(fusible, sym.id), threshold) for sym in plan.symbols
            if fusible.symbol(sym.id) and fusible.worth_a_kernel(sym.id)}
