"""ir/passes/fold.py: constant operators and pure functions fold; attributes, parameters and rand do not."""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics, Span
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.functions import FUNCTIONS
from grammarc.ir.passes.fold import PURE, fold_constants
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_expr, print_module, print_rule
from grammarc.ir.traverse import rewrite_expr

FILE = "g.cga"


def folded(text: str) -> tuple[ir.Module, Diagnostics]:
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags), diags, check=True, stop_after="fold")
    return module, diags


def fold_expr(expr: str) -> str:
    """The folded form of one expression, as the x of a translation (attrs h, flag; param p)."""
    module, diags = folded(f"attr h = 3\nattr flag = true\na(p) ~> T({expr}, 0, 0)")
    assert not diags.has_errors, diags
    return print_expr(module.rules[0].alternatives[0].body[0].vector[0])


@pytest.mark.parametrize("expr, expected", [
    # arithmetic, with precedence
    ("1 + 2 * 3", "7"),
    ("(1 + 2) * 3", "9"),
    ("10 / 4", "2.5"),
    ("7 % 3", "1"),
    ("-7 % 3", "-1"),  # fmod: the sign of the dividend, as the backend computes it
    ("2 - 3 - 4", "-5"),
    ("-(2)", "-2"),
    ("--3", "3"),
    ("-(1 - 4)", "3"),
    ("+5", "5"),
    # pure functions, angles in degrees
    ("sin(90)", "1"),
    ("cos(180)", "-1"),
    ("sin(30) * 2", "1"),
    ("tan(45)", "1"),
    ("asin(1)", "90"),
    ("acos(0)", "90"),
    ("atan(1)", "45"),
    ("atan2(1, 1)", "45"),
    ("sqrt(16)", "4"),
    ("pow(2, 10)", "1024"),
    ("exp(0) + log(1)", "1"),
    ("min(3, 4) + max(3, 4)", "7"),
    ("floor(-2.5)", "-3"),
    ("ceil(2.1)", "3"),
    ("round(2.5)", "3"),
    ("round(-2.5)", "-3"),  # half away from zero, as CGA
    ("round(2.4)", "2"),
    ("abs(-3)", "3"),
    ("floor(sqrt(2) * 10)", "14"),
    # rand is random: never folded, its arguments are
    ("rand()", "rand()"),
    ("rand(1 + 1, 3)", "rand(2, 3)"),
    ("rand(1, 2) * 2", "(rand(1, 2) * 2)"),
    # attributes and parameters stay references
    ("h * 2", "(@h * 2)"),
    ("p + 1 * 2", "($p + 2)"),
    ("(1 + 2) * p", "(3 * $p)"),
    ("p * 1", "($p * 1)"),  # no algebra, only constants
    ("-h", "-@h"),
    ("sin(h)", "sin(@h)"),
    ("Scope.sx / 2", "(Scope.sx / 2)"),
])
def test_fold_numbers(expr, expected):
    assert fold_expr(expr) == expected


@pytest.mark.parametrize("guard, expected", [
    ("1 < 2", "true"),
    ("2 <= 1", "false"),
    ("1 + 1 == 2", "true"),
    ("1 != 1", "false"),
    ('"a" == "a"', "true"),
    ('"a" != "a"', "false"),
    ("true == false", "false"),
    ("true && false", "false"),
    ("false || true", "true"),
    ("!false", "true"),
    ("not (1 > 2)", "true"),
    ("sin(90) == 1 and cos(0) == 1", "true"),
    ("flag && 1 < 2", "(@flag && true)"),
    ("p > 1 + 1", "($p > 2)"),
    ("p == 1", "($p == 1)"),
])
def test_fold_guards(guard, expected):
    module, diags = folded(f'attr flag = true\na(p) : {guard} ~> b\nz ~> a(1)')
    assert not diags.has_errors
    assert print_expr(module.rules[0].guard) == expected


def test_fold_attribute_defaults_but_not_attribute_references():
    module, diags = folded("attr h = 1 + 2\nattr w = h * 2\nattr t = sin(90)\na ~> S(h, w, 2 * 3)")
    assert not diags
    assert print_module(module) == (
        "attr h = 3\nattr w = (@h * 2)\nattr t = 1\nPRIORITY 0:\na ~> S(@h, @w, 6)"
    )


def test_fold_everywhere_in_a_rule():
    module, _ = folded(
        'a ~> Subdiv("X", 1 + 1, 2r){ b(2 * 2) | Repeat("Y", 3 - 1){ Comp("edge", 1 + 1){ c } } }'
        " R(0, 45 * 2, 0) : 1 / 2 ~> d : 1 - 1 / 2\nb(x) ~> e"
    )
    assert module.rules[0].alternatives[0].prob == ir.Num(0.5, module.rules[0].alternatives[0].prob.span)
    assert print_rule(module.rules[0]) == (
        'a ~> Subdiv("X", 2, 2r){ b(4) | Repeat("Y", 2){ Comp("edge", 2){ c } } } R(0, 90, 0) : 0.5 '
        "~> d : 0.5"
    )


def test_folded_constant_keeps_the_span_of_the_expression():
    module, _ = folded("a ~> T(1 + 2, 0, 0)")
    value = module.rules[0].alternatives[0].body[0].vector[0]
    assert value == ir.Num(3.0, Span(FILE, 1, 10, 1, 11))


@pytest.mark.parametrize("text, col, message", [
    ("a ~> T(1 / 0, 0, 0)", 10, "division by zero"),
    ("a ~> T(5 % 0, 0, 0)", 10, "division by zero"),
    ("a ~> T(1 / (2 - 2), 0, 0)", 10, "division by zero"),
    ("a ~> T(sqrt(-1), 0, 0)", 8, "`sqrt` is undefined for these arguments"),
    ("a ~> T(log(0), 0, 0)", 8, "`log` is undefined for these arguments"),
    ("a ~> T(asin(2), 0, 0)", 8, "`asin` is undefined for these arguments"),
    ("a ~> T(exp(1000), 0, 0)", 8, "`exp` is undefined for these arguments"),
])
def test_fold_errors(text, col, message):
    _, diags = folded(text)
    assert [(d.span.line, d.span.col, d.message) for d in diags] == [(1, col, message)]


def test_division_by_zero_in_an_attribute_default():
    _, diags = folded("attr a = 1 / 0\nx ~> y")
    assert [(d.span.line, d.span.col, d.message) for d in diags] == [(1, 12, "division by zero")]


def test_division_by_a_parameter_is_not_an_error():
    _, diags = folded("a ~> b(0)\nb(x) ~> T(1 / x, 0, 0)")
    assert not diags


def test_nothing_to_fold_returns_the_same_objects():
    diags = Diagnostics()
    module = run_passes(parse_source(
        'attr h = 3\na(x) : x > h ~> T(x, rand(), Scope.sx) Subdiv("Y", h, 1r){ b(x) | c } : 1\n'
        "z ~> a(h)\nb(y) ~> c", FILE, diags), diags, check=True, stop_after="types")
    assert not diags
    assert fold_constants(module, diags) is module


def test_folding_one_rule_keeps_the_other_rules_and_attrs():
    diags = Diagnostics()
    module = run_passes(parse_source("attr h = 3\na ~> T(1 + 1, 0, 0)\nb ~> T(h, 0, 0)", FILE, diags),
                        diags, check=True, stop_after="types")
    result = fold_constants(module, diags)
    assert result is not module
    assert result.rules[0] is not module.rules[0]
    assert result.rules[1] is module.rules[1]
    assert result.attrs[0] is module.attrs[0]


def test_rewrite_expr_identity():
    expr = ir.Binary("+", ir.Num(1.0), ir.Unary("-", ir.AttrRef("h")))
    assert rewrite_expr(expr, lambda e: e) is expr
    swapped = rewrite_expr(expr, lambda e: ir.Num(2.0) if e == ir.Num(1.0) else e)
    assert swapped == ir.Binary("+", ir.Num(2.0), ir.Unary("-", ir.AttrRef("h")))
    assert swapped.right is expr.right


def test_every_math_function_folds_and_none_that_reads_the_shape():
    assert not any(FUNCTIONS[f].shape for f in PURE)
    numeric = {f for f, s in FUNCTIONS.items() if s.params and set(s.params) == {ir.Type.NUM}
               and s.result in (ir.Type.NUM, ir.Type.BOOL) and not s.shape}
    assert numeric <= set(PURE)


def test_a_call_with_a_wrong_count_of_arguments_is_the_checkers_error_not_folded():
    _, diags = folded('version "2022.0"\nLot --> extrude(sqrt(4, 3)) A\n')
    assert [(d.code, d.message) for d in diags if d.is_error] == [("arity", "`sqrt` takes 1 argument, got 2")]
