"""What the lowerings of both dialects share: spans, random-stream sites, the expression operators.

A dialect's ``Lowering`` subclasses ``LoweringBase`` and defines ``expr`` (how an argument that must be a
plain expression is checked) and its own statements and operations.
"""

from __future__ import annotations

from lark import Token, Transformer, v_args

from grammarc.diagnostics import Diagnostics, Span
from grammarc.ir import nodes as ir


@v_args(inline=True, meta=True)
class LoweringBase(Transformer):
    """Parse tree of one statement -> IR pieces. ``sites`` numbers random-stream sites in source order."""

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
