"""compiler.py: compile_grammar reads, parses and runs the passes (the rule graph and assets among them).

A grammar with errors raises GrammarError listing every one; warnings come back with the grammar.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from grammarc.compiler import compile_grammar
from grammarc.errors import GrammarError, UsageError

PAPER = Path(__file__).parent / "frontend" / "grammars"


def compile_errors(path, text=None, **kwargs) -> list[tuple[str, int, int, str]]:
    """Every diagnostic of the GrammarError, by position."""
    with pytest.raises(GrammarError) as info:
        compile_grammar(path, text=text, **kwargs)
    return sorted((d.code, d.span.line, d.span.col, d.message) for d in info.value.diagnostics)


def test_compiles_and_reads_the_file(write):
    text = 'attr h = 3\nlot ~> S(1r, h, 1r) Comp("sidefaces"){ facade }\nfacade ~> I("cube")\n'
    path = write("g.cga", text)
    grammar = compile_grammar(path)
    assert grammar.path == str(path)
    assert grammar.digest == hashlib.sha256(text.encode()).hexdigest()
    assert grammar.sources == {str(path): text}
    assert grammar.warnings == ()
    assert [r.symbol for r in grammar.module.rules] == ["lot", "facade"]
    assert grammar.graph.start == "lot" and grammar.graph.reachable == frozenset({"lot", "facade"})
    assert grammar.assets == ("builtin:cube", "builtin:quad") and grammar.asset_ids == {"cube": 0}


def test_every_error_of_every_stage_is_listed(write):
    text = (
        "lot(x) ~> a b c d\n"                    # start rule with a parameter (a warning)
        'a ~> Subdv("Y", 1){ b }\n'              # unknown operation (lowering)
        "b ~> T(1, 2\n"                          # syntax error
        "c ~> T(zz, 0, 0)\n"                     # unknown identifier (resolve)
        "d : 1 ~> e : 0.5 ~> f : 0.2\n"          # guard type (types), probabilities
        'e ~> I("../../etc/passwd")'             # asset escaping the grammar folder
    )
    errors = compile_errors(write("g.cga", text))
    assert sorted(errors, key=lambda e: e[1:3]) == [
        ("start-params", 1, 1, ("the start rule `lot` takes parameters (x): a lot has no arguments to pass; "
         "build it with --start 'lot(...)' giving their values")),
        ("unknown-op", 2, 6, "unknown operation `Subdv` (did you mean `Subdiv`?)"),
        ("syntax", 3, 7, "unclosed `(`"),
        ("unknown-name", 4, 8, "unknown identifier `zz` in rule `c`"),
        ("probability", 5, 1, "probabilities of `d` sum to 0.7 (0.5 + 0.2), not 1"),
        ("type", 5, 5, "a guard must be a bool, got a num"),
        ("asset", 6, 6, f"asset path `../../etc/passwd` leaves the asset folders ({write('x', '').parent})"),
    ]


def test_an_error_in_an_imported_file_shows_its_line_and_caret(write):
    write("facade.cga", 'version "2022.0"\nFacade --> extrude(depht)\n')
    main = write("main.cga", 'version "2022.0"\nimport f : "facade.cga"\nLot --> f.Facade\n')
    with pytest.raises(GrammarError) as info:
        compile_grammar(main)
    shown = str(info.value).splitlines()
    assert shown[0].startswith(f"{main.parent / 'facade.cga'}:2:20: error: unknown identifier `depht`")
    assert shown[1:3] == [" 2 | Facade --> extrude(depht)", "   |                    ^^^^^"]


def test_grammar_error_renders_every_error_with_its_line_and_caret(write):
    path = write("g.cga", "a ~> b c\nb ~> Subdv(\"Y\", 1){ c }\nc ~> T(1r, 0, 0)\n")
    with pytest.raises(GrammarError) as info:
        compile_grammar(path)
    assert str(info.value) == (
        f"{path}:2:6: error: unknown operation `Subdv` (did you mean `Subdiv`?)\n"
        ' 2 | b ~> Subdv("Y", 1){ c }\n'
        "   |      ^^^^^\n"
        f"{path}:3:8: error: a relative size like `1r` is only allowed in `S` and `Subdiv`\n"
        " 3 | c ~> T(1r, 0, 0)\n"
        "   |        ^^"
    )
    assert info.value.exit_code == 2


def test_text_overrides_the_file(tmp_path):
    grammar = compile_grammar(tmp_path / "never_written.cga", text="a ~> b")
    assert grammar.module.start == "a"


def test_missing_file_is_a_usage_error(tmp_path):
    with pytest.raises(UsageError, match="cannot read grammar"):
        compile_grammar(tmp_path / "nope.cga")


@pytest.mark.parametrize("text", ["", "\n\n", "// only a comment\n", "/* block */", "attr h = 3\n"])
def test_empty_grammar(tmp_path, text):
    assert compile_errors(tmp_path / "g.cga", text) == [("empty", 1, 1, "the grammar has no rules")]


def test_a_grammar_whose_rules_all_fail_to_parse_is_not_also_empty(tmp_path):
    [(code, line, col, message)] = compile_errors(tmp_path / "g.cga", "a ~> T(1,,2)")
    assert (code, line, col) == ("syntax", 1, 10) and message.startswith("unexpected `,`, expected one of")


def test_stochastic_continuation_without_a_rule(tmp_path):
    assert compile_errors(tmp_path / "g.cga", "~> a : 1\nb ~> c") == [
        ("syntax", 1, 1, "a stochastic alternative needs a rule before it")]


def test_start_symbol(tmp_path):
    grammar = compile_grammar(tmp_path / "g.cga", text="lot ~> a\na ~> b", start="a")
    assert grammar.graph.start == "a"
    assert [w.message for w in grammar.warnings] == ["rule for `lot` is never reached from `a`"]
    with pytest.raises(UsageError, match="start symbol `zz` has no rule"):
        compile_grammar(tmp_path / "g.cga", text="lot ~> a", start="zz")


def test_start_rule_that_failed_to_parse_reports_its_syntax_error(tmp_path):
    # `--start lot` with a broken lot rule: the syntax error, not "no rule"
    assert compile_errors(tmp_path / "g.cga", "a ~> b\nlot ~> T(1,", start="lot") == [
        ("syntax", 2, 9, "unclosed `(`")]


def test_start_rule_with_parameters_needs_their_values_to_be_derived(tmp_path):
    text = "attr h = 1\nlot(w) ~> b(w)\nb(x) ~> c"
    with pytest.raises(UsageError, match=r"the start rule `lot` takes parameters \(w\): a lot has no arguments "
                       r"to pass; build it with --start 'lot\(...\)' giving their values"):
        compile_grammar(tmp_path / "g.cga", text=text)
    checked = compile_grammar(tmp_path / "g.cga", text=text, derive=False)  # `grammarc check`
    assert [(w.code, w.span.line) for w in checked.warnings] == [("start-params", 2)]
    derived = compile_grammar(tmp_path / "g.cga", text=text, start="lot(3)")
    assert derived.graph.start == "lot(3)" and not derived.warnings
    assert derived.graph.edges["lot(3)"] == ("lot",)


def test_start_arguments_that_do_not_fit_the_rule(tmp_path):
    text = 'lot(w, kind) ~> b(w)\nb(x) ~> S(x, 1, 1) c'
    with pytest.raises(UsageError, match=r"--start calls `lot` with 1 argument; it takes 2 \(w, kind\)"):
        compile_grammar(tmp_path / "g.cga", text=text, start="lot(3)")
    errors = compile_errors(tmp_path / "g.cga", text, start='lot("tall", "a")')
    assert errors == [("type", 2, 11, "a size must be a num, got a str")]  # at the use of `w`


def test_warnings_as_errors(tmp_path):
    text = "lot ~> a\nlost ~> x"
    assert compile_errors(tmp_path / "g.cga", text, warnings_as_errors=True) == [
        ("unreachable", 2, 1, "rule for `lost` is never reached from `lot`")]
    assert [w.code for w in compile_grammar(tmp_path / "g.cga", text=text).warnings] == ["unreachable"]


@pytest.mark.parametrize("name, fragment", [
    ("../../etc/passwd", "leaves the asset folders"),
    ("../sibling.obj", "leaves the asset folders"),
    ("C:/Windows/x.obj", "is absolute"),
    ("builtin:sphere", "unknown built-in asset"),
])
def test_asset_paths_that_are_errors(write, name, fragment):
    [(code, line, col, message)] = compile_errors(write("g.cga", f'a ~> b\nb ~> I("{name}")'))
    assert (code, line, col) == ("asset", 2, 6)
    assert f"`{name}`" in message and fragment in message


def test_missing_obj_asset_is_a_warning_and_keeps_its_name(write):
    grammar = compile_grammar(write("g.cga", 'a ~> I("win.obj") I("sub/door.obj") I("win.obj") I("/P/assets/x.obj")'))
    assert [(w.code, w.span.col) for w in grammar.warnings] == [("asset", 6), ("asset", 19), ("asset", 50)]
    assert "asset `win.obj` not found" in grammar.warnings[0].message
    # a workspace path that no root holds is missing too, as CityEngine inserts nothing for it
    assert grammar.warnings[2].message.endswith("the record keeps its name; a workspace path: --workspace gives "
                                                "the folder of its projects")
    assert grammar.assets == ("builtin:cube", "builtin:quad", "win.obj", "sub/door.obj", "/P/assets/x.obj")
    assert grammar.asset_ids == {"win.obj": 2, "sub/door.obj": 3, "/P/assets/x.obj": 4}


def test_assets_resolve_in_the_grammar_folder_then_asset_roots(write, tmp_path):
    write("win.obj", "v 0 0 0\n")
    (tmp_path / "kit").mkdir()
    (tmp_path / "kit" / "door.obj").write_text("v 0 0 0\n")
    path = write("g.cga", 'a ~> I("win.obj") I("./win.obj") I("door.obj") I("cylinder") I("builtin:cube")')
    grammar = compile_grammar(path, asset_roots=(tmp_path / "kit",))
    assert grammar.warnings == ()
    assert grammar.assets == ("builtin:cube", "builtin:quad", "win.obj", "door.obj", "builtin:cylinder")
    assert grammar.asset_ids == {
        "win.obj": 2, "./win.obj": 2, "door.obj": 3, "cylinder": 4, "builtin:cube": 0}


def test_warnings_come_back_with_the_grammar(write):
    grammar = compile_grammar(write("g.cga", "attr h = 1\nlot ~> a(2)\na(h) ~> leaf(h)\nlost ~> x"))
    assert [(w.code, w.span.line) for w in grammar.warnings] == [
        ("shadow", 3), ("terminal-args", 3), ("unreachable", 4)]
    assert all(not w.is_error for w in grammar.warnings)


def test_paper_grammars_compile(tmp_path):
    mass = compile_grammar(PAPER / "mass_model.cga")
    assert mass.warnings == ()
    assert mass.graph.terminals == ("facade",)

    puuc = compile_grammar(PAPER / "puuc.cga")
    missing = sorted(w.message.split("`")[1] for w in puuc.warnings)
    assert missing == ["apron.obj", "cylinder.obj", "jamb.obj", "lintel.obj", "reverse_apron.obj", "wall.obj"]
    assert all(w.code == "asset" for w in puuc.warnings)
    assert len(puuc.module.rules) == 21 and puuc.graph.start == "footprint"
