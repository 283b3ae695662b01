"""Lower CityEngine CGA (cityengine.lark) to the IR, one statement at a time.

The same IR as the paper notation: CityEngine's ``split`` becomes ``GroupSplit`` (absolute, ``'`` relative
and ``~`` floating sizes, repeat groups), ``comp(f)`` with selectors ``CompFaces``, ``case`` and ``p%``
blocks ``Case`` and ``Stochastic`` operations, ``case`` and ``p%`` expressions ``Select``. Functions and
constants-as-functions are inlined by ``assemble``; rules overloaded by arity get one symbol per arity
(``Pipe/1``, ``Pipe/3``). An operation or construct that grammarc does not implement is an error
``unsupported: NAME`` at its span, never skipped.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from lark import Token, v_args

from grammarc.diagnostics import Diagnostics, Span, suggest
from grammarc.frontend.lowering import LoweringBase
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import rewrite_body, rewrite_expr, sub_bodies

#: Operations that are parsed and accepted but do not change the record (listed in its meta).
NOT_APPLIED = frozenset({
    "texture", "setupProjection", "projectUV", "tileUV", "translateUV", "scaleUV", "rotateUV",
    "normalizeUV", "deleteUV", "reverseNormals", "print", "setNormals", "softenNormals", "label",
    # the pivot only moves the model's own origin in an export; scope.t* stay relative to the lot
    "setPivot",
})
#: CityEngine operations grammarc does not implement yet (the geometry and context issues bring most).
UNSUPPORTED_OPS = frozenset({
    "innerPolygon",
    "trim",
    "mirrorScope",
    "insertAlongUV", "scatter", "footprint", "tileUV", "splitArea", "inline", "resetGeometry", "taper",
    "primitiveCylinder", "primitiveSphere", "primitiveDisk", "primitiveCone", "primitiveQuad",
    "deleteHoles", "reduceGeometry", "rectify", "semiPolygon",
} - NOT_APPLIED)
#: CityEngine built-in functions mapped onto the IR's.
FUNCTION_NAMES = {"rint": "round", "ln": "log"}
AXIS_NAMES = {"x": (0,), "y": (1,), "z": (2,), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2), "xyz": (0, 1, 2)}
SCOPE_MEMBERS = {
    **{f"scope.{f}": f for f in ("sx", "sy", "sz", "tx", "ty", "tz", "rx", "ry", "rz")},
    "initialShape.origin.px": "ox", "initialShape.origin.py": "oy", "initialShape.origin.pz": "oz",
}
#: Shape queries without arguments, written as members (``geometry.area``) or calls (``geometry.area()``).
GEOMETRY_QUERIES = ("geometry.area", "geometry.volume", "geometry.nVertices", "geometry.nFaces")


@dataclass(frozen=True, slots=True)
class Annotated:
    annotations: tuple[tuple[str, tuple[str, ...]], ...]
    declaration: object


@dataclass(frozen=True, slots=True)
class RuleDef:
    name: str
    params: tuple[str, ...]
    body: ir.Body
    span: Span
    site: int


@dataclass(frozen=True, slots=True)
class FunctionDef:
    name: str
    params: tuple[str, ...]
    value: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class PendingOffset:
    """``offset(d)`` before the ``comp(f)`` that takes its inside and border faces."""

    distance: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class EdgeDistances:
    """``comp(fe){ sel: d | ... }`` as ``setback``'s argument: a distance per edge selector."""

    values: tuple[tuple[str, ir.Expr], ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Import:
    """``import prefix : "file.cga"`` (or without a prefix): the file's rules and attributes, named
    ``prefix.Name``; an attribute the importing file declares too takes the importing file's value."""

    prefix: str | None
    path: str
    span: Span


@dataclass(frozen=True, slots=True)
class Style:
    """``style Name``: the attributes after it redefine the defaults for that style."""

    name: str
    span: Span


@dataclass(frozen=True, slots=True)
class Sized:
    """A split part's size or an argument with its kind (absolute, ``'`` relative, ``~`` floating)."""

    kind: ir.SizeKind
    value: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Part:
    size: Sized
    body: ir.Body
    merged: bool
    span: Span


@dataclass(frozen=True, slots=True)
class Group:
    parts: tuple
    span: Span


@v_args(inline=True, meta=True)
class Lowering(LoweringBase):
    """One CityEngine statement's parse tree -> IR pieces (``Annotated`` declarations)."""

    def unsupported(self, name: str, span: Span, why: str = ""):
        self.diags.error("unsupported", f"unsupported: {name}" + (f" ({why})" if why else ""), span)
        return ir.Empty(span)

    def __default__(self, data, children, meta):
        return self.unsupported(str(data), self.span(meta))

    def expr(self, value) -> ir.Expr:
        """An argument that must be a plain expression."""
        if isinstance(value, Sized):
            if value.kind is not ir.SizeKind.ABSOLUTE:
                self.unsupported("relative or floating value here", value.span)
            return value.value
        if isinstance(value, EdgeDistances):
            self.unsupported("comp(fe){...} outside setback", value.span)
            return ir.placeholder(value.span)
        return value

    # ------------------------------------------------------------------------------------- declarations
    def statement(self, meta, *children):
        *annotations, declaration = children
        return Annotated(tuple(annotations), declaration)

    def annotation(self, meta, name, args):
        return (str(name), tuple(args or ()))

    def annotation_args(self, meta, *args):
        from grammarc.ir.printer import print_expr

        return tuple(a if isinstance(a, str) else print_expr(self.expr(a)) for a in args)

    def keyword_arg(self, meta, name, value):
        from grammarc.ir.printer import print_expr

        return f"{name}={print_expr(self.expr(value))}"

    def version(self, meta, text):
        return None

    def style(self, meta, name):
        return Style(str(name), self.token_span(name))

    def import_prefixed(self, meta, prefix, path, *names):
        if any(n is not None for n in names):
            return self.unsupported("import with a list of names", self.span(meta))
        return Import(str(prefix), str(path)[1:-1], self.span(meta))

    def import_plain(self, meta, path):
        return Import(None, str(path)[1:-1], self.span(meta))

    def attr_decl(self, meta, name, value):
        return ir.AttrDecl(str(name), value, self.token_span(name))

    def const_decl(self, meta, name, value):
        return ir.AttrDecl(str(name), value, self.token_span(name), const=True)

    def function_def(self, meta, name, params, value):
        return FunctionDef(str(name), params or (), value, self.token_span(name))

    def rule_def(self, meta, name, params, arrow, body):
        return RuleDef(str(name), params or (), _as_body(body), self.token_span(name), self.site())

    def params(self, meta, *names):
        return tuple(str(n) for n in names if n is not None)

    # ------------------------------------------------------------------------------------------ bodies
    def body(self, meta, *items):
        return self.fuse_offsets(items)

    def fuse_offsets(self, items) -> ir.Body:
        """``offset(d) comp(f){ inside: ... | border: ... }`` becomes one component split of the offset's
        faces; an ``offset(d)`` that no such comp follows would need several faces in one shape."""
        out: list = []
        pending = None
        for item in items:
            if isinstance(item, PendingOffset):
                pending = item
                continue
            if pending is not None and isinstance(item, ir.NotApplied):
                out.append(item)
                continue
            if pending is not None:
                if isinstance(item, ir.CompFaces) and item.kind == "f" and \
                        set(item.selectors) <= ir.OFFSET_SELECTORS:
                    item = replace(item, offset=pending.distance)
                else:
                    self.unsupported("offset(d) without comp(f){ inside | border } after it", pending.span,
                                     "write offset(d, inside) or offset(d, border) for one face")
                pending = None
            out.append(item)
        if pending is not None:
            self.unsupported("offset(d) without comp(f){ inside | border } after it", pending.span,
                             "write offset(d, inside) or offset(d, border) for one face")
        return tuple(out)

    def case_block(self, meta, *branches):
        *cases, default = branches
        return (ir.Case(tuple(cases), default, self.span(meta)),)

    def case_branch(self, meta, cond, body):
        return (cond, _as_body(body))

    def else_branch(self, meta, body):
        return _as_body(body)

    def stochastic_block(self, meta, *branches):
        *chances, default = branches
        return (ir.Stochastic(tuple(chances), default if default is not None else (), self.span(meta),
                              self.site()),)

    def stochastic_branch(self, meta, probability, percent, body):
        return (probability, _as_body(body))

    def symbol(self, meta, name):
        text, span = str(name), self.token_span(name)
        if text in _BARE_OPS:
            return _OPS[text](self, text, (), span)
        if text in NOT_APPLIED:
            return ir.NotApplied(text, span)
        if text in UNSUPPORTED_OPS:
            return self.unsupported(text, span)
        return ir.Symbol(text, (), span, self.site())

    def leaf(self, meta, name, dot):
        return ir.Symbol(str(name), (), self.token_span(name), self.site(), leaf=True)

    def imported_symbol(self, meta, prefix, name):
        return ir.Symbol(f"{prefix}.{name}", (), self.token_span(prefix), self.site())

    def imported_call(self, meta, prefix, name, args):
        return ir.Symbol(f"{prefix}.{name}", tuple(self.expr(a) for a in (args or ())), self.token_span(prefix),
                         self.site())

    def push(self, meta, tok):
        return ir.Push(self.token_span(tok))

    def pop(self, meta, tok):
        return ir.Pop(self.token_span(tok))

    def args(self, meta, *args):
        return tuple(args)

    def relative(self, meta, prime, value):
        return Sized(ir.SizeKind.RELATIVE, value, self.token_span(prime))

    def floating(self, meta, tilde, value):
        return Sized(ir.SizeKind.FLOATING, value, self.token_span(tilde))

    def selector_function(self, meta, name, args, parts):
        """``comp(fe){ sel: d | ... }`` as setback's argument: per-edge distances (``EdgeDistances``);
        any other operation with parts is no argument."""
        span = self.token_span(name)
        if str(name) != "comp" or len(args or ()) != 1 or not isinstance(args[0], ir.Name) or \
                args[0].name != "fe":
            return self.unsupported(f"{name}(...){{...}} as an argument", span, "only setback(comp(fe){ ... })")
        chosen = self.selector_parts("comp(fe)", parts, _SETBACK_SELECTORS - {"remainder"})
        if chosen is None:
            return ir.placeholder(span)
        values = []
        for selector, body in zip(*chosen):
            # a part's body is one expression, parsed as an operation: a call, or a name
            if len(body) == 1 and isinstance(body[0], ir.Symbol):
                op = body[0]
                func = FUNCTION_NAMES.get(op.name, op.name)
                value = ir.Call(func, op.args, op.span, self.site()) if op.args or func in ir.FUNCTIONS \
                    else ir.Name(op.name, op.span)
            else:
                self.unsupported("this comp(fe) part", span, "each part gives one distance: `all : 3`")
                return ir.placeholder(span)
            values.append((selector, value))
        return EdgeDistances(tuple(values), span)

    def size_prefix(self, meta, prefix):
        if prefix is None:
            return ir.SizeKind.ABSOLUTE
        return ir.SizeKind.RELATIVE if str(prefix) == "'" else ir.SizeKind.FLOATING

    def part(self, meta, kind, value, body):
        return Part(Sized(kind, value, getattr(value, "span", self.span(meta))), _as_body(body), False,
                    self.span(meta))

    def merged_part(self, meta, kind, value, body):
        return Part(Sized(kind, value, getattr(value, "span", self.span(meta))), _as_body(body), True,
                    self.span(meta))

    def repeat_group(self, meta, parts, star):
        return Group(parts, self.span(meta))

    def parts(self, meta, *parts):
        return tuple(parts)

    # -------------------------------------------------------------------------------------- operations
    def call(self, meta, name, args):
        op, span, args = str(name), self.token_span(name), args or ()
        handler = _OPS.get(op)
        if handler is not None:
            return handler(self, op, args, span)
        if op in NOT_APPLIED:
            return ir.NotApplied(op, span)
        if op in UNSUPPORTED_OPS or op in _SPLIT_OPS:
            return self.unsupported(op, span)
        if op in _SETBACK_OPS or op == "innerRectangle":
            return self.unsupported(f"{op} without selector parts", span,
                                    f"write {op}(...) {{ ... | remainder: ... }}")
        return ir.Symbol(op, tuple(self.expr(a) for a in args), span, self.site())

    def split_call(self, meta, name, args, parts, star):
        op, span, args = str(name), self.token_span(name), args or ()
        if op == "split":
            return self.op_split(args, parts, star is not None, span)
        if op == "comp":
            if star is not None:
                return self.unsupported("`*` after comp", self.token_span(star), "only split repeats")
            return self.op_comp(args, parts, span)
        if op in _SETBACK_OPS:
            if star is not None:
                return self.unsupported(f"`*` after {op}", self.token_span(star), "only split repeats")
            return self.op_setback(op, args, parts, span)
        if op == "innerRectangle":
            if star is not None:
                return self.unsupported(f"`*` after {op}", self.token_span(star), "only split repeats")
            return self.op_inner_rectangle(op, args, parts, span)
        return self.unsupported(op, span)

    def arity(self, op, args, counts, span) -> bool:
        if len(args) in counts:
            return True
        want = " or ".join(str(c) for c in counts)
        self.diags.error("arity", f"`{op}` takes {want} arguments, got {len(args)}", span)
        return False

    def op_roof(self, op, args, span):
        """``roofHip``, ``roofGable``, ``roofShed``, ``roofPyramid``: by angle, or with a leading
        ``byAngle``/``byHeight`` selector. The arguments after the value, in CityEngine's order:
        hip (overhang, even), gable (overhangX, overhangY, even, index), shed (index), pyramid none."""
        by_height = False
        if args and isinstance(args[0], ir.Name) and args[0].name in ("byAngle", "byHeight"):
            by_height = args[0].name == "byHeight"
            args = args[1:]
        names = _ROOF_ARGUMENTS[op] + (("index",) if op == "roofGable" and not by_height else ())
        if not 1 <= len(args) <= 1 + len(names):
            self.diags.error("arity", f"`{op}` takes 1 to {1 + len(names)} arguments after the "
                             f"byAngle/byHeight selector, got {len(args)}", span)
            return ir.Empty(span)
        given = dict(zip(names, (self.expr(a) for a in args[1:])))
        even = given.get("even")
        if even is not None and not (isinstance(even, ir.Bool) and not even.value):
            return self.unsupported(f"{op} with even ridges", even.span,
                                    "only even = false: even ridges make non-planar faces")
        if op == "roofGable" and "index" in given:
            return self.unsupported("roofGable with an edge index", given["index"].span,
                                    "the ridge follows the straight skeleton")
        zero = ir.Num(0.0, span)
        overhang = given.get("overhang", given.get("overhangX", zero))
        index = given.get("index", zero) if op == "roofShed" else zero
        return ir.Roof(op, self.expr(args[0]), by_height, overhang, given.get("overhangY"), index, span)

    def op_envelope(self, op, args, span):
        """``envelope(normal|world.up, maxHeight, baseHeight, angle, ...)``: one (baseHeight, angle) pair,
        or the pairs for front, back, sides (or right and left), which must come out equal."""
        if len(args) not in (4, 6, 8, 10):
            return self.unsupported(f"envelope with {len(args)} arguments", span,
                                    "envelope(direction, maxHeight, baseHeight, angle, ...) with 1 to 4 sides")
        if not isinstance(args[0], ir.Name) or args[0].name not in ("normal", "world.up", "face.normal"):
            return self.unsupported("envelope with this direction", span, "normal or world.up")
        pairs = [(self.expr(args[k]), self.expr(args[k + 1])) for k in range(2, len(args), 2)]
        (base, angle), others = pairs[0], tuple(pairs[1:])
        zero = ir.Num(0.0, span)
        return ir.Roof("envelope", angle, False, base, None, zero, span, cap=self.expr(args[1]), sides=others)

    def op_extrude(self, op, args, span):
        if len(args) != 1:
            return self.unsupported(f"extrude with {len(args)} arguments", span, "only extrude(height)")
        return ir.Extrude(self.expr(args[0]), span)

    def op_translate(self, op, args, span):
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        return ir.Translate(tuple(self.scoped(a, axis) for axis, a in enumerate(args)), span)

    def scoped(self, arg, axis: int) -> ir.Expr:
        """``'v`` in ``t``: v times the scope size on that axis."""
        if isinstance(arg, Sized) and arg.kind is ir.SizeKind.RELATIVE:
            return ir.Binary("*", arg.value, ir.ScopeRef("s" + "xyz"[axis], arg.span), arg.span)
        return self.expr(arg)

    def op_scale(self, op, args, span):
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        sizes = []
        for a in args:
            if isinstance(a, Sized) and a.kind is ir.SizeKind.RELATIVE:
                sizes.append(ir.Size(ir.SizeKind.RELATIVE, a.value, a.span))
            else:
                value = self.expr(a)
                sizes.append(ir.Size(ir.SizeKind.ABSOLUTE, value, getattr(value, "span", span)))
        return ir.Scale(tuple(sizes), span)

    def op_rotate(self, op, args, span):
        if len(args) != 3:
            return self.unsupported(f"r with {len(args)} arguments", span, "only r(x, y, z)")
        return ir.Rotate(tuple(self.expr(a) for a in args), span)

    def op_color(self, op, args, span):
        if len(args) not in (1, 3, 4):
            return self.unsupported(f"color with {len(args)} arguments", span,
                                    'color(r, g, b) or color("#rrggbb")')
        return ir.SetColor(tuple(self.expr(a) for a in args[:3]), span)

    def op_offset(self, op, args, span):
        if len(args) == 1:
            return PendingOffset(self.expr(args[0]), span)
        if len(args) == 2 and isinstance(args[1], ir.Name) and args[1].name in ("inside", "border"):
            return ir.Offset(self.expr(args[0]), args[1].name, span)
        return self.unsupported("offset with these arguments", span,
                                "offset(d), offset(d, inside), offset(d, border)")

    def op_mirror(self, op, args, span):
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        return ir.Mirror(tuple(self.expr(a) for a in args), span)

    def op_align(self, op, args, span):
        if not args or (len(args) == 1 and isinstance(args[0], ir.Name) and args[0].name == "world.xyz"):
            return ir.AlignScope("world", None, span)
        if len(args) == 1 and isinstance(args[0], ir.Name) and args[0].name in ("y", "world.y"):
            return ir.AlignScope("y", None, span)
        return self.unsupported("alignScopeToAxes with this axis", span,
                                "alignScopeToAxes(), alignScopeToAxes(world.xyz) and alignScopeToAxes(y)")

    def op_align_geometry(self, op, args, span):
        if len(args) not in (2, 3) or not isinstance(args[0], ir.Name) or args[0].name not in ("yUp", "zUp"):
            return self.unsupported("alignScopeToGeometry with these arguments", span,
                                    "alignScopeToGeometry(yUp|zUp, 0[, edgeIndex])")
        face = self.expr(args[1])
        if not (isinstance(face, ir.Num) and face.value == 0):
            return self.unsupported("alignScopeToGeometry on a face other than 0", getattr(face, "span", span))
        edge = self.expr(args[2]) if len(args) == 3 else ir.Num(0.0, span)
        return ir.AlignScope("geometry-" + args[0].name[0], (edge, ir.Num(0.0), ir.Num(0.0)), span)

    def op_rotate_scope(self, op, args, span):
        if len(args) != 3:
            return self.unsupported(f"rotateScope with {len(args)} arguments", span)
        return ir.AlignScope("rotate", tuple(self.expr(a) for a in args), span)

    def op_center(self, op, args, span):
        axes = self.axis_argument(op, args, span)
        return ir.Center(axes, span) if axes else ir.Empty(span)

    def axis_argument(self, op, args, span) -> tuple[int, ...]:
        if len(args) == 1 and isinstance(args[0], ir.Name) and args[0].name in AXIS_NAMES:
            return AXIS_NAMES[args[0].name]
        self.diags.error("axis", f"`{op}` expects an axis selector (x, y, z, xy, xz, yz, xyz)", span)
        return ()

    def op_insert(self, op, args, span):
        if len(args) != 1:
            return self.unsupported(f"i with {len(args)} arguments", span, "only i(asset)")
        if isinstance(args[0], ir.Str):
            return ir.UseAsset(args[0].value, span)
        return ir.UseAsset("", span, name=self.expr(args[0]))

    def op_cube(self, op, args, span):
        if args:
            return self.unsupported("primitiveCube with arguments", span)
        return ir.UseAsset("builtin:cube", span)

    def op_nil(self, op, args, span):
        return ir.Empty(span)

    def op_set(self, op, args, span):
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        target = args[0]
        if isinstance(target, ir.Name) and target.name in ir.SHAPE_ATTRIBUTES:
            return ir.SetAttr(target.name, self.expr(args[1]), span)
        if isinstance(target, ir.Name) and target.name == "trim.horizontal":
            value = self.expr(args[1])
            if isinstance(value, ir.Bool) and not value.value:
                return ir.NotApplied("set(trim.horizontal)", span)  # CityEngine's default
            return self.unsupported("set(trim.horizontal, ...) other than false", span,
                                    "horizontal trim planes are not made")
        if isinstance(target, ir.Name) and target.name.startswith("material."):
            return ir.NotApplied(f"set({target.name})", span)
        if not isinstance(target, ir.Name):
            return self.unsupported("set of this target", span, "set(attribute, value)")
        return ir.SetAttr(target.name, self.expr(args[1]), span)

    def op_report(self, op, args, span):
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        return ir.Report(self.expr(args[0]), self.expr(args[1]), span)

    def op_split(self, args, parts, repeat, span):
        if not args or not isinstance(args[0], ir.Name) or args[0].name not in ("x", "y", "z"):
            self.diags.error("axis", "`split` expects an axis x, y or z", span)
            return ir.Empty(span)
        for extra in args[1:]:
            if not (isinstance(extra, ir.Name) and extra.name in ("adjust", "noAdjust")):
                return self.unsupported("this split option", getattr(extra, "span", span))
            if extra.name == "noAdjust":
                return self.unsupported("split(..., noAdjust)", extra.span)
        sizes, groups, bodies = [], [], []
        n_groups = 0
        for item in parts:
            if isinstance(item, Group):
                for inner in item.parts:
                    if isinstance(inner, Group):
                        return self.unsupported("nested repeat groups", inner.span)
                    sizes.append(self.size_of(inner))
                    groups.append(n_groups)
                    bodies.append(inner.body)
                n_groups += 1
            else:
                sizes.append(self.size_of(item))
                groups.append(-1)
                bodies.append(item.body)
        return ir.GroupSplit("xyz".index(args[0].name), tuple(sizes), tuple(groups), tuple(bodies), repeat,
                             span, self.site())

    def size_of(self, part: Part) -> ir.Size:
        if part.merged:
            self.unsupported("`=` in split", part.span)
        return ir.Size(part.size.kind, part.size.value, part.size.span)

    def op_comp(self, args, parts, span):
        if len(args) != 1 or not isinstance(args[0], ir.Name) or args[0].name not in _COMP_SELECTORS:
            kind = args[0].name if args and isinstance(args[0], ir.Name) else "?"
            return self.unsupported(f"comp({kind})", span, "comp(f), comp(e) and comp(v)")
        kind = args[0].name
        known = _COMP_SELECTORS[kind]
        selectors, bodies = [], []
        for part in parts:
            if isinstance(part, Group):
                return self.unsupported("repeat group in comp", part.span)
            value = part.size.value
            if part.size.kind is not ir.SizeKind.ABSOLUTE or not isinstance(value, ir.Name):
                return self.unsupported("this comp selector", part.span)
            if value.name not in known:
                why = f"comp({kind}) selects {', '.join(sorted(known))}" + suggest(value.name, known)
                return self.unsupported(f"comp({kind}) selector `{value.name}`", value.span, why)
            if part.merged:
                self.diags.warning(
                    "merged", f"`{value.name}=` gives one shape for all its faces in CityEngine; grammarc "
                    "derives them one by one (the same leaves; operations that read the scope differ)",
                    part.span)
            selectors.append(value.name)
            bodies.append(part.body)
        return ir.CompFaces(tuple(selectors), tuple(bodies), span, self.site(), kind)

    def op_setback(self, op, args, parts, span):
        """``setback(d) { sel: A | remainder: B }``; ``shapeL/U/O(widths...) { shape: A | remainder: B }``;
        ``setback(comp(fe){ sel: d | ... }) { ... }`` with distances per edge."""
        sides = _SETBACK_OPS[op]
        if op == "setback" and len(args) == 1 and isinstance(args[0], EdgeDistances):
            chosen = self.selector_parts(op, parts, _SETBACK_SELECTORS)
            if chosen is None:
                return ir.Empty(span)
            return ir.Setback(args[0].values, chosen[0], chosen[1], span, self.site(), per_edge=True)
        if not self.arity(op, args, (len(sides) if sides else 1,), span):
            return None
        known = _SETBACK_SELECTORS if not sides else frozenset({"shape", "remainder"})
        chosen = self.selector_parts(op, parts, known)
        if chosen is None:
            return ir.Empty(span)
        selectors = tuple("all" if s == "shape" else s for s in chosen[0])
        exprs = tuple(self.expr(a) for a in args)
        if sides:
            distances = tuple(zip(sides, exprs))
        else:
            distances = tuple((s, exprs[0]) for s in selectors if s != "remainder")
        return ir.Setback(distances, selectors, chosen[1], span, self.site())

    def op_convexify(self, op, args, span):
        if len(args) > 1:
            return self.unsupported(f"convexify with {len(args)} arguments", span,
                                    "convexify() and convexify(maxLength)")
        return ir.Convexify(self.expr(args[0]) if args else None, span)

    def op_cleanup(self, op, args, span):
        """``cleanupGeometry(components, tolerance)``, components one of ``ir.CLEANUP_COMPONENTS``."""
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        component = args[0]
        known = ir.CLEANUP_COMPONENTS
        if not isinstance(component, ir.Name) or component.name not in known:
            got = (f"`{component.name}`{suggest(component.name, known)}" if isinstance(component, ir.Name)
                   else "a string" if isinstance(component, ir.Str) else "an expression")
            self.diags.error("component", f"`{op}` cleans up {', '.join(sorted(known))}, got {got}",
                             getattr(component, "span", span))
            return ir.Empty(span)
        return ir.CleanupGeometry(component.name, self.expr(args[1]), span)

    def op_inner_rectangle(self, op, args, parts, span):
        """``innerRectangle(scope|edge) { shape: A | remainder: B }``."""
        if len(args) != 1 or not isinstance(args[0], ir.Name) or args[0].name not in ("scope", "edge"):
            return self.unsupported("innerRectangle with these arguments", span,
                                    "innerRectangle(scope) and innerRectangle(edge)")
        chosen = self.selector_parts(op, parts, frozenset({"shape", "remainder"}))
        if chosen is None:
            return ir.Empty(span)
        return ir.InnerRectangle(args[0].name, chosen[0], chosen[1], span, self.site())

    def selector_parts(self, op, parts, known):
        """The selectors and bodies of ``{ sel: A | ... }`` parts, all among ``known`` (None after an
        error); ``sel=`` is derived as ``sel:``, with a warning."""
        selectors, bodies = [], []
        for part in parts:
            if isinstance(part, Group):
                self.unsupported(f"repeat group in {op}", part.span)
                return None
            value = part.size.value
            if part.size.kind is not ir.SizeKind.ABSOLUTE or not isinstance(value, ir.Name):
                self.unsupported(f"this {op} selector", part.span)
                return None
            if value.name not in known:
                why = f"{op} selects {', '.join(sorted(known - {'remainder'}))} and remainder"
                self.unsupported(f"{op} selector `{value.name}`", value.span, why + suggest(value.name, known))
                return None
            if part.merged:
                self.diags.warning(
                    "merged", f"`{value.name}=` gives one shape for all its polygons in CityEngine; grammarc "
                    "derives them one by one (the same leaves; operations that read the scope differ)",
                    part.span)
            selectors.append(value.name)
            bodies.append(part.body)
        return tuple(selectors), tuple(bodies)

    # ------------------------------------------------------------------------------------- expressions
    def value_case(self, meta, *items):
        *pairs, default = items
        result = default
        for i in range(len(pairs) - 2, -1, -2):
            result = ir.Select(self.expr(pairs[i]), pairs[i + 1], result, self.span(meta))
        return result

    def value_stochastic(self, meta, *items):
        *pairs, default = [i for i in items if not (isinstance(i, Token) and i.type == "PERCENT_COLON")]
        # p% : a  q% : b  else : c  ->  draw u once; u < p -> a, u < p + q -> b, else c
        site = self.site()
        u = ir.Call("rand", (), self.span(meta), site)
        result, bounds, total = default, [], None
        for i in range(0, len(pairs), 2):
            share = ir.Binary("/", pairs[i], ir.Num(100.0), pairs[i].span)
            total = share if total is None else ir.Binary("+", total, share, share.span)
            bounds.append((total, pairs[i + 1]))
        for bound, value in reversed(bounds):
            result = ir.Select(ir.Binary("<", u, bound, self.span(meta)), value, result, self.span(meta))
        return result

    def string(self, meta, tok):
        text = str(tok)[1:-1].replace('\\"', '"').replace("\\\\", "\\")
        return ir.Str(text, self.token_span(tok))

    def dotted_name(self, meta, *names):
        return tuple(str(n) for n in names), Span(self.file, names[0].line, names[0].column,
                                                  names[-1].end_line, names[-1].end_column)

    def name(self, meta, tok):
        if str(tok) == "fileRandom":
            return ir.Call("fileRandom", (), self.token_span(tok), 0)
        return ir.Name(str(tok), self.token_span(tok))

    def member(self, meta, dotted):
        names, span = dotted
        text = ".".join(names)
        if text in SCOPE_MEMBERS:
            return ir.ScopeRef(SCOPE_MEMBERS[text], span)
        if text in GEOMETRY_QUERIES:
            return ir.Call(text, (), span, self.site())
        if text in ir.CONTEXT_FIELDS:
            return ir.ContextRef(text, span)
        if names[0] in _UNSUPPORTED_MEMBERS:
            self.unsupported(text, span)
            return ir.placeholder(span)
        # material.*, scope.xy, world.xyz...: arguments of set, setupProjection, alignScopeToAxes; as a
        # value anywhere else, name resolution reports them
        return ir.Name(text, span)

    def member_function(self, meta, dotted, args):
        names, span = dotted
        text = ".".join(names)
        if text in GEOMETRY_QUERIES and not args:
            return ir.Call(text, (), span, self.site())
        if text == "geometry.isRectangular" and len(args or ()) <= 1:
            tolerance = self.expr(args[0]) if args else ir.Num(0.0, span)
            return ir.Call(text, (tolerance,), span, self.site())
        self.unsupported(f"{text}()", span)
        return ir.placeholder(span)

    def function(self, meta, name, args):
        span = self.token_span(name)
        func = FUNCTION_NAMES.get(str(name), str(name))
        args = tuple(self.expr(a) for a in (args or ()))
        if func == "p" and len(args) == 1:
            return ir.Call("p", args, span, self.site())
        if func == "fileRandom" and not args:
            return ir.Call("fileRandom", (), span, 0)  # one draw per lot for the whole file
        return ir.Call(func, args, span, self.site())

    def array(self, meta, *items):
        self.unsupported("arrays", self.span(meta))
        return ir.placeholder(self.span(meta))

    def index(self, meta, array, index):
        self.unsupported("array indexing", self.span(meta))
        return ir.placeholder(self.span(meta))


_OPS = {
    "color": Lowering.op_color,
    "offset": Lowering.op_offset,
    "mirror": Lowering.op_mirror,
    "alignScopeToAxes": Lowering.op_align,
    "alignScopeToGeometry": Lowering.op_align_geometry,
    "rotateScope": Lowering.op_rotate_scope,
    "extrude": Lowering.op_extrude,
    "t": Lowering.op_translate,
    "s": Lowering.op_scale,
    "r": Lowering.op_rotate,
    "center": Lowering.op_center,
    "i": Lowering.op_insert,
    "primitiveCube": Lowering.op_cube,
    "NIL": Lowering.op_nil,
    "set": Lowering.op_set,
    "report": Lowering.op_report,
    "convexify": Lowering.op_convexify,
    "cleanupGeometry": Lowering.op_cleanup,
    "envelope": Lowering.op_envelope,
    "roofHip": Lowering.op_roof,
    "roofGable": Lowering.op_roof,
    "roofShed": Lowering.op_roof,
    "roofPyramid": Lowering.op_roof,
}
#: The optional arguments after a roof's value (roofGable's ``index`` only by angle).
_ROOF_ARGUMENTS = {"roofHip": ("overhang", "even"), "roofGable": ("overhangX", "overhangY", "even"),
                   "roofShed": ("index",), "roofPyramid": ()}
#: Operations CityEngine also takes without their parentheses (other bare names are rules).
_BARE_OPS = frozenset({"NIL", "primitiveCube", "convexify"})
_SPLIT_OPS = frozenset({"split", "comp"})
#: CityEngine's street selectors (``geometry.streets``): the lot's street edges and the faces along them.
_STREET_SELECTORS = frozenset(f"street.{s}" for s in ("front", "back", "left", "right", "side"))
_COMP_SELECTORS = {
    "f": ir.FACE_SELECTORS | ir.OFFSET_SELECTORS | _STREET_SELECTORS
    | {f"{frame}.{s}" for frame in ("object", "world") for s in ir.FACE_SELECTORS},
    "e": ir.EDGE_SELECTORS,
    "v": ir.VERTEX_SELECTORS,
}
#: Setback operations and the edges their distances move (``setback`` moves those its parts select).
_SETBACK_OPS = {"setback": (), "shapeL": ("front", "left"), "shapeU": ("front", "right", "left"),
                "shapeO": ("front", "right", "back", "left")}
#: Edge selectors of ``setback``: an edge is named as the face an extrusion of the polygon would make of it.
_SETBACK_SELECTORS = (_COMP_SELECTORS["f"] - ir.OFFSET_SELECTORS) | {"all", "remainder", "streetSide", "noStreetSide"}
#: Shape attributes that grammarc does not provide yet: comp.index, split.index, initialShape.origin...
_UNSUPPORTED_MEMBERS = frozenset({"comp", "split", "initialShape", "geometry"})


def _as_body(value) -> ir.Body:
    return value if isinstance(value, tuple) else (value,)


# ---------------------------------------------------------------------------------------------- assembly


def assemble(file: str, statements: list, diags: Diagnostics, imports=()) -> ir.Module:
    """Declarations in source order -> Module: start rule, overloads by arity, functions inlined, the
    imported modules' rules and attributes merged under their prefixes."""
    attrs: list[ir.AttrDecl] = []
    functions: dict[str, FunctionDef] = {}
    rules: list[tuple[RuleDef, tuple]] = []
    style = None
    for st in statements:
        if not isinstance(st, Annotated):
            st = Annotated((), st)  # a declaration without annotations comes bare from the parser
        decl = st.declaration
        if isinstance(decl, Style):
            if style is None:
                diags.warning("style", f"style `{decl.name}` is not derived: grammarc derives the Default "
                              "style (PRT's Default$...)", decl.span)
            style = decl
            continue
        if style is not None and isinstance(decl, ir.AttrDecl):
            continue  # a redefinition for the style
        if isinstance(decl, ir.AttrDecl):
            if any(a.name == decl.name for a in attrs):
                diags.error("duplicate-attr", f"attribute `{decl.name}` is declared twice", decl.span)
            attrs.append(replace(decl, annotations=st.annotations))
        elif isinstance(decl, FunctionDef):
            functions[decl.name] = decl
        elif isinstance(decl, RuleDef):
            rules.append((decl, st.annotations))
    arities: dict[str, set[int]] = {}
    for rule, _ in rules:
        arities.setdefault(rule.name, set()).add(len(rule.params))

    def symbol_name(name: str, arity: int) -> str:
        return f"{name}/{arity}" if len(arities.get(name, ())) > 1 else name

    inline = _Inliner(functions, {a.name for a in attrs}, diags)
    attrs = [replace(a, default=inline.expr(a.default, frozenset())) for a in attrs]
    start = None
    lowered: list[ir.Rule] = []
    for rule, notes in rules:
        name = symbol_name(rule.name, len(rule.params))
        if any(a[0] == "StartRule" for a in notes) and start is None:
            start = name
        params = frozenset(rule.params)
        # a leaf `X.` names a shape, not a rule: it keeps its name when rules `X` are overloaded
        body = _map_symbols(rule.body, lambda op: replace(op, name=symbol_name(op.name, len(op.args)))
                            if op.name in arities and not op.leaf else op)
        body = rewrite_body(body, lambda e, p=params: inline.expr(e, p))
        lowered.append(ir.Rule(symbol=name, params=rule.params, guard=None,
                               alternatives=(ir.Alternative(body, None, rule.span),), priority=0,
                               span=rule.span, site=rule.site))
    if start is None and lowered:
        start = lowered[0].symbol
    imported = []
    for statement, module in imports:
        more_attrs, more_rules = _prefixed(module, statement.prefix, {a.name for a in attrs})
        attrs.extend(more_attrs)
        lowered.extend(more_rules)
        imported.extend((module.file, *module.imported))
    return ir.Module(file=file, attrs=tuple(attrs), rules=tuple(lowered), start=start, dialect="cityengine",
                     imported=tuple(dict.fromkeys(imported)))


def _prefixed(module: ir.Module, prefix: str | None, forwarded: set[str]):
    """An imported module's attributes and rules under ``prefix.``; its attributes that the importing
    file declares too are dropped, so that their names resolve to the importer's (forwarding)."""
    if prefix is None:
        return [a for a in module.attrs if a.name not in forwarded], list(module.rules)
    own_attrs = {a.name for a in module.attrs} - forwarded

    def rename(params):
        def visit(e):
            if isinstance(e, ir.Name) and e.name in own_attrs and e.name not in params:
                return replace(e, name=f"{prefix}.{e.name}")
            if isinstance(e, ir.AttrRef) and e.name in own_attrs:  # from an inlined function
                return replace(e, name=f"{prefix}.{e.name}")
            return e
        return visit

    attrs = [replace(a, name=f"{prefix}.{a.name}", default=rewrite_expr(a.default, rename(())))
             for a in module.attrs if a.name in own_attrs]
    rules = []
    for rule in module.rules:
        bodies = []
        for alt in rule.alternatives:
            body = _map_symbols(alt.body, lambda op: replace(op, name=f"{prefix}.{op.name}"))
            bodies.append(replace(alt, body=rewrite_body(body, rename(set(rule.params)))))
        rules.append(replace(rule, symbol=f"{prefix}.{rule.symbol}", alternatives=tuple(bodies)))
    return attrs, rules


def _map_symbols(body: ir.Body, fn) -> ir.Body:
    """``body`` with ``fn`` applied to every successor symbol, nested bodies included."""
    out = []
    for op in body:
        if isinstance(op, ir.Symbol):
            op = fn(op)
        elif isinstance(op, (ir.Case, ir.Stochastic)):
            op = replace(op, branches=tuple((c, _map_symbols(b, fn)) for c, b in op.branches),
                         default=_map_symbols(op.default, fn))
        elif sub_bodies(op):
            op = replace(op, parts=tuple(_map_symbols(b, fn) for b in op.parts))
        out.append(op)
    return tuple(out)


class _Inliner:
    """Replaces calls of user functions (and bare names of parameterless ones) by their bodies.

    A function's body is inlined in its own scope (its parameters, then the attributes) before the
    caller's arguments are bound, so that its names never see the parameters of the rule that calls it.
    """

    def __init__(self, functions: dict[str, FunctionDef], attrs: set[str], diags: Diagnostics):
        self.functions = functions
        self.attrs = attrs
        self.diags = diags
        #: Function name -> its body with the functions it calls inlined (computed once per function).
        self.bodies: dict[str, ir.Expr] = {}

    def expr(self, expr: ir.Expr, params: frozenset, calling: tuple[str, ...] = ()) -> ir.Expr:
        """``expr`` with user functions inlined; ``calling`` are the functions being inlined around it."""
        def visit(e: ir.Expr) -> ir.Expr:
            if isinstance(e, ir.Name) and e.name not in params and e.name not in self.attrs \
                    and e.name in self.functions and not self.functions[e.name].params:
                return self.call(self.functions[e.name], (), e.span, calling)
            if isinstance(e, ir.Call) and e.func not in ir.FUNCTIONS and e.func not in ir.CONVERSIONS:
                fn = self.functions.get(e.func)
                if fn is None:
                    self.diags.error("unknown-function", f"unknown function `{e.func}`"
                                     f"{suggest(e.func, [*ir.FUNCTIONS, *self.functions])}", e.span)
                    return ir.placeholder(e.span)
                if len(fn.params) != len(e.args):
                    self.diags.error("arity", f"`{e.func}` takes {len(fn.params)} arguments, got "
                                     f"{len(e.args)}", e.span)
                    return ir.placeholder(e.span)
                return self.call(fn, e.args, e.span, calling)
            return e

        return rewrite_expr(expr, visit)

    def call(self, fn: FunctionDef, args: tuple, span: Span, calling: tuple[str, ...]) -> ir.Expr:
        if fn.name in calling:
            # reported where the function calls itself, once (its body is inlined once)
            self.diags.error("unsupported", f"unsupported: recursive function `{fn.name}`", span)
            return ir.placeholder(span)
        if fn.name not in self.bodies:
            self.bodies[fn.name] = self.expr(fn.value, frozenset(fn.params), (*calling, fn.name))
        bound = dict(zip(fn.params, args))

        def substitute(e: ir.Expr) -> ir.Expr:
            if not isinstance(e, ir.Name):
                return e
            if e.name in bound:
                return bound[e.name]  # the caller's expression, already inlined in the caller's scope
            return ir.AttrRef(e.name, e.span) if e.name in self.attrs else e

        return rewrite_expr(self.bodies[fn.name], substitute)
