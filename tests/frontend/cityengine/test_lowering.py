"""frontend/cityengine/lowering.py with grammars/cityengine.lark: declarations, rule bodies and
CityEngine's expressions lowered to IR.

Accepted constructs are checked as grammar text -> canonical IR text after all passes, or by the IR nodes
they make; what grammarc does not implement must come out as ``unsupported: NAME`` at its span, never be
skipped.
"""

from __future__ import annotations

import pytest

from grammarc.backend.attributes import check_overrides
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.errors import UsageError
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_body, print_expr
from grammarc.ir.traverse import iter_ops

from .lowered import GRAMMARS, VERSION, assert_unsupported_at, body_of, compile_ir, errors, module_of, rules

# -------------------------------------------------------------------------------------- declarations


def test_annotations_are_kept_on_attributes():
    module = module_of(VERSION + """
@Group("Building", 1) @Order(2)
@Range(min=1, max=5)
attr floors = 3
@Enum("flat", "gable")
@Description("the roof")
attr roof = "flat"
@Hidden
attr seed = 0
@Range(1, 5) @Distance
attr width = 2
attr plain = 1
@StartRule
Lot --> A
""")
    notes = {a.name: a.annotations for a in module.attrs}
    assert notes == {
        "floors": (("Group", ('"Building"', "1")), ("Order", ("2",)), ("Range", ("min=1", "max=5"))),
        "roof": (("Enum", ('"flat"', '"gable"')), ("Description", ('"the roof"',))),
        "seed": (("Hidden", ()),),
        "width": (("Range", ("1", "5")), ("Distance", ())),
        "plain": (),
    }


def test_annotations_on_the_declarations_line():
    module = module_of(VERSION + "@Hidden attr seed = 0\nattr plain = 1\nLot --> A\n")
    assert {a.name: a.annotations for a in module.attrs} == {"seed": (("Hidden", ()),), "plain": ()}


def test_const_is_an_attribute_that_cannot_be_set():
    module = module_of(VERSION + "const w = 3\nattr h = w * 2\nLot --> extrude(h) s(w, '1, '1) A\n")
    attrs = {a.name: a for a in module.attrs}
    assert attrs["w"].const and not attrs["h"].const
    assert body_of(VERSION + "const w = 3\nattr h = w * 2\nLot --> extrude(h) s(w, '1, '1) A\n") \
        == "extrude(@h) S(@w, 1r, 1r) A"
    # --attr on an attribute is fine, on a constant a usage error
    check_overrides(module, {"h": 4.0})
    with pytest.raises(UsageError, match="`w` is a constant"):
        check_overrides(module, {"w": 4.0})
    assert errors(VERSION + "const w = 3\nLot --> set(w, 4) A\n") == [(3, 9, "`set` of the constant `w`")]



# ------------------------------------------------------------------------------------- case and p%


def test_case_block_with_else():
    text = VERSION + """attr h = 10
Lot -->
    case scope.sx > 10 && h > 5 :
        extrude(h) Tall
    case scope.sx > 5 || scope.sz > 5 :
        Wide
    else :
        NIL
"""
    assert body_of(text) == ("{ case ((Scope.sx > 10) && (@h > 5)): extrude(@h) Tall "
                             "case ((Scope.sx > 5) || (Scope.sz > 5)): Wide else: \u03b5 }")
    case = module_of(text).rules[0].alternatives[0].body[0]
    assert isinstance(case, ir.Case) and len(case.branches) == 2


def test_nested_case_and_stochastic_blocks():
    text = VERSION + """Lot -->
    case scope.sx > 10 :
        case scope.sz > 10 : Big
        else : Wide
    case scope.sx > 5 :
        30% : A
        20% : B
        else : C
    else :
        [ t(0, 1, 0) A. ] B.
"""
    assert body_of(text) == ("{ case (Scope.sx > 10): { case (Scope.sz > 10): Big else: Wide } "
                             "case (Scope.sx > 5): { % 30: A % 20: B else: C } else: [ T(0, 1, 0) A. ] B. }")


def test_stochastic_block():
    body = module_of(VERSION + "Lot -->\n    30% : A\n    20% : B B\n    else : C\n").rules[0] \
        .alternatives[0].body
    assert len(body) == 1 and isinstance(body[0], ir.Stochastic)
    op = body[0]
    assert [(print_expr(p), len(b)) for p, b in op.branches] == [("30", 1), ("20", 2)]
    assert [s.name for s in op.default] == ["C"]


def test_stochastic_block_without_else_and_with_an_attribute_as_percentage():
    assert body_of(VERSION + "attr share = 40\nLot -->\n    share% : A\n") == "{ % @share: A else: \u03b5 }"
    assert body_of(VERSION + "Lot -->\n    50% : A\n    else : NIL\n") == "{ % 50: A else: \u03b5 }"



# ------------------------------------------------------------------------------------------ expressions


def test_case_and_stochastic_expressions_in_attribute_defaults():
    module = module_of(VERSION + """attr h = 12
attr style = case h > 30 : "tower" case h > 10 : "block" else : "house"
attr floors = case h > 10 : (case h > 20 : 6 else : 4) else : 1
attr roof = 30% : "flat" 20% : "gable" else : "hip"
Lot --> A
""")
    defaults = {a.name: print_expr(a.default) for a in module.attrs}
    assert defaults["style"] == '((@h > 30) ? "tower" : ((@h > 10) ? "block" : "house"))'
    assert defaults["floors"] == "((@h > 10) ? ((@h > 20) ? 6 : 4) : 1)"
    # one p() per share, in turn, each given that none before was taken: 0.2 of what 0.3 leaves
    roof = module.attrs[3].default
    assert print_expr(roof) == '(p(0.3) ? "flat" : (p(0.285714) ? "gable" : "hip"))'
    assert roof.other.cond.args[0].value == pytest.approx(0.2 / 0.7)
    assert roof.cond.site != roof.other.cond.site
    assert {a.name: a.type for a in module.attrs}["roof"] is ir.Type.STR


def test_string_concatenation():
    module = module_of(VERSION + 'attr level = 2\nattr name = "floor_" + str(level) + ".obj"\n'
                       'Lot --> report("level " + level, 1) A\n')
    assert print_expr(module.attrs[1].default) == '(("floor_" + str(@level)) + ".obj")'
    assert module.attrs[1].type is ir.Type.STR


def test_a_selector_argument_is_its_keywords_text():
    """`assetInfo(a, sx)`: CityEngine's selector keyword, as `assetInfo(a, "sx")`; another name stays one."""
    module = module_of(VERSION + 'attr q = "sy"\nLot --> report("a", assetInfo("x.obj", sx)) '
                       'report("b", assetInfo("x.obj", q)) report("c", assetsSortSize("x.obj;", xz, 0))\n')
    reports = [op for op in iter_ops(module) if isinstance(op, ir.Report)]
    assert [print_expr(op.value) for op in reports] == [
        'assetInfo("x.obj", "sx")', 'assetInfo("x.obj", @q)', 'assetsSortSize("x.obj;", "xz", 0)']


def test_arrays_lower_to_literals_ranges_and_indices():
    module = module_of(VERSION + 'const a = [1, 2 ;\n           3, 4]\nconst r = [0 : 2 : size(a) - 1]\n'
                       'attr b = a[a .> 1 .&& .!(a .== 4)][0] + a[1, [0, 1]][1] + a[1:2][0]\n'
                       'attr s = ["x", "y"] .+ "z"\nLot --> extrude(b) [ s(1, 1, 1) A ] B\n')
    printed = {a.name: print_expr(a.default) for a in module.attrs}
    assert printed == {
        "a": "[1, 2 ; 3, 4]",
        "r": "[0:2:(size(@a) - 1)]",
        "b": "((@a[((@a .> 1) .&& .!(@a .== 4))][0] + @a[1, [0, 1]][1]) + @a[[1:1:2]][0])",
        "s": '(["x", "y"] .+ "z")',
    }


def test_brackets_in_bodies_are_still_push_and_pop():
    assert body_of(VERSION + "attr a = [2, 3]\nLot --> [ t(a[0], 0, 0) A ] [ B ] C\n") == \
        "[ T(@a[0], 0, 0) A ] [ B ] C"


def test_convert_initial_shape_and_print_lower_to_calls():
    """``convert``'s keywords become strings, its form on an array three calls; ``initialShape.origin.o*``
    is the lot's orientation, ``scope.elevation`` its origin's world y; the ``print`` function is a call that
    gives its argument."""
    module = module_of(VERSION + "attr a = convert(x, scope, world, pos, 1, 2, 3)\n"
                       "attr b = convert(scope, pivot, orient, [1, 2, 3])\nattr c = initialShape.origin.oy\n"
                       "attr d = initialShape.name + initialShape.startRule\nattr e = print(2) + 1\n"
                       "attr f = scope.elevation\nLot --> A\n")
    printed = {a.name: print_expr(a.default) for a in module.attrs}
    assert printed["a"] == 'convert("x", "scope", "world", "pos", 1, 2, 3)'
    assert printed["b"] == "[" + ", ".join(f'convert("{c}", "scope", "pivot", "orient", [1, 2, 3][0], '
                                           '[1, 2, 3][1], [1, 2, 3][2])' for c in "xyz") + "]"
    assert printed["c"] == 'convert("y", "object", "world", "orient", 0, 0, 0)'
    assert printed["d"] == "(initialShape.name() + initialShape.startRule())"
    assert printed["e"] == "(print(2) + 1)"
    assert printed["f"] == 'convert("y", "scope", "world", "pos", 0, 0, 0)'  # the scope origin's height


def test_context_attributes_lower_to_context_refs():
    module = module_of(VERSION + 'Lot --> comp(f){ side : Side }\nSide --> report("i", comp.index) '
                       'report("n", comp.total) report("s", comp.sel == "left") split(x){ 1 : Part }*\n'
                       'Part --> report("p", split.index + split.total) Part.\n')
    refs = {e.name for r in module.rules for op in iter_ops(r.alternatives[0].body)
            if isinstance(op, ir.Report) for e in _exprs(op.value) if isinstance(e, ir.ContextRef)}
    assert refs == {"comp.index", "comp.total", "comp.sel", "split.index", "split.total"}


def _exprs(e):
    from grammarc.ir.traverse import iter_exprs

    return list(iter_exprs(e))



# ---------------------------------------------------------------------------------- geometry queries


def test_geometry_queries_with_and_without_parentheses_and_their_selectors():
    """A query is a call whether written as a member or with parentheses; a selector becomes its name
    as a string, a compass direction the world frame's face (north is the world's back, -z)."""
    body = body_of(VERSION + "Lot --> extrude(geometry.height + geometry.height() + geometry.area(top) "
                   "+ geometry.area(world.north) + geometry.angle(azimuth)) A\nA --> X.\n")
    for call in ("geometry.height()", 'geometry.area("top")', 'geometry.area("world.back")',
                 'geometry.angle("azimuth")'):
        assert call in body, body


@pytest.mark.parametrize("line, message", [
    ("Lot --> case geometry.isConcav : A else : B",
     "unknown function `geometry.isConcav` (did you mean `geometry.isConcave`?)"),
    ("Lot --> extrude(geometry.isPlanar) A", "`geometry.isPlanar` takes 1 argument, got 0"),
    ("Lot --> extrude(geometry.nEdges(2)) A", "`geometry.nEdges` takes 0 arguments, got 1"),
])
def test_unknown_queries_and_their_arguments_are_named(line, message):
    assert [m for _, _, m in errors(VERSION + line + "\nA --> X.\nB --> X.\n")] == [message]


# ------------------------------------------------------------------------------------ the unsupported


@pytest.mark.parametrize("line, name, at", [
    ("Lot --> case inside(near) : A else : B", "inside with these arguments", "inside"),
    ("Lot --> case touches(sel(1, 2)) : A else : B", "touches with these arguments", "touches"),
    ("Lot --> extrude(minimumDistance(intra)) A", "minimumDistance with these arguments", "minimumDistance"),
    ("Lot --> extrude(initialShape.origin.qx) A", "initialShape.origin.qx", "initialShape"),
    ("Lot --> extrude(geometry.du(0, area)) A", "geometry.du in this space", "geometry"),
    ("Lot --> extrude(geometry.area(north)) A", "geometry.area selector `north`", "north"),
    ('Lot --> case geometry.hasTags("roof") : A else : B', "geometry.hasTags()", "geometry"),
    ("Lot --> extrude(size(geometry.materials())) A", "geometry.materials()", "geometry"),
    ("Lot --> F([3, 4])\nF(h) --> extrude(h[0])", "an array as argument 1 of `F`", "["),
    ('Lot --> report("h", [3, 4])', "an array as a reported value", "["),
])
def test_unsupported_construct_is_named_at_its_span(line, name, at):
    assert_unsupported_at(line, name, at)


def test_the_unsupported_fixture_reports_every_construct_once():
    """``unsupported.cga``: each line marked ``//! NAME`` gives exactly one error, ``unsupported: NAME``,
    on that line and nowhere else; no line is skipped."""
    text = (GRAMMARS / "unsupported.cga").read_text()
    want = {}
    for number, line in enumerate(text.splitlines(), start=1):
        if "//!" in line:
            want[number] = line.split("//!")[1].strip()
    found = errors(text)
    assert sorted(line for line, _, _ in found) == sorted(want), found
    for line, _, message in found:
        assert message.startswith(f"unsupported: {want[line]}"), (line, message)



# -------------------------------------------------------------------------------------------- fixture


def test_building_fixture_lowers_every_construct():
    grammar = compile_grammar(GRAMMARS / "building.cga")
    module = grammar.module
    assert module.dialect == "cityengine" and module.start == "Lot"
    assert [w.code for w in grammar.warnings] == ["asset"]  # assets/window.obj is not shipped
    ops = {type(op) for r in module.rules for alt in r.alternatives for op in iter_ops(alt.body)}
    assert ops >= {ir.Extrude, ir.CompFaces, ir.GroupSplit, ir.Case, ir.Stochastic, ir.SetAttr, ir.Report,
                   ir.UseAsset, ir.NotApplied, ir.Center, ir.Translate, ir.Scale, ir.Empty, ir.Symbol,
                   ir.SetupProjection, ir.ProjectUV}
    consts = [a.name for a in module.attrs if a.const]
    assert consts == ["window_asset", "floor_h", "tile_w"]
    height = next(a for a in module.attrs if a.name == "height")
    assert ("Range", ("min=3", "max=30", "restricted=false")) in height.annotations
    assert grammar.assets == ("builtin:cube", "builtin:quad", "assets/window.obj")
    assert make_plan(grammar).not_applied == ("print",)


# ------------------------------------------------------------------------------ the free syntax (issue 17)


def test_a_case_block_in_brackets_ends_at_the_bracket():
    # ESRI.lib's streets: `[ case type == "MAJOR" : ... else : ... ]` then more operations
    text = VERSION + """attr type = "MAJOR"
Lot -->
  	[ extrude(3) A ]
	[ case type == "MAJOR":
		t(0, 1, 0) B
	  else:
		C ]
	[ 30% : D else : E ] F
"""
    assert body_of(text) == ('[ extrude(3) A ] [ { case (@type == "MAJOR"): T(0, 1, 0) B else: C } ] '
                             "[ { % 30: D else: E } ] F")
    assert errors(VERSION + "Lot --> [ A B\n") and errors(VERSION + "Lot --> A ] B\n")


def test_a_split_group_without_star_is_its_parts_in_place():
    # the Swiss building rules: `split(x){ {~0.5 : Wall} | ~0.8 : Door | {~0.5 : Wall} }`
    text = VERSION + "Lot --> split(x){ {~0.5 : W} | ~0.8 : D | { ~3 : T | 1 : S }* | {~0.5 : W | 2 : V} }\n"
    assert body_of(text) == "split(x){ ~0.5: W | ~0.8: D | { ~3: T | 1: S }* | ~0.5: W | 2: V }"


def test_edge_distances_may_be_numbers_and_a_number_elsewhere_is_an_error():
    text = VERSION + "Lot --> setback(comp(fe){ street.front : 3 | street.back = 1.5 }){ all : A | remainder : B }\n"
    assert body_of(text) == "setback(comp(fe){ street.front=3, street.back=1.5 }){ all: A | remainder: B }"
    assert errors(VERSION + "Lot --> split(x){ 2 : 3 | ~1 : A }\nB --> comp(f){ front : 4 }\n") == [
        (2, 23, "a number where operations are expected"), (3, 24, "a number where operations are expected")]


def test_edge_distances_as_a_constant_are_the_distances_of_the_setbacks_that_name_it():
    """The Swiss building rules keep ``const d = comp(fe){ ... }`` and write ``setback(d){ ... }``: the
    constant's distances are constants ``d{k:selector}``, the setback's per edge."""
    module, diags = compile_ir(VERSION + "const a = 4\nconst d = comp(fe){ street.front : a | street.back = 1 }\n"
                              "Lot --> setback(d){ all = A | remainder : B }\n")
    assert not diags.has_errors and [d.code for d in diags] == ["merged", "start-rule"]  # all=, not street.back=
    assert [a.name for a in module.attrs] == ["a", "d{0:street.front}", "d{1:street.back}"]
    assert print_body(module.rules[0].alternatives[0].body) == (
        "setback(comp(fe){ street.front=@d{0:street.front}, street.back=@d{1:street.back} }){ all: A | remainder: B }")
    assert_unsupported_at("attr d = comp(fe){ street.front : a | street.back = b }", "comp(fe){...} outside "
                          "setback", "comp")


def test_annotation_arguments_are_kept_as_written():
    module, diags = compile_ir(VERSION + """
@Description("post width (and depth)") @Order(6)#@Range(0,6)
attr w = 1
@Handle(shape=Post*^2, axis = y) @Range(min = 0, max=f(1, 2), restricted=false) @Enum("a, b", [1, 2])
attr h = 2
@Frobnicate(3)
attr k = 3
@StartRule
Lot --> A
""")
    notes = {a.name: a.annotations for a in module.attrs}
    assert notes == {
        "w": (("Description", ('"post width (and depth)"',)), ("Order", ("6",))),
        "h": (("Handle", ("shape=Post*^2", "axis=y")), ("Range", ("min=0", "max=f(1, 2)", "restricted=false")),
              ("Enum", ('"a, b"', "[1, 2]"))),
        "k": (("Frobnicate", ("3",)),),
    }
    # CityEngine warns of an annotation it does not know, and goes on
    assert [(d.code, d.span.line, d.message) for d in diags] == [
        ("annotation", 7, "unknown annotation `@Frobnicate`: kept, but nothing reads it")]


def test_case_and_stochastic_expressions_as_arguments():
    text = VERSION + """attr h = 14
Lot --> extrude(case h > 10 : h else : 10) set(material.color.r, case h > 1 : 0.5 else : 1) # not applied
    s('1, (case h > 12 : 1 else : 0.8) * scope.sy, '1) A(30% : 1 else : 2)
A(x) --> X.
"""
    assert body_of(text) == ("extrude(((@h > 10) ? @h : 10)) "
                             "color(((@h > 1) ? 0.5 : 1), material.color.g, material.color.b) "
                             "S(1r, (((@h > 12) ? 1 : 0.8) * Scope.sy), 1r) A((p(0.3) ? 1 : 2))")


def test_value_case_needs_else():
    # the reference writes every value case with its else; without one there is no value
    assert errors(VERSION + "attr h = case 1 > 0 : 2\nLot --> A\n")[0][2].startswith("unexpected end")


def test_case_block_without_else_gives_no_successor():
    text = VERSION + "Lot -->\n    case scope.sx > 10 : Big\n    case scope.sx > 5 : Wide\n"
    case = module_of(text).rules[0].alternatives[0].body[0]
    assert isinstance(case, ir.Case) and len(case.branches) == 2 and case.default == ()


def test_leaf_of_a_rule_with_parameters():
    text = VERSION + "Lot --> extrude(2) Facade. Facade(3)\nFacade(n) --> s(n, '1, '1) F.\n"
    body = module_of(text).rules[0].alternatives[0].body
    leaf, call = body[1], body[2]
    assert (leaf.name, leaf.args, leaf.leaf) == ("Facade", (), True)
    assert (call.name, len(call.args), call.leaf) == ("Facade", 1, False)


def test_typed_parameters_of_rules_and_functions():
    text = VERSION + """half(float x) = x / 2
label(string s, bool b) = case b : s else : "no"
Lot --> A(2, "x", true, 1)
A(float h, string s, bool b, float[] a) --> extrude(half(h)) print(label(s, b)) B.
"""
    assert rules(text)["A"].startswith("A(h, s, b, a) ~> extrude(($h / 2))")


def test_scatter_with_operations_in_braces_lowers_with_its_body():
    assert body_of(VERSION + "Lot --> extrude(3) scatter(surface, 10, uniform) { s(1, 1, 1) Tree } A\n") == (
        "extrude(3) scatter(surface, 10, uniform){ S(1, 1, 1) Tree } A")


def test_occlusion_targets_and_labels_may_be_computed():
    """``inside(sel(text), label)``: ``sel`` makes the target of a string, a constant one is the keyword;
    the label is any string."""
    module = module_of(VERSION + 'attr where = "intra"\nattr seek = "k"\n'
                       'Lot --> case inside(sel(where), seek) || overlaps(sel("inter"), "k" + seek) : A else : B\n')
    [case] = [op for op in iter_ops(module.rules[0].alternatives[0].body) if isinstance(op, ir.Case)]
    assert print_expr(case.branches[0][0]) == '(inside(sel(@where), @seek) || overlaps(inter, ("k" + @seek)))'
    assert errors(VERSION + "Lot --> case touches(all, 3) : A else : B\n") == [
        (2, 27, "an occlusion label must be a str, got a num")]


def test_minimum_distance_is_a_number_with_a_target_and_a_label():
    module = module_of(VERSION + 'attr seek = "k"\nLot --> extrude(minimumDistance(sel("in" + "tra"), seek) + 1) A\n')
    [extrude] = [op for op in iter_ops(module.rules[0].alternatives[0].body) if isinstance(op, ir.Extrude)]
    assert print_expr(extrude.height) == '(minimumDistance(sel(("in" + "tra")), @seek) + 1)'
    assert errors(VERSION + 'Lot --> case minimumDistance(all, "k") : A else : B\n') == [
        (2, 14, "a case condition must be a bool, got a num")]
