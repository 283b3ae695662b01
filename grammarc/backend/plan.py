"""The executable form of a grammar: symbols numbered, rules grouped per symbol, strings interned.

The derivation looks everything up here by symbol id; nothing in it refers to syntax.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from grammarc.backend.leaf_parts import leaf_inserts
from grammarc.backend.occlusion import ANCESTORS
from grammarc.compiler import Grammar
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_exprs, iter_ops, op_exprs

#: The per-shape column of the colour set by ``color()``: 0xRRGGBB as a float (white to begin with).
COLOR_SLOT = "#color"
WHITE_RGB = float(0xFFFFFF)


class Strings:
    """Interned strings: a string value in a column is an int32 id, compared by equality.

    Each worker process has its own table (``grammarc.workers``): ids never leave the process that made
    them (reports and records carry the strings)."""

    def __init__(self) -> None:
        self.ids: dict[str, int] = {}

    def intern(self, text: str) -> int:
        return self.ids.setdefault(text, len(self.ids))


@dataclass(frozen=True)
class SymbolPlan:
    id: int
    name: str
    #: The symbol's rules in source order (empty for a terminal symbol).
    rules: tuple[ir.Rule, ...]
    #: The stage at which shapes of this symbol are derived: the lowest priority of its rules.
    priority: int
    param_types: tuple[ir.Type, ...]

    @property
    def terminal(self) -> bool:
        return not self.rules


@dataclass(frozen=True)
class Plan:
    grammar: Grammar
    symbols: tuple[SymbolPlan, ...]
    symbol_ids: dict[str, int]
    start: int
    strings: Strings
    #: Distinct priorities in derivation order (lowest first).
    stages: tuple[int, ...]
    #: Per-shape values: attributes that rules ``set`` and the split/comp context the grammar reads
    #: (``split.index``...): name -> index into ``Shapes.dynamic``.
    dynamic: dict[str, int]
    #: CityEngine semantics: a body that makes no successor leaves its shape as a leaf.
    leaf_bodies: bool
    #: Names of operations accepted without effect on the record (material, UV, print).
    not_applied: tuple[str, ...]
    #: Interned string id -> asset id, for assets named by computed strings (``i(asset)``); -1: none.
    asset_of_string: dict[int, int]
    #: Symbols whose rules ask occlusion queries (they wait for the rest of their stage), and whether
    #: any query looks at other lots (then the build derives twice: ``backend.occlusion``).
    queries: frozenset[int] = frozenset()
    inter: bool = False
    #: Symbols whose rules split on snap planes: each lot's shapes are taken one after the other
    #: (``Executor.apply``).
    snapping: frozenset[int] = frozenset()
    #: Symbols whose rule only places an asset, by id: split parts naming them skip the shape stage
    #: (``backend.leaf_parts``).
    leaf_inserts: dict = field(default_factory=dict)

    @property
    def symbol_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.symbols)


def make_plan(grammar: Grammar) -> Plan:
    module = grammar.module
    names = list(grammar.graph.nonterminals) + list(grammar.graph.terminals)
    ids = {name: i for i, name in enumerate(names)}
    param_types = dict(module.param_types)
    symbols = []
    for i, name in enumerate(names):
        rules = tuple(r for r in module.rules if r.symbol == name)
        priority = min((r.priority for r in rules), default=0)
        symbols.append(SymbolPlan(i, name, rules, priority, param_types.get(name, ())))
    strings = Strings()
    for expr in _all_exprs(module):
        if isinstance(expr, ir.Str):
            strings.intern(expr.value)
    stages = tuple(sorted({s.priority for s in symbols if s.rules}))
    ops = [op for rule in module.rules for alt in rule.alternatives for op in iter_ops(alt.body)]
    context = [e.name for e in _all_exprs(module) if isinstance(e, ir.ContextRef)]
    colour = [COLOR_SLOT] if any(isinstance(op, ir.SetColor) for op in ops) else []
    # CityEngine trims inserted geometry at the planes a comp(f) leaves between neighbouring faces
    trims = list(TRIM_SLOTS) if module.dialect == "cityengine" and any(
        isinstance(op, ir.CompFaces) and op.kind == "f" for op in ops) and any(
        isinstance(op, ir.UseAsset) for op in ops) else []
    occlusion = {symbol.id: [e for rule in symbol.rules for e in _rule_exprs(rule) if isinstance(e, ir.Occlusion)]
                 for symbol in symbols}
    occlusion = {k: v for k, v in occlusion.items() if v}
    ancestors = list(ANCESTORS) if occlusion or any(isinstance(op, ir.Label) for op in ops) else []
    dynamic = {name: i for i, name in enumerate(dict.fromkeys(
        [op.name for op in ops if isinstance(op, ir.SetAttr)] + sorted(set(context)) + colour + trims
        + ancestors))}
    not_applied = tuple(sorted({op.name for op in ops if isinstance(op, ir.NotApplied)}))
    strings.intern("")
    for answer in ("none", "part", "full"):  # of Shape.occ
        strings.intern(answer)
    for selector in ir.FACE_SELECTORS:
        strings.intern(selector)
    asset_of_string = {strings.intern(raw): asset for raw, asset in grammar.asset_ids.items()}
    plan = Plan(grammar, tuple(symbols), ids, ids[grammar.graph.start], strings, stages, dynamic,
                module.dialect == "cityengine", not_applied, asset_of_string, frozenset(occlusion),
                any(e.target != "intra" for found in occlusion.values() for e in found),
                frozenset(s.id for s in symbols if any(getattr(op, "snap", False) for rule in s.rules
                                                       for alt in rule.alternatives for op in iter_ops(alt.body))))
    return replace(plan, leaf_inserts=leaf_inserts(plan))


#: Per-shape columns of a shape's two vertical trim planes, (nx, ny, nz, d) each in world coordinates:
#: inserted geometry keeps the side where n . X + d >= 0 (NaN: no plane).
TRIM_SLOTS = tuple(f"trim.{k}" for k in range(8))
#: ``set(trim.vertical, false)`` turns the planes off for a shape and its successors (1: on, 0: off).
TRIM_SWITCH = "trim.vertical"


#: Operations after which a body's shape is not the body's to emit: it was replaced by successors, split
#: into parts, deleted, or handed to case branches (which emit their own leaves).
_CONSUMING = (ir.Symbol, ir.Empty, ir.Split, ir.Repeat, ir.Comp, ir.GroupSplit, ir.CompFaces, ir.Insert,
              ir.Case, ir.Stochastic, ir.Setback, ir.InnerRectangle)


def consumes(body: ir.Body) -> bool:
    """Whether ``body`` replaces its shape (CityEngine: a body that does not leaves a leaf)."""
    return any(isinstance(op, _CONSUMING) for op in body)


def _all_exprs(module: ir.Module):
    for attr in module.attrs:
        yield from iter_exprs(attr.default)
    for rule in module.rules:
        yield from _rule_exprs(rule)


def _rule_exprs(rule: ir.Rule):
    roots = [rule.guard] if rule.guard is not None else []
    for alt in rule.alternatives:
        if alt.prob is not None:
            roots.append(alt.prob)
        for op in iter_ops(alt.body):
            roots.extend(op_exprs(op))
    for root in roots:
        yield from iter_exprs(root)
