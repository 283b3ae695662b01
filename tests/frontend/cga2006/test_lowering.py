"""frontend/cga2006/lowering.py: the paper's statements, successors and expressions lowered to IR.

Accepted syntax is checked as one-liners, grammar text -> canonical IR text after all passes; errors as
the exact (line, column, message) that lowering and the IR passes report: no error may hide another, and
none may cascade from one already reported.
"""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics, render
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_module
from grammarc.ir.traverse import iter_exprs, iter_ops, op_exprs

from .lowered import FILE, compile_ir, diagnose, errors, lowering_errors, rules

# ------------------------------------------------------------------------------------------ accepted syntax


@pytest.mark.parametrize("arrow", ["~>", "->", "-->", "\u2192", "\u21dd", ";"])
def test_every_arrow_form(arrow):
    assert rules(f"a {arrow} b c") == ["a ~> b c : 1"]


@pytest.mark.parametrize("text, expected", [
    # rule labels as in the paper, with or without a space
    ("1: a ~> b", "a ~> b : 1"),
    ("12 : a ~> b", "a ~> b : 1"),
    # parameters and guards
    ("a(h) : h > 9 ~> b", "a(h) : ($h > 9) ~> b : 1"),
    ("a(x, y) ~> b", "a(x, y) ~> b : 1"),
    ("a() ~> b", "a ~> b : 1"),
    ("a : Scope.sx >= 2 ~> b", "a : (Scope.sx >= 2) ~> b : 1"),
    # empty shapes and the scope stack
    ("a ~> \u03b5", "a ~> \u03b5 : 1"),
    ("a ~> epsilon", "a ~> \u03b5 : 1"),
    ("a ~> null", "a ~> \u03b5 : 1"),
    ("a ~>", "a ~> \u03b5 : 1"),
    ("a ~> [ T(1, 2, 3) b ] c", "a ~> [ T(1, 2, 3) b ] c : 1"),
    ("a ~> [[b]]", "a ~> [ [ b ] ] : 1"),
    # typographic quotes of the extracted paper
    ("a ~> I(\u201dcube\u201d)", 'a ~> I("cube") : 1'),
    ("a ~> I(\u201ccube\u201d)", 'a ~> I("cube") : 1'),
    ("a ~> Subdiv(\u201dX\u201d, 1r){ b }", 'a ~> Subdiv("X", 1r){ b } : 1'),
    # boolean operators, words and symbols, with C precedence (not > and > or)
    ("a(x) : x > 1 and x < 2 ~> b", "a(x) : (($x > 1) && ($x < 2)) ~> b : 1"),
    ("a(x) : x > 1 && x < 2 ~> b", "a(x) : (($x > 1) && ($x < 2)) ~> b : 1"),
    ("a(x) : x < 1 or x > 2 ~> b", "a(x) : (($x < 1) || ($x > 2)) ~> b : 1"),
    ("a(x) : x < 1 || x > 2 ~> b", "a(x) : (($x < 1) || ($x > 2)) ~> b : 1"),
    ("a(x) : not x > 1 ~> b", "a(x) : !($x > 1) ~> b : 1"),
    ("a(x) : !(x > 1) ~> b", "a(x) : !($x > 1) ~> b : 1"),
    ("a(x) : x < 1 || x > 2 && x != 5 ~> b", "a(x) : (($x < 1) || (($x > 2) && ($x != 5))) ~> b : 1"),
    ("a(x) : (x < 1 || x > 2) && x != 5 ~> b", "a(x) : ((($x < 1) || ($x > 2)) && ($x != 5)) ~> b : 1"),
    ("a(x) : not x > 1 or x == 0 ~> b", "a(x) : (!($x > 1) || ($x == 0)) ~> b : 1"),
    # arithmetic precedence and associativity
    ("a(x) ~> T(x - 1 - 2, x * 2 + 1, x / 2 / 4)",
     "a(x) ~> T((($x - 1) - 2), (($x * 2) + 1), (($x / 2) / 4)) : 1"),
    ("a(x) ~> T(-x, +x, x % 3)", "a(x) ~> T(-$x, $x, ($x % 3)) : 1"),
    ("a(x) ~> T(1e2, .5, 2.)", "a(x) ~> T(100, 0.5, 2) : 1"),
    # keywords do not eat the start of longer names
    (("a(nullable, trueh, falsey, order, android, notice) ~> "
      "T(nullable + trueh, falsey + order, android + notice)"),
     ("a(nullable, trueh, falsey, order, android, notice) ~> "
      "T(($nullable + $trueh), ($falsey + $order), ($android + $notice)) : 1")),
    ("a ~> epsilons nulls attribute PRIORITYx", "a ~> epsilons nulls attribute PRIORITYx : 1"),
])
def test_accepted(text, expected):
    assert rules(text) == [expected]



def test_stochastic_alternatives_on_one_line():
    assert rules("a ~> b : 0.5 ~> c : 0.3 ; d : 0.2") == ["a ~> b : 0.5 ~> c : 0.3 ~> d : 0.2"]


def test_labels_are_kept():
    module, _ = compile_ir("1: a ~> b\nb ~> c\n17: c ~> d")
    assert [r.label for r in module.rules] == ["1", None, "17"]


def test_attr_declarations():
    module, diags = compile_ir('attr h = 3\nattr name = "brick"\nattr tall = h > 2\na ~> S(1r, h, 1r)')
    assert not diags
    assert print_module(module) == (
        'attr h = 3\nattr name = "brick"\nattr tall = (@h > 2)\nPRIORITY 0:\na ~> S(1r, @h, 1r) : 1'
    )
    assert [a.type for a in module.attrs] == [ir.Type.NUM, ir.Type.STR, ir.Type.BOOL]


def test_spans_are_file_line_col():
    module, _ = compile_ir("attr x = 1\n\nlot ~> T(x, 0, 0)\n  b(2)")
    rule = module.rules[0]
    assert (rule.span.file, rule.span.line, rule.span.col) == (FILE, 3, 1)
    translate, symbol = rule.alternatives[0].body
    assert (translate.span.line, translate.span.col) == (3, 8)
    assert (translate.vector[0].span.line, translate.vector[0].span.col) == (3, 10)
    assert (symbol.span.line, symbol.span.col) == (4, 3)


def test_call_sites_are_unique_and_in_source_order():
    # sites number the random streams: rules, successor symbols, splits and function calls
    module, _ = compile_ir('a ~> b c Subdiv("X", 1r){ d }\nb ~> T(rand(), 0, 0) Repeat("X", 1){ e }')
    sites = [r.site for r in module.rules]
    for rule in module.rules:
        for op in iter_ops(rule.alternatives[0].body):
            sites += [op.site] if hasattr(op, "site") else []
            sites += [e.site for x in op_exprs(op) for e in iter_exprs(x) if isinstance(e, ir.Call)]
    assert sorted(sites) == list(range(1, 10))
    a_ops = module.rules[0].alternatives[0].body
    assert a_ops[0].site < a_ops[1].site < a_ops[2].site



# -------------------------------------------------------------------------------------- scope brackets


@pytest.mark.parametrize("text, errors", [
    ("a ~> [ b", [(1, 6, "unclosed `[`")]),
    ("a ~> b ] c", [(1, 8, "`]` without a `[` before it")]),
    ("a ~> ] [ b", [(1, 6, "`]` without a `[` before it"), (1, 8, "unclosed `[`")]),
    ('a ~> Subdiv("X", 1r, 1r){ [ b | ] c }',
     [(1, 27, "unclosed `[`"), (1, 33, "`]` without a `[` before it")]),
])
def test_scope_brackets_pair_up_in_each_successor(text, errors):
    assert lowering_errors(text) == errors



# ---------------------------------------------------------------------------------------------- errors


@pytest.mark.parametrize("text, expected", [
    # unknown operations, functions and names
    ('a ~> Subdv("Y", 1){ b }', [(1, 6, "unknown operation `Subdv` (did you mean `Subdiv`?)")]),
    ('a ~> Repaet("X", 1){ b }', [(1, 6, "unknown operation `Repaet` (did you mean `Repeat`?)")]),
    ("a ~> T(sqr(4), 0, 0)", [(1, 8, "unknown function `sqr` (did you mean `sqrt`?)")]),
    ("a ~> T(frobnicate(4), 0, 0)", [(1, 8, "unknown function `frobnicate`")]),
    ("a ~> T(Scope.foo, 0, 0)", [(1, 8, "unknown scope attribute `Scope.foo`")]),
    ("a ~> T(Scope.szz, 0, 0)", [(1, 8, "unknown scope attribute `Scope.szz` (did you mean `sz`?)")]),
    ("a ~> T(Lot.area, 0, 0)", [(1, 8, "unknown name `Lot.area`")]),
    ("a ~> T(Lot.area(), 0, 0)", [(1, 8, "unknown function `Lot.area`")]),
    ("a ~> floor(1, 2)", []),  # a successor symbol, not the function: it has no rule, see the warning test
    ("a ~> T(floor(1, 2), 0, 0)", [(1, 8, "`floor` takes 1 argument, got 2")]),
    ("a ~> T(rand(1, 2, 3), 0, 0)", [(1, 8, "`rand` takes 0 to 2 arguments, got 3")]),
    ("a ~> b(1r)", [(1, 8, "a relative size like `1r` is only allowed in `S` and `Subdiv`")]),
    # parameters
    ("a(x, x) ~> b", [(1, 6, "parameter `x` appears twice")]),
])
def test_lowering_errors(text, expected):
    assert errors(text) == expected


def test_a_bad_context_query_is_one_error_at_its_line_and_nothing_else():
    # the second line proves the position is this construct's, and that nothing cascades from it
    diags = diagnose('z ~> a\na : Shape.visible("river") ~> b')
    [d] = [d for d in diags if d.is_error]
    assert (d.span.line, d.span.col) == (2, 5) and d.message.startswith('`Shape.visible` takes "street" (the lot')


def test_occlusion_queries_lower_with_their_subsets():
    from grammarc.ir import nodes as ir
    from grammarc.ir.printer import print_expr

    module = run_passes(parse_source(
        'a : Shape.occ("noparent") == "none" ~> b\n'
        'b : Scope.occ("all", "distance", 4) != "full" ~> c\n'
        'c : Shape.occ("active") == "part" ~> d\n', FILE, Diagnostics()), Diagnostics(), check=True)
    found = [rule.guard.left for rule in module.rules]
    assert [(e.parents, e.active, e.label) for e in found] == [(False, False, None), (True, False, None),
                                                               (True, True, None)]
    assert all(isinstance(e, ir.Occlusion) and e.kind == "occ" for e in found)
    assert print_expr(found[1]) == 'Shape.occ("all", "distance", 4)'


def test_all_errors_of_a_file_are_reported():
    text = (
        'a ~> Subdv("Y", 1){ b } T(1r, 0, 0)\n'
        "b ~> T(1, 2) c(1, 2)\n"
        'c(x) ~> I("cube")\n'
        'd ~> Comp("edge"){ e } Roof("hiped", 30){ r }'
    )
    positions = [(line, col) for line, col, _ in errors(text)]
    assert positions == [(1, 6), (1, 27), (2, 6), (2, 14), (4, 6), (4, 29)]


def test_unknown_operation_renders_with_a_caret_under_the_name():
    text = 'facade ~> Subdv("Y", 3){ floor }\n'
    [d] = [d for d in diagnose(text) if d.is_error]
    assert render(d, {FILE: text}) == (
        "g.cga:1:11: error: unknown operation `Subdv` (did you mean `Subdiv`?)\n"
        ' 1 | facade ~> Subdv("Y", 3){ floor }\n'
        "   |           ^^^^^"
    )


def test_arguments_of_a_symbol_without_rules_are_a_warning():
    diags = diagnose("a ~> floor(1, 2)")
    [d] = diags
    assert (d.severity.value, d.span.col, d.message) == (
        "warning", 6, "`floor` has no rule, so its arguments are not used")
