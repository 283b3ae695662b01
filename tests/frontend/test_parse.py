"""frontend/parse.py and grammars/cga2006.lark: what the paper notation accepts, and syntax errors.

Accepted syntax is checked as one-liners: grammar text -> canonical text of the IR after all passes
(``$h`` parameters, ``@name`` attributes, binaries parenthesized, every alternative with its probability).
"""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics, render, render_all
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_module, print_rule
from grammarc.ir.traverse import iter_exprs, iter_ops, op_exprs

FILE = "g.cga"


def compile_ir(text: str) -> tuple[ir.Module, Diagnostics]:
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags), diags, check=True)
    return module, diags


def rules(text: str) -> list[str]:
    module, diags = compile_ir(text)
    assert not diags.has_errors, render_all(diags, {FILE: text})
    return [print_rule(r) for r in module.rules]


def syntax_errors(text: str) -> list[tuple[int, int, str]]:
    diags = Diagnostics()
    parse_source(text, FILE, diags)
    return [(d.span.line, d.span.col, d.message) for d in diags if d.is_error]


# ------------------------------------------------------------------------------------------- accepted syntax

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
    # scope rules
    ("a ~> T(0,0,6) S(8,10,18) R(0,90,0)", "a ~> T(0, 0, 6) S(8, 10, 18) R(0, 90, 0) : 1"),
    ("a ~> Rx(10) Ry(20) Rz(30)", "a ~> R(10, 0, 0) R(0, 20, 0) R(0, 0, 30) : 1"),
    ("a ~> S(1r, 0.5r, 2)", "a ~> S(1r, 0.5r, 2) : 1"),
    ('a ~> I("cube") I("win.obj")', 'a ~> I("cube") I("win.obj") : 1'),
    # typographic quotes of the extracted paper
    ("a ~> I(\u201dcube\u201d)", 'a ~> I("cube") : 1'),
    ("a ~> I(\u201ccube\u201d)", 'a ~> I("cube") : 1'),
    ("a ~> Subdiv(\u201dX\u201d, 1r){ b }", 'a ~> Subdiv("X", 1r){ b } : 1'),
    # splits
    ('a ~> Subdiv("Y",3.5,0.3,1r){ b | c | d }', 'a ~> Subdiv("Y", 3.5, 0.3, 1r){ b | c | d } : 1'),
    ('a ~> Subdiv("X", 1r, 1r){ \u03b5 | b c }', 'a ~> Subdiv("X", 1r, 1r){ \u03b5 | b c } : 1'),
    ('a ~> Subdiv("XY", 1, 2){ b }', 'a ~> Subdiv("XY", 1, 2){ b } : 1'),
    ('a ~> Subdiv("XZ", 1, 2){ b | c | d | e }', 'a ~> Subdiv("XZ", 1, 2){ b | c | d | e } : 1'),
    ('a ~> Repeat("X", 2){ b }', 'a ~> Repeat("X", 2){ b } : 1'),
    ('a ~> Repeat("XY", 1, 2){ b }', 'a ~> Repeat("XY", 1, 2){ b } : 1'),
    ('a ~> Repeat("XYZ", 1, 2, 3){ b | c }', 'a ~> Repeat("XYZ", 1, 2, 3){ b | c } : 1'),
    ('a ~> Comp("edge", 3){A}', 'a ~> Comp("edge", 3){ A } : 1'),
    ('a ~> Comp("faces"){ A }', 'a ~> Comp("faces"){ A } : 1'),
    ('a ~> Comp("sidefaces"){ A | B }', 'a ~> Comp("sidefaces"){ A | B } : 1'),
    ('a ~> Comp("vertex", 0){ A } Comp("topedges"){ B }',
     'a ~> Comp("vertex", 0){ A } Comp("topedges"){ B } : 1'),
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


def test_stochastic_continuation_lines_indented_and_at_column1():
    text = "a ~> b : 0.5\n    ~> c : 0.25\n; d : 0.125\n\u2192 e : 0.125\nf ~> g"
    assert rules(text) == ["a ~> b : 0.5 ~> c : 0.25 ~> d : 0.125 ~> e : 0.125", "f ~> g : 1"]


def test_rule_split_over_lines_as_in_the_paper():
    text = """3: sidewing
     ; S(1r,1r,Scope.sz*rand(0.4,1.0)) facades : 0.5
     ; S(1r,Scope.sy*rand(0.2,0.9),Scope.sz*rand(0.4,1.0))
        facades : 0.3
     ; \u03b5 : 0.2
"""
    assert rules(text) == [(
        "sidewing ~> S(1r, 1r, (Scope.sz * rand(0.4, 1))) facades : 0.5 "
        "~> S(1r, (Scope.sy * rand(0.2, 0.9)), (Scope.sz * rand(0.4, 1))) facades : 0.3 ~> \u03b5 : 0.2"
    )]


def test_nested_subdiv_puuc_rule_7():
    text = ("door ~> Subdiv(\"Y\",door_h,1r){ Subdiv(\"X\",1r,door_w,1r) "
            "{ jamb(-jamb_a) | null | jamb(jamb_a) } | lintel }\n"
            "attr door_h = 2\nattr door_w = 1\nattr jamb_a = 3\njamb(a) ~> R(0, 0, a)")
    assert rules(text)[0] == (
        'door ~> Subdiv("Y", @door_h, 1r){ Subdiv("X", 1r, @door_w, 1r)'
        "{ jamb(-@jamb_a) | \u03b5 | jamb(@jamb_a) } | lintel } : 1"
    )


def test_nested_bodies_over_lines():
    text = 'a ~> Subdiv("X", 1r, 2, 1r){ b |\n  Subdiv("Y", 2r, 1, 1r){ c | d | c } |\n  b }'
    assert rules(text) == ['a ~> Subdiv("X", 1r, 2, 1r){ b | Subdiv("Y", 2r, 1, 1r){ c | d | c } | b } : 1']


def test_priority_blocks_assign_priorities():
    text = "a ~> b\nPRIORITY 1:\nb ~> c\nc ~> d\nPRIORITY 3:\nd ~> e\nPRIORITY 2:\ne ~> f"
    module, diags = compile_ir(text)
    assert not diags
    priorities = [(r.symbol, r.priority) for r in module.rules]
    assert priorities == [("a", 0), ("b", 1), ("c", 1), ("d", 3), ("e", 2)]
    assert print_module(module).splitlines()[:3] == ["PRIORITY 0:", "a ~> b : 1", "PRIORITY 1:"]


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


@pytest.mark.parametrize("comment", [
    "// line comment", "# hash comment", "/* block */", "/* block\n   over lines */",
])
def test_comments(comment):
    assert rules(f"{comment}\na ~> b {comment}\n  c\n{comment}\nd ~> e") == ["a ~> b c : 1", "d ~> e : 1"]


def test_comment_inside_a_rule_between_items():
    assert rules("a ~> b /* c */ d // e\n  f # g\n  h") == ["a ~> b d f h : 1"]


def test_start_is_the_first_rule():
    module, _ = compile_ir("attr x = 1\nlot ~> a\na ~> b")
    assert module.start == "lot"


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


# ---------------------------------------------------------------------------------------------- syntax errors

def test_every_syntax_error_is_reported_at_its_line():
    text = "a ~> b c\nb ~> T(1,,2)\nc ~> d\nd e f\ne ~> g $ h\nf ~> g\n  ~> i : 0.5 )\n"
    errors = syntax_errors(text)
    assert [(line, col) for line, col, _ in errors] == [(2, 10), (4, 3), (5, 8), (7, 14)]
    assert "unexpected `,`" in errors[0][2]
    assert errors[1][2] == "a rule needs an arrow `~>` before `e`"
    assert errors[2][2] == "unexpected character `$`"
    assert "unexpected `)`" in errors[3][2]


def test_good_rules_survive_syntax_errors_of_others():
    diags = Diagnostics()
    module = parse_source("a ~> b\nb ~> (\nc ~> d", FILE, diags)
    assert [r.symbol for r in module.rules] == ["a", "c"]
    assert len(diags) == 1


def test_missing_arrow():
    assert syntax_errors("a\nb ~> c") == [(1, 1, "a rule needs an arrow `~>` and a successor")]
    assert syntax_errors("a(x) : x > 1 b") == [(1, 14, "a rule needs an arrow `~>` before `b`")]
    assert syntax_errors('a : "->" == "x" b') == [(1, 17, "a rule needs an arrow `~>` before `b`")]


def test_unclosed_bracket_points_at_the_bracket():
    text = 'a ~> Subdiv("Y", 1, 2){ c |\n  d\nb ~> T(1, 2\nc ~> x /* ( */ [ y'
    assert syntax_errors(text) == [(1, 23, "unclosed `{`"), (3, 7, "unclosed `(`"), (4, 16, "unclosed `[`")]


def test_unclosed_bracket_then_column1_brace_hints_at_the_bracket():
    diags = Diagnostics()
    parse_source("a ~> T(1, 2\n{ b }", FILE, diags)
    [d] = diags
    assert (d.span.line, d.span.col) == (2, 1)
    assert "unexpected `{`" in d.message
    assert d.hint == "a `(` on line 1 of this rule is not closed"


@pytest.mark.parametrize("text, errors", [
    ("a ~> [ b", [(1, 6, "unclosed `[`")]),
    ("a ~> b ] c", [(1, 8, "`]` without a `[` before it")]),
    ("a ~> ] [ b", [(1, 6, "`]` without a `[` before it"), (1, 8, "unclosed `[`")]),
    ('a ~> Subdiv("X", 1r, 1r){ [ b | ] c }',
     [(1, 27, "unclosed `[`"), (1, 33, "`]` without a `[` before it")]),
])
def test_scope_brackets_pair_up_in_each_successor(text, errors):
    assert syntax_errors(text) == errors


def test_unterminated_string():
    assert syntax_errors('a ~> I("cube)') == [(1, 8, 'unexpected character `"`')]


def test_end_of_statement_error_is_on_its_last_line_of_code():
    # the comment and blank line after `:` are not where the probability is missing
    [(line, col, message)] = syntax_errors("a ~> b :\n  // why\n\nc ~> d")
    assert (line, col, message) == (1, 8, "unexpected end of statement")


@pytest.mark.parametrize("text, line, col, fragment", [
    ("attr = 3", 1, 6, "unexpected `=`"),
    ("attr x =", 1, 8, "unexpected end of statement"),
    ("PRIORITY x:", 1, 10, "expected an integer"),
    ("a ~> b : ", 1, 8, "unexpected end of statement"),
    ("a ~> b : // c", 1, 8, "unexpected end of statement"),
    ("a ~> S(-1r, 1, 1)", 1, 10, "unexpected `r`"),
    ("a ~> Scope.sx", 1, 11, "unexpected `.`"),
    ("a(x) : 1 < x < 2 ~> b", 1, 14, "unexpected `<`"),
])
def test_syntax_error_positions(text, line, col, fragment):
    [(got_line, got_col, message)] = syntax_errors(text)
    assert (got_line, got_col) == (line, col)
    assert fragment in message


def test_expected_tokens_are_named_for_people():
    [(_, _, message)] = syntax_errors("a ~> T(1,,2)")
    assert "`!`" in message and "__ANON" not in message and "LPAR" not in message
    diags = Diagnostics()
    parse_source("attr x =", FILE, diags)
    assert "`not`" in diags[0].hint and "NOT" not in diags[0].hint


def test_stochastic_continuation_without_a_rule():
    diags = Diagnostics()
    parse_source("// nothing before\n~> x : 1", FILE, diags)
    [d] = diags
    assert (d.span.line, d.span.col) == (2, 1)
    assert d.message == "a stochastic alternative needs a rule before it"


def test_render_shows_the_line_and_a_caret_under_the_error():
    text = "a ~> b\nb ~> g $ h\n"
    diags = Diagnostics()
    parse_source(text, FILE, diags)
    assert render(diags[0], {FILE: text}) == (
        "g.cga:2:8: error: unexpected character `$`\n"
        " 2 | b ~> g $ h\n"
        "   |        ^"
    )


def test_render_caret_spans_the_token_and_shows_the_hint():
    text = "x ~> y\nb ~> Subdiv(\"Y\", 1, 2){ c | d\n"
    diags = Diagnostics()
    parse_source(text, FILE, diags)
    assert render(diags[0], {FILE: text}) == (
        "g.cga:2:23: error: unclosed `{`\n"
        ' 2 | b ~> Subdiv("Y", 1, 2){ c | d\n'
        "   |                       ^\n"
        "  hint: expected one of `|`, `}`"
    )


def test_render_all_sorts_by_position():
    text = "a ~> (\nb ~> $\n"
    diags = Diagnostics()
    parse_source(text, FILE, diags)
    out = render_all(list(reversed(diags)), {FILE: text})
    assert out.index("g.cga:1:") < out.index("g.cga:2:")
