"""Which symbols a fused kernel derives: the whitelist of operations and expressions, and where a region ends.

A region is a symbol (its *root*) with the symbols its rules lead to, all derived by one generated kernel
(``codegen``) from the root's pending shapes: no intermediate shape columns, the terminals written straight
into the records. It covers what needs no context: the scope operations ``S`` and ``T``, single-axis
``Subdiv`` and ``Repeat`` (no snapping), ``I``, ``ε``, ``[ ]``, successor symbols (with arguments), leaves
(a successor without rules, or ``X.``, without arguments: its box or rectangle is a record at once, as
``terminals.emit_leaves`` makes it), guards and sizes made of numbers, attributes, parameters (numbers),
``scope.sx|sy|sz``, arithmetic, ``min``, ``max`` and ``rand``, and stochastic rules (their draws and
``rand``'s from the shape's counter-based stream, ``backend.random``, whose keys the kernel carries). Anything
else - another operation, another function - keeps the symbol for the interpreter (``backend.execute``),
which remains the reference: both give the same records, bit for bit (``tests/backend/fusion``).

A successor symbol is derived inside the region (*inlined*) only where the interpreter's record order can be
kept (``backend.fusion`` explains the order): when the symbol is named once in the whole grammar (its
pending shapes then come from this one place), or when its rule only places an asset (``leaf_parts``: its
shapes' records are the same however its batches are concatenated). Any other successor is *handed off*:
the kernel writes its shapes (scope, key, depth, parameters of numbers), which join the symbol's pending
batches where the interpreter's would, and its rules run at its turn, by the interpreter or by the kernel
of its own region. The whole grammar is left to the interpreter where records carry more than an
asset and a transform (colours, texture channels or coordinates, trims), where shapes carry per-shape
state (``set``, ``split.index``, a pivot), where an insert occludes, in a search that sums a design's leaves
(``backend.aggregates``), and in CityEngine's dialect (a body's end is a leaf, and shapes draw from PRT's
sequential stream, which successors move on in place).
``GRAMMARC_FUSION=off`` turns fusion off; ``GRAMMARC_FUSION=always`` compiles a kernel for any batch, however
small (``COMPILE_AT``).
"""

from __future__ import annotations

import os
from collections import Counter

from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_ops

#: The environment switch: ``off`` derives everything with the interpreter.
SWITCH = "GRAMMARC_FUSION"

#: Operators a fused expression may use: arithmetic of numbers, comparisons of numbers, logic.
ARITHMETIC = frozenset({"+", "-", "*", "/"})
COMPARE = frozenset({"<", "<=", ">", ">=", "==", "!="})
LOGIC = frozenset({"&&", "||"})
#: The scope fields a fused expression may read: the scope's size.
SIZES = {"sx": 0, "sy": 1, "sz": 2}
#: The functions a fused expression may call: ``rand`` draws from the shape's counter-based stream.
FUNCTIONS = frozenset({"min", "max", "rand"})


#: A kernel that is not compiled yet is compiled once a process has met this many shapes of its root:
#: compiling one costs seconds, which a build of a few lots would not win back (a compiled one serves
#: every batch).
COMPILE_AT = 10_000


def compile_at() -> int | None:
    """The shapes from which a kernel is compiled (``COMPILE_AT``; 0 with ``GRAMMARC_FUSION=always``, as the
    tests run), or None where fusion is ``off``."""
    value = os.environ.get(SWITCH, "").strip().lower()
    if value in ("off", "0", "false", "no"):
        return None
    return 0 if value == "always" else COMPILE_AT


def grammar_allows(plan) -> bool:
    """Whether ``plan``'s grammar may be fused at all (see the module docstring)."""
    # a search's aggregates count the shapes and leaves each symbol is given (``backend.aggregates``)
    return not (plan.leaf_bodies or plan.sequential_random or plan.queries or plan.occluders or plan.dynamic
                or plan.color_slot is not None or plan.material_slots or plan.uv_slots
                or plan.trim_slot is not None or plan.pivot_slot is not None or plan.grammar.module.objectives)


class Fusible:
    """The answers of one plan: which symbols' rules may be fused, which may be inlined (memoized)."""

    def __init__(self, plan) -> None:
        self.plan = plan
        self.uses = Counter(op.name for op in iter_ops(plan.grammar.module) if isinstance(op, ir.Symbol))
        self._fusible: dict[int, bool] = {}

    def symbol(self, sym_id: int) -> bool:
        """Whether every rule of symbol ``sym_id`` and every symbol it leads to can be fused."""
        if sym_id not in self._fusible:
            self._fusible[sym_id] = False  # a symbol that leads back to itself is not fused
            self._fusible[sym_id] = self._rules(self.plan.symbols[sym_id])
        return self._fusible[sym_id]

    def worth_a_kernel(self, sym_id: int) -> bool:
        """Whether the region of fusible symbol ``sym_id`` splits or repeats: a kernel's compilation pays off
        where shapes fan out (one of scope operations and inserts alone the interpreter runs as fast)."""
        for rule in applied_rules(self.plan.symbols[sym_id]):
            for op in iter_ops(rule):
                if isinstance(op, (ir.Split, ir.Repeat)):
                    return True
                if (isinstance(op, ir.Symbol) and not self.plan.makes_leaves(op) and self.inlined(op.name)
                        and self.worth_a_kernel(self.plan.symbol_ids[op.name])):
                    return True
        return False

    def inlined(self, name: str) -> bool:
        """Whether the successor symbol ``name``, which has rules, is derived inside its region (module
        docstring)."""
        plan = self.plan
        sym_id = plan.symbol_ids[name]
        alone = self.uses[name] == 1 and sym_id != plan.start
        # a symbol on a cycle of the rule graph is handed off, or its code would hold itself
        return ((alone or sym_id in plan.leaf_inserts) and name not in plan.grammar.graph.recursive
                and self.symbol(sym_id))

    def _rules(self, sym) -> bool:
        if not sym.rules or any(t is not ir.Type.NUM for t in sym.param_types) or sym.id in self.plan.snapping:
            return False
        for rule in applied_rules(sym):
            if rule.guard is not None and not self.expr(rule.guard):
                return False
            alternatives = rule.alternatives
            # a search's consequents are chosen by its states (``backend.choices``)
            if alternatives[0].choice or (len(alternatives) > 1 and not all(self.expr(a.prob) for a in alternatives)):
                return False
            if not all(self.body(a.body) for a in alternatives):
                return False
        return applied_rules(sym)[-1].guard is None  # shapes no rule applies to would be leaves

    def body(self, body: ir.Body) -> bool:
        return all(self.op(op) for op in body)

    def op(self, op: ir.Op) -> bool:
        if isinstance(op, ir.Scale):
            return not op.mirrors and all(self.expr(s.value) for s in op.sizes)
        if isinstance(op, ir.Translate):
            return all(self.expr(e) for e in op.vector)
        if isinstance(op, ir.Split):
            return (len(op.axes) == 1 and not op.snap and all(self.expr(s.value) for s in op.sizes)
                    and all(self.body(part) for part in op.parts))
        if isinstance(op, ir.Repeat):
            return (len(op.axes) == 1 and not op.snap and all(self.expr(e) for e in op.sizes)
                    and all(self.body(part) for part in op.parts))
        if isinstance(op, ir.Symbol):
            if self.plan.makes_leaves(op):  # its leaves are records at once, wherever it is named
                return not op.args
            target = self.plan.symbols[self.plan.symbol_ids[op.name]]
            # derived here, or handed off: its shapes wait for its turn, their parameters numbers
            return all(self.expr(arg) for arg in op.args) and (
                self.inlined(op.name) or all(t is ir.Type.NUM for t in target.param_types))
        return isinstance(op, (ir.Insert, ir.Empty, ir.Push, ir.Pop))

    def expr(self, expr: ir.Expr) -> bool:
        if isinstance(expr, (ir.Num, ir.Bool, ir.Param)):  # parameters: numbers (``_rules``)
            return True
        if isinstance(expr, ir.AttrRef):
            return True  # a column of numbers, which the runner checks (``run.attribute_columns``)
        if isinstance(expr, ir.ScopeRef):
            return expr.field in SIZES
        if isinstance(expr, ir.Unary):
            return expr.op in ("-", "!") and self.expr(expr.operand)
        if isinstance(expr, ir.Binary):
            return expr.op in ARITHMETIC | COMPARE | LOGIC and self.expr(expr.left) and self.expr(expr.right)
        if isinstance(expr, ir.Call):
            return expr.func in FUNCTIONS and all(self.expr(arg) for arg in expr.args)
        return False


def applied_rules(sym) -> tuple[ir.Rule, ...]:
    """The rules of ``sym`` that may apply: up to the first without a guard (``execute.apply_all``)."""
    for k, rule in enumerate(sym.rules):
        if rule.guard is None:
            return sym.rules[:k + 1]
    return sym.rules
