"""The executable form of a grammar: symbols numbered, rules grouped per symbol, strings interned.

The derivation looks everything up here by symbol id; nothing in it refers to syntax.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from grammarc.backend.fusion import fused_regions
from grammarc.backend.leaf_parts import leaf_inserts
from grammarc.backend.materials import COLOR_FIELDS, MAP_FIELDS
from grammarc.backend.slots import (
    ANCESTORS,
    COLOR_SLOT,
    HORIZONTAL_SWITCH,
    PIVOT_SLOTS,
    RING_START,
    TRIM_INSERTED,
    TRIM_PLANES,
    TRIM_SWITCH,
    uv_slots,
)
from grammarc.backend.trim_reads import unread_plane_sites
from grammarc.geometry.trim import HORIZONTAL_PLANES, VERTICAL_PLANES
from grammarc.ir import nodes as ir
from grammarc.ir.printer import comp_selectors
from grammarc.ir.traverse import all_exprs, iter_ops
from grammarc.model.assets import load_asset
from grammarc.model.grammar import Grammar


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
    #: Names of operations accepted without effect on the record (material, texture, print).
    not_applied: tuple[str, ...]
    #: Interned string id -> asset id, for assets named by computed strings (``i(asset)``); -1: none.
    asset_of_string: dict[int, int]
    #: Symbols whose rules ask occlusion queries (they wait for the rest of their stage), and whether
    #: any query looks at other lots (then the build derives twice: ``backend.occlusion``).
    queries: frozenset[int] = frozenset()
    inter: bool = False
    #: Symbols whose rules split on snap planes: each lot's shapes are taken one after the other
    #: (``execute.apply``).
    snapping: frozenset[int] = frozenset()
    #: Symbols whose rule only places an asset, by id: split parts naming them skip the shape stage
    #: (``backend.leaf_parts``).
    leaf_inserts: dict = field(default_factory=dict)
    #: Symbols whose pending shapes fused kernels derive, by id: their ``backend.fusion.Region``.
    fused: dict = field(default_factory=dict)
    #: Indices into ``Shapes.dynamic`` of the columns the derivation adds (``backend.slots``), None where
    #: the grammar needs none: the colour (else no colours are recorded and the rows are white), the id of
    #: the trim planes (``slots.TRIM_PLANES``, when inserted geometry is trimmed) and ``trim.vertical`` (when
    #: the grammar sets it).
    color_slot: int | None = None
    #: The texture channels the grammar sets or reads: (index into ``ir.MATERIAL_MAPS``, index into
    #: ``Shapes.dynamic``) each (``backend.materials``).
    material_slots: tuple[tuple[int, int], ...] = ()
    trim_slot: int | None = None
    #: The sites of the ``comp(f)`` splits whose faces' trim planes nothing reads (``backend.trim_reads``): their
    #: faces keep the planes their shape had, unread.
    unread_planes: frozenset[int] = frozenset()
    trim_switch: int | None = None
    #: whether each shape's geometry was inserted (``slots.TRIM_INSERTED``), where shapes have trim planes.
    inserted_slot: int | None = None
    #: whether the trim planes' rows hold horizontal planes too, and ``trim.horizontal``: where the grammar
    #: turns them on.
    horizontal_planes: bool = False
    horizontal_switch: int | None = None
    #: Whether shapes carry their occluding ancestors (``backend.occlusion``): the grammar asks occlusion
    #: queries or labels shapes.
    occluders: bool = False
    #: Texture set -> index into ``Shapes.dynamic`` of its two columns (``slots.uv_slots``), for the sets
    #: the grammar's texture operations and queries name; empty: no shape carries texture coordinates.
    uv_slots: dict = field(default_factory=dict)
    #: Index into ``Shapes.dynamic`` of the first of the pivot's columns (``backend.pivot``), None where the
    #: grammar needs no pivot of its own.
    pivot_slot: int | None = None
    #: Index into ``Shapes.dynamic`` of the corner each box's ring starts at (``backend.box_rings``), None
    #: where the grammar turns no scope around a rectangle whose edges it numbers.
    ring_slot: int | None = None
    #: ``load_asset(name, asset_roots) -> AssetMesh``: how trimmed inserts get their asset's triangles
    #: (the model's loader, or a test's stand-in).
    load_asset: Callable = load_asset
    #: CityEngine semantics: shapes draw from PRT's sequential stream, not from counter-based keys
    #: (``backend.streams``).
    sequential_random: bool = False

    @property
    def trim_width(self) -> int:
        """The width of a row of the chunk's ``TrimPlanes``: the vertical planes, then any horizontal ones."""
        return 4 * (VERTICAL_PLANES + (HORIZONTAL_PLANES if self.horizontal_planes else 0))

    @property
    def symbol_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.symbols)

    def makes_leaves(self, successor: ir.Symbol) -> bool:
        """Whether ``successor``'s shapes are leaves (records) at once: a symbol without rules, or ``X.``."""
        return successor.leaf or self.symbols[self.symbol_ids[successor.name]].terminal


def make_plan(grammar: Grammar, *, load_asset: Callable = load_asset) -> Plan:
    """The plan of ``grammar``; ``load_asset(name, asset_roots) -> AssetMesh`` loads the assets whose
    inserts are trimmed (``Plan.load_asset``)."""
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
    for expr in all_exprs(module):
        if isinstance(expr, ir.Str):
            strings.intern(expr.value)
    stages = tuple(sorted({s.priority for s in symbols if s.rules}))
    ops = iter_ops(module)
    # the colour's components and the opacity are read from the colour column (``backend.materials``)
    context = [e.name for e in all_exprs(module) if isinstance(e, ir.ContextRef) and e.name not in COLOR_FIELDS]
    colour = [COLOR_SLOT] if any(isinstance(op, (ir.SetColor, ir.SetOpacity, ir.SetMaterial)) for op in ops) else []
    # setMaterial's names are known per shape only: every texture channel gets its column
    colour += list(MAP_FIELDS) if any(isinstance(op, ir.SetMaterial) for op in ops) else []
    # CityEngine trims inserted geometry (assets, primitives) at the planes a comp(f) leaves between
    # neighbouring faces, and a shape's own where it says `trim()`
    trims = [TRIM_PLANES, TRIM_INSERTED] if module.dialect == "cityengine" and any(
        isinstance(op, ir.CompFaces) and op.kind == "f" for op in ops) and any(
        isinstance(op, (ir.UseAsset, ir.Primitive, ir.Trim)) for op in ops) else []
    # horizontal planes only where the grammar may turn them on (CityEngine's default is off)
    horizontal = bool(trims) and any(
        isinstance(op, ir.SetAttr) and op.name == HORIZONTAL_SWITCH
        and not (isinstance(op.value, ir.Bool) and not op.value.value) for op in ops)
    occlusion = {symbol.id: [e for rule in symbol.rules for e in all_exprs(rule) if isinstance(e, ir.Occlusion)]
                 for symbol in symbols}
    occlusion = {k: v for k, v in occlusion.items() if v}
    ancestors = list(ANCESTORS) if occlusion or any(isinstance(op, ir.Label) for op in ops) else []
    uv_sets = texture_sets(module, ops)
    pivot = list(PIVOT_SLOTS) if uses_pivot(module, ops, all_exprs(module)) else []
    ring = [RING_START] if renumbers_boxes(module, ops) else []
    dynamic = {name: i for i, name in enumerate(dict.fromkeys(
        [op.name for op in ops if isinstance(op, ir.SetAttr)] + sorted(set(context)) + colour + trims
        + ancestors + [name for s in uv_sets for name in uv_slots(s)] + pivot + ring))}
    not_applied = tuple(sorted({op.name for op in ops if isinstance(op, ir.NotApplied)}))
    strings.intern("")
    for answer in ("none", "part", "full"):  # of Shape.occ
        strings.intern(answer)
    for selector in ir.FACE_SELECTORS:
        strings.intern(selector)
    asset_of_string = {strings.intern(raw): asset for raw, asset in grammar.asset_ids.items()}
    for op in ops:  # comp.sel of every selector (after the ids above, which stay as they were)
        if isinstance(op, ir.CompFaces):
            for text in comp_selectors(op):
                strings.intern(text)
    trim_slot = dynamic.get(TRIM_PLANES)
    plan = Plan(
        grammar=grammar, symbols=tuple(symbols), symbol_ids=ids, start=ids[grammar.graph.start], strings=strings,
        stages=stages, dynamic=dynamic, leaf_bodies=module.dialect == "cityengine", not_applied=not_applied,
        sequential_random=module.dialect == "cityengine",
        asset_of_string=asset_of_string, queries=frozenset(occlusion),
        inter=any(e.target != "intra" for found in occlusion.values() for e in found),
        snapping=frozenset(s.id for s in symbols if any(getattr(op, "snap", False) for rule in s.rules
                                                        for op in iter_ops(rule))),
        color_slot=dynamic.get(COLOR_SLOT), trim_slot=trim_slot,
        unread_planes=unread_plane_sites(module, grammar.graph.start) if trim_slot is not None else frozenset(),
        material_slots=tuple((k, dynamic[name]) for k, name in enumerate(MAP_FIELDS) if name in dynamic),
        trim_switch=dynamic.get(TRIM_SWITCH) if trim_slot is not None else None,
        inserted_slot=dynamic.get(TRIM_INSERTED),
        horizontal_planes=horizontal, horizontal_switch=dynamic.get(HORIZONTAL_SWITCH),
        occluders=ANCESTORS[0] in dynamic, load_asset=load_asset,
        uv_slots={s: dynamic[uv_slots(s)[0]] for s in uv_sets}, pivot_slot=dynamic.get(PIVOT_SLOTS[0]),
        ring_slot=dynamic.get(RING_START))
    plan = replace(plan, leaf_inserts=leaf_inserts(plan))
    return replace(plan, fused=fused_regions(plan))


#: CityEngine's queries of texture coordinates, whose first argument (0 when left out) names the set.
UV_QUERIES = frozenset(f"geometry.{name}" for name in ("uMin", "uMax", "vMin", "vMax", "du", "dv"))


def texture_sets(module: ir.Module, ops) -> list[int]:
    """The texture sets the grammar's operations and queries name, in order (the lowering made each a
    whole number)."""
    sets = {op.uv_set for op in ops if isinstance(op, TEXTURE_OPS) or (isinstance(op, ir.GroupSplit)
                                                                     and op.uv_set >= 0)}
    sets |= {op.source for op in ops if isinstance(op, ir.CopyUV)}
    for expr in all_exprs(module):
        if isinstance(expr, ir.Call) and expr.func in UV_QUERIES:
            sets.add(int(expr.args[0].value) if expr.args and isinstance(expr.args[0], ir.Num) else 0)
    return sorted(sets)


def uses_pivot(module: ir.Module, ops, exprs) -> bool:
    """Whether the shapes of ``module`` (its operations ``ops``, its expressions ``exprs``) need pivots of their
    own (``backend.pivot``)."""
    if module.dialect != "cityengine":
        return False
    for op in ops:
        if isinstance(op, ir.SetPivot) or (isinstance(op, ir.Transform) and op.system == "pivot"):
            return True
        angles = op.angles if isinstance(op, ir.Rotate) and op.fixed else \
            op.angles if isinstance(op, ir.AlignScope) and op.mode == "rotate" else ()
        if sum(not (isinstance(a, ir.Num) and a.value == 0) for a in angles) > 1:
            return True
    for expr in exprs:
        if isinstance(expr, ir.ScopeRef) and expr.field[0] in "tr":
            return True
        if isinstance(expr, ir.Call) and expr.func == "convert" and any(
                isinstance(a, ir.Str) and a.value == "pivot" for a in expr.args[1:3]):
            return True
    return False


#: Operations that turn a scope around its geometry, restarting a box's implicit ring at the new scope.
REFRAMING_OPS = (ir.AlignScope, ir.AlignToGeometry, ir.AlignScopeToBBox)
#: Operations whose results depend on where a face's ring starts: its edges' and side faces' numbers
#: (``comp``, ``setback`` and ``shapeL/U/O`` by edge), and where pieces cut or moved in from it start.
RING_OPS = (ir.Comp, ir.CompFaces, ir.Setback, ir.SetbackToArea, ir.Offset)


def renumbers_boxes(module: ir.Module, ops) -> bool:
    """Whether shapes of ``module`` need the corner their box's ring starts at (``backend.box_rings``):
    a CityEngine grammar that turns scopes (``rotateScope``, ``alignScopeToAxes``...) and numbers edges or
    cuts faces. PRT keeps a polygon's vertex order whatever its scope; elsewhere a rectangle turned with
    its scope starts its ring where the new scope does, as before."""
    return module.dialect == "cityengine" and any(isinstance(op, REFRAMING_OPS) for op in ops) and any(
        isinstance(op, RING_OPS) for op in ops)


TEXTURE_OPS = (ir.SetupProjection, ir.ProjectUV, ir.TransformUV, ir.TileUV, ir.NormalizeUV, ir.CopyUV,
               ir.InsertAlongUV)
