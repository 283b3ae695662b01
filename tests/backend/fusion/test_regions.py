"""Which symbols fused kernels derive: the whitelist, inlining, and what turns fusion off."""

from __future__ import annotations

from pathlib import Path

from grammarc.backend.fusion.regions import ENDING, SWITCH, grammar_refusals, symbol_refusals
from grammarc.backend.operations import OPERATIONS
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.ir import nodes as ir

ROOT = Path(__file__).resolve().parents[3]


def fused(write, text: str) -> set[str]:
    plan = make_plan(compile_grammar(write("g.cga", text)))
    return {plan.symbols[k].name for k in plan.fused}


def test_symbols_whose_shapes_do_not_fan_out_are_left_to_the_interpreter(write):
    assert fused(write, """
lot ~> S(1r, 3, 1r) T(0, 1, 0) box
box ~> [ S(1r, 1r, 0.5) I("cube") ] I("quad")
""") == set()


def test_the_facade_benchmark_is_fused_below_its_component_split():
    plan = make_plan(compile_grammar(ROOT / "benchmarks" / "facade.cga"))
    assert {plan.symbols[k].name for k in plan.fused} == {"facade", "floor", "tile"}


def test_an_operation_off_the_whitelist_keeps_its_symbol_whose_shapes_are_handed_off(write):
    # ``b`` is the interpreter's: ``lot``'s kernel hands its shapes on to it
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ a | b }
a ~> Repeat("Y", 2){ c }
b ~> R(0, 30, 0) I("cube")
c ~> I("quad")
""") == {"lot", "a"}


def test_a_symbol_named_twice_is_inlined_only_if_it_only_places_an_asset(write):
    # ``x`` is named by ``a`` and ``b`` and splits: inlined, ``a`` and ``b`` would not keep its order; its
    # shapes are handed off to its own region
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ a | b }
a ~> T(1, 0, 0) x
b ~> S(1r, 2, 1r) x
x ~> Subdiv("Y", 1r, 1r){ I("cube") | I("quad") }
""") == {"lot", "x"}
    # a leaf insert is the same however its batches come
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ a | b }
a ~> T(1, 0, 0) x
b ~> S(1r, 2, 1r) x
x ~> S(1r, 1r, 0.2) I("cube")
""") == {"lot"}


def test_leaves_are_emitted_inside_a_region_wherever_their_symbol_is_named(write):
    # ``socle`` and ``plaster`` have no rules: their boxes are records where ``band`` and ``wall`` name them
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ band | wall }
band ~> Subdiv("Y", 0.8, 1r){ socle | plaster }
wall ~> Repeat("X", 2){ plaster | I("cube") }
""") == {"lot", "band", "wall"}
    # a leaf with arguments is left to the interpreter, and with it ``band``
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ band(1) | band(2) }
band(k) ~> Subdiv("Y", k, 1r){ socle(k) | plaster }
""") == {"lot"}


def test_splits_along_several_axes_are_fused_but_those_that_snap(write):
    plan = make_plan(compile_grammar(write("g.cga", """
lot ~> Subdiv("X", 1r, 1r, 1r){ a | b | d }
a ~> Subdiv("XZ", 1, 1r){ I("cube") | ε | ε | I("quad") }
b ~> Repeat("XYZ", 1, 2, 3){ I("cube") | I("quad") }
d ~> Repeat("XS", 1){ I("cube") }
""")))
    assert {plan.symbols[k].name for k in plan.fused} == {"lot", "a", "b"}  # ``lot`` hands ``d`` its shapes
    assert symbol_refusals(plan)["d"].what == "`d` snaps"

def test_random_choices_min_max_rand_and_parameters_are_fused_other_functions_not(write):
    assert fused(write, """
lot ~> Subdiv("X", 1r, rand(1, 2)){ a(2) | b }
a(k) ~> S(k, 1r, min(Scope.sz, 3)) Repeat("Y", k){ [ T(0, 0, k) I("quad") ] I("cube") }
b ~> Repeat("Y", 1){ I("cube") } : 0.5
  ~> I("quad") : 0.5
""") == {"lot", "a", "b"}
    # ``c`` is the interpreter's (``sin``), ``lot`` hands its shapes on; a search's consequents are chosen by
    # its states
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ c | d }
c ~> Repeat("Y", sin(Scope.sx) + 2){ I("cube") }
d ~> Repeat("Y", 1){ I("cube") } ?
  ~> I("quad") ?
""") == {"lot"}


def test_recursion_is_handed_off(write):
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ lot | I("cube") }
""") == {"lot"}
    # named once, by itself: handed off to itself, never inlined into itself
    assert fused(write, """
lot ~> Subdiv("X", 1r, 1r){ a | I("cube") }
a ~> Repeat("X", 1){ b }
b ~> S(1r, 0.5r, 1r) b
""") == {"lot", "a"}


def test_the_switch_turns_fusion_off(write, monkeypatch):
    monkeypatch.setenv(SWITCH, "off")
    assert not make_plan(compile_grammar(ROOT / "benchmarks" / "facade.cga")).fused


def test_cityengine_splits_scope_operations_inserts_and_brackets_are_fused(write):
    assert fused(write, """
version "2023.0"
Lot --> split(x){ 2: A | { ~1: B | '0.1: NIL }* }*
A --> s('1, '1, 2) t(0, 0, -1) center(xz) i("builtin:cube")
B --> [ t(0, 1, 0) C. ] split(y){ 1: A | ~2: i("door.obj") }
""") == {"Lot", "B"}


def test_a_cityengine_case_is_fused(write):
    text = """
version "2023.0"
Lot --> split(x){ ~2: A | ~1: B }*
A --> case scope.sx > 1: split(y){ ~1: C. }* case scope.sx > 0.5: NIL else: s('1, 2, '1)
B --> [ case scope.sz > 1: C. else: D ] t(0, 0, 1) D
D --> split(y){ ~1: C. }*
E --> case scope.sx > 1: split(y){ ~1: C. }* else: extrude(2)
"""
    assert fused(write, text) == {"Lot", "A", "D"}  # ``B`` makes no shapes of its own: not worth a kernel
    assert set(symbol_refusals(make_plan(compile_grammar(write("g.cga", text))))) == {"E"}


def test_cityengine_draws_are_fused_what_needs_geometry_or_texture_space_not(write):
    plan = make_plan(compile_grammar(write("g.cga", """
version "2023.0"
Lot --> split(x){ rand(1, 2): A | ~1: B }*
A --> 30%: split(y){ ~1: C }* else: case p(0.5): NIL else: C
B --> splitArea(x){ ~1: C }*
C --> i("door.obj", zUp, alignSizeAndPosition)
D --> setupProjection(0, scope.xy, 1, 1) split(u, unitSpace, 0){ ~1: C }*
""")))
    refused = symbol_refusals(plan)
    assert "Lot" not in refused and "A" not in refused
    assert refused["B"].name == "splitArea"
    assert refused["C"].what == "an `i` that turns the asset or keeps its size"
    assert refused["D"].name == "setupProjection"
    assert grammar_refusals(plan) == []  # texture coordinates pass through the kernels


def test_what_keeps_a_grammar_and_each_symbol_out_is_said_with_where(write):
    plan = make_plan(compile_grammar(write("g.cga", """
version "2023.0"
Lot --> split(x){ 2: A | ~1: B }*
A --> s('1, '1, 2) i("builtin:cube")
B --> case scope.sx > 1: rotateScope(0, 90, 0)
      else: NIL
C --> case inside(): NIL else: A
""")))
    assert [w.split(" (")[0] for w in grammar_refusals(plan)] == ["occlusion"]
    refused = symbol_refusals(plan)
    assert str(refused["B"]).startswith("an operation no kernel takes: `rotateScope(0, 90, 0)` at ")
    assert refused["B"].name == "rotateScope" and str(refused["B"]).endswith("g.cga:5:26")
    assert set(refused) == {"B", "C"}  # ``Lot`` hands its shapes to ``B``; ``A``'s ``s`` and ``i`` are fused
    # a fused grammar: nothing keeps it out, and its fused symbols have no refusal
    facade = make_plan(compile_grammar(ROOT / "benchmarks" / "facade.cga"))
    assert grammar_refusals(facade) == []
    assert set(symbol_refusals(facade)) == {"mass"}  # its component split
    assert str(symbol_refusals(facade)["mass"]).startswith("an operation no kernel takes: `Comp(")


def test_shapes_that_carry_columns_are_fused_but_a_split_whose_index_is_read(write):
    """Colours, textures and attributes ``set`` pass through the kernels; ``split.index``, which a split writes
    and no kernel does, keeps every symbol that splits out."""
    plan = make_plan(compile_grammar(write("g.cga", """
version "2023.0"
attr lit = false
Lot --> color(1, 0, 0) set(lit, true) setupProjection(0, scope.xy, 1, 1) projectUV(0) A
A --> split(x){ ~1: case lit: B else: C. }*
B --> split(y){ ~1: s('1, '1, 0.2) i("builtin:cube") }*
""")))
    assert grammar_refusals(plan) == [] and {plan.symbols[k].name for k in plan.fused} == {"A", "B"}
    plan = make_plan(compile_grammar(write("h.cga", """
version "2023.0"
Lot --> split(x){ ~1: A }*
A --> s('1, '1, split.index) B
B --> split(y){ ~1: C. }*
""")))
    refused = symbol_refusals(plan)
    assert set(refused) == {"Lot", "A", "B"} and not plan.fused
    assert str(refused["B"]).startswith("a split whose `split.index` or `split.total` a rule reads: `split(y)")
    assert refused["A"].what == "an expression no kernel takes"  # reading it


def test_the_fused_operations_that_end_a_body_are_those_the_interpreter_ends_it_with():
    """``ENDING``: no leaf at a CityEngine body's end after them, as ``execute.run`` decides with the table."""
    fused = (*ENDING, ir.Scale, ir.Translate, ir.UseAsset)  # and `[ ]` and `center`, which the runner keeps
    assert [t for t in fused if OPERATIONS[t].consumes] == list(ENDING)


def test_the_fused_operations_that_write_a_per_shape_column_are_i_set_and_color():
    """A root's per-shape columns are those of everything its region makes (``regions``) but those it writes:
    of the operations a kernel takes, ``i`` (its geometry inserted, which the kernel knows where it writes
    its code), ``set`` and ``color`` (whose values the kernel writes beside its records and shapes); a
    split's parts are the parent's columns and ``split.index`` (``children.with_context``), whose reading
    keeps splits out."""
    fused = (*ENDING, ir.Scale, ir.Translate, ir.UseAsset, ir.SetAttr, ir.SetColor, ir.NotApplied)  # and `center`
    assert [t for t in fused if "dynamic" in OPERATIONS[t].writes] == [ir.UseAsset, ir.SetAttr, ir.SetColor]


def test_strings_are_fused_as_the_values_of_set_and_color_and_in_equalities_only(write):
    plan = make_plan(compile_grammar(write("g.cga", """
version "2023.0"
attr tex = "a.jpg"
attr hue = "#ffffff"
Lot --> split(x){ ~1: A | ~1: C | ~1: D | ~1: E | ~1: F | ~1: G("g.jpg", tex) | ~1: H(hue + "0") | ~1: I("i") }*
A --> texture(tex) color(hue) set(material.dirtmap, "d.jpg") reverseNormals split(y){ ~1: B. }*
C --> split(y){ ~1: set(material.colormap, tex + ".png") B. }*
D --> split(y){ ~1: color("teal") B. }*
E --> split(y){ ~1: case tex == hue || "b.jpg" != tex: B. else: NIL }*
F --> split(y){ ~1: case tex < hue: B. else: NIL }*
G(image, other) --> split(y){ ~1: case image != other: texture(image) color(hue) J(image, true) else: NIL }*
H(name) --> split(y){ ~1: B. }*
I(name) --> split(y){ ~1: case name < "j": B. else: NIL }*
J(name, on) --> set(material.colormap, name) B.
""")))
    refused = symbol_refusals(plan)
    assert {plan.symbols[k].name for k in plan.fused} == {"A", "E", "G", "H"}
    assert refused["C"].what == "a string other than a constant, an attribute or a parameter"
    assert refused["D"].what == 'a colour that is not "#rrggbb"' and refused["D"].text == '"teal"'
    assert refused["F"].what == "a string attribute"
    assert refused["I"].what == "a string parameter"  # compared as no kernel compares strings
    assert refused["Lot"].text == '(@hue + "0")'  # H's argument
