"""IR nodes: frozen, slotted dataclasses, one class per construct, each with its source span.

A ``Module`` holds attribute declarations and rules. A ``Rule`` rewrites a symbol: an optional guard and
one or more stochastic ``Alternative``s, each a ``Body`` (a tuple of operations executed in order on the
current scope). Expressions are typed trees (``Type``); names are resolved by ``passes.resolve`` from
``Name`` into ``Param`` or ``AttrRef``.

Every node declares its children once, on its fields (``child``): which fields hold expressions, and of
which type they must be, which hold bodies. ``traverse`` walks and rebuilds any node from these
declarations, ``passes.types`` checks the expressions against them and ``printer`` prints a node it has
no format for from them, so a new operation is its class here and nothing in those three.

Geometry conventions (shared with the backend): a scope has an origin, three orthonormal axes (rows of a
3x3 matrix, right-handed) and a size. Angles are in degrees. Axis indices are 0, 1, 2 for x, y, z.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import Field, dataclass, field, fields
from enum import Enum
from pathlib import Path
from typing import Any

from grammarc.diagnostics import NO_SPAN, Span


class Type(Enum):
    NUM = "num"
    BOOL = "bool"
    STR = "str"
    #: CityEngine's arrays (``float[]``, ``bool[]``, ``string[]``): 1-D or 2-D, of one element type.
    NUMS = "num[]"
    BOOLS = "bool[]"
    STRS = "str[]"
    UNKNOWN = "unknown"

    @property
    def is_array(self) -> bool:
        return self in _ELEMENTS

    @property
    def element(self) -> Type:
        """The element type of an array type; a scalar type is its own."""
        return _ELEMENTS.get(self, self)

    @property
    def array(self) -> Type:
        """The array type of a scalar type (UNKNOWN for UNKNOWN); an array type is its own."""
        return _ARRAYS.get(self, self)


_ELEMENTS = {Type.NUMS: Type.NUM, Type.BOOLS: Type.BOOL, Type.STRS: Type.STR}
_ARRAYS = {element: array for array, element in _ELEMENTS.items()}


class SizeKind(Enum):
    ABSOLUTE = "abs"
    RELATIVE = "rel"
    #: CityEngine's `~` sizes; the paper notation has none, the CityEngine frontend will lower to it.
    FLOATING = "float"


# ---------------------------------------------------------------------------------------------- declarations


class Holds(Enum):
    """What a child field holds, which says where a walk finds its expressions and bodies."""

    #: Expressions, alone or in (nested) tuples and ``Size``s, with plain values (str, int, bool) beside
    #: them: the node's own arguments.
    EXPRS = "exprs"
    #: One body (a tuple of operations).
    BODY = "body"
    #: A tuple of bodies (the parts of a split).
    BODIES = "bodies"
    #: ``(condition, body)`` pairs (the branches of ``case`` and of a stochastic choice).
    BRANCHES = "branches"
    #: A tuple of nodes walked on their own (a module's rules, a rule's alternatives).
    NODES = "nodes"


@dataclass(frozen=True, slots=True)
class Child:
    """The declaration of one child field (see ``child``)."""

    want: Type | Callable[[Any], Type | None] | None
    what: str | tuple[str, ...] | Callable[[Any], str]
    holds: Holds

    def want_of(self, node) -> Type | None:
        """The type the field's expressions must have in ``node``; None: not checked from here."""
        return self.want(node) if callable(self.want) else self.want

    def what_of(self, node) -> str | tuple[str, ...]:
        return self.what(node) if callable(self.what) else self.what


def child(want: Type | Callable | None = None, what: str | tuple | Callable = "", *,
          holds: Holds = Holds.EXPRS, **options) -> Field:
    """A dataclass field that holds children of the node, declared once for every walker.

    ``want`` is the type the field's expressions must have (``passes.types`` checks it), or a function of
    the node for the few that depend on it, or None where the checker types them another way. ``what``
    names them in the type error ("a size must be a num, got a str"): a string, a function of the node,
    or a tuple of nouns taken in turn for the field's expressions (``Roof.sides``: height, angle, height,
    ...). ``holds`` says what the field holds; ``options`` go to ``dataclasses.field`` (``default=``).
    A plain field (a string, a number) may be declared too, so that the printer shows it.
    """
    return field(metadata={_CHILD: Child(want, what, holds)}, **options)


_CHILD = "grammarc.child"
_DECLARED: dict[type, tuple[tuple[str, Child], ...]] = {}


def children(cls: type) -> tuple[tuple[str, Child], ...]:
    """The declared child fields of a node class, as (field name, declaration) in field order.

    Read from the dataclass fields once per class: every walk asks for every node it visits.
    """
    declared = _DECLARED.get(cls)
    if declared is None:
        declared = _DECLARED[cls] = tuple((f.name, f.metadata[_CHILD]) for f in fields(cls)
                                          if _CHILD in f.metadata)
    return declared


# ----------------------------------------------------------------------------------------------- expressions


@dataclass(frozen=True, slots=True)
class Num:
    value: float
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Str:
    value: str
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Bool:
    value: bool
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Name:
    """An identifier before name resolution."""

    name: str
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Param:
    """The ``index``-th parameter of the rule being applied."""

    index: int
    name: str
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class AttrRef:
    """A control parameter: its default, overridden per lot or by ``--attr``."""

    name: str
    span: Span = NO_SPAN


#: The attribute name of ``placeholder``: no declaration can have it.
PLACEHOLDER = "<error>"


def placeholder(span: Span = NO_SPAN) -> AttrRef:
    """A stand-in for an expression whose error is already reported.

    It names no declared attribute, so its type is unknown and no second error cascades from it (a
    typed stand-in such as ``0`` would make ``Shape.occ("all") == "none"`` a type error too). Only
    modules with errors hold one, and those are never derived.
    """
    return AttrRef(PLACEHOLDER, span)


#: Scope fields readable from expressions: size, translation (origin) and rotation (degrees, x then y
#: then z, relative to the lot's scope) per axis; ``ox oy oz``: the lot's scope origin in the world.
SCOPE_FIELDS = ("sx", "sy", "sz", "tx", "ty", "tz", "rx", "ry", "rz", "ox", "oy", "oz")


@dataclass(frozen=True, slots=True)
class ScopeRef:
    field: str
    span: Span = NO_SPAN


#: Unary operators and the type each takes and gives.
UNARY_TYPES = {"-": Type.NUM, "!": Type.BOOL, ".-": Type.NUMS, ".!": Type.BOOLS}


@dataclass(frozen=True, slots=True)
class Unary:
    op: str  # "-", "!", and on arrays ".-", ".!"
    operand: Expr = child(lambda e: UNARY_TYPES[e.op], lambda e: f"the operand of `{e.op}`")
    span: Span = NO_SPAN


#: Binary operators by category; the category decides the result type. CityEngine's element-wise
#: operators on arrays are these with a dot before them (``.+``, ``.<``, ``.&&``).
COMPARE_OPS = frozenset({"<", "<=", ">", ">=", "==", "!="})
LOGIC_OPS = frozenset({"&&", "||"})


@dataclass(frozen=True, slots=True)
class Binary:
    op: str
    #: typed by the operator (``passes.types.type_of``): ``==`` takes any one type, ``+`` strings too
    left: Expr = child()
    right: Expr = child()
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Call:
    """A built-in function (``ir.functions``). ``site`` numbers the call so that ``rand`` draws differ per
    call site."""

    func: str
    #: typed by the function's signature (``passes.types``)
    args: tuple[Expr, ...] = child(None, lambda e: f"an argument of `{e.func}`")
    span: Span = NO_SPAN
    site: int = 0


#: CityEngine's texture channels (``material.colormap``...), in the order of the record's ``materials``.
MATERIAL_MAPS = ("colormap", "bumpmap", "dirtmap", "specularmap", "opacitymap", "normalmap", "emissivemap",
                 "occlusionmap", "roughnessmap", "metallicmap")
#: The material attributes a shape carries and expressions read: its texture channels, its colour and opacity.
MATERIAL_FIELDS = {**{f"material.{m}": Type.STR for m in MATERIAL_MAPS},
                   **{f"material.color.{c}": Type.NUM for c in "rgb"}, "material.opacity": Type.NUM}
#: What a shape knows of the split or component split that made it (CityEngine's ``split.index``...), and
#: its material.
CONTEXT_FIELDS = {"split.index": Type.NUM, "split.total": Type.NUM, "comp.index": Type.NUM,
                  "comp.total": Type.NUM, "comp.sel": Type.STR, **MATERIAL_FIELDS}


@dataclass(frozen=True, slots=True)
class ContextRef:
    """``split.index``, ``split.total``, ``comp.index``, ``comp.total``, ``comp.sel`` and the material
    attributes (``MATERIAL_FIELDS``) of the shape."""

    name: str
    span: Span = NO_SPAN


#: CityEngine's occlusion queries, its context queries that give numbers, and their targets.
OCCLUSION_KINDS = frozenset({"inside", "overlaps", "touches"})
CONTEXT_KINDS = frozenset({"minimumDistance", "contextCount"})
OCCLUSION_TARGETS = frozenset({"intra", "inter", "all"})


@dataclass(frozen=True, slots=True)
class Occlusion:
    """CityEngine's ``inside`` / ``overlaps`` / ``touches([target[, label]])``: whether the shape's
    geometry lies in, overlaps or touches a closed occluder of its own lot (``intra``), of other lots
    (``inter``) or of either (``all``), of any label or of ``label`` (``backend.occlusion``). The
    paper's ``Shape.occ(...)`` is kind ``occ``: ``"none"``, ``"part"`` or ``"full"``, against the shapes
    of every lot, its ancestors too unless ``parents`` is false, leaves only if ``active``, the scope
    enlarged by ``distance``.

    CityEngine's target may be computed, ``inside(sel(text), ...)`` (``sel`` makes a selector of a
    string): ``which`` is that string per shape, in place of ``target``; a label may be any string
    expression, ``named``, in place of the constant ``label``.

    The context queries (``CONTEXT_KINDS``) are numbers: ``minimumDistance`` the distance from the
    shape's scope to the nearest scope labelled ``label`` (or ``named``) of the target's lots,
    ``contextCount`` the number of shapes labelled so."""

    kind: str
    target: str
    label: str | None
    span: Span = NO_SPAN
    parents: bool = False
    active: bool = False
    distance: Expr | None = child(Type.NUM, "a distance", default=None)
    which: Expr | None = child(Type.STR, "an occlusion target", default=None)
    named: Expr | None = child(Type.STR, "an occlusion label", default=None)


@dataclass(frozen=True, slots=True)
class Select:
    """``cond ? then : other`` per shape: CityEngine's ``case`` and ``p% :`` expressions lower to it."""

    cond: Expr = child(Type.BOOL, "a condition")
    #: of one type, whichever it is (``passes.types.type_of``)
    then: Expr = child()
    other: Expr = child()
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class ArrayLit:
    """CityEngine's array initialization ``[a, b ; c, d]``: ``rows`` separated by ``;``, each the values
    separated by ``,``. A value may be an array (``Range`` too): it is concatenated in place, so
    ``[0, [1, 2]]`` is ``[0, 1, 2]`` and ``[a ; b]`` stacks the rows of ``a`` over those of ``b``."""

    #: of one element type, scalars or arrays (``passes.types.type_of``)
    rows: tuple[tuple[Expr, ...], ...] = child()
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Range:
    """CityEngine's colon operator ``base : step : limit`` inside brackets: the numbers base, base + step,
    ... up to ``limit`` (included), as a 1-row array; empty when ``step`` goes away from ``limit``."""

    base: Expr = child(Type.NUM, "the start of a range")
    step: Expr = child(Type.NUM, "the step of a range")
    limit: Expr = child(Type.NUM, "the end of a range")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Index:
    """CityEngine's index operator ``a[i]`` (linear, row by row) and ``a[i, j]`` (row, column). An index
    that is an array selects several elements (bool arrays: where true) and gives an array shaped like
    it; an index out of range gives the element type's default (0, false, "")."""

    array: Expr = child()  # an array (``passes.types.type_of``)
    #: numbers or arrays of numbers or bools (``passes.types.type_of``)
    index: Expr = child()
    column: Expr | None = child(default=None)
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Choose:
    """``choose(a, b, c)``: a set of consequents, one per value (GRAMATICA's operators). A search fixes
    which value each state takes; a build draws one from the shape's stream at ``site``, all equally
    likely, so that a search grammar also builds."""

    #: of one type, whichever it is (``passes.types.type_of``)
    options: tuple[Expr, ...] = child(None, "an option of `choose`")
    span: Span = NO_SPAN
    site: int = 0


#: The aggregates over a design's shapes of one symbol, and what each reads of a shape: ``count`` the
#: shapes (or those where a bool holds), ``area`` and ``volume`` their scopes', the others a number.
AGGREGATES = ("count", "sum", "min", "max", "mean", "area", "volume")


@dataclass(frozen=True, slots=True)
class Aggregate:
    """``count("room")``, ``sum(Scope.sx of "room")``, ``area("room")``...: a value of a whole design (a
    search state), over the shapes its derivation gave ``symbol``; only the search statements
    (``Objective``) read them."""

    func: str
    symbol: str
    value: Expr | None = child(lambda e: Type.BOOL if e.func == "count" else Type.NUM,
                               lambda e: f"the value `{e.func}` aggregates", default=None)
    span: Span = NO_SPAN


Expr = (Num | Str | Bool | Name | Param | AttrRef | ScopeRef | Unary | Binary | Call | Select | ContextRef
        | Occlusion | ArrayLit | Range | Index | Choose | Aggregate)

#: CityEngine shape attributes that ``set`` changes for a shape and its successors (not declared attrs).
SHAPE_ATTRIBUTES: dict[str, Type] = {"trim.vertical": Type.BOOL, "trim.horizontal": Type.BOOL,
                                     **{f"material.{m}": Type.STR for m in MATERIAL_MAPS}}

# ------------------------------------------------------------------------------------------------ operations


@dataclass(frozen=True, slots=True)
class Size:
    """One size of ``S`` or ``Subdiv``: an expression and whether it is absolute or relative (``1r``)."""

    kind: SizeKind
    value: Expr = child()  # checked as the size of the operation that holds it
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Symbol:
    """Create a shape with this symbol on the current scope (a successor shape).

    ``leaf`` (CityEngine's ``X.``): the shape is a leaf named ``name`` even if ``name`` has rules.
    """

    name: str
    #: typed by the parameters of ``name``'s rules (``passes.types``)
    args: tuple[Expr, ...] = child()
    span: Span = NO_SPAN
    site: int = 0
    leaf: bool = False


@dataclass(frozen=True, slots=True)
class Empty:
    """The empty shape (``ε``, ``epsilon``, ``null``): nothing is created."""

    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Translate:
    """``T(x,y,z)``: move the scope origin along its own axes."""

    vector: tuple[Expr, Expr, Expr] = child(Type.NUM, "a translation")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Scale:
    """``S(x,y,z)``: set the scope size; relative sizes scale the current size. A negative size fails the
    shape, or, when ``mirrors`` (CityEngine's ``s``), mirrors it along that axis (``operations.scope``)."""

    sizes: tuple[Size, Size, Size] = child(Type.NUM, "a size")
    span: Span = NO_SPAN
    mirrors: bool = False


@dataclass(frozen=True, slots=True)
class Rotate:
    """Rotate the scope axes by angles in degrees, around the origin, or around the scope's centre when
    ``center`` (CityEngine ``r(scopeCenter, x, y, z)``): about its own x, then the new y, then the new z
    (the paper's ``R``), or, when ``fixed``, about its x, then y, then z as they were (CityEngine's ``r``:
    ``backend.euler``)."""

    angles: tuple[Expr, Expr, Expr] = child(Type.NUM, "an angle")
    span: Span = NO_SPAN
    center: bool = False
    fixed: bool = False


@dataclass(frozen=True, slots=True)
class Push:
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Pop:
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Insert:
    """``I("name")``: an instance of an asset mapped onto the scope box."""

    asset: str
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Split:
    """``Subdiv(axes, sizes...){parts}``: split the scope along one or more axes.

    With several axes, the scope is split along the first axis, then every part along the next axis,
    with the same sizes; cells are numbered with the first axis varying fastest. Part ``i`` of the body
    applies to cell ``i`` modulo the number of parts.
    """

    axes: tuple[int, ...]
    sizes: tuple[Size, ...] = child(Type.NUM, "a size")
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0
    #: ``Subdiv("XS", ...)``: each snap plane across the scope moves the split line nearest to it (paper
    #: section 3.3); ``snap_label`` names the snap shapes to use (None: all of the lot's).
    snap: bool = False
    snap_label: str | None = None


@dataclass(frozen=True, slots=True)
class Repeat:
    """``Repeat(axes, size per axis){parts}``: ceil(scope size / size) elements per axis, sizes adjusted."""

    axes: tuple[int, ...]
    sizes: tuple[Expr, ...] = child(Type.NUM, "a size")
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0
    #: ``Repeat("XS", ...)``: the snap planes across the scope cut it first and each piece repeats on
    #: its own (paper section 3.3); ``snap_label`` as for ``Split``.
    snap: bool = False
    snap_label: str | None = None


@dataclass(frozen=True, slots=True)
class Label:
    """CityEngine's ``label(name)``: the shape's closed geometry becomes an occluder with that label, a
    string per shape (``label(occlusionLabel)``, an attribute, is common)."""

    name: Expr = child(Type.STR, "a label")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Snap:
    """The paper's ``Snap(axes[, label])`` and ``SnapLines(axes[, label])`` (section 3.3): construction
    planes of the lot, for the snapped splits of later rules. ``normal`` is the scope axis across the
    plane; ``Snap`` puts one plane through the scope's origin, ``SnapLines`` one at each end of the
    scope along ``normal``. The shape itself goes on."""

    normal: int
    label: str | None
    lines: bool
    span: Span = NO_SPAN


#: Component selectors of ``Comp``; those in COMP_INDEXED take an index argument.
COMP_KINDS = frozenset({
    "faces", "sidefaces", "top", "bottom", "edges", "sideedges", "topedges", "bottomedges", "vertices",
    "face", "sideface", "edge", "vertex",
})
COMP_INDEXED = frozenset({"face", "sideface", "edge", "vertex"})


@dataclass(frozen=True, slots=True)
class Comp:
    """``Comp(kind[, index]){parts}``: split into faces, edges or vertices; component i takes part i mod k."""

    kind: str
    index: Expr | None = child(Type.NUM, "a component index")
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class Cut:
    """``Cut(e1, t1, e2, t2){ A | B }`` (GRAMATICA's ice-ray grammar): the shape's polygon in its scope's
    x-z plane divided by the line from the point at fraction ``t1`` of its edge ``e1`` to the point at
    ``t2`` of edge ``e2`` (edges in ring order from its first vertex, modulo their number;
    ``geometry.edge_cuts``). ``A`` takes the piece from the first point on along the ring to the second, ``B``
    the other; each piece's scope is its bounding box in the parent's."""

    edges: tuple[Expr, Expr] = child(Type.NUM, "an edge number")
    at: tuple[Expr, Expr] = child(Type.NUM, "a fraction of an edge")
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class Extrude:
    """CityEngine ``extrude(h)`` and ``extrude(direction, h)``: a flat shape becomes a solid along its
    normal (its flat scope axis; ``face.normal``, ``vertex.normal``) or the world's up axis (``world.up``,
    ``world.up.flatTop``, one of ``EXTRUDE_DIRECTIONS``); a negative height extrudes the other way."""

    height: Expr = child(Type.NUM, "a height")
    span: Span = NO_SPAN
    direction: str = "face.normal"


#: ``extrude``'s directions: CityEngine's names (``world.y`` is an older spelling of ``world.up``).
EXTRUDE_DIRECTIONS = frozenset({"face.normal", "vertex.normal", "world.up", "world.up.flatTop"})


@dataclass(frozen=True, slots=True)
class Center:
    """CityEngine ``center(axes)``: centre the scope on the scope the body started with (or the last
    ``[``) along the given axes."""

    axes: tuple[int, ...]
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class UseAsset:
    """CityEngine ``i(asset, up, mode)`` and ``primitiveCube()``: the shape's geometry becomes the asset
    placed by ``mode``; the shape goes on (a leaf emits the asset as an instance).

    ``asset`` is the name when it is written as a string; otherwise ``name`` computes it per shape (a
    parameter or constant holding an asset path). ``up`` is the asset's up axis, ``"yUp"`` or ``"zUp"``
    (turned -90 degrees about x); ``mode`` one of ``INSERT_MODES``: fitted to the scope, or the scope
    made the asset's own size, at the asset's own position or centred on the scope's xz. Either may be
    computed, a string per shape (``up_by``, ``mode_by``, in place of ``up`` and ``mode``).
    """

    asset: str
    span: Span = NO_SPAN
    name: Expr | None = child(Type.STR, "an asset name", default=None)
    up: str = "yUp"
    mode: str = "alignSizeAndPosition"
    up_by: Expr | None = child(Type.STR, "an up axis", default=None)
    mode_by: Expr | None = child(Type.STR, "an insert mode", default=None)


#: ``i()``'s up axes and insert modes, the default first.
UP_AXES = ("yUp", "zUp")
INSERT_MODES = ("alignSizeAndPosition", "keepSizeAndPosition", "keepSizeAlignPosition")


@dataclass(frozen=True, slots=True)
class AlignScope:
    """New scope axes, the geometry unchanged: CityEngine ``alignScopeToAxes()`` (``mode`` "world"),
    ``alignScopeToAxes(x|y|z)`` ("x", "y", "z": that world axis, the next axis projected) and
    ``rotateScope(x, y, z)`` ("rotate", ``angles``)."""

    mode: str
    angles: tuple[Expr, Expr, Expr] | None = child(Type.NUM, "an angle", default=None)
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class SetColor:
    """CityEngine ``color(r, g, b)`` (0 to 1 each) or ``color("#rrggbb")``: the shape's colour, which its
    instances and faces carry into the record."""

    values: tuple[Expr, ...] = child(lambda op: Type.STR if len(op.values) == 1 else Type.NUM,
                                     lambda op: "a colour" if len(op.values) == 1 else "a colour component")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Offset:
    """CityEngine ``offset(d, inside|border|all)``: the face's polygon grown (d > 0) or shrunk (d < 0) with
    mitred corners, keeping the inset (``inside``), the ring around it (``border``) or both as the faces
    of one shape (``all``, and ``offset(d)`` that no ``comp(f)`` of them follows)."""

    distance: Expr = child(Type.NUM, "an offset distance")
    select: str
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Mirror:
    """CityEngine ``mirror(x, y, z)``: mirror the geometry along the scope axes whose flag is true."""

    axes: tuple[Expr, Expr, Expr] = child(Type.BOOL, "a mirror flag")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Case:
    """``case c1: B1 case c2: B2 else: B`` inside a body: each shape runs the first branch that holds."""

    branches: tuple[tuple[Expr, Body], ...] = child(Type.BOOL, "a case condition", holds=Holds.BRANCHES)
    default: Body = child(holds=Holds.BODY)
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Stochastic:
    """``30% : B1 20% : B2 else: B``: each shape draws one branch (percentages, ``else`` the rest)."""

    branches: tuple[tuple[Expr, Body], ...] = child(Type.NUM, "a percentage", holds=Holds.BRANCHES)
    default: Body = child(holds=Holds.BODY)
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class SetAttr:
    """CityEngine ``set(attr, value)``: the attribute's value for this shape and its descendants."""

    name: str
    #: typed by the attribute ``name`` (``passes.types``)
    value: Expr = child()
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Report:
    """CityEngine ``report(key, value)``: summed per lot (count, sum, mean, min, max) beside the output."""

    key: Expr = child(what="a report key")  # any type: its text is the key
    value: Expr = child(what="a reported value")  # any type: numbers are summed, other values counted
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class NotApplied:
    """An operation that is accepted but has no effect on the record (the material settings other than
    colours, opacity and texture maps, ``reverseNormals``, ``print``); the output's meta lists it."""

    name: str
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class GroupSplit:
    """CityEngine ``split(axis){ size: A | 'rel: B | ~float: C | { ... }* }[*]``.

    Sizes: absolute, relative to the scope (``'``) or floating (``~``, adjusted so the parts fill the
    scope). ``groups[i]`` is the repeat group of part ``i`` (-1 outside any group); a group repeats as
    often as it fits, rounded when it holds floating sizes. ``repeat``: the whole split is one group.
    """

    axis: int
    sizes: tuple[Size, ...] = child(Type.NUM, "a size")
    groups: tuple[int, ...]
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    repeat: bool
    span: Span = NO_SPAN
    site: int = 0
    #: ``split(axis, noAdjust)`` when false: each part's scope is its slab of the parent's scope, not the
    #: bounding box of its piece of the geometry.
    adjust: bool = True
    #: ``split(u|v, uvSpace|unitSpace, uvSet)``: the texture set whose u (``axis`` 0) or v (1) the split cuts
    #: along (-1: a split of the scope), and whether sizes are metres on the surface (``unitSpace``).
    uv_set: int = -1
    unit_space: bool = False


#: Face selectors of CityEngine's ``comp(f)``, relative to the shape's scope.
FACE_SELECTORS = frozenset({
    "front", "back", "left", "right", "top", "bottom", "side", "vertical", "horizontal", "aslant",
    "nutant", "all",
})

#: CityEngine's compass names of the world's face selectors (the world's x east, z south, y up): the
#: ``world.`` selectors they are.
WORLD_COMPASS = {"world.south": "world.front", "world.north": "world.back", "world.east": "world.right",
                 "world.west": "world.left", "world.up": "world.top", "world.down": "world.bottom"}


@dataclass(frozen=True, slots=True)
class Setback:
    """CityEngine ``setback(d) { sel: A | remainder: B }`` and ``shapeL/U/O(...) { shape: A | remainder: B }``:
    the face's edges move in, each edge by the distance of the first selector of ``distances`` it
    matches (selectors as comp(f) names the faces an extrusion would give the edges). A part takes the
    strips of the edges whose first matching selector it is; ``remainder`` takes the rest of the face.
    ``shapeL/U/O`` are setbacks of the front, right, back and left edges whose strips all go to ``all``.
    ``per_edge``: ``setback(comp(fe){ sel: d | ... })``, the distances evaluated for each edge, which sees
    ``comp.index`` (its number in the face's edge order) and ``comp.total``."""

    distances: tuple[tuple[str, Expr], ...] = child(Type.NUM, "a setback distance")
    selectors: tuple[str, ...]
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0
    per_edge: bool = False


@dataclass(frozen=True, slots=True)
class Convexify:
    """CityEngine ``convexify()`` and ``convexify(maxLength)``: the face becomes its convex parts (one
    shape whose faces ``comp(f)`` splits), cut only along split lines shorter than ``max_length``."""

    max_length: Expr | None = child(Type.NUM, "a split line length")
    span: Span = NO_SPAN


#: Components of CityEngine's ``cleanupGeometry``.
CLEANUP_COMPONENTS = frozenset({"vertices", "edges", "faces", "all"})


@dataclass(frozen=True, slots=True)
class CleanupGeometry:
    """CityEngine ``cleanupGeometry(components, tolerance)``: the shape's geometry tidied in its scope
    (``geometry.cleanup``): vertices merged, then collinear vertices (``vertices``), the edges between
    coplanar faces (``edges``), duplicate and small faces (``faces``) or all of them removed.
    ``tolerance`` runs from 0 (exact matches) to 1 (1 m, 10 degrees, 1 m^2)."""

    component: str
    tolerance: Expr = child(Type.NUM, "a cleanup tolerance")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class DeleteHoles:
    """CityEngine ``deleteHoles()``: the faces of the shape's geometry lose their holes, keeping their
    outer rings."""

    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class InnerRectangle:
    """CityEngine ``innerRectangle(scope|edge) { shape: A | remainder: B }``: the largest rectangle inside
    the face (sides along the scope's x, or along one of its long edges) and the rest of the face."""

    align: str
    selectors: tuple[str, ...]
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class Roof:
    """CityEngine ``roofHip``, ``roofGable``, ``roofShed``, ``roofPyramid``, ``envelope`` and the paper's
    ``Roof(type, angle)``: the face becomes a roof mesh over it (``geometry.roofs``). ``value`` is the
    slope in degrees, or the height when ``by_height``; ``overhang`` and ``overhang_y`` the eave and
    gable overhangs; ``index`` the shed's edge, and with ``indexed`` the edge a gable's ridge runs along
    (``roofGable(angle, overhangX, overhangY, even, index)``)."""

    kind: str
    value: Expr = child(Type.NUM, lambda op: "a roof height" if op.by_height else "a roof angle")
    by_height: bool
    overhang: Expr = child(Type.NUM, "an overhang")
    overhang_y: Expr | None = child(Type.NUM, "an overhang")
    index: Expr = child(Type.NUM, "an edge index")
    span: Span = NO_SPAN
    #: ``envelope(dir, maxHeight, baseHeight, angle, ...)``: the height where it is cut flat, and the
    #: (baseHeight, angle) pairs after the front's (``overhang``, ``value``): back; back and sides; or back,
    #: right and left.
    cap: Expr | None = child(Type.NUM, "a height", default=None)
    sides: tuple[tuple[Expr, Expr], ...] = child(Type.NUM, ("a base height", "an angle"), default=())
    indexed: bool = False
    #: ``roofHip(angle, overhang, even)``, ``roofGable(angle, overhangX, overhangY, even)``: level ridges.
    even: Expr | None = child(Type.BOOL, "even", default=None)


#: Selectors of the faces an ``offset`` makes.
OFFSET_SELECTORS = frozenset({"inside", "border", "all"})
#: The edges of a roof by where its faces meet (``geometry.meshes.roof_edge_kinds``), selectors of ``comp(e)``.
ROOF_EDGE_SELECTORS = ("eave", "ridge", "hip", "valley")
#: Edge and vertex selectors of ``comp(e)`` and ``comp(v)``.
EDGE_SELECTORS = frozenset({"vertical", "horizontal", "aslant", "all", "border", "inside", *ROOF_EDGE_SELECTORS})
VERTEX_SELECTORS = frozenset({"all", "border", "inside"})


@dataclass(frozen=True, slots=True)
class CompFaces:
    """CityEngine ``comp(f|e|v){ sel: A | sel: B }``: each face (edge, vertex) goes to the first selector
    it matches; ``kind`` is "f", "e" or "v". A selector ``"3"`` takes the component of that index, a
    selector ``"#k"`` the one whose index is the value of ``picks[k]`` for its shape (``comp(f){ n + 1 : A }``
    with an expression, a constant or an attribute)."""

    selectors: tuple[str, ...]
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0
    kind: str = "f"
    #: ``offset(d) comp(f){ inside: ... | border: ... }``: the faces are the offset's inside and border.
    offset: Expr | None = child(Type.NUM, "an offset distance", default=None)
    picks: tuple[Expr, ...] = child(Type.NUM, "a component index", default=())


#: CityEngine's coordinate systems of ``translate`` and ``rotate``.
COORDINATE_SYSTEMS = frozenset({"scope", "pivot", "object", "world"})


@dataclass(frozen=True, slots=True)
class Transform:
    """CityEngine ``translate(rel|abs, system, x, y, z)`` (``kind`` "translate": the scope origin moved by,
    or set to, a position in ``system``) and ``rotate(rel|abs, system, x, y, z)`` ("rotate": the scope's
    angles in ``system`` added to, or set to, the given ones, around the scope origin)."""

    kind: str
    relative: bool
    system: str
    values: tuple[Expr, Expr, Expr] = child(
        Type.NUM, lambda op: "a translation" if op.kind == "translate" else "an angle")
    span: Span = NO_SPAN


#: Where ``scatter`` draws its points, and the scope positions its gaussian can centre on.
SCATTER_DOMAINS = frozenset({"surface", "volume", "scope"})
SCATTER_MEANS = frozenset({"center", "front", "back", "left", "right", "top", "bottom"})


@dataclass(frozen=True, slots=True)
class Scatter:
    """CityEngine ``scatter(domain, n, uniform|gaussian[, mean, stddev]) { body }``: ``count`` point shapes
    (zero-size scopes) on the surface, in the volume or in the scope of the shape, each running ``parts[0]``.
    ``gaussian`` draws around the scope position ``mean`` with standard deviation ``stddev``, in metres or,
    when ``relative``, times the scope's size on each axis. The shape itself goes on."""

    domain: str
    count: Expr = child(Type.NUM, "a number of points")
    gaussian: bool
    mean: str
    stddev: Expr = child(Type.NUM, "a standard deviation")
    relative: bool
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0

@dataclass(frozen=True, slots=True)
class AlignToGeometry:
    """CityEngine ``alignScopeToGeometry(upAxis, face, edge)``: the scope's x along an edge of a face of the
    geometry, its y (``up`` "yUp") or z ("zUp") along the face's normal, fitted to the unchanged geometry.
    ``face`` is "index" (``face_index``), "largest", "world.lowest" or "any"; ``edge`` is "index"
    (``edge_index``), "longest" or "world.lowest" (``geometry.align``)."""

    up: str
    face: str
    edge: str
    face_index: Expr | None = child(Type.NUM, "a face index", default=None)
    edge_index: Expr | None = child(Type.NUM, "an edge index", default=None)
    span: Span = NO_SPAN


#: CityEngine's primitives: their segment arguments (with defaults) and their size arguments, in order.
PRIMITIVES = {
    "cube": ((), ("width", "height", "depth")),
    "quad": ((), ("width", "length")),
    "disk": ((16,), ("radius",)),
    "cylinder": ((16,), ("radius", "height")),
    "cone": ((16,), ("radius", "height")),
    "sphere": ((16, 16), ("radius",)),
}


@dataclass(frozen=True, slots=True)
class Primitive:
    """CityEngine ``primitiveCube/Quad/Disk/Cylinder/Sphere/Cone(segments..., sizes...)``: the shape's
    geometry becomes the primitive (``PRIMITIVES`` names each kind's arguments).

    Without ``sizes`` the primitive fills the scope; with them the scope takes the primitive's size,
    centred on the old scope in x and z and standing on its y = 0 (a radius gives a diameter). ``segments``
    must fold to constants: they choose the built-in mesh (``asset_names.primitive_asset``).
    """

    kind: str
    segments: tuple[Expr, ...] = child(Type.NUM, "a number of segments")
    sizes: tuple[Expr, ...] | None = child(Type.NUM, "a size", default=None)
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Trim:
    """CityEngine ``trim()``: the shape's geometry cut by its trim planes (those a ``comp(f)`` left between
    neighbouring faces, ``geometry.trim``), keeping the side its face is on and closing the cuts."""

    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class SplitArea(GroupSplit):
    """CityEngine ``splitArea(axis){ area: A | 'rel: B | ~float: C | { ... }* }[*]``: a ``GroupSplit``
    whose sizes are areas of the geometry, each part cut off by a plane across ``axis`` where the
    geometry before it has that area."""


@dataclass(frozen=True, slots=True)
class ReduceGeometry:
    """CityEngine ``reduceGeometry(tolerance)``: the share ``tolerance`` (0 to 1) of the vertices of the
    shape's faces removed where that changes them least (``geometry.reduce``)."""

    tolerance: Expr = child(Type.NUM, "a tolerance")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class MirrorScope:
    """CityEngine ``mirrorScope(x, y, z)``: the scope's axes whose flag is true reversed, its origin at
    their far ends, the geometry unchanged."""

    axes: tuple[Expr, Expr, Expr] = child(Type.BOOL, "a mirror flag")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class SetOpacity:
    """CityEngine ``set(material.opacity, v)``: the shape's opacity (1 opaque, 0 transparent), the alpha of
    the colour its instances and faces carry into the record."""

    value: Expr = child(Type.NUM, "an opacity")
    span: Span = NO_SPAN


#: ``setupProjection`` axes: the frame ("scope" or "world") and the axes of u and v in it.
PROJECTION_AXES = {f"{frame}.{a}{b}": (frame, "xyz".index(a), "xyz".index(b))
                   for frame in ("scope", "world") for a in "xyz" for b in "xyz" if a != b}


@dataclass(frozen=True, slots=True)
class SetupProjection:
    """CityEngine ``setupProjection(uvSet, axes, width, height[, uOffset, vOffset[, uwFactor]])``: the
    projection of texture set ``uv_set``, kept on the shape (and inherited) until ``projectUV`` applies
    it: u runs along the frame's axis ``u_axis`` one texture ``width`` per unit, v along ``v_axis``, from the
    frame's origin moved by the offsets (metres). Relative and floating sizes measure the scope's extent
    along that axis (``'0.5``: two tiles; ``~2``: whole tiles of about 2 m), and so do relative offsets
    (``'0.5``: half of it; a floating offset is its value). ``uwFactor`` drives the w
    coordinate, which grammarc does not keep."""

    uv_set: int
    frame: str
    u_axis: int
    v_axis: int
    sizes: tuple[Size, Size] = child(Type.NUM, "a texture size")
    offsets: tuple[Size, Size] = child(Type.NUM, "a texture offset")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class ProjectUV:
    """CityEngine ``projectUV(uvSet)``: the shape's texture coordinates of set ``uv_set`` become its
    projection's (``deleteUV`` when ``delete``: it has none)."""

    uv_set: int
    delete: bool = False
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class TransformUV:
    """CityEngine ``translateUV(uvSet, u, v)``, ``scaleUV(uvSet, u, v)`` and ``rotateUV(uvSet, degrees)``
    (``kind``): the texture coordinates moved, scaled or turned about (0, 0) in texture space."""

    kind: str
    uv_set: int
    values: tuple[Expr, ...] = child(Type.NUM, "a texture coordinate change")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class TileUV:
    """CityEngine ``tileUV(uvSet, width, height)``: texture coordinates rescaled so that a tile is
    ``width`` by ``height`` metres on the surface (0: that direction is left alone; ``~``: whole tiles over
    the geometry's extent; ``'``: a share of it)."""

    uv_set: int
    sizes: tuple[Size, Size] = child(Type.NUM, "a texture size")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class NormalizeUV:
    """CityEngine ``normalizeUV(uvSet, uv|uvUniform|u|v, separatePerFace|collectiveAllFaces)``: texture
    coordinates moved and scaled into [0, 1] over the shape's geometry (``uvUniform``: one scale for both,
    the larger extent's). A shape's faces share one affine texture map, so ``separatePerFace`` normalizes the
    shape as a whole, as ``collectiveAllFaces`` does."""

    uv_set: int
    mode: str
    span: Span = NO_SPAN

@dataclass(frozen=True, slots=True)
class SetbackToArea:
    """CityEngine ``setbackToArea(area[, minDistances[, maxDistances]]) { sel: A | remainder: B }``: a
    ``setback`` whose distances are found so that the remainder has ``area``. Every edge a part selects
    moves by its minimum plus one offset common to the face, capped at its maximum (``minimum`` and
    ``maximum`` are evaluated per edge, as ``Setback.distances`` are with ``per_edge``: 0 and no cap
    where none is given); edges no part selects stay. Where no offset reaches the area the nearest one is
    taken: none when the face is already smaller (or the minimums take more), all the way to the maximums
    when they leave more."""

    area: Expr = child(Type.NUM, "an area")
    minimum: tuple[tuple[str, Expr], ...] = child(Type.NUM, "a setback distance")
    maximum: tuple[tuple[str, Expr], ...] = child(Type.NUM, "a setback distance")
    selectors: tuple[str, ...]
    parts: tuple[Body, ...] = child(holds=Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class Taper:
    """CityEngine ``taper(height)``: the face becomes a pyramid, its apex ``height`` along the face's normal
    over the face's centre of gravity, its scope's y along that normal."""

    height: Expr = child(Type.NUM, "a taper height")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class ResetGeometry:
    """CityEngine ``resetGeometry()``: the shape's geometry, scope and pivot become its lot's initial shape's
    again and its trim planes go; its attributes (colour, material, texture space, ``set`` values) stay."""

    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class AlignScopeToBBox:
    """CityEngine ``alignScopeToGeometryBBox(xz|zx|xy|yx|yz|zy)``: the scope turned about its third axis so
    that the two named span the smallest rectangle around the geometry seen along that axis, the first
    (``axes[0]``, a scope axis number) along its longer side."""

    axes: tuple[int, int]
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Footprint:
    """CityEngine ``footprint()``: the shape's geometry projected along its scope's y onto the plane y = 0
    of its scope, a flat geometry."""

    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Rectify:
    """CityEngine ``rectify(angle)``: a face's edges within ``angle`` degrees of one of its scope axes made
    parallel to it (``geometry.rectify``)."""

    angle: Expr = child(Type.NUM, "an angle")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class CopyUV:
    """CityEngine ``copyUV(uvSetSource, uvSetDest)``: texture set ``uv_set`` takes the coordinates of set
    ``source`` (its projection stays its own)."""

    uv_set: int
    source: int
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class InsertAlongUV:
    """CityEngine ``insertAlongUV(uvSet, asset, height[, heightDirection, heightAlignment])``: the shape's
    geometry becomes the asset laid along texture set ``uv_set``: the asset's x runs along u, one copy per
    whole unit of u, its z against v over v in [0, 1], its y ``height`` metres along ``direction``
    (``"scope.y"`` or ``"vertex.normal"``), cut to the shape's faces. ``alignment`` is ``"alignPosition"``
    (the asset's lowest point on the faces) or ``"keepPosition"`` (its own origin on them). ``asset`` and
    ``name`` as in ``UseAsset``."""

    uv_set: int
    asset: str
    height: Expr = child(Type.NUM, "a height")
    span: Span = NO_SPAN
    name: Expr | None = child(Type.STR, "an asset name", default=None)
    direction: str = "scope.y"
    alignment: str = "alignPosition"


@dataclass(frozen=True, slots=True)
class ResetMaterial:
    """CityEngine ``resetMaterial()`` and ``resetMaterial(shape|all)``: the shape's material back to
    CityEngine's default (white, opaque, no texture channels)."""

    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class SetMaterial:
    """CityEngine ``setMaterial(material)``: the material attributes named in the string array
    ``[name0, value0, name1, value1, ...]`` (without the ``material.`` prefix; a table of two columns reads
    alike) set as ``set(material.<name>, value)`` sets each."""

    material: Expr = child(Type.STRS, "a material array")
    span: Span = NO_SPAN


#: ``insertAlongUV``'s height directions and alignments, the defaults first.
ALONG_UV_DIRECTIONS = ("scope.y", "vertex.normal")
ALONG_UV_ALIGNMENTS = ("alignPosition", "keepPosition")


@dataclass(frozen=True, slots=True)
class SetPivot:
    """CityEngine ``setPivot(xyz|yzx|zxy, corner)``: the shape's pivot moves to corner ``corner`` (0 to 7) of
    its scope, its axes the scope's renamed by ``axes`` and turned to point into the scope, and the scope
    takes the pivot's axes and origin around the unchanged geometry (``backend.pivot``)."""

    axes: str
    corner: Expr = child(Type.NUM, "a corner index")
    span: Span = NO_SPAN


Op = (Symbol | Empty | Translate | Scale | Rotate | Push | Pop | Insert | Split | Repeat | Comp | Extrude
      | Center | UseAsset | Case | Stochastic | SetAttr | Report | NotApplied | GroupSplit | CompFaces
      | AlignScope | Mirror | Offset | SetColor | Setback | Roof | InnerRectangle | Convexify
      | CleanupGeometry | DeleteHoles | Snap | Label | Transform | Scatter | AlignToGeometry | Primitive
      | Trim | SplitArea | ReduceGeometry | MirrorScope | SetOpacity | SetupProjection | ProjectUV | TransformUV
      | TileUV | NormalizeUV | SetbackToArea | Taper | ResetGeometry | AlignScopeToBBox
      | Footprint | Rectify | CopyUV | InsertAlongUV | ResetMaterial | SetMaterial
      | SetPivot | Cut)
Body = tuple[Op, ...]


# -------------------------------------------------------------------------------------------------- top level


@dataclass(frozen=True, slots=True)
class Alternative:
    body: Body = child(holds=Holds.BODY)
    prob: Expr | None = child(Type.NUM, "a probability")
    span: Span = NO_SPAN
    #: One of a set of consequents (``~> B ?``): a search takes each; a build takes one, all equally likely.
    choice: bool = False


@dataclass(frozen=True, slots=True)
class Rule:
    """``[label:] symbol(params) : guard ~> alternatives``; the first rule of a symbol whose guard holds applies."""

    symbol: str
    params: tuple[str, ...]
    guard: Expr | None = child(Type.BOOL, "a guard")
    alternatives: tuple[Alternative, ...] = child(holds=Holds.NODES)
    priority: int
    label: str | None = None
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class AttrDecl:
    """``attr name = default``; a ``const`` is an attribute that lots and ``--attr`` cannot override.

    ``annotations`` keeps CityEngine's ``@Range(...)``, ``@Enum(...)``, ... as (name, argument texts).
    """

    name: str
    default: Expr = child()  # its type is the attribute's
    span: Span = NO_SPAN
    type: Type = Type.UNKNOWN
    const: bool = False
    annotations: tuple[tuple[str, tuple[str, ...]], ...] = ()


#: The search statements: what each is, and the type of its expression.
OBJECTIVES = {"goal": Type.BOOL, "prune": Type.BOOL, "cost": Type.NUM, "heuristic": Type.NUM}


@dataclass(frozen=True, slots=True)
class Objective:
    """``goal: expr``, ``prune: expr`` (of a design), ``heuristic: expr`` (of a design, for A*) and
    ``cost: expr`` (of the shape a rule is applied to, added per application): what a search
    (``grammarc search``) looks for. A design's expressions read its aggregates (``Aggregate``), the lot's
    attributes and, as ``Scope``, the lot's own shape."""

    kind: str
    expr: Expr = child(lambda o: OBJECTIVES[o.kind], lambda o: f"the {o.kind}")
    span: Span = NO_SPAN


@dataclass(frozen=True)
class RuleGraph:
    """What ``passes.rulegraph`` finds of the symbols: those with rules, the leaves, what the start symbol
    reaches and what recurses. It lives here, beside the ``Module`` that carries it, because every layer
    after the passes reads it from the module."""

    start: str
    #: Symbols with rules, in order of first definition.
    nonterminals: tuple[str, ...]
    #: Symbols used in successors that have no rule: their shapes are leaves.
    terminals: tuple[str, ...]
    reachable: frozenset[str]
    #: Symbols on a cycle of the graph (directly or mutually recursive).
    recursive: frozenset[str]
    edges: dict[str, tuple[str, ...]]


@dataclass(frozen=True, slots=True)
class Module:
    """A whole grammar: its file, attributes, rules in source order, and the start symbol.

    The analyses travel with it: every pass takes a module and returns one (``pipeline``), so what the
    rule graph and asset resolution find becomes fields of the module they return (``graph``,
    ``assets``, ``asset_ids``), and the checked module carries everything the backend reads. The
    compiler sets ``start`` and ``roots`` before the passes, as the file's own and the caller's choices.
    """

    file: str
    attrs: tuple[AttrDecl, ...] = child(holds=Holds.NODES)
    rules: tuple[Rule, ...] = child(holds=Holds.NODES)
    start: str | None
    #: Parameter types per symbol, filled by ``passes.types``.
    param_types: tuple[tuple[str, tuple[Type, ...]], ...] = ()
    #: ``cga2006`` or ``cityengine``. In CityEngine CGA a body that makes no successor leaves its shape
    #: as a leaf (``Lot --> extrude(10)`` is a mass); in the paper notation such a body emits nothing.
    dialect: str = "cga2006"
    #: Files whose rules and attributes were imported into this module (CityEngine ``import``).
    imported: tuple[str, ...] = ()
    #: Folders that ``I()`` names are resolved in, in order (the grammar's, then ``--assets`` ones). None
    #: for a module lowered outside the compiler (by a test, a tool): checked, but not made ready to derive
    #: (its start rule may take parameters, its asset names stay unresolved).
    roots: tuple[Path, ...] | None = None
    #: The symbol graph from ``start``, found by ``passes.rulegraph`` (None before, or without rules).
    graph: RuleGraph | None = None
    #: Canonical asset names, found by ``passes.assets``: an asset's index is its id in the record.
    assets: tuple[str, ...] = ()
    #: ``I()`` name as written -> asset id, as pairs: the module is frozen (``model.Grammar`` has the dict).
    asset_ids: tuple[tuple[str, int], ...] = ()
    #: The search statements (goal, cost, heuristic, prune), at most one of each.
    objectives: tuple[Objective, ...] = child(holds=Holds.NODES, default=())

    def objective(self, kind: str) -> Expr | None:
        """The expression of the search statement ``kind``, None where the grammar has none."""
        return next((o.expr for o in self.objectives if o.kind == kind), None)
