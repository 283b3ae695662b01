"""Lower the parse tree of the paper notation (cga2006.lark) to IR, one statement at a time.

Each method of ``Lowering`` handles one grammar rule or alias: the statements (``nodes``), successors and
the paper's expressions; the operations are ``operations``' and the expression operators ``LoweringBase``'s.
Problems are appended to the diagnostics list and a harmless placeholder is returned, so that lowering goes
on and every error is reported; ``__default__`` turns a tree the lowering does not know into "unsupported
construct" at its span.
"""

from __future__ import annotations

from lark import Token, v_args

from grammarc.diagnostics import Span, suggest
from grammarc.frontend.cga2006.nodes import ContinuationStatement, PriorityStatement, Relative, RuleStatement
from grammarc.frontend.cga2006.operations import OPERATIONS, PART_OPERATIONS, OperationLowering
from grammarc.frontend.lowering import LoweringBase
from grammarc.ir import nodes as ir
from grammarc.ir.functions import FUNCTIONS

#: Occlusion queries (paper section 3.2), parsed as dotted calls: both test the shape's scope.
OCCLUSION_QUERIES = {("Shape", "occ"), ("Scope", "occ")}


@v_args(inline=True, meta=True)
class Lowering(OperationLowering, LoweringBase):
    """Parse tree of one statement -> IR pieces. ``sites`` numbers random-stream sites in source order."""

    def __default__(self, data, children, meta):
        span = self.span(meta)
        self.diags.error("unsupported", f"unsupported construct `{data}`", span)
        return ir.Empty(span)

    def expr(self, arg):
        """An argument that must be an expression (not ``1r``)."""
        if isinstance(arg, Relative):
            self.diags.error(
                "relative", "a relative size like `1r` is only allowed in `S` and `Subdiv`", arg.span
            )
            return arg.value
        return arg

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

    def choice_alternative(self, meta, arrow, body):
        """``~> successor ?``: one of a set of consequents."""
        return ir.Alternative(body, None, self.span(meta), choice=True)

    def objective(self, meta, name, expr):
        """``goal: expr`` and the other search statements; any other ``name: expr`` lacks its successor."""
        if str(name) not in ir.OBJECTIVES:
            self.diags.error("syntax", f"`{name}: ...` is neither a rule (it has no `~>` successor) nor a "
                             f"search statement ({', '.join(f'`{k}:`' for k in ir.OBJECTIVES)})",
                             self.token_span(name))
            return None  # nothing to assemble
        return ir.Objective(str(name), self.expr(expr), self.token_span(name))

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

    def symbol(self, meta, name):
        return ir.Symbol(str(name), (), self.token_span(name), self.site())

    def empty(self, meta, tok):
        return ir.Empty(self.token_span(tok))

    def relative(self, meta, tok):
        return Relative(ir.Num(float(str(tok)[:-1]), self.token_span(tok)), self.token_span(tok))

    def call(self, meta, name, args, parts):
        """An operation of ``OPERATIONS`` or ``PART_OPERATIONS``, or a successor symbol with arguments."""
        op, span, args = str(name), self.token_span(name), args or ()
        if op in OPERATIONS:
            self.expect_no_parts(op, parts, span)
            return OPERATIONS[op](self, op, args, span)
        if op in PART_OPERATIONS:
            return PART_OPERATIONS[op](self, op, args, parts, span)
        if parts is not None:
            known = [*OPERATIONS, *PART_OPERATIONS]
            self.diags.error("unknown-op", f"unknown operation `{op}`{suggest(op, known)}", span)
            return ir.Empty(span)
        return ir.Symbol(op, tuple(self.expr(a) for a in args), span, self.site())

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
        if str(head) == "geometry" and f"{head}.{field}" in FUNCTIONS:  # CityEngine's queries of the geometry
            return self.function(meta, Token("NAME", f"{head}.{field}", head.start_pos, head.line, head.column,
                                             field.end_line, field.end_column, head.end_pos), args)
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

    def aggregate(self, meta, name, value, symbol):
        """``sum(Scope.sx of "room")``: an aggregate of a design."""
        span = self.token_span(name)
        if str(name) not in ir.AGGREGATES or str(name) in ("area", "volume"):
            self.diags.error("unknown-function", f"`{name}(... of \"symbol\")` is not an aggregate: "
                             "count, sum, min, max and mean take a value of each shape", span)
            return ir.placeholder(span)
        return ir.Aggregate(str(name), str(symbol)[1:-1], self.expr(value), span)

    def function(self, meta, name, args):
        span = self.token_span(name)
        args = tuple(self.expr(a) for a in (args or ()))
        func = str(name)
        if func == "choose":
            if len(args) < 1:
                self.diags.error("arity", "`choose` takes one value or more", span)
                return ir.placeholder(span)
            return ir.Choose(args, span, self.site())
        if func in ("count", "area", "volume") and len(args) == 1 and isinstance(args[0], ir.Str):
            return ir.Aggregate(func, args[0].value, None, span)
        signature = FUNCTIONS.get(func)
        if signature is None:
            self.diags.error("unknown-function",
                             f"unknown function `{func}`{suggest(func, FUNCTIONS)}", span)
            return ir.placeholder(span)
        if not signature.takes(len(args)):
            self.diags.error("arity", f"`{func}` takes {signature.arity()} "
                             f"argument{'s' if len(signature.params) != 1 else ''}, got {len(args)}", span)
            return ir.Num(0.0, span)
        return ir.Call(func, args, span, self.site())

