"""frontend/direct.py: an operation lowered straight to its IR node, its arguments the node's fields."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import pytest

from grammarc.diagnostics import NO_SPAN, Diagnostics, Span
from grammarc.frontend.direct import direct
from grammarc.frontend.lowering import LoweringBase
from grammarc.ir import nodes as ir


@dataclass(frozen=True, slots=True)
class Pair:
    left: ir.Expr
    right: ir.Expr
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Drawn:
    point: tuple[ir.Expr, ir.Expr, ir.Expr]
    weight: ir.Expr
    span: Span = NO_SPAN
    site: int = 0


@dataclass(frozen=True, slots=True)
class Named:
    name: str
    span: Span = NO_SPAN


SPAN = Span("g.cga", 1, 1, 1, 4)


def lowering() -> LoweringBase:
    return LoweringBase("g.cga", Diagnostics(), itertools.count(7))


def nums(*values: float) -> tuple[ir.Num, ...]:
    return tuple(ir.Num(v) for v in values)


def test_direct_fills_the_fields_before_span_with_the_arguments_in_order():
    assert direct(Pair)(lowering(), "pair", nums(1, 2), SPAN) == Pair(*nums(1, 2), SPAN)


def test_direct_takes_a_tuple_field_of_n_expressions_as_n_arguments_and_draws_a_site():
    assert direct(Drawn)(lowering(), "drawn", nums(1, 2, 3, 4), SPAN) == Drawn(nums(1, 2, 3), ir.Num(4), SPAN, 7)


@pytest.mark.parametrize("node, args, message", [
    (Pair, nums(1), "`op` takes 2 arguments, got 1"),
    (Drawn, nums(1, 2, 3), "`op` takes 4 arguments, got 3"),
])
def test_direct_reports_a_wrong_count_and_lowers_to_empty(node, args, message):
    low = lowering()
    assert direct(node)(low, "op", args, SPAN) == ir.Empty(SPAN)
    assert [(d.code, d.message, d.span) for d in low.diags] == [("arity", message, SPAN)]


def test_direct_checks_each_argument_as_the_dialect_does():
    class Checked(LoweringBase):
        def expr(self, value):
            self.diags.warning("checked", "checked", SPAN)
            return value

    low = Checked("g.cga", Diagnostics(), itertools.count(1))
    direct(Pair)(low, "pair", nums(1, 2), SPAN)
    assert len(low.diags) == 2


def test_direct_refuses_a_node_with_a_field_that_is_no_expression():
    with pytest.raises(TypeError, match="Named.name"):
        direct(Named)
