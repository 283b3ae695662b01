"""Which symbols a fused kernel derives: the whitelist of operations and expressions, and where a region ends.

A region is a symbol (its *root*) with the symbols its rules lead to, all derived by one generated kernel
(``codegen``) from the root's pending shapes: no intermediate shape columns, the terminals written straight
into the records. It covers what needs no context: the scope operations ``S`` and ``T``, ``Subdiv`` and
``Repeat`` along one axis or several (no snapping), ``I``, ``ε``, ``[ ]``, successor symbols (with
arguments), leaves (a successor without rules, or ``X.``, without arguments: its box or rectangle is a
record at once, as ``terminals.emit_leaves`` makes it), guards and sizes made of numbers, attributes, parameters (numbers,
booleans), ``scope.sx|sy|sz``, arithmetic, ``min``, ``max``, ``rand`` and ``p``, and stochastic rules (their
draws and ``rand``'s from the shape's counter-based stream, ``backend.random``, whose keys the kernel
carries). In CityEngine's dialect it covers ``s``, ``t`` and ``center``, ``split`` of the scope (its repeat
groups and floating sizes, laid by the interpreter's kernels), ``i`` of an asset named in the rule (fitted
to the scope), ``case``, stochastic ``%`` choices, ``NIL``, ``[ ]``, ``set`` and ``color`` (below),
successors and leaves; a body that hands its shape to nothing ends in a leaf. Shapes there carry their state
in PRT's sequential stream, which the kernel moves on as the interpreter does, where shapes are made and
where they draw (``rand``, ``p``, ``%``). Anything else - another operation, another function - keeps the
symbol for the interpreter (``backend.execute``),
which remains the reference: both give the same records, bit for bit (``tests/backend/fusion``).

A successor symbol is derived inside the region (*inlined*) only where the interpreter's record order can be
kept (``backend.fusion`` explains the order): when the symbol is named once in the whole grammar (its
pending shapes then come from this one place), or when its rule only places an asset (``leaf_parts``: its
shapes' records are the same however its batches are concatenated). Any other successor is *handed off*:
the kernel writes its shapes (scope, key, depth, parameters), which join the symbol's pending
batches where the interpreter's would, and its rules run at its turn, by the interpreter or by the kernel
of its own region.

Shapes may carry per-shape columns (``Plan.dynamic``: colours, texture channels and coordinates, trim
planes, a pivot, box rings, attributes rules ``set``). A region writes some of them: ``set`` of a value a
kernel computes (numbers and booleans as its expressions, a string as a constant or another attribute's,
which is an interned id), ``color`` (three components, or ``"#rrggbb"`` as a constant or an attribute's,
looked up in a table of the interned strings), each a variable of the code from there on, which the
expressions after it read and which the records and shapes handed off below it carry (``codegen``); an
``i`` marks its geometry inserted, which the kernel knows where it writes its code. Everything else a
region makes of a root has the root's columns, so the kernel writes the root's row beside its records and
shapes (``fused``); an attribute a shape carries is read from its root's row where the region has not set
it. The texture maps and trim planes are in world coordinates, which a split or a move keeps. A string
(a constant, an attribute's or a parameter's, all interned ids) is read only as the value of ``set`` or
``color`` or of a successor's string parameter, or compared with ``==`` or ``!=`` to another one: the
kernels' arithmetic is of numbers. A split where the grammar reads
``split.index`` or ``split.total`` writes them, which no kernel does: its symbol is left to the
interpreter. Operations CityEngine has that change nothing in the record (``reverseNormals``, ``print``,
the other material settings: ``ir.NotApplied``) are nothing in a kernel either. The whole grammar is left
to the interpreter where an insert occludes and in a search that sums a design's leaves
(``backend.aggregates``). ``grammar_refusals`` says which of these keep a grammar out,
``Fusible.refusal`` the first construct that keeps a symbol out and where it is: what ``grammarc check
--fusion`` prints.
``GRAMMARC_FUSION=off`` turns fusion off; ``GRAMMARC_FUSION=always`` compiles a kernel for any batch, however
small (``COMPILE_AT``).
"""

from __future__ import annotations

import math
import os
from collections import Counter
from dataclasses import dataclass

from grammarc.backend.materials import hex_color
from grammarc.backend.streams import draws
from grammarc.diagnostics import Span
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_expr, print_op
from grammarc.ir.traverse import iter_ops

#: The environment switch: ``off`` derives everything with the interpreter.
SWITCH = "GRAMMARC_FUSION"

#: Operators a fused expression may use: arithmetic of numbers, comparisons of numbers, logic.
ARITHMETIC = frozenset({"+", "-", "*", "/"})
COMPARE = frozenset({"<", "<=", ">", ">=", "==", "!="})
LOGIC = frozenset({"&&", "||"})
#: The scope fields a fused expression may read: the scope's size.
SIZES = {"sx": 0, "sy": 1, "sz": 2}
#: The functions a fused expression may call: ``rand`` and ``p`` draw from the shape's stream.
FUNCTIONS = frozenset({"min", "max", "rand", "p"})
#: The types of the parameters a kernel takes: numbers and booleans (as the interpreter holds them, float64),
#: strings as their interned ids.
PARAMETERS = frozenset({ir.Type.NUM, ir.Type.BOOL, ir.Type.STR})
#: The per-shape columns a split writes to its children (``children.with_context``).
SPLIT_CONTEXT = frozenset({"split.index", "split.total"})


#: The fused operations after which a body's shape is not the body's to emit as a leaf (CityEngine's
#: dialect): it was replaced by successors, split into parts, handed to branches, placed or deleted (the
#: operations' ``consumes``, ``operations.table``, which imports the plan and so cannot be read here).
ENDING = (ir.Split, ir.Repeat, ir.GroupSplit, ir.Insert, ir.Symbol, ir.Case, ir.Stochastic, ir.Empty)

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
    return not grammar_refusals(plan)


def grammar_refusals(plan) -> list[str]:
    """Why ``plan``'s grammar may not be fused at all, one phrase each (none: it may be; the module
    docstring says why each keeps it out)."""
    found = (
        (plan.queries or plan.occluders, "occlusion (queries, occluding inserts, labels)"),
        # a search's aggregates count the shapes and leaves each symbol is given (``backend.aggregates``)
        (plan.grammar.module.objectives, "a search's objectives"),
    )
    return [reason for present, reason in found if present]


class Fusible:
    """The answers of one plan: which symbols' rules may be fused and why not, which may be inlined
    (memoized)."""

    def __init__(self, plan) -> None:
        self.plan = plan
        self.uses = Counter(op.name for op in iter_ops(plan.grammar.module) if isinstance(op, ir.Symbol))
        #: The types of the attributes, declared and CityEngine's own (``ir.SHAPE_ATTRIBUTES``).
        self.types = {attr.name: attr.type for attr in plan.grammar.module.attrs} | ir.SHAPE_ATTRIBUTES
        self._refusals: dict[int, Refusal | None] = {}
        self.params: tuple[ir.Type, ...] = ()  # the types of the parameters of the symbol whose rules are read

    def symbol(self, sym_id: int) -> bool:
        """Whether every rule of symbol ``sym_id`` and every symbol it leads to can be fused."""
        return self.refusal(sym_id) is None

    def refusal(self, sym_id: int) -> Refusal | None:
        """Why symbol ``sym_id``'s rules, or those of a symbol they lead to, cannot be fused: the first
        construct no kernel takes, with where it is (None: they can)."""
        if sym_id not in self._refusals:
            sym = self.plan.symbols[sym_id]
            self._refusals[sym_id] = Refusal(f"`{sym.name}` leads back to itself")  # not fused
            self._refusals[sym_id] = self._rules(sym)
        return self._refusals[sym_id]

    def worth_a_kernel(self, sym_id: int) -> bool:
        """Whether the region of fusible symbol ``sym_id`` splits or repeats: a kernel's compilation pays off
        where shapes fan out (one of scope operations and inserts alone the interpreter runs as fast)."""
        for rule in applied_rules(self.plan.symbols[sym_id]):
            for op in iter_ops(rule):
                if isinstance(op, (ir.Split, ir.Repeat)) or type(op) is ir.GroupSplit:
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

    def _rules(self, sym) -> Refusal | None:
        outer, self.params = self.params, sym.param_types
        try:
            return self._read_rules(sym)
        finally:
            self.params = outer

    def _read_rules(self, sym) -> Refusal | None:
        if not sym.rules:
            return Refusal(f"`{sym.name}` has no rules")
        if any(t not in PARAMETERS for t in sym.param_types):
            return Refusal(f"`{sym.name}` has a parameter that is not a number, a boolean or a string")
        if sym.id in self.plan.snapping:
            return Refusal(f"`{sym.name}` snaps")
        for rule in applied_rules(sym):
            if rule.guard is not None and (why := self.expr(rule.guard)):
                return why
            if rule.guard is not None and self.plan.sequential_random and draws(rule.guard):
                return Refusal("a guard that draws from PRT's stream", "", rule.span)
            alternatives = rule.alternatives
            # a search's consequents are chosen by its states (``backend.choices``)
            if alternatives[0].choice:
                return Refusal("a search's choice", "", rule.span)
            if len(alternatives) > 1 and (why := _first(self.expr(a.prob) for a in alternatives)):
                return why
            if why := _first(self.body(a.body) for a in alternatives):
                return why
        if applied_rules(sym)[-1].guard is not None:
            return Refusal(f"`{sym.name}`'s shapes that no rule applies to would be leaves")
        return None

    def body(self, body: ir.Body) -> Refusal | None:
        return _first(self.op(op) for op in body)

    def op(self, op: ir.Op) -> Refusal | None:
        if isinstance(op, ir.Scale):  # CityEngine's `s` of a negative size mirrors: the interpreter derives it
            return _first(self.expr(s.value) for s in op.sizes)
        if isinstance(op, ir.Translate):
            return _first(self.expr(e) for e in op.vector)
        if isinstance(op, (ir.Split, ir.Repeat, ir.GroupSplit)) and SPLIT_CONTEXT & self.plan.dynamic.keys():
            return _refused(op, "a split whose `split.index` or `split.total` a rule reads")
        if isinstance(op, (ir.Split, ir.Repeat)):  # one that snaps keeps its symbol out (``_read_rules``)
            sizes = (s.value for s in op.sizes) if isinstance(op, ir.Split) else op.sizes
            return _first(self.expr(e) for e in sizes) or _first(self.body(part) for part in op.parts)
        if type(op) is ir.GroupSplit:  # not its subclass ``splitArea``, whose layout needs the geometry
            if op.uv_set >= 0:
                return _refused(op, "a split in texture space")
            return _first(self.expr(s.value) for s in op.sizes) or _first(self.body(part) for part in op.parts)
        if isinstance(op, ir.UseAsset):
            if op.name is not None or op.up_by is not None or op.mode_by is not None:
                return _refused(op, "an `i` of a computed asset, up axis or mode")
            if op.up != ir.UP_AXES[0] or op.mode != ir.INSERT_MODES[0]:
                return _refused(op, "an `i` that turns the asset or keeps its size")
            return None
        if isinstance(op, ir.Symbol):
            if self.plan.makes_leaves(op):  # its leaves are records at once, wherever it is named
                return _refused(op, "a leaf with arguments") if op.args else None
            target = self.plan.symbols[self.plan.symbol_ids[op.name]]
            # derived here, or handed off: its shapes wait for its turn with their parameters
            if any(t not in PARAMETERS for t in target.param_types):
                return _refused(op, "a successor with a parameter that is not a number, a boolean or a string")
            return _first(self.value(arg, t) for arg, t in zip(op.args, target.param_types))
        if isinstance(op, (ir.Case, ir.Stochastic)):  # conditions, or percentages
            return (_first(self.expr(value) for value, _ in op.branches)
                    or _first(self.body(body) for body in (*(body for _, body in op.branches), op.default)))
        if isinstance(op, ir.SetAttr):
            return self.value(op.value, self.types.get(op.name))
        if isinstance(op, ir.SetColor):
            if len(op.values) == 3:
                return _first(self.expr(value) for value in op.values)
            value = op.values[0]
            if isinstance(value, ir.Str) and math.isnan(hex_color(value.value)):
                return _refused(value, "a colour that is not \"#rrggbb\"")
            return None if self.string(value) else _refused(value, "a colour other than a constant, an attribute or "
                                                                   "a parameter")
        if isinstance(op, (ir.Insert, ir.Empty, ir.Push, ir.Pop, ir.NotApplied, ir.Center)):
            return None
        return _refused(op, "an operation no kernel takes")

    def value(self, expr: ir.Expr, kind: ir.Type | None) -> Refusal | None:
        """Why ``expr`` is no value of type ``kind`` a kernel takes (an attribute ``set``, a successor's
        argument): a string as ``string`` says, anything else as ``expr`` does."""
        if kind is ir.Type.STR:
            return None if self.string(expr) else _refused(expr, "a string other than a constant, an attribute or "
                                                                 "a parameter")
        return self.expr(expr)

    def string(self, expr: ir.Expr) -> bool:
        """Whether ``expr`` is a string a kernel takes as a value: a constant, a string attribute or a string
        parameter (all interned ids)."""
        return (isinstance(expr, ir.Str) or (isinstance(expr, ir.AttrRef) and self.types.get(expr.name) is ir.Type.STR)
                or (isinstance(expr, ir.Param) and self.params[expr.index] is ir.Type.STR))

    def expr(self, expr: ir.Expr) -> Refusal | None:
        if isinstance(expr, (ir.Num, ir.Bool)):
            return None
        if isinstance(expr, ir.Param):  # a number or a boolean (``_rules``), or a string
            return _refused(expr, "a string parameter") if self.params[expr.index] is ir.Type.STR else None
        if isinstance(expr, ir.AttrRef):  # a column of numbers (or booleans), which the runner checks
            return _refused(expr, "a string attribute") if self.types.get(expr.name) is ir.Type.STR else None
        if isinstance(expr, ir.ScopeRef):
            return None if expr.field in SIZES else _refused(expr, "a scope field other than a size")
        if isinstance(expr, ir.Unary):
            return self.expr(expr.operand) if expr.op in ("-", "!") else _refused(expr, "an operator")
        if isinstance(expr, ir.Binary):
            if expr.op not in ARITHMETIC | COMPARE | LOGIC:
                return _refused(expr, "an operator")
            if expr.op in ("==", "!=") and self.string(expr.left) and self.string(expr.right):
                return None  # the same text is the same interned id
            return self.expr(expr.left) or self.expr(expr.right)
        if isinstance(expr, ir.Call):
            if expr.func not in FUNCTIONS:
                return _refused(expr, "a function no kernel takes")
            return _first(self.expr(arg) for arg in expr.args)
        return _refused(expr, "an expression no kernel takes")


def _first(reasons) -> Refusal | None:
    """The first of ``reasons`` (an iterable of refusals or None), or None."""
    return next((why for why in reasons if why), None)


@dataclass(frozen=True)
class Refusal:
    """Why a symbol is not fused: ``what`` keeps it out (``an operation no kernel takes``), the construct
    (its text, as ``grammarc check --dump-ir`` prints it, cut short of its bodies; its name: the text's first word) and where it is, or only ``what`` for a reason of the symbol itself."""

    what: str
    text: str = ""
    span: Span | None = None

    @property
    def name(self) -> str:
        return self.text.replace("(", " ").split()[0] if self.text else ""

    def __str__(self) -> str:
        return self.what + (f": `{self.text}`" if self.text else "") + (f" at {self.span}" if self.span else "")


def _refused(node, what: str) -> Refusal:
    if isinstance(node, (ir.Case, ir.Stochastic)):  # printed as its bodies: named by its first branch
        text = f"{'case' if isinstance(node, ir.Case) else '%'} {print_expr(node.branches[0][0])}"
    else:
        text = (print_op(node) if isinstance(node, ir.Op) else print_expr(node)).split("{")[0].strip()
    return Refusal(what, text if len(text) <= 60 else text[:57] + "...", node.span)


def symbol_refusals(plan) -> dict[str, Refusal]:
    """Why each symbol with rules is not fused, by name: its first refusal (what ``grammarc check
    --fusion`` lists, with ``grammar_refusals``; symbols fused are left out)."""
    fusible = Fusible(plan)
    return {sym.name: why for sym in plan.symbols if sym.rules and (why := fusible.refusal(sym.id))}


def applied_rules(sym) -> tuple[ir.Rule, ...]:
    """The rules of ``sym`` that may apply: up to the first without a guard (``execute.apply_all``)."""
    for k, rule in enumerate(sym.rules):
        if rule.guard is None:
            return sym.rules[:k + 1]
    return sym.rules
