"""Lower CityEngine CGA (cityengine.lark) to the IR, one statement at a time: declarations, rule bodies and
CityEngine's expressions here, the operations in ``operations``, the expression operators in
``LoweringBase``.

The same IR as the paper notation: CityEngine's ``split`` becomes ``GroupSplit`` (absolute, ``'`` relative
and ``~`` floating sizes, repeat groups), ``comp(f)`` with selectors ``CompFaces``, ``case`` and ``p%``
blocks ``Case`` and ``Stochastic`` operations, ``case`` and ``p%`` expressions ``Select``. Functions and
constants-as-functions are inlined by ``assemble``; rules overloaded by arity get one symbol per arity
(``Pipe/1``, ``Pipe/3``). An operation or construct that grammarc does not implement is an error
``unsupported: NAME`` at its span, never skipped.
"""

from __future__ import annotations

import re
from dataclasses import replace

from lark import Token, v_args

from grammarc.diagnostics import Span, suggest
from grammarc.frontend.cityengine.nodes import (
    Annotated,
    EdgeDistances,
    EdgeTable,
    FunctionDef,
    Group,
    Import,
    Part,
    PendingOffset,
    RuleDef,
    Sized,
    Style,
    as_body,
)
from grammarc.frontend.cityengine.operations import (
    ALL_OPERATIONS,
    BARE_OPS,
    BODY_OPERATIONS,
    NOT_APPLIED,
    OPERATIONS,
    PART_OPERATIONS,
    REPEATING,
    SETBACK_SELECTORS,
    SPLIT_OPS,
    UNSUPPORTED_MEMBERS,
    UNSUPPORTED_OPS,
    WITHOUT_PARTS,
    OperationLowering,
)
from grammarc.frontend.lowering import LoweringBase
from grammarc.ir import nodes as ir
from grammarc.ir.functions import CONVERT_SELECTORS, FUNCTIONS

#: The annotations of CityEngine's CGA reference ("Annotations", 2019-2025).
ANNOTATIONS = frozenset((
    "Angle", "Color", "Description", "Directory", "DisplayName", "Distance", "Enum", "File", "Group",
    "Handle", "Hidden", "InLine", "InMesh", "InPoint", "InPointCloud", "InPolygon", "MaterialFile", "Order",
    "Out", "Percent", "Range", "StartRule",
))
#: CityEngine built-in functions mapped onto the IR's.
FUNCTION_NAMES = {"rint": "round", "ln": "log"}
#: Operations of older CGA versions under their names of today: ESRI.lib's 2014.0 rule files move texture
#: coordinates with ``offsetUV(uvSet, u, v)``, ``translateUV`` since.
OPERATION_NAMES = {"offsetUV": "translateUV"}
SCOPE_MEMBERS = {
    **{f"scope.{f}": f for f in ("sx", "sy", "sz", "tx", "ty", "tz", "rx", "ry", "rz")},
    "initialShape.origin.px": "ox", "initialShape.origin.py": "oy", "initialShape.origin.pz": "oz",
}
#: Built-ins taking a selector keyword (``assetInfo(a, sx)``): the argument's index and the keywords, lowered
#: to their text (CityEngine takes them quoted too, ``assetBestSize(q, "xz")``).
SELECTOR_ARGUMENTS = {
    **dict.fromkeys(("assetInfo",), (1, frozenset({"sx", "sy", "sz", "tx", "ty", "tz"}))),
    **dict.fromkeys(("imageInfo",), (1, frozenset({"sx", "sy"}))),
    **dict.fromkeys(("assetNamingInfo", "assetNamingInfos"), (1, frozenset({"g", "m"}))),
    **dict.fromkeys(("assetsSortSize", "assetsSortRatio", "imagesSortRatio"),
                    (1, frozenset({"x", "y", "z", "xy", "xz", "yz", "xyz", "yx", "zx", "zy"}))),
}
#: ``initialShape.origin.o{x|y|z}``: the lot's orientation, a component of ``convert``'s.
INITIAL_ORIENTATION = {f"initialShape.origin.o{c}": c for c in "xyz"}
#: ``pivot.p{x|y|z}`` and ``pivot.o{x|y|z}``: the pivot's origin and orientation in the object system.
PIVOT_MEMBERS = frozenset(f"pivot.{k}{c}" for k in "po" for c in "xyz")
#: The faces ``geometry.isOriented`` checks for, by their normals, as ``comp(f)`` selects them.
_ORIENTATIONS = frozenset(
    {f"{frame}{s}" for frame in ("", "object.") for s in ("front", "back", "left", "right", "top", "bottom", "side")}
    | {f"world.{s}" for s in ("north", "south", "west", "east", "up", "down", "side")}
    | {f"street.{s}" for s in ("front", "back", "left", "right", "side")})
#: The selector of each geometry query that takes one: the faces it measures, or the angle it gives.
GEOMETRY_SELECTORS = {
    "geometry.area": _ORIENTATIONS | {"all", "surface"},
    "geometry.isOriented": _ORIENTATIONS,
    "geometry.angle": frozenset({"maxSlope", "azimuth", "zenith"}),
}
#: CityEngine's compass selectors as the scope's names in the world's frame (north is -z, east +x).
WORLD_DIRECTIONS = {"world.north": "world.back", "world.south": "world.front", "world.east": "world.right",
                    "world.west": "world.left", "world.up": "world.top", "world.down": "world.bottom"}
#: The geometry queries of the reference that grammarc cannot answer yet, and why.
UNANSWERED_QUERIES = {
    **{f"geometry.{name}": "the groups and materials of assets are not kept" for name in ("groups", "materials")},
    **{f"geometry.{name}": "geometry tags, as `tag` makes them" for name in ("hasTags", "tags")},
}


@v_args(inline=True, meta=True)
class Lowering(OperationLowering, LoweringBase):
    """One CityEngine statement's parse tree -> IR pieces (``Annotated`` declarations)."""

    #: CityEngine's arity errors say "`setback` takes 1 arguments"; kept as they were.
    one_argument = "arguments"

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
        """``@Name(args)`` -> (name, argument texts): annotations only guide CityEngine's inspector (but
        ``@StartRule``), so their arguments are kept as written, blanks around a keyword's ``=`` dropped.
        An annotation CityEngine does not document is kept with a warning, as CityEngine does."""
        if str(name) not in ANNOTATIONS:
            self.diags.warning("annotation", f"unknown annotation `@{name}`: kept, but nothing reads it",
                               self.token_span(name))
        return (str(name), _annotation_arguments(str(args)[1:-1]) if args is not None else ())

    def version(self, meta, text):
        return None

    def style(self, meta, name):
        return Style(str(name), self.token_span(name))

    def import_prefixed(self, meta, prefix, styles, path, args):
        # the styles to import are not kept: grammarc derives the Default style
        return self.import_plain(meta, path, args, str(prefix))

    def import_plain(self, meta, path, args, prefix=None):
        protected = tuple(a for a in args or () if isinstance(a, str))
        return Import(prefix, path, self.span(meta), protected, args == (),
                      tuple(a for a in args or () if isinstance(a, ir.AttrDecl)),
                      tuple(a for a in args or () if isinstance(a, RuleDef)))

    def import_styles(self, meta, *names):
        return None

    def import_path(self, meta, path):
        return str(path)[1:-1] if path.type == "STRING" else str(path)

    def import_args(self, meta, *args):
        return tuple(a for a in args if a is not None)

    def import_protect(self, meta, name):
        return str(name)

    def import_attr(self, meta, name, value):
        return ir.AttrDecl(str(name), value, self.token_span(name))

    def import_extension(self, meta, name, params, arrow, body):
        return RuleDef(str(name), params or (), as_body(body), self.token_span(name), self.site())

    def import_rule_override(self, meta, prefix, name, params, arrow, body):
        """``prefix.Rule --> ...``: the importing file's own ``Rule`` of an imported file (assembly)."""
        return RuleDef(f"{prefix}.{name}", params or (), as_body(body), self.token_span(prefix), self.site())

    def import_leaf(self, meta, prefix, name, dot):
        return ir.Symbol(f"{prefix}.{name}", (), self.token_span(prefix), self.site(), leaf=True)

    def attr_decl(self, meta, name, value):
        return ir.AttrDecl(str(name), self.expr(value), self.token_span(name))

    def const_decl(self, meta, name, value):
        if isinstance(value, EdgeDistances):
            return EdgeTable(str(name), value)
        return ir.AttrDecl(str(name), self.expr(value), self.token_span(name), const=True)

    def function_def(self, meta, name, params, value):
        return FunctionDef(str(name), params or (), value, self.token_span(name))

    def rule_def(self, meta, name, params, arrow, body):
        return RuleDef(str(name), params or (), as_body(body), self.token_span(name), self.site())

    def params(self, meta, *names):
        return tuple(str(n) for n in names if n is not None)

    def typed_param(self, meta, kind, name):
        """``float h``: CityEngine infers a parameter's type from its uses, and so does grammarc; the
        declared type is accepted and not checked."""
        return name

    # ------------------------------------------------------------------------------------------ bodies
    def body(self, meta, *items):
        return self.fuse_offsets([op for item in items for op in as_body(item)])

    def bracketed(self, meta, lsqb, body, rsqb):
        """``[ ... ]``: the scope pushed, the operations (a body, or a ``case`` or ``p%`` block, which
        ends at the ``]``) run, the scope popped; what follows continues from the pushed scope."""
        return (ir.Push(self.token_span(lsqb)), *as_body(body), ir.Pop(self.token_span(rsqb)))

    def fuse_offsets(self, items) -> ir.Body:
        """``offset(d) comp(f){ inside: ... | border: ... }`` becomes one component split of the offset's
        faces; an ``offset(d)`` that no such comp follows is ``offset(d, all)``, the shape of both."""
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
                    out.append(ir.Offset(pending.distance, "all", pending.span))
                pending = None
            out.append(item)
        if pending is not None:
            out.append(ir.Offset(pending.distance, "all", pending.span))
        return tuple(out)

    def case_block(self, meta, *branches):
        """``case c : A ... [else : B]``; without ``else`` a shape that meets no condition gets no
        successor (CityEngine's reference always writes the ``else``; public files leave it out)."""
        *cases, default = branches
        return (ir.Case(tuple(cases), default if default is not None else (), self.span(meta)),)

    def case_branch(self, meta, cond, body):
        return (cond, as_body(body))

    def else_branch(self, meta, body):
        return as_body(body)

    def stochastic_block(self, meta, *branches):
        *chances, default = branches
        return (ir.Stochastic(tuple(chances), default if default is not None else (), self.span(meta),
                              self.site()),)

    def stochastic_branch(self, meta, probability, percent, body):
        return (probability, as_body(body))

    def symbol(self, meta, name):
        text, span = str(name), self.token_span(name)
        if text in BARE_OPS:
            return OPERATIONS[text](self, text, (), span)
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
        chosen = self.selector_parts("comp(fe)", parts, SETBACK_SELECTORS - {"remainder"}, noun=None)
        if chosen is None:
            return ir.placeholder(span)
        values = []
        for selector, body in zip(*chosen):
            # a part's body is one expression, parsed as an operation: a call, or a name
            if len(body) == 1 and isinstance(body[0], ir.Num):
                value = body[0]
            elif len(body) == 1 and isinstance(body[0], ir.Symbol):
                op = body[0]
                func = FUNCTION_NAMES.get(op.name, op.name)
                value = ir.Call(func, op.args, op.span, self.site()) if op.args or func in FUNCTIONS \
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
        return Part(Sized(kind, value, getattr(value, "span", self.span(meta))), as_body(body), False,
                    self.span(meta))

    def merged_part(self, meta, kind, value, body):
        return Part(Sized(kind, value, getattr(value, "span", self.span(meta))), as_body(body), True,
                    self.span(meta))

    def number_part(self, meta, kind, value, number):
        """``all : 3``: a part whose body is a number, a distance of ``comp(fe){ ... }``
        (``selector_function`` takes it); in any other split the number is an error (``assembly``)."""
        return self.part(meta, kind, value, ir.Num(float(number), self.token_span(number)))

    def merged_number_part(self, meta, kind, value, number):
        return self.merged_part(meta, kind, value, ir.Num(float(number), self.token_span(number)))

    def repeat_group(self, meta, parts, star):
        return Group(parts, self.span(meta))

    def group_once(self, meta, parts):
        """``{ a : A | b : B }`` without ``*``: a group taken once is its parts, in their place (public
        files write it beside repeated groups, `split(x){ {~0.5 : Wall} | {~3 : Tile}* }`)."""
        return parts

    def parts(self, meta, *parts):
        return tuple(p for part in parts for p in (part if isinstance(part, tuple) else (part,)))

    # -------------------------------------------------------------------------------------- operations
    def call(self, meta, name, args):
        """``op(args)``: an operation of ``OPERATIONS``, one accepted but not applied, or a rule call."""
        op, span, args = str(name), self.token_span(name), args or ()
        op = OPERATION_NAMES.get(op, op)
        handler = OPERATIONS.get(op)
        if handler is not None:
            return handler(self, op, args, span)
        if op in NOT_APPLIED:
            return ir.NotApplied(op, span)
        if op in UNSUPPORTED_OPS or op in SPLIT_OPS:
            return self.unsupported(op, span)
        if op in WITHOUT_PARTS:
            return WITHOUT_PARTS[op](self, op, args, span)
        if op in PART_OPERATIONS:
            return self.unsupported(f"{op} without selector parts", span,
                                    f"write {op}(...) {{ ... | remainder: ... }}")
        return ir.Symbol(op, tuple(self.expr(a) for a in args), span, self.site())

    def scatter(self, meta, name, args, body):
        """``scatter(...) { operations }``: an operation of ``BODY_OPERATIONS``; without braces its points
        have an empty body (they stay leaves)."""
        op = str(name)
        return BODY_OPERATIONS[op](self, op, args or (), as_body(body) if body is not None else (),
                                   self.token_span(name))

    def split_call(self, meta, name, args, parts, star):
        """``op(args){ parts }``, and ``split(args){ parts }*``: an operation of ``PART_OPERATIONS``."""
        op, span, args = str(name), self.token_span(name), args or ()
        handler = PART_OPERATIONS.get(op)
        if handler is None:
            if op not in ALL_OPERATIONS:  # a rule call takes no parts: a misspelt operation
                self.diags.error("unknown-op", f"unknown operation `{op}`"
                                 f"{suggest(op, PART_OPERATIONS) or suggest(op, ALL_OPERATIONS)}", span)
                return ir.Empty(span)
            return self.unsupported(op, span)
        if star is None:
            return handler(self, op, args, parts, span)
        if op not in REPEATING:
            return self.unsupported(f"`*` after {op}", self.token_span(star), "only split and splitArea repeat")
        return handler(self, op, args, parts, span, repeat=True)

    # ------------------------------------------------------------------------------------- expressions
    def value_case(self, meta, *items):
        *pairs, default = items
        result = default
        for i in range(len(pairs) - 2, -1, -2):
            result = ir.Select(self.expr(pairs[i]), pairs[i + 1], result, self.span(meta))
        return result

    def value_stochastic(self, meta, *items):
        *pairs, default = [i for i in items if not (isinstance(i, Token) and i.type == "PERCENT_COLON")]
        # p% : a  q% : b  else : c  ->  p(p / 100) ? a : p(q / 100 / (1 - p / 100)) ? b : c: one draw per
        # percentage, in turn, each given that none before was taken (the frequencies stay p, q and the
        # rest); a two-way one is p(p / 100), as PRT draws it
        span = self.span(meta)
        chances, before = [], None
        for i in range(0, len(pairs), 2):
            share = ir.Binary("/", pairs[i], ir.Num(100.0), pairs[i].span)
            chances.append(share if before is None else
                           ir.Binary("/", share, ir.Binary("-", ir.Num(1.0), before, span), span))
            before = share if before is None else ir.Binary("+", before, share, share.span)
        result = default
        for chance, value in reversed(list(zip(chances, pairs[1::2]))):
            result = ir.Select(ir.Call("p", (chance,), span, self.site()), value, result, span)
        return result

    def string(self, meta, tok):
        text = str(tok)[1:-1].replace('\\"', '"').replace("\\\\", "\\")
        return ir.Str(text, self.token_span(tok))

    def dotted_name(self, meta, *names):
        return tuple(str(n) for n in names), Span(self.file, names[0].line, names[0].column,
                                                  names[-1].end_line, names[-1].end_column)

    def name(self, meta, tok):
        return ir.Name(str(tok), self.token_span(tok))

    def member(self, meta, dotted):
        names, span = dotted
        text = ".".join(names)
        if text in SCOPE_MEMBERS:
            return ir.ScopeRef(SCOPE_MEMBERS[text], span)
        if names[0] == "geometry":  # the checker names what it takes, or the closest query to an unknown one
            return self.unanswered(text, span) if text in UNANSWERED_QUERIES else ir.Call(text, (), span, self.site())
        if text in ir.CONTEXT_FIELDS:
            return ir.ContextRef(text, span)
        if text in ("initialShape.name", "initialShape.startRule"):
            return ir.Call(text, (), span, self.site())
        if text == "scope.elevation":
            # the reference: the height of the scope's origin above the sea, the world's y (read only)
            zero = ir.Num(0.0, span)
            return self.convert((ir.Name("y", span), ir.Name("scope", span), ir.Name("world", span),
                                 ir.Name("pos", span), zero, zero, zero), span)
        if text in INITIAL_ORIENTATION:  # the lot's orientation in world: its object system's
            zero = ir.Num(0.0, span)
            return self.convert((ir.Name(INITIAL_ORIENTATION[text], span), ir.Name("object", span),
                                 ir.Name("world", span), ir.Name("orient", span), zero, zero, zero), span)
        if text in PIVOT_MEMBERS:  # the pivot's origin and angles in the object system (``backend.pivot``)
            zero = ir.Num(0.0, span)
            kind = "pos" if names[1][0] == "p" else "orient"
            return self.convert((ir.Name(names[1][1], span), ir.Name("pivot", span), ir.Name("object", span),
                                 ir.Name(kind, span), zero, zero, zero), span)
        if names[0] in UNSUPPORTED_MEMBERS:
            self.unsupported(text, span)
            return ir.placeholder(span)
        # material.*, scope.xy, world.xyz...: arguments of set, setupProjection, alignScopeToAxes; as a
        # value anywhere else, name resolution reports them
        return ir.Name(text, span)

    def member_function(self, meta, dotted, args):
        names, span = dotted
        text = ".".join(names)
        args = tuple(self.expr(a) for a in args or ())
        if text in UNANSWERED_QUERIES:
            return self.unanswered(text, span, "()")
        if text in GEOMETRY_SELECTORS and len(args) == 1:
            return self.geometry_selector(text, args[0], span)
        if text in ("geometry.du", "geometry.dv") and len(args) == 2:
            if not (isinstance(args[1], ir.Name) and args[1].name in ("uvSpace", "unitSpace")):
                self.unsupported(f"{text} in this space", span, "uvSpace or unitSpace")
                return ir.placeholder(span)
            args = (args[0], ir.Str(args[1].name, args[1].span))
        if text == "geometry.isRectangular" and not args:
            args = (ir.Num(0.0, span),)
        # a geometry query (the checker checks the arguments, or names the closest query), or a function
        # of an imported file, `prefix.name(...)`, which assembly inlines
        return ir.Call(text, args, span, self.site())

    def geometry_selector(self, query: str, value: ir.Expr, span: Span) -> ir.Expr:
        """``geometry.area(top)``, ``geometry.angle(azimuth)``: the selector as a constant string, the
        compass directions as the world frame's faces (``WORLD_DIRECTIONS``)."""
        known = GEOMETRY_SELECTORS[query]
        if not isinstance(value, ir.Name) or value.name not in known:
            named = isinstance(value, ir.Name)
            self.unsupported(f"{query} selector `{value.name}`" if named else f"this {query} selector", value.span,
                             f"{query} selects {', '.join(sorted(known))}" + (suggest(value.name, known) if named else ""))
            return ir.placeholder(span)
        selector = ir.Str(WORLD_DIRECTIONS.get(value.name, value.name), value.span)
        return ir.Call(query, (selector,), span, self.site())

    def unanswered(self, query: str, span: Span, called: str = "") -> ir.Expr:
        self.unsupported(query + called, span, UNANSWERED_QUERIES[query])
        return ir.placeholder(span)

    def function(self, meta, name, args):
        span = self.token_span(name)
        if str(name) in ir.OCCLUSION_KINDS | ir.CONTEXT_KINDS:
            return self.occlusion(str(name), args or (), span)
        func = FUNCTION_NAMES.get(str(name), str(name))
        args = tuple(self.expr(a) for a in (args or ()))
        if func == "p" and len(args) == 1:
            return ir.Call("p", args, span, self.site())
        index, keywords = SELECTOR_ARGUMENTS.get(func, (-1, ()))
        if 0 <= index < len(args) and isinstance(args[index], ir.Name) and args[index].name in keywords:
            args = args[:index] + (ir.Str(args[index].name, args[index].span),) + args[index + 1:]
        if func == "convert":
            return self.convert(args, span)
        return ir.Call(func, args, span, self.site())

    def convert(self, args, span) -> ir.Expr:
        """``convert(x|y|z, from, to, pos|orient, x, y, z)`` with its keywords as strings, and
        ``convert(from, to, pos|orient, coordinates)`` as the array of its three components' calls."""
        on_array = len(args) == 4
        keywords = (ir.Name("x", span), *args[:3]) if on_array else args[:4]
        if len(args) not in (4, 7) or not all(isinstance(a, ir.Name) and a.name in allowed
                                              for a, allowed in zip(keywords, CONVERT_SELECTORS)):
            self.unsupported("convert with these arguments", span, "convert(x|y|z, scope|pivot|object|world, "
                             "scope|pivot|object|world, pos|orient, x, y, z) or convert(from, to, pos|orient, "
                             "[x, y, z])")
            return ir.placeholder(span)
        systems = tuple(ir.Str(a.name, a.span) for a in keywords[1:])
        if not on_array:
            return ir.Call("convert", (ir.Str(args[0].name, args[0].span), *systems, *args[4:]), span, self.site())
        values = tuple(ir.Index(args[3], ir.Num(float(i), span), None, span) for i in range(3))
        return ir.ArrayLit((tuple(ir.Call("convert", (ir.Str(c, span), *systems, *values), span, self.site())
                                  for c in "xyz"),), span)

    def occlusion(self, kind: str, args, span) -> ir.Expr:
        """``inside`` / ``overlaps`` / ``touches([target[, label]])`` and the context queries
        ``minimumDistance`` / ``contextCount(target, label)``: the target ``intra``, ``inter`` or ``all``,
        or ``sel(text)`` computed; the label a string, constant or computed."""
        args = tuple(self.expr(a) for a in args)
        target = args[0].name if args and isinstance(args[0], ir.Name) else None
        chosen = args[0].args[0] if args and isinstance(args[0], ir.Call) and args[0].func == "sel" \
            and len(args[0].args) == 1 else None
        if isinstance(chosen, ir.Str) and chosen.value in ir.OCCLUSION_TARGETS:
            target, chosen = chosen.value, None
        context = kind in ir.CONTEXT_KINDS  # a context query takes both arguments
        if len(args) not in ((2,) if context else (0, 1, 2)) or (args and target not in ir.OCCLUSION_TARGETS
                                                                 and chosen is None):
            forms = f"{kind}(intra|inter|all|sel(text), label)" if context else \
                f"{kind}(), {kind}(intra|inter|all[, label]) and {kind}(sel(text)[, label])"
            self.unsupported(f"{kind} with these arguments", span, forms)
            return ir.placeholder(span)
        label = args[1] if len(args) == 2 else None
        constant = label.value if isinstance(label, ir.Str) else None
        return ir.Occlusion(kind, target or "all", constant, span, which=chosen,
                            named=None if constant is not None else label)

    def elementwise_unary(self, meta, op, operand):
        """``.-a``, ``.+a``, ``.!a`` on arrays (``.+a`` is ``a``)."""
        if str(op) == ".+":
            return self.expr(operand)
        return ir.Unary(str(op), self.expr(operand), self.span(meta))

    def array(self, meta, *rows):
        """``[a, b ; c, d]``: an array literal; ``[base:limit]`` alone is its range."""
        if len(rows) == 1 and len(rows[0]) == 1 and isinstance(rows[0][0], ir.Range):
            return rows[0][0]
        return ir.ArrayLit(tuple(rows), self.span(meta))

    def array_row(self, meta, *items):
        return tuple(self.expr(i) for i in items)

    def range(self, meta, base, second, third):
        base, second = self.expr(base), self.expr(second)
        if third is None:  # base : limit
            return ir.Range(base, ir.Num(1.0, self.span(meta)), second, self.span(meta))
        return ir.Range(base, second, self.expr(third), self.span(meta))

    def index(self, meta, array, index, column):
        """``a[i]`` and ``a[i, j]``; an index may be an array or a range (``a[1:3]``)."""
        return ir.Index(self.expr(array), self.expr(index), None if column is None else self.expr(column),
                        self.span(meta))


#: An annotation's arguments: strings whole, brackets balanced, split at the commas outside them.
_ANNOTATION_PIECE = re.compile(r'"(?:\\.|[^"\\])*"|[([{]|[)\]}]|,|[^"()\[\]{},]+')


def _annotation_arguments(text: str) -> tuple[str, ...]:
    """``min = 0, max=f(1, 2), "a, b"`` -> ``("min=0", "max=f(1, 2)", '"a, b"')``."""
    arguments, current, depth = [], [], 0
    for piece in _ANNOTATION_PIECE.findall(text):
        if piece == "," and depth == 0:
            arguments.append("".join(current))
            current = []
            continue
        depth += (piece in "([{") - (piece in ")]}") if len(piece) == 1 else 0
        current.append(piece)
    arguments.append("".join(current))
    return tuple(re.sub(r"^\s*(\w+)\s*=(?!=)\s*", r"\1=", a).strip() for a in arguments if a.strip())
