"""frontend/lowering.py with grammars/expressions.lark: what the two dialects share.

Both dialect grammars import their expressions from ``expressions.lark`` and both lowerings inherit the
expression operators from ``LoweringBase``, so an expression both dialects can write lowers to the same IR
in either.
"""

from __future__ import annotations

import itertools

import pytest

from grammarc.diagnostics import Diagnostics, Span
from grammarc.frontend.lowering import LoweringBase
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_expr


def lowered(text: str, dialect: str) -> str:
    """The printed default of ``attr v = text`` in ``dialect``, straight from lowering."""
    diags = Diagnostics()
    module = parse_source(f"attr v = {text}\n", "g.cga", diags, dialect)
    assert not diags.has_errors, list(diags)
    return print_expr(module.attrs[0].default)


@pytest.mark.parametrize("text, printed", [
    ("1 + 2 * 3 - 4 / 5 % 6", "((1 + (2 * 3)) - ((4 / 5) % 6))"),
    ("-x - +y", "(-x - y)"),
    ("a < b || c >= d && !e", "((a < b) || ((c >= d) && !e))"),
    ("!(a == b) != c", "!((a == b) != c)"),  # `!` binds less than a comparison
    ("(1 + 2) * 3", "((1 + 2) * 3)"),
    ("true && false", "(true && false)"),
    ('x + "s"', '(x + "s")'),
    ("1e2 / .5 + 2.", "((100 / 0.5) + 2)"),
    ("sqrt(4) + rand(1, 2) + rand()", "((sqrt(4) + rand(1, 2)) + rand())"),
])
def test_an_expression_lowers_alike_in_both_dialects(text, printed):
    assert lowered(text, "cga2006") == lowered(text, "cityengine") == printed


@pytest.mark.parametrize("paper, cityengine", [
    ("a or b and not c", "a || b && !c"),
    ("Scope.sx * 2", "scope.sx * 2"),
])
def test_each_dialect_adds_its_own_forms_to_the_shared_expressions(paper, cityengine):
    assert lowered(paper, "cga2006") == lowered(cityengine, "cityengine")


@pytest.mark.parametrize("dialect, text", [
    ("cityengine", "a or b"),
    ("cityengine", "\u201cs\u201d"),
    ("cga2006", "[1, 2]"),
    ("cga2006", "$a"),
])
def test_one_dialects_forms_are_not_the_others(dialect, text):
    diags = Diagnostics()
    parse_source(f"attr v = {text}\n", "g.cga", diags, dialect)
    assert [d.code for d in diags if d.is_error] == ["syntax"]


# ------------------------------------------------------------------------------------------------- arity


SPAN = Span("g.cga", 1, 1, 1, 4)


def lowering() -> LoweringBase:
    return LoweringBase("g.cga", Diagnostics(), itertools.count(7))


def nums(*values: float) -> tuple[ir.Num, ...]:
    return tuple(ir.Num(v) for v in values)


@pytest.mark.parametrize("one, message", [
    ("argument", "`Rx` takes 1 argument, got 2"),
    ("arguments", "`Rx` takes 1 arguments, got 2"),
])
def test_arity_counts_one_argument_as_the_dialect_words_it(one, message):
    low = lowering()
    low.one_argument = one
    assert not low.arity("Rx", nums(1, 2), (1,), SPAN)
    assert [d.message for d in low.diags] == [message]
