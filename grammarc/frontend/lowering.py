"""What the lowerings of both dialects share: spans, random-stream sites, the expression operators of
``grammars/expressions.lark``, scope brackets and argument lists, arity checks (``direct``, the lowering of
an operation whose arguments are its IR node's fields, is in ``direct.py``, and the sites' numbering in
``sites.py``: the statements of a file the lowered cache keeps need those, not lark).

A dialect's ``Lowering`` subclasses ``LoweringBase`` and defines ``expr`` (how an argument that must be a
plain expression is checked), its statements, and its operations in two tables: ``OPERATIONS`` for calls
without parts, name -> handler(lowering, op, args, span); ``PART_OPERATIONS`` for calls with parts
``{ ... }``, name -> handler(lowering, op, args, parts, span).
"""

from __future__ import annotations

from lark import Token, Transformer, v_args

from grammarc.diagnostics import Diagnostics, Span
from grammarc.ir import nodes as ir


@v_args(inline=True, meta=True)
class LoweringBase(Transformer):
    """Parse tree of one statement -> IR pieces. ``sites`` numbers random-stream sites in source order."""

    #: How an arity error counts one argument (``Rx`` takes 1 argument).
    one_argument = "argument"

    def __init__(self, file: str, diags: Diagnostics, sites):
        super().__init__()
        self.file = file
        self.diags = diags
        self.sites = sites
        self.fallback = Span(file, 0, 0, 0, 0)

    # ------------------------------------------------------------------------------------------ helpers
    def span(self, meta) -> Span:
        if getattr(meta, "empty", True):
            return self.fallback
        return Span(self.file, meta.line, meta.column, meta.end_line, meta.end_column)

    def token_span(self, tok: Token) -> Span:
        return Span(self.file, tok.line, tok.column, tok.end_line, tok.end_column)

    def site(self) -> int:
        return next(self.sites)

    def expr(self, value) -> ir.Expr:
        """``value`` as a plain expression; a dialect reports its special argument forms here."""
        return value

    def arity(self, op: str, args: tuple, counts: tuple[int, ...], span: Span) -> bool:
        """Whether ``op`` got one of ``counts`` arguments; an ``arity`` error at ``span`` if not."""
        if len(args) in counts:
            return True
        want = " or ".join(str(c) for c in counts)
        noun = self.one_argument if counts == (1,) else "arguments"
        self.diags.error("arity", f"`{op}` takes {want} {noun}, got {len(args)}", span)
        return False

    # ------------------------------------------------------------------- scope brackets, arguments, parts
    def push(self, meta, tok):
        return ir.Push(self.token_span(tok))

    def pop(self, meta, tok):
        return ir.Pop(self.token_span(tok))

    def args(self, meta, *args):
        return tuple(args)

    def parts(self, meta, *parts):
        return tuple(parts)

    # ------------------------------------------------------------------------------------- expressions
    def or_(self, meta, left, right):
        return ir.Binary("||", self.expr(left), self.expr(right), self.span(meta))

    def and_(self, meta, left, right):
        return ir.Binary("&&", self.expr(left), self.expr(right), self.span(meta))

    def not_(self, meta, operand):
        return ir.Unary("!", self.expr(operand), self.span(meta))

    def binary(self, meta, left, op, right):
        return ir.Binary(str(op), self.expr(left), self.expr(right), self.token_span(op))

    def neg(self, meta, operand):
        return ir.Unary("-", self.expr(operand), self.span(meta))

    def number(self, meta, tok):
        return ir.Num(float(tok), self.token_span(tok))

    def true(self, meta, tok):
        return ir.Bool(True, self.token_span(tok))

    def false(self, meta, tok):
        return ir.Bool(False, self.token_span(tok))

    def name(self, meta, tok):
        return ir.Name(str(tok), self.token_span(tok))
