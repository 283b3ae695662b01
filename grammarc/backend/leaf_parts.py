"""Split parts whose symbol only places an asset: their records written straight from the parent's scope.

Most terminals of a city come out of a split part whose symbol's one rule inserts an asset, after a
constant ``S`` or ``T`` at most (``wall ~> I("quad")``, ``window ~> S(1r, 1r, 0.2) T(0, 0, -0.2)
I("cube")``). The general path makes each such part a child shape (seven columns and the parameters),
again a successor shape (a new random key, its depth), gathers it into its symbol's batch, and only
then computes its transform: some 600 bytes moved for a 64-byte record, which bounds the facade
benchmark. Here the transform is computed from the parent's scope and the part's offset in one pass
(``kernels.scope.leaf_xforms``), and the records wait in the symbol's pending list (``LeafRecords``)
until the schedule reaches that symbol, where the general path would have emitted them: the records and
their order are the same (tests: the facade grammar against a copy whose leaf rules carry a guard).

A symbol qualifies (``leaf_inserts``) when its rule cannot tell its shapes apart and leaves nothing
behind but the instance: one rule, no guard, one alternative, a body of at most one ``S`` and one ``T``
of number literals (sizes not negative) and one ``I``; in the paper notation, in a grammar without
occlusion (an instance would be an occluder) nor colours, and not a symbol that snaps or asks queries. The part
must name it without arguments (``wall``, not ``wall(1)`` nor ``wall.``); a split whose parts read
``split.total``, or whose children are clipped polygons, takes the general path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grammarc.backend.kernels.scope import leaf_xforms
from grammarc.backend.shapes import Shapes
from grammarc.ir import nodes as ir

__all__ = ["LeafInsert", "LeafPart", "LeafRecords", "leaf_inserts"]


@dataclass(frozen=True)
class LeafInsert:
    """What a qualifying symbol's rule does: per axis, a size (absolute, or a factor where ``relative``)
    or none (NaN), an offset along the scope axes, and the asset."""

    symbol: int
    asset: int
    size: np.ndarray  # (3,) float64, NaN: unchanged
    relative: np.ndarray  # (3,) bool
    offset: np.ndarray | None  # (3,) float64, or None without T


@dataclass(frozen=True)
class LeafRecords:
    """Records of a ``LeafInsert`` symbol made ahead of its turn: emitted when its batch comes."""

    symbol: int
    xform: np.ndarray  # (m, 3, 4) float32
    lot: np.ndarray  # (m,) int32

    def __len__(self) -> int:
        return len(self.lot)


@dataclass(frozen=True, eq=False)
class LeafPart:
    """A split part naming a ``LeafInsert`` symbol: its children ``rows`` (k,) of the split's cut (each
    child's ``parent`` row of ``shapes``, ``pos`` and ``length`` along ``axis``), whose records the body
    runner makes when it reaches the part (``records``), where it would have run the part's body."""

    leaf: LeafInsert
    shapes: Shapes
    axis: int
    rows: np.ndarray
    parent: np.ndarray
    pos: np.ndarray
    length: np.ndarray

    def records(self, frames: np.ndarray, lot_origin: np.ndarray) -> LeafRecords:
        """The part's records from the chunk's frame table ``frames`` (F, 3, 3) and its lots' origins
        ``lot_origin`` (L, 3) (``kernels.scope.leaf_xforms``)."""
        leaf, shapes = self.leaf, self.shapes
        xform = leaf_xforms(shapes.origin, lot_origin[shapes.lot], shapes.size, shapes.frame, frames, self.axis, self.rows, self.parent,
                            self.pos, self.length, leaf.size, leaf.relative,
                            leaf.offset if leaf.offset is not None else np.zeros(0))
        return LeafRecords(leaf.symbol, xform, shapes.lot[self.parent[self.rows]])


def leaf_inserts(plan) -> dict[int, LeafInsert]:
    """The symbols of ``plan`` whose rule only places an asset (see the module docstring), by id."""
    # a search's aggregates count the shapes a symbol is given (``backend.aggregates``): none is skipped
    if plan.leaf_bodies or plan.queries or plan.occluders or plan.color_slot is not None or plan.material_slots \
            or plan.uv_slots or plan.grammar.module.objectives:
        return {}
    found = {}
    for sym in plan.symbols:
        if len(sym.rules) != 1 or sym.id in plan.snapping:
            continue
        rule = sym.rules[0]
        if rule.guard is not None or len(rule.alternatives) != 1:
            continue
        leaf = _leaf(sym.id, rule.alternatives[0].body, plan.grammar.asset_ids)
        if leaf is not None:
            found[sym.id] = leaf
    return found


def _leaf(symbol: int, body: ir.Body, asset_ids: dict[str, int]) -> LeafInsert | None:
    *moves, last = body if body else (None,)
    if not isinstance(last, ir.Insert):
        return None
    scales = [op for op in moves if isinstance(op, ir.Scale)]
    translates = [op for op in moves if isinstance(op, ir.Translate)]
    if len(scales) + len(translates) != len(moves) or len(scales) > 1 or len(translates) > 1:
        return None
    size, relative = np.full(3, np.nan), np.zeros(3, dtype=bool)
    for scale in scales:
        values = [s.value.value if isinstance(s.value, ir.Num) else None for s in scale.sizes]
        if any(v is None or not v >= 0 for v in values):
            return None
        size[:] = values
        relative[:] = [s.kind is ir.SizeKind.RELATIVE for s in scale.sizes]
    offset = None
    for translate in translates:
        if not all(isinstance(e, ir.Num) for e in translate.vector):
            return None
        offset = np.array([e.value for e in translate.vector], dtype=np.float64)
    return LeafInsert(symbol, asset_ids[last.asset], size, relative, offset)
