"""ir/verify.py and ir/pipeline.py: what legal IR is after each stage, checked between passes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from grammarc.diagnostics import Diagnostics, Span
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import PASSES, run_passes
from grammarc.ir.verify import STAGES, verify

FILE = "g.cga"
GRAMMAR = (
    'attr h = 3\nlot ~> S(1r, h, 1r) Subdiv("Y", h, 1r){ floor(h) | roof } : 0.5 ~> ε : 0.5\n'
    "floor(x) : x > 1 ~> T(0, 0, rand()) Comp(\"edge\", 1){ e }\nroof ~> [ I(\"cube\") ]"
)


def lowered(text: str = GRAMMAR, roots: tuple[Path, ...] | None = (Path(__file__).parent,)) -> ir.Module:
    """The module as the compiler hands it to the passes (with asset folders), or as a test lowers it."""
    diags = Diagnostics()
    module = parse_source(text, FILE, diags)
    assert not diags
    return replace(module, roots=roots)


def test_pipeline_lists_the_stages_in_order():
    assert ("lower",) + tuple(name for name, _ in PASSES) == STAGES


def test_legal_ir_after_every_stage():
    diags = Diagnostics()
    module = lowered()
    assert verify(module, "lower") == []
    for name, _ in PASSES:
        module = run_passes(lowered(), diags, check=True, stop_after=name)
        assert verify(module, name) == [], name
    assert not diags


def test_unresolved_name_is_legal_after_lower_but_not_after_resolve():
    module = lowered("a ~> T(h, 0, 0)")
    assert verify(module, "lower") == []
    assert verify(module, "resolve") == ["rule `a` (line 1): unresolved name `h`"]


def test_missing_probability_is_illegal_after_probabilities():
    module = run_passes(lowered("a ~> b"), Diagnostics(), check=True, stop_after="fold")
    assert verify(module, "fold") == []
    assert verify(module, "probabilities") == ["rule `a` (line 1): alternative without probability"]


def test_missing_parameter_types_are_illegal_after_types():
    module = run_passes(lowered("a ~> b(1)\nb(x) ~> c"), Diagnostics(), check=True, stop_after="types")
    # a symbol without parameters needs no entry
    assert verify(replace(module, param_types=()), "types") == ["rule `b` (line 2): parameter types missing"]


def test_site_used_twice():
    module = lowered("a ~> b c")
    b, c = module.rules[0].alternatives[0].body
    planted = replace(module, rules=(replace(module.rules[0], alternatives=(
        replace(module.rules[0].alternatives[0], body=(b, replace(c, site=b.site))),)),))
    assert verify(planted, "lower") == [f"rule `a` (line 1): site {b.site} used twice"]


def test_parameter_out_of_range_and_span_from_another_file():
    rule = ir.Rule("a", ("x",), ir.Binary(">", ir.Param(1, "y", Span(FILE, 1, 1, 1, 2)),
                                           ir.Num(0.0, Span("other.cga", 1, 1, 1, 2))),
                   (ir.Alternative((), ir.Num(1.0)),), 0, span=Span(FILE, 1, 1, 1, 2))
    problems = verify(ir.Module(FILE, (), (rule,), "a", (("a", (ir.Type.NUM,)),)), "probabilities")
    assert problems == [
        "rule `a` (line 1): parameter index 1 out of range",
        "rule `a` (line 1): span from another file other.cga:1:1",
    ]


def test_undeclared_attribute_and_error_placeholder_are_illegal_after_resolve():
    translate = ir.Translate((ir.AttrRef("h"), ir.placeholder(), ir.Num(0.0)))
    rule = ir.Rule("a", (), None, (ir.Alternative((translate,), ir.Num(1.0)),), 0)
    module = ir.Module(FILE, (), (rule,), "a", (("a", ()),))
    assert verify(module, "resolve") == [
        "rule `a` (line 0): undeclared attribute `h`",
        f"rule `a` (line 0): undeclared attribute `{ir.PLACEHOLDER}`",
    ]
    declared = replace(module, attrs=(ir.AttrDecl("h", ir.Num(1.0)),))
    assert verify(declared, "resolve") == [f"rule `a` (line 0): undeclared attribute `{ir.PLACEHOLDER}`"]


def test_pipeline_checks_ir_and_raises_on_illegal_ir():
    module = lowered("a ~> b c")
    b, c = module.rules[0].alternatives[0].body
    planted = replace(module, rules=(replace(module.rules[0], alternatives=(
        replace(module.rules[0].alternatives[0], body=(b, replace(c, site=b.site))),)),))
    with pytest.raises(AssertionError, match="illegal IR after lower"):
        run_passes(planted, Diagnostics(), check=True)
    run_passes(planted, Diagnostics(), check=False)  # without the check nothing complains


def test_pipeline_runs_every_pass_after_errors_and_skips_the_checks():
    # errors become placeholders: all passes still run, so one call lists problems of every pass
    diags = Diagnostics()
    text = 'a ~> T(zz, 0, 0) b : 0.5 ~> c : 0.4\nd : 1 ~> T(1 / 0, 0, 0) I("/x.obj")'
    run_passes(lowered(text), diags, check=True)
    assert [d.code for d in diags] == ["unknown-name", "type", "division", "probability", "unreachable", "asset"]


def test_the_graph_must_be_the_start_symbols():
    module = run_passes(lowered(), Diagnostics(), check=True, stop_after="rulegraph")
    assert verify(replace(module, graph=None), "rulegraph") == ["module: no rule graph"]
    assert verify(replace(module, start="floor"), "rulegraph") == [
        "module: the graph starts at `lot`, the module at `floor`"]
    other = replace(module.graph, nonterminals=("lot",))
    assert verify(replace(module, graph=other), "rulegraph") == [
        "module: the graph's symbols with rules are not the rules'"]


def test_every_inserted_asset_must_have_an_id():
    module = run_passes(lowered(), Diagnostics(), check=True)
    assert module.asset_ids == (("cube", 0),)
    assert verify(replace(module, asset_ids=()), "assets") == [
        "module: asset `cube` at g.cga:4:11 has no id"]
    assert verify(replace(module, assets=("builtin:quad",)), "assets") == [
        "module: assets 0 and 1 are not the leaf cube and quad"]
    # a module lowered outside the compiler keeps its asset names unresolved
    assert verify(replace(module, roots=None, asset_ids=()), "assets") == []


def test_stop_after():
    module = run_passes(lowered("a ~> T(1 + 1, 0, 0)"), Diagnostics(), check=True, stop_after="resolve")
    assert module.param_types == ()
    assert isinstance(module.rules[0].alternatives[0].body[0].vector[0], ir.Binary)
