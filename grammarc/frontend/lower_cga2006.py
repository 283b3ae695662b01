"""Lower the parse tree of the paper notation (cga2006.lark) to IR, one statement at a time.

Each method of ``Lowering`` handles one grammar rule or alias. Problems are appended to the diagnostics
list and a harmless placeholder is returned, so that lowering goes on and every error is reported;
``__default__`` turns a tree the lowering does not know into "unsupported construct" at its span.
"""

from __future__ import annotations

from dataclasses import dataclass

from lark import v_args

from grammarc.diagnostics import Diagnostics, Span, suggest
from grammarc.frontend.lowering import LoweringBase
from grammarc.ir import nodes as ir

#: Split axes of Subdiv and Repeat (paper section 2, "Basic split rule").
AXES = {
    "X": (0,), "Y": (1,), "Z": (2,),
    "XY": (0, 1), "XZ": (0, 2), "YZ": (1, 2), "XYZ": (0, 1, 2),
}
#: Snap split axes (paper section 3.3): the axis with ``S`` snaps to the lot's snap planes.
SNAP_AXES = {"XS": (0,), "YS": (1,), "ZS": (2,)}
#: The scope axis across a snap shape's plane, by the axes the paper names (``Snap("XZ")``: the floor
#: plane, across y; ``Snap("Y")``: the vertical line of a facade, a plane through it and the facade's
#: normal z, so across x).
SNAP_NORMALS = {"XZ": 1, "ZX": 1, "XY": 2, "YX": 2, "YZ": 0, "ZY": 0, "X": 1, "Y": 0, "Z": 0}

#: The paper's roof types (section 3.1) and the roofs that build them: a cross gable is the gable roof of
#: a cross-shaped footprint, a cone the pyramid of a many-sided one; mansard and gambrel are the hip and
#: the gable roof with two slopes (``geometry.roofs``).
ROOF_TYPES = {"hipped": "roofHip", "gabled": "roofGable", "cross-gable": "roofGable", "cone": "roofPyramid",
              "pyramid": "roofPyramid", "shed": "roofShed", "mansard": "mansard", "gambrel": "gambrel"}
#: Context queries (paper section 3.2), parsed as dotted calls.
#: Occlusion queries (section 3.2): both test the shape's scope.
OCCLUSION_QUERIES = {("Shape", "occ"), ("Scope", "occ")}

OPERATIONS = ("T", "S", "R", "Rx", "Ry", "Rz", "I", "Subdiv", "Repeat", "Comp", "Roof", "Snap", "SnapLines")


@dataclass(frozen=True, slots=True)
class Relative:
    """A relative size argument (``1r``): only S and Subdiv accept it."""

    value: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class RuleStatement:
    label: str | None
    symbol: str
    params: tuple[str, ...]
    guard: ir.Expr | None
    alternatives: tuple[ir.Alternative, ...]
    span: Span
    site: int


@dataclass(frozen=True, slots=True)
class ContinuationStatement:
    """``~> successor : prob`` lines that add alternatives to the rule before them."""

    alternatives: tuple[ir.Alternative, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class PriorityStatement:
    value: int
    span: Span


Statement = RuleStatement | ContinuationStatement | PriorityStatement | ir.AttrDecl


@v_args(inline=True, meta=True)
class Lowering(LoweringBase):
    """Parse tree of one statement -> IR pieces. ``sites`` numbers random-stream sites in source order."""

    def __default__(self, data, children, meta):
        span = self.span(meta)
        self.diags.error("unsupported", f"unsupported construct `{data}`", span)
        return ir.Empty(span)

    # -------------------------------------------------------------------------------------- statements
    def rule(self, meta, label, name, params, guard, alternatives):
        return RuleStatement(
            label=str(label) if label is not None else None,
            symbol=str(name),
            params=params or (),
            guard=guard,
            alternatives=alternatives,
            span=self.token_span(name),
            site=self.site(),
        )

    def params(self, meta, *names):
        names = [n for n in names if n is not None]
        seen = set()
        for n in names:
            if str(n) in seen:
                self.diags.error("duplicate-param", f"parameter `{n}` appears twice", self.token_span(n))
            seen.add(str(n))
        return tuple(str(n) for n in names)

    def continuation(self, meta, alternatives):
        return ContinuationStatement(alternatives, self.span(meta))

    def priority(self, meta, value):
        return PriorityStatement(int(value), self.span(meta))

    def attr_decl(self, meta, name, default):
        return ir.AttrDecl(str(name), self.expr(default), self.token_span(name))

    def alternatives(self, meta, *alts):
        return tuple(alts)

    def alternative(self, meta, arrow, body, prob):
        return ir.Alternative(body, self.expr(prob) if prob is not None else None, self.span(meta))

    # -------------------------------------------------------------------------------------- successors
    def successor(self, meta, *items):
        # `[` and `]` pair up within one successor (a split part is a successor of its own)
        pushed = []
        for item in items:
            if isinstance(item, ir.Push):
                pushed.append(item)
            elif isinstance(item, ir.Pop) and pushed:
                pushed.pop()
            elif isinstance(item, ir.Pop):
                self.diags.error("syntax", "`]` without a `[` before it", item.span)
        for item in pushed:
            self.diags.error("syntax", "unclosed `[`", item.span,
                             hint="close it with `]` in the same successor")
        # an operation may lower to several (``Roof(...){ part }`` is the roof, then its part)
        return tuple(op for item in items for op in (item if isinstance(item, tuple) else (item,)))

    def parts(self, meta, *bodies):
        return tuple(bodies)

    def symbol(self, meta, name):
        return ir.Symbol(str(name), (), self.token_span(name), self.site())

    def empty(self, meta, tok):
        return ir.Empty(self.token_span(tok))

    def push(self, meta, tok):
        return ir.Push(self.token_span(tok))

    def pop(self, meta, tok):
        return ir.Pop(self.token_span(tok))

    def args(self, meta, *args):
        return tuple(args)

    def relative(self, meta, tok):
        return Relative(ir.Num(float(str(tok)[:-1]), self.token_span(tok)), self.token_span(tok))

    def call(self, meta, name, args, parts):
        op = str(name)
        span = self.token_span(name)
        args = args or ()
        handler = _CALLS.get(op)
        if handler is not None:
            return handler(self, op, args, parts, span)
        if parts is not None:
            self.diags.error("unknown-op", f"unknown operation `{op}`{suggest(op, OPERATIONS)}", span)
            return ir.Empty(span)
        return ir.Symbol(op, tuple(self.expr(a) for a in args), span, self.site())

    def expect_args(self, op, args, counts, span) -> bool:
        if len(args) not in counts:
            want = " or ".join(str(c) for c in counts)
            noun = "argument" if counts == (1,) else "arguments"
            self.diags.error("arity", f"`{op}` takes {want} {noun}, got {len(args)}", span)
            return False
        return True

    def expect_no_parts(self, op, parts, span) -> None:
        if parts is not None:
            self.diags.error("syntax", f"`{op}` takes no `{{...}}` body", span)

    def expect_parts(self, op, parts, span) -> tuple:
        if parts is None:
            self.diags.error("syntax", f"`{op}` needs a body `{{ A | B | ... }}`", span)
            return ((),)
        return parts

    def expr(self, arg):
        """An argument that must be an expression (not ``1r``)."""
        if isinstance(arg, Relative):
            self.diags.error(
                "relative", "a relative size like `1r` is only allowed in `S` and `Subdiv`", arg.span
            )
            return arg.value
        return arg

    def size(self, arg) -> ir.Size:
        if isinstance(arg, Relative):
            return ir.Size(ir.SizeKind.RELATIVE, arg.value, arg.span)
        return ir.Size(ir.SizeKind.ABSOLUTE, arg, getattr(arg, "span", self.fallback))

    def string_arg(self, op, arg, span, what) -> str | None:
        if isinstance(arg, ir.Str):
            return arg.value
        self.diags.error("type", f"`{op}` expects {what} as a string literal", getattr(arg, "span", span))
        return None

    def axes(self, op, arg, span) -> tuple[tuple[int, ...], bool] | None:
        """A split's axes and whether it snaps (``"XS"``), or None after an error."""
        text = self.string_arg(op, arg, span, "an axis")
        if text is None:
            return None
        if text in SNAP_AXES:
            return SNAP_AXES[text], True
        if text not in AXES:
            known = [*AXES, *SNAP_AXES]
            self.diags.error(
                "axis", f"unknown split axis \"{text}\", expected one of {', '.join(known)}", arg.span
            )
            return None
        return AXES[text], False

    def snap_label(self, op, args, snap: bool, span) -> tuple[tuple, str | None]:
        """A snapped split's trailing label (``Subdiv("XS", ..., "tilesnap")``) and the other args."""
        if snap and args and isinstance(args[-1], ir.Str):
            return args[:-1], args[-1].value
        return args, None

    def op_translate(self, op, args, parts, span):
        self.expect_no_parts(op, parts, span)
        if not self.expect_args(op, args, (3,), span):
            return ir.Empty(span)
        return ir.Translate(tuple(self.expr(a) for a in args), span)

    def op_scale(self, op, args, parts, span):
        self.expect_no_parts(op, parts, span)
        if not self.expect_args(op, args, (3,), span):
            return ir.Empty(span)
        return ir.Scale(tuple(self.size(a) for a in args), span)

    def op_rotate(self, op, args, parts, span):
        self.expect_no_parts(op, parts, span)
        if op == "R":
            if not self.expect_args(op, args, (3,), span):
                return ir.Empty(span)
            return ir.Rotate(tuple(self.expr(a) for a in args), span)
        if not self.expect_args(op, args, (1,), span):
            return ir.Empty(span)
        zero = ir.Num(0.0, span)
        angles = [zero, zero, zero]
        angles["xyz".index(op[1])] = self.expr(args[0])
        return ir.Rotate(tuple(angles), span)

    def op_insert(self, op, args, parts, span):
        self.expect_no_parts(op, parts, span)
        if not self.expect_args(op, args, (1,), span):
            return ir.Empty(span)
        name = self.string_arg(op, args[0], span, "an asset name")
        return ir.Insert(name, span) if name is not None else ir.Empty(span)

    def op_subdiv(self, op, args, parts, span):
        parts = self.expect_parts(op, parts, span)
        if len(args) < 2:
            self.diags.error("arity", f"`{op}` takes an axis and at least one size, "
                             f"got {_count(len(args), 'argument')}", span)
            return ir.Empty(span)
        chosen = self.axes(op, args[0], span)
        if chosen is None:
            return ir.Empty(span)
        axes, snap = chosen
        rest, label = self.snap_label(op, args[1:], snap, span)
        sizes = tuple(self.size(a) for a in rest)
        cells = len(sizes) ** len(axes)
        if len(parts) != cells and not (len(axes) > 1 and len(parts) == 1):
            self.diags.error(
                "parts",
                f"`{op}` has {cells} {'parts' if len(axes) == 1 else 'cells'} but {len(parts)} "
                f"successor{'s' if len(parts) != 1 else ''} in its body",
                span,
                hint="give one successor per size, separated by `|` (use ε for an empty part)",
            )
        return ir.Split(axes, sizes, parts, span, self.site(), snap, label)

    def op_repeat(self, op, args, parts, span):
        parts = self.expect_parts(op, parts, span)
        if len(args) < 2:
            self.diags.error("arity", f"`{op}` takes an axis and a size per axis, "
                             f"got {_count(len(args), 'argument')}", span)
            return ir.Empty(span)
        chosen = self.axes(op, args[0], span)
        if chosen is None:
            return ir.Empty(span)
        axes, snap = chosen
        rest, label = self.snap_label(op, args[1:], snap, span)
        if len(rest) != len(axes):
            self.diags.error("arity", f"`{op}(\"{args[0].value!s}\", ...)` takes {len(axes)} "
                             f"size{'s' if len(axes) > 1 else ''}, got {len(rest)}", span)
            return ir.Empty(span)
        return ir.Repeat(axes, tuple(self.expr(a) for a in rest), parts, span, self.site(), snap, label)

    def op_snap(self, op, args, parts, span):
        """``Snap(axes[, label])`` and ``SnapLines(axes[, label])``: construction planes (``ir.Snap``)."""
        self.expect_no_parts(op, parts, span)
        if not self.expect_args(op, args, (1, 2), span):
            return ir.Empty(span)
        text = self.string_arg(op, args[0], span, "the axes of its plane")
        label = self.string_arg(op, args[1], span, "a label") if len(args) == 2 else None
        if text is None or (len(args) == 2 and label is None):
            return ir.Empty(span)
        if text not in SNAP_NORMALS:
            self.diags.error("axis", f"unknown snap axes \"{text}\", expected one of "
                             f"{', '.join(SNAP_NORMALS)}", args[0].span)
            return ir.Empty(span)
        return ir.Snap(SNAP_NORMALS[text], label, op == "SnapLines", span)

    def op_comp(self, op, args, parts, span):
        parts = self.expect_parts(op, parts, span)
        if not args:
            self.diags.error("arity", f"`{op}` takes a component type, got no arguments", span)
            return ir.Empty(span)
        kind = self.string_arg(op, args[0], span, "a component type")
        if kind is None:
            return ir.Empty(span)
        if kind not in ir.COMP_KINDS:
            self.diags.error("comp", f"unknown component type \"{kind}\"{suggest(kind, ir.COMP_KINDS)}",
                             args[0].span)
            return ir.Empty(span)
        want = (2,) if kind in ir.COMP_INDEXED else (1,)
        if not self.expect_args(f"{op}(\"{kind}\")", args, want, span):
            return ir.Empty(span)
        index = self.expr(args[1]) if len(args) == 2 else None
        return ir.Comp(kind, index, parts, span, self.site())

    def op_roof(self, op, args, parts, span):
        """``Roof(type, angle){ part }`` (paper section 3.1): a roof over the scope's footprint, its
        part applied to the roof. Lowered to the roof, then the part's operations."""
        if not self.expect_args(op, args, (2,), span):
            return ir.Empty(span)
        kind = self.string_arg(op, args[0], span, "a roof type")
        if kind is None:
            return ir.Empty(span)
        if kind not in ROOF_TYPES:
            self.diags.error("roof", f'unknown roof type "{kind}"{suggest(kind, ROOF_TYPES)}', args[0].span)
            return ir.Empty(span)
        if parts is not None and len(parts) != 1:
            self.diags.error("syntax", f"`{op}` takes one part, got {len(parts)}", span)
            return ir.Empty(span)
        zero = ir.Num(0.0, span)
        roof = ir.Roof(ROOF_TYPES[kind], self.expr(args[1]), False, zero, None, zero, span)
        return (roof, *(parts[0] if parts is not None else ()))

    # ------------------------------------------------------------------------------------- expressions
    def string(self, meta, tok):
        return ir.Str(str(tok)[1:-1], self.token_span(tok))

    def dotted(self, meta, head, field):
        span = Span(self.file, head.line, head.column, field.end_line, field.end_column)
        if str(head) == "Scope" and str(field) in ir.SCOPE_FIELDS:
            return ir.ScopeRef(str(field), span)
        if str(head) == "Scope":
            self.diags.error("unknown-name", f"unknown scope attribute `Scope.{field}`"
                             f"{suggest(str(field), ir.SCOPE_FIELDS)}", span)
        else:
            self.diags.error("unknown-name", f"unknown name `{head}.{field}`", span)
        return ir.placeholder(span)

    def dotted_function(self, meta, head, field, args):
        span = Span(self.file, head.line, head.column, field.end_line, field.end_column)
        if (str(head), str(field)) in OCCLUSION_QUERIES:
            return self.occlusion(f"{head}.{field}", args or (), span)
        if (str(head), str(field)) == ("Shape", "visible"):
            return self.visible(tuple(self.expr(a) for a in args or ()), span)
        self.diags.error("unknown-function", f"unknown function `{head}.{field}`", span)
        return ir.placeholder(span)

    def visible(self, args, span) -> ir.Expr:
        """``Shape.visible("street")``: whether the shortest sightline to the lot's street is clear. The
        Puuc paper writes ``Shape.visible("front")`` for the same: the lot's front is its street."""
        if len(args) != 1 or not isinstance(args[0], ir.Str) or args[0].value.lower() not in ("street", "front"):
            self.diags.error("arity", '`Shape.visible` takes "street" (the lot\'s street edges) or "front"', span)
            return ir.Bool(True, span)
        return ir.Occlusion("visible", "all", None, span, parents=True)

    def occlusion(self, name: str, args, span) -> ir.Expr:
        """``Shape.occ("all" | "active" | "noparent" | LABEL[, "distance", d])``."""
        args = tuple(self.expr(a) for a in args)
        which = args[0].value if args and isinstance(args[0], ir.Str) else None
        distance = None
        if which is not None and len(args) == 3 and isinstance(args[1], ir.Str) and args[1].value == "distance":
            distance = args[2]
        elif len(args) != 1 or which is None:
            self.diags.error("arity", f'`{name}` takes "all", "active", "noparent" or a label, and '
                             'optionally "distance" and a distance', span)
            return ir.Str("none", span)
        label = which if which not in ("all", "active", "noparent") else None
        return ir.Occlusion("occ", "all", label, span, parents=which != "noparent", active=which == "active",
                            distance=distance)

    def function(self, meta, name, args):
        span = self.token_span(name)
        args = tuple(self.expr(a) for a in (args or ()))
        func = str(name)
        if func not in ir.FUNCTIONS:
            self.diags.error("unknown-function",
                             f"unknown function `{func}`{suggest(func, ir.FUNCTIONS)}", span)
            return ir.placeholder(span)
        low, high, _ = ir.FUNCTIONS[func]
        if not low <= len(args) <= high:
            want = str(low) if low == high else f"{low} to {high}"
            self.diags.error("arity", f"`{func}` takes {want} argument{'s' if high != 1 else ''}, "
                             f"got {len(args)}", span)
            return ir.Num(0.0, span)
        return ir.Call(func, args, span, self.site())


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


_CALLS = {
    "T": Lowering.op_translate,
    "S": Lowering.op_scale,
    "R": Lowering.op_rotate,
    "Rx": Lowering.op_rotate,
    "Ry": Lowering.op_rotate,
    "Rz": Lowering.op_rotate,
    "I": Lowering.op_insert,
    "Subdiv": Lowering.op_subdiv,
    "Repeat": Lowering.op_repeat,
    "Snap": Lowering.op_snap,
    "SnapLines": Lowering.op_snap,
    "Comp": Lowering.op_comp,
    "Roof": Lowering.op_roof,
}


def assemble(file: str, statements: list[Statement], diags: Diagnostics) -> ir.Module:
    """Statements in source order -> Module: PRIORITY blocks, stochastic continuation lines."""
    attrs: list[ir.AttrDecl] = []
    pending: list[list] = []  # [RuleStatement, alternatives, priority]
    priority = 0
    for st in statements:
        if isinstance(st, PriorityStatement):
            priority = st.value
        elif isinstance(st, ir.AttrDecl):
            if any(a.name == st.name for a in attrs):
                diags.error("duplicate-attr", f"attribute `{st.name}` is declared twice", st.span)
            attrs.append(st)
        elif isinstance(st, RuleStatement):
            pending.append([st, list(st.alternatives), priority])
        elif isinstance(st, ContinuationStatement):
            if not pending:
                diags.error("syntax", "a stochastic alternative needs a rule before it", st.span,
                            hint="write `symbol ~> successor : probability` first")
            else:
                pending[-1][1].extend(st.alternatives)
    rules = tuple(
        ir.Rule(
            symbol=st.symbol, params=st.params, guard=st.guard, alternatives=tuple(alts),
            priority=prio, label=st.label, span=st.span, site=st.site,
        )
        for st, alts, prio in pending
    )
    start = rules[0].symbol if rules else None
    return ir.Module(file=file, attrs=tuple(attrs), rules=rules, start=start)
