"""frontend/parse.py: which dialect reads a text, how a file is parsed statement by statement (rules over
several lines, comments), and syntax errors: every one reported, at its place, named for people.

Accepted syntax is checked as grammar text -> canonical text of the IR after all passes (``$h``
parameters, ``@name`` attributes, binaries parenthesized, every alternative with its probability).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from grammarc.compiler import compile_grammar
from grammarc.diagnostics import Diagnostics, render, render_all
from grammarc.errors import GrammarError
from grammarc.frontend.parse import detect_dialect, parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_rule

FILE = "g.cga"
CITYENGINE = Path(__file__).parent / "grammars" / "cityengine"
VERSION = 'version "2022.0"\n'


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



# ------------------------------------------------------------------------------------------ the dialect


@pytest.mark.parametrize("text", [
    'version "2022.0"\nLot --> A\n',
    '@StartRule\nLot --> A\n',
    "Lot --> extrude(10) Mass\n",
    "Lot -->\n    A\n",
    "Facade --> split(y){ ~3.5 : Floor }*\n",
    "Mass --> comp(f){ top : Roof }\n",
    "const h = 3\nLot --> A\n",
])
def test_cityengine_is_detected(text):
    assert detect_dialect(text) == "cityengine"
    assert parse_source(text, FILE, Diagnostics()).dialect == "cityengine"


@pytest.mark.parametrize("text", [
    "lot ~> S(1r, 10, 1r) facades\n",
    'facade ~> Subdiv("Y", 3.5, 1r){ floor | facade }\n',
    "1: a --> b c\n",
    'attr h = 3\nfacades ~> Comp("sidefaces"){ facade }\n',
])
def test_paper_notation_is_detected(text):
    assert detect_dialect(text) == "cga2006"
    assert parse_source(text, FILE, Diagnostics()).dialect == "cga2006"


def test_the_same_text_lowers_in_the_dialect_asked_for():
    diags = Diagnostics()
    module = parse_source("Lot --> A B\n", FILE, diags, "cityengine")
    assert module.dialect == "cityengine" and not diags
    assert [type(op) for op in module.rules[0].alternatives[0].body] == [ir.Symbol, ir.Symbol]



# ----------------------------------------------------------------------------------- statements over lines


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


@pytest.mark.parametrize("comment", [
    "// line comment", "# hash comment", "/* block */", "/* block\n   over lines */",
])
def test_comments(comment):
    assert rules(f"{comment}\na ~> b {comment}\n  c\n{comment}\nd ~> e") == ["a ~> b c : 1", "d ~> e : 1"]


def test_comment_inside_a_rule_between_items():
    assert rules("a ~> b /* c */ d // e\n  f # g\n  h") == ["a ~> b d f h : 1"]



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



def test_syntax_errors_of_several_statements_are_all_reported():
    """``syntax_errors.cga``: one error per broken statement, the statements between them still lowered."""
    text = (CITYENGINE / "syntax_errors.cga").read_text()
    diags = Diagnostics()
    module = parse_source(text, FILE, diags)
    assert module.dialect == "cityengine"
    found = [(d.span.line, d.message.split(",")[0]) for d in diags if d.is_error]
    assert found == [
        (6, "unexpected `|`"),  # inside the `(` left open on line 5
        (8, "unexpected `}`"),
        (11, "unexpected `Floor`"),
        (14, "unclosed `{`"),
        (18, "unexpected `:`"),
    ]
    assert [r.symbol for r in module.rules] == ["Lot", "Tile"]


def test_syntax_error_renders_with_the_file_line_and_caret(tmp_path):
    path = tmp_path / "bad.cga"
    path.write_text(VERSION + "Lot --> extrude(10) Mass\nMass --> comp(f){ top : Roof | }\n")
    with pytest.raises(GrammarError) as caught:
        compile_grammar(path)
    (diag,) = caught.value.diagnostics
    assert (diag.span.line, diag.span.col) == (3, 32)
    assert f"{path}:3:32: error: unexpected `}}`" in str(caught.value)


# --------------------------------------------------------------------------- free layout, BOM, large inputs


def test_cityengine_syntax_errors_of_a_free_layout_are_all_reported_at_their_place():
    text = VERSION + "  attr h = (1\nLot --> extrude(h) A B --> s(1,, 1) C\n   D = 1 +\nE --> F\n"
    found = syntax_errors(text)
    assert [(line, col) for line, col, _ in found] == [(2, 12), (3, 32), (4, 10)]
    assert found[0][2] == "unclosed `(`" and found[1][2].startswith("unexpected `,`, expected one of")
    assert found[2][2] == "unexpected end of statement"


def test_byte_order_mark_is_no_syntax_error():
    module, diags = compile_ir("\ufeff" + VERSION + "Lot --> A\n")
    assert not diags.has_errors and module.dialect == "cityengine"
    assert syntax_errors("\ufeffLot ~> A\n") == []
    # the mark is not a column: an error on the first line is where the eye sees it
    assert syntax_errors("\ufeffattr x = (1\nLot --> A") == [(1, 10, "unclosed `(`")]


def test_dialect_detection_is_linear_in_blank_lines():
    import time

    start = time.perf_counter()
    assert detect_dialect("\n" * 1_000_000 + "Lot --> A\n") == "cityengine"
    assert detect_dialect("\n" * 1_000_000 + "Lot ~> A\n") == "cga2006"
    assert parse_source("\n" * 1_000_000 + "Lot --> A\n", FILE, Diagnostics()).rules[0].span.line == 1_000_001
    assert time.perf_counter() - start < 30  # quadratic: hours


# ------------------------------------------------------------------------------------------ deep nesting
def _nested(kind: str, n: int) -> str:
    """A statement nesting ``n`` levels of one construct."""
    body = "A"
    if kind == "subdiv":
        for _ in range(n):
            body = f'Subdiv("X", 1r, 1r){{ {body} | B }}'
        return f"Lot ~> {body}\n"
    if kind == "split":
        for _ in range(n):
            body = f"split(x){{ 1 : {body} | ~1 : B }}"
    elif kind == "case":
        for i in range(n):
            body = f"case scope.sx > {i} : {body} else : B"
    elif kind == "minus":
        body = f"extrude({'-' * n}1) A"
    elif kind == "sum":
        body = f"extrude({' + '.join(['1'] * n)}) A"
    return f"{VERSION}Lot --> {body}\n"


def _deepest(kind: str) -> int:
    """The deepest nesting of ``kind`` that parses without a `nesting` error."""
    low, high = 1, 1
    while not _too_deep(_nested(kind, high)):
        low, high = high, high * 2
    while high - low > 1:
        middle = (low + high) // 2
        low, high = (low, middle) if _too_deep(_nested(kind, middle)) else (middle, high)
    return low


def _too_deep(text: str) -> bool:
    diags = Diagnostics()
    parse_source(text, FILE, diags)
    codes = [d.code for d in diags if d.is_error]
    assert codes in ([], ["nesting"]), codes
    return codes == ["nesting"]


@pytest.mark.parametrize("kind", ["subdiv", "split", "case", "minus", "sum"])
def test_deepest_accepted_nesting_builds_and_one_more_level_is_an_error(kind, tmp_path, capsys):
    from grammarc.cli import main

    deepest = _deepest(kind)
    assert deepest >= 20  # real grammars nest a handful of levels
    grammar = tmp_path / "g.cga"
    grammar.write_text(_nested(kind, deepest))
    assert main(["build", str(grammar), "--emit", str(tmp_path / "out.npz"), "--quiet", "--workers", "1",
                 "--max-depth", "400"]) == 0
    grammar.write_text(_nested(kind, deepest + 1))
    assert main(["check", str(grammar)]) == 2
    assert "nesting too deep" in capsys.readouterr().err


@pytest.mark.parametrize("kind, n", [("subdiv", 1000), ("split", 300), ("minus", 500)])
def test_the_issues_deep_nestings_are_errors_at_their_line(kind, n):
    diags = Diagnostics()
    parse_source("\n" + _nested(kind, n), FILE, diags)
    line = 2 if kind == "subdiv" else 3  # after the version line
    assert [(d.code, d.span.line, d.span.col) for d in diags] == [("nesting", line, 1)]


@pytest.mark.parametrize("dialect, text", [("cityengine", 'version "2022.0"\nLot --> extrude(3) A.\n'),
                                           ("cga2006", "lot ~> S(1, 2, 3) I(\"box\")\n")])
def test_a_file_the_lowered_cache_keeps_is_read_without_lark(tmp_path, dialect, text):
    """lark and the dialects' lowerings are imported only where a statement is parsed: a fresh process
    reading a file whose statements the user's cache folder keeps imports neither, and reads the same."""
    script = f"""
import sys
from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir.printer import print_rule
module = parse_source({text!r}, "g.cga", Diagnostics(), {dialect!r})
print([print_rule(rule) for rule in module.rules], sorted(m for m in sys.modules if m.startswith("lark")
      or m.endswith(".lowering")) != [])
"""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path), "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    runs = [subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
            for _ in range(2)]
    lowered, kept = (run.stdout.strip() for run in runs)
    assert lowered.startswith("['") and lowered.endswith("True") and kept == lowered.removesuffix("True") + "False"
