"""frontend/lower_cityengine.py with grammars/cityengine.lark: CityEngine CGA to IR.

Accepted constructs are checked as grammar text -> canonical IR text after all passes (``$p`` parameters,
``@name`` attributes, binaries parenthesized), or by the IR nodes they make; what grammarc does not
implement must come out as ``unsupported: NAME`` at its span, never be skipped. The grammars are written
the way public CityEngine rule files use the features.
"""

from __future__ import annotations

import re
import signal
from pathlib import Path

import pytest

from grammarc.backend.attributes import check_overrides
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.diagnostics import Diagnostics, render_all
from grammarc.errors import GrammarError, UsageError
from grammarc.frontend.parse import detect_dialect, parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_expr, print_rule
from grammarc.ir.traverse import iter_ops

FILE = "g.cga"
GRAMMARS = Path(__file__).parent / "grammars" / "cityengine"
VERSION = 'version "2022.0"\n'


def compile_ir(text: str) -> tuple[ir.Module, Diagnostics]:
    """Lower and run the passes with the IR verified after each (CityEngine dialect)."""
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True)
    return module, diags


def module_of(text: str) -> ir.Module:
    module, diags = compile_ir(text)
    assert not diags.has_errors, render_all(diags, {FILE: text})
    return module


def rules(text: str) -> dict[str, str]:
    """Symbol -> printed rule, for a grammar without errors."""
    return {r.symbol: print_rule(r) for r in module_of(text).rules}


def body_of(text: str, symbol: str = "Lot") -> str:
    """The printed body of ``symbol``'s rule (between the arrow and the probability)."""
    printed = rules(text)[symbol]
    return printed.split(" ~> ", 1)[1].removesuffix(" : 1")


def errors(text: str) -> list[tuple[int, int, str]]:
    """(line, col, message) of every error, lowering and passes."""
    diags = Diagnostics()
    run_passes(parse_source(text, FILE, diags, "cityengine"), diags)
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


# ------------------------------------------------------------------------------------ every construct


@pytest.mark.parametrize("body, printed", [
    ("extrude(10) Mass", "extrude(10) Mass"),
    ("extrude(h * 2)", "extrude((@h * 2))"),
    ("t(1, 2, 3) A", "T(1, 2, 3) A"),
    ("t('0.5, 0, '-1) A", "T((0.5 * Scope.sx), 0, (-1 * Scope.sz)) A"),
    ("s('1, '0.5, 2) A", "S(1r, 0.5r, 2) A"),
    ("s(scope.sx - 1, 3, '1) A", "S((Scope.sx - 1), 3, 1r) A"),
    ("r(0, 90, 0) A", "R(0, 90, 0) A"),
    ("[ t(0, 3, 0) A ] B", "[ T(0, 3, 0) A ] B"),
    ("NIL", "\u03b5"),
    ("A.", "A."),
    ("A. B", "A. B"),
    ('i("builtin:cube")', 'i("builtin:cube")'),
    ("primitiveCube()", 'i("builtin:cube")'),
    ("primitiveCube", 'i("builtin:cube")'),
    ("center(xz) A", "center(xz) A"),
    ("center(x) A", "center(x) A"),
    ("alignScopeToAxes() A", "alignScopeToAxes() A"),
    ("alignScopeToAxes(world.xyz) A", "alignScopeToAxes() A"),
    ("alignScopeToAxes(y) A", "alignScopeToAxes(y) A"),
    ("rotateScope(0, 90, 0) A", "rotateScope(0, 90, 0) A"),
    ("set(h, h + 1) A", "set(h, (@h + 1)) A"),
    ('report("area", geometry.area) A', 'report("area", geometry.area()) A'),
    ('report("volume", geometry.volume()) A', 'report("volume", geometry.volume()) A'),
    ("split(z){ 1 : A | ~1 : B }", "split(z){ 1: A | ~1: B }"),
    ("comp(f){ front : A | side : B. | top : NIL }", "comp(f){ front: A | side: B. | top: \u03b5 }"),
    ('color("#ff0000") A', 'color("#ff0000") A'),
    ("color(1, 0.5, 0) A", "color(1, 0.5, 0) A"),
    ('texture("brick.jpg") A', "texture(...) A"),
    ("setupProjection(0, scope.xy, ~1.5, ~1) projectUV(0) A", "setupProjection(...) projectUV(...) A"),
    ('print("h = " + h) A', "print(...) A"),
    ("set(material.color.r, 1) A", "set(material.color.r)(...) A"),
    ("set(trim.vertical, false) A", "set(trim.vertical, false) A"),
    ("set(trim.horizontal, false) A", "set(trim.horizontal)(...) A"),
    ("extrude(rint(scope.sx)) A", "extrude(round(Scope.sx)) A"),
    ("extrude(ln(scope.sx)) A", "extrude(log(Scope.sx)) A"),
    ("extrude(rand(2, 4)) A", "extrude(rand(2, 4)) A"),
    ("cleanupGeometry(all, 0.1) A", "cleanupGeometry(all, 0.1) A"),
    ("cleanupGeometry(faces, h / 10) A", "cleanupGeometry(faces, (@h / 10)) A"),
    ('report("k", scope.sx > 1 && !(scope.sz < 2) || h == 3) A',
     'report("k", (((Scope.sx > 1) && !(Scope.sz < 2)) || (@h == 3))) A'),
])
def test_operations_lower(body, printed):
    assert body_of(f"{VERSION}attr h = 3\nLot --> {body}\n") == printed


def test_operations_lower_to_their_nodes():
    module = module_of(VERSION + 'Lot --> extrude(3) center(x) alignScopeToAxes() i("builtin:cube") '
                       'color("#fff") set(h, 2) report("k", 1) comp(f){ all : A } \nattr h = 1\n')
    ops = list(iter_ops(module.rules[0].alternatives[0].body))
    assert [type(op) for op in ops] == [ir.Extrude, ir.Center, ir.AlignScope, ir.UseAsset, ir.SetColor,
                                        ir.SetAttr, ir.Report, ir.CompFaces, ir.Symbol]
    assert ops[7].selectors == ("all",)


def test_not_applied_operations_are_listed_for_the_meta(tmp_path):
    path = tmp_path / "g.cga"
    path.write_text(VERSION + 'Lot --> color(1, 0, 0) extrude(3) texture("a.jpg") tileUV(0, 1, 1) '
                    'print(scope.sx) set(material.opacity, 0.5) Mass.\n')
    assert make_plan(compile_grammar(path)).not_applied == (
        "print", "set(material.opacity)", "texture", "tileUV")


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


def test_start_rule_annotation_picks_the_start():
    module = module_of(VERSION + "Helper --> A\n@StartRule\nLot --> Helper\n@StartRule\nOther --> A\n")
    assert module.start == "Lot"


def test_without_start_rule_the_first_rule_starts():
    assert module_of(VERSION + "Helper --> A\nLot --> Helper\n").start == "Helper"


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


def test_functions_with_parameters_are_inlined():
    text = VERSION + """attr h = 10
window_w(w) = case w > 3 : w * 0.6 else : w * 0.5
half(x) = x / 2
Lot --> extrude(half(h)) s(window_w(scope.sx), '1, '1) A
"""
    assert body_of(text) == ("extrude((@h / 2)) S(((Scope.sx > 3) ? (Scope.sx * 0.6) : (Scope.sx * 0.5)), "
                             "1r, 1r) A")


def test_zero_argument_functions_are_inlined_where_named():
    text = VERSION + "attr a = 2\nattr b = 3\ntileW = a + b\nfloors = tileW * 2\nLot --> extrude(floors) A\n"
    assert body_of(text) == "extrude(((@a + @b) * 2)) A"


def test_functions_call_functions_and_rules_pass_parameters():
    text = VERSION + ("twice(x) = x * 2\nquad(x) = twice(twice(x))\n"
                      "Lot --> A(3)\nA(n) --> extrude(quad(n + 1))\n")
    assert body_of(text, "A") == "extrude(((($n + 1) * 2) * 2))"


def test_a_function_sees_attributes_not_the_parameters_of_the_rule_that_calls_it():
    """A function body's names are its parameters and the attributes (CityEngine scopes them so), even
    when the calling rule has a parameter of the same name."""
    text = VERSION + ("attr h = 5\ntall = h * 2\nplus(x) = x + h\n"
                      "Lot --> A(1)\nA(h) --> extrude(tall) s(plus(h), 1, 1)\n")
    module = module_of(text)
    assert print_rule(module.rules[1]) == "A(h) ~> extrude((@h * 2)) S(($h + @h), 1, 1) : 1"


def test_an_argument_named_like_a_function_stays_the_callers_parameter():
    text = VERSION + "w = 3\ntwice(x) = x * 2\nLot --> A(1)\nA(w) --> extrude(twice(w))\n"
    assert body_of(text, "A") == "extrude(($w * 2))"


def _alarm(signum, frame):
    raise TimeoutError("lowering did not finish")


@pytest.mark.parametrize("functions", [
    "fib(n) = fib(n - 1) + 1\n",
    "fib(n) = case n < 2 : n else : fib(n - 1) + fib(n - 2)\n",
    ("even(n) = case n == 0 : true else : odd(n - 1)\nodd(n) = case n == 0 : false else : even(n - 1)\n"
     "fib(n) = case even(n) : 1 else : 2\n"),
])
def test_recursive_function_is_unsupported(functions):
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(10)
    try:
        found = errors(VERSION + functions + "Lot --> extrude(fib(5)) A\n")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    assert found, "a recursive function must be an error"
    assert all(m.startswith("unsupported: recursive function") for _, _, m in found), found
    assert len(found) <= 2  # reported where it recurses, not once per expansion


def test_unknown_function_and_wrong_arity_are_errors():
    text = VERSION + "half(x) = x / 2\nLot --> extrude(halve(4)) s(half(1, 2), 1, 1) A\n"
    assert errors(text) == [(3, 17, "unknown function `halve` (did you mean `half`?)"),
                            (3, 29, "`half` takes 1 arguments, got 2")]


def test_functions_of_an_imported_file_see_its_attributes(tmp_path):
    """An imported file's functions read its attributes under its prefix, or the importer's attribute of
    the same name (forwarding), as its rules do."""
    (tmp_path / "facade.cga").write_text(VERSION + "attr depth = 7\nattr width = 2\nthick = depth / 2\n"
                                         "wide = width * 3\nFacade --> extrude(thick) s(wide, '1, '1) X\n")
    (tmp_path / "main.cga").write_text(VERSION + 'import f : "facade.cga"\nattr width = 5\n'
                                       "Lot --> extrude(width) f.Facade\n")
    # not compile_grammar: the strict IR check refuses spans from imported files for now
    diags = Diagnostics()
    main = tmp_path / "main.cga"
    module = run_passes(parse_source(main.read_text(), str(main), diags, path=main), diags, check=False)
    assert not diags.has_errors, diags
    assert [a.name for a in module.attrs] == ["width", "f.depth"]
    assert [print_rule(r) for r in module.rules] == [
        "Lot ~> extrude(@width) f.Facade : 1",
        "f.Facade ~> extrude((@f.depth / 2)) S((@width * 3), 1r, 1r) f.X : 1"]


def test_rules_overloaded_by_arity_get_one_symbol_each():
    text = VERSION + """Lot --> Pipe(2)
Pipe(a) --> Pipe(a, 1, 2)
Pipe(a, b, c) --> s(a, b, c) Pipe.
Single(x) --> A
"""
    printed = rules(text)
    assert printed == {
        "Lot": "Lot ~> Pipe/1(2) : 1",
        "Pipe/1": "Pipe/1(a) ~> Pipe/3($a, 1, 2) : 1",
        "Pipe/3": "Pipe/3(a, b, c) ~> S($a, $b, $c) Pipe. : 1",
        "Single": "Single(x) ~> A : 1",
    }


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
    # one draw per shape, compared with the cumulative shares
    roof = module.attrs[3].default
    assert print_expr(roof) == '((rand() < 0.3) ? "flat" : ((rand() < 0.5) ? "gable" : "hip"))'
    assert roof.cond.left.site == roof.other.cond.left.site
    assert {a.name: a.type for a in module.attrs}["roof"] is ir.Type.STR


def test_string_concatenation():
    module = module_of(VERSION + 'attr level = 2\nattr name = "floor_" + str(level) + ".obj"\n'
                       'Lot --> report("level " + level, 1) A\n')
    assert print_expr(module.attrs[1].default) == '(("floor_" + str(@level)) + ".obj")'
    assert module.attrs[1].type is ir.Type.STR


# ------------------------------------------------------------------------------------- split and comp


def test_split_sizes_and_repeat_groups():
    text = VERSION + ("Floor --> split(x){ 0.5 : Wall | { ~3 : Tile | 1 : Pillar }* | '0.1 : Wall"
                      " | { ~2 : Tile }* | 0.5 : Wall }\n")
    op = module_of(text).rules[0].alternatives[0].body[0]
    assert isinstance(op, ir.GroupSplit) and op.axis == 0 and not op.repeat
    K = ir.SizeKind
    assert [(s.kind, print_expr(s.value)) for s in op.sizes] == [
        (K.ABSOLUTE, "0.5"), (K.FLOATING, "3"), (K.ABSOLUTE, "1"), (K.RELATIVE, "0.1"), (K.FLOATING, "2"),
        (K.ABSOLUTE, "0.5")]
    assert op.groups == (-1, 0, 0, -1, 1, -1)
    assert [[s.name for s in p] for p in op.parts] == [["Wall"], ["Tile"], ["Pillar"], ["Wall"], ["Tile"],
                                                       ["Wall"]]


def test_whole_split_repeat_and_nested_splits():
    op = module_of(VERSION + "Facade --> split(y){ ~3.5 : split(x){ { ~2 : Tile }* } | 0.2 : Ledge }*\n") \
        .rules[0].alternatives[0].body[0]
    assert op.axis == 1 and op.repeat and op.groups == (-1, -1)
    inner = op.parts[0][0]
    assert isinstance(inner, ir.GroupSplit) and inner.axis == 0 and inner.groups == (0,)


def test_split_parts_take_operation_sequences():
    assert body_of(VERSION + "Lot --> split(z){ 2 : t(0, 1, 0) s('1, 2, '1) A | ~1 : [ B ] C. }\n") \
        == "split(z){ 2: T(0, 1, 0) S(1r, 2, 1r) A | ~1: [ B ] C. }"


@pytest.mark.parametrize("selectors", [
    ("front", "back", "left", "right", "top", "bottom"),
    ("side", "top"),
    ("vertical", "horizontal"),
    ("aslant", "nutant", "all"),
])
def test_comp_faces_selectors(selectors):
    parts = " | ".join(f"{s} : {s.capitalize()}" for s in selectors)
    op = module_of(f"{VERSION}Mass --> comp(f){{ {parts} }}\n").rules[0].alternatives[0].body[0]
    assert isinstance(op, ir.CompFaces)
    assert op.selectors == selectors
    assert [p[0].name for p in op.parts] == [s.capitalize() for s in selectors]


def test_shape_u_moves_front_right_and_left_edges_into_its_shape_part():
    op = module_of(f"{VERSION}Lot --> shapeU(5, 3, 11){{ shape : A | remainder = B }}\n"
                   ).rules[0].alternatives[0].body[0]
    assert isinstance(op, ir.Setback)
    assert [s for s, _ in op.distances] == ["front", "right", "left"]
    assert [d.value for _, d in op.distances] == [5, 3, 11]
    assert op.selectors == ("all", "remainder")


def test_setback_moves_the_edges_its_parts_select():
    op = module_of(f"{VERSION}Lot --> setback(4){{ front : A | left : B | remainder : C }}\n"
                   ).rules[0].alternatives[0].body[0]
    assert [s for s, _ in op.distances] == ["front", "left"]
    assert op.selectors == ("front", "left", "remainder")


@pytest.mark.parametrize("line, at, message", [
    ("Lot --> cleanupGeometry(vertex, 0) A", "vertex",
     "`cleanupGeometry` cleans up all, edges, faces, vertices, got `vertex` (did you mean `vertices`?)"),
    ('Lot --> cleanupGeometry("all", 0) A', '"all"',
     "`cleanupGeometry` cleans up all, edges, faces, vertices, got a string"),
    ("Lot --> cleanupGeometry(all) A", "cleanupGeometry", "`cleanupGeometry` takes 2 arguments, got 1"),
    ("Lot --> cleanupGeometry(all, 0, 1) A", "cleanupGeometry", "`cleanupGeometry` takes 2 arguments, got 3"),
])
def test_cleanup_geometry_names_a_wrong_component_or_argument_count_at_its_line(line, at, message):
    assert errors(VERSION + line + "\n") == [(2, line.index(at) + 1, message)]


# ------------------------------------------------------------------------------------ the unsupported


@pytest.mark.parametrize("line, name, at", [
    ("Lot --> offset(-2) Inner", "offset(d) without comp(f){ inside | border } after it", "offset"),
    ("Lot --> offset(-2, outside) Inner", "offset with these arguments", "offset"),
    ("Lot --> setback(3){ street.top : Garden | remainder : Building }", "setback selector `street.top`",
     "street"),
    ("Lot --> setback(3) Garden", "setback without selector parts", "setback"),
    ("Lot --> setback(3){ 2 : Garden }", "this setback selector", "2"),
    ("Lot --> roofGable(30, 1, 1, false, 2) Roof", "roofGable with an edge index", "2)"),
    ("Lot --> roofHip(30, 1, true) Roof", "roofHip with even ridges", "true"),
    ("Lot --> envelope(normal, 10, 45) Roof", "envelope with 3 arguments", "envelope"),
    ("Lot --> trim() Roof", "trim", "trim"),
    ("Lot --> case inside(near) : A else : B", "inside with these arguments", "inside"),
    ("Lot --> case touches(all, 3) : A else : B", "touches with these arguments", "touches"),
    ("Lot --> label(3) A", "label with these arguments", "label"),
    ("Lot --> shapeL(4, 4){ front : A | remainder : NIL }", "shapeL selector `front`", "front"),
    ("Lot --> innerRectangle(world){ shape : A | remainder : NIL }", "innerRectangle with these arguments",
     "innerRectangle"),
    ("Lot --> innerRectangle(scope){ front : A | remainder : NIL }", "innerRectangle selector `front`",
     "front"),
    ("Lot --> primitiveCylinder(16, 1, 2)", "primitiveCylinder", "primitiveCylinder"),
    ("Lot --> mirrorScope(true, false, false) A", "mirrorScope", "mirrorScope"),
    ("Lot --> taper(4) A", "taper", "taper"),
    ("Lot --> comp(x){ all : A }", "comp(x)", "comp"),
    ("Lot --> comp(f){ street.top : A }", "comp(f) selector `street.top`", "street"),
    ("Lot --> comp(f){ fornt : A }", "comp(f) selector `fornt`", "fornt"),
    ("Lot --> comp(e){ front : A }", "comp(e) selector `front`", "front"),
    ("Lot --> comp(f){ 0 : A }", "this comp selector", "0"),
    ("Lot --> comp(f){ { front : A }* }", "repeat group in comp", "{ front"),
    ("Lot --> comp(f){ front : A }*", "`*` after comp", "*"),
    ("Lot --> split(x, noAdjust){ 1 : A }*", "split(..., noAdjust)", "noAdjust"),
    ("Lot --> split(x){ 1 = A }", "`=` in split", "1 = A"),
    ("Lot --> split(x){ { 1 : A | { 2 : B }* }* }", "nested repeat groups", "{ 2"),
    ("Lot --> extrude(world.y, 10)", "extrude with 2 arguments", "extrude"),
    ("Lot --> i(\"a.obj\", yUp, keepSizeAndPosition)", "i with 3 arguments", "i("),
    ("Lot --> alignScopeToAxes(x) A", "alignScopeToAxes with this axis", "alignScopeToAxes"),
    ("Lot --> alignScopeToGeometry(xUp, 0) A", "alignScopeToGeometry with these arguments",
     "alignScopeToGeometry"),
    ("Lot --> alignScopeToGeometry(yUp, any, longest) A", "alignScopeToGeometry on a face other than 0",
     "any"),
    ("Lot --> r(scopeCenter, 0, 45, 0) A", "r with 4 arguments", "r("),
    ("Lot --> extrude(geometry.height) A", "geometry.height", "geometry"),
    ("Lot --> extrude(initialShape.startRule) A", "initialShape.startRule", "initialShape"),
    ("Lot --> extrude(geometry.du(0, unitSpace)) A", "geometry.du()", "geometry"),
    ("Lot --> extrude(heights[0]) A", "array indexing", "heights"),
    ("attr heights = [3, 4, 5]", "arrays", "["),
    ('import facade : "facade.cga" (Facade, Wall)', "import with a list of names", "import"),
])
def test_unsupported_construct_is_named_at_its_span(line, name, at):
    text = VERSION + line + "\nOther --> A\n"
    found = errors(text)
    col = line.index(at) + 1
    assert len(found) == 1, found
    got_line, got_col, message = found[0]
    assert (got_line, got_col) == (2, col), found
    assert re.fullmatch(rf"unsupported: {re.escape(name)}( \(.*\))?", message), message


@pytest.mark.parametrize("line, at", [
    ("Mass --> comp(f){ side= Wall }", "side"),
    ("Mass --> comp(f){ top : Roof | all= Rest }", "all="),
])
def test_merged_selector_is_derived_face_by_face_with_a_warning(line, at):
    module, diags = compile_ir(VERSION + line + "\n")
    assert not diags.has_errors
    assert [(d.code, d.span.line, d.span.col) for d in diags] == [("merged", 2, line.index(at) + 1)]
    assert isinstance(module.rules[0].alternatives[0].body[0], ir.CompFaces)


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


def test_syntax_errors_of_several_statements_are_all_reported():
    """``syntax_errors.cga``: one error per broken statement, the statements between them still lowered."""
    text = (GRAMMARS / "syntax_errors.cga").read_text()
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


# -------------------------------------------------------------------------------------------- fixture


def test_building_fixture_lowers_every_construct():
    grammar = compile_grammar(GRAMMARS / "building.cga")
    module = grammar.module
    assert module.dialect == "cityengine" and module.start == "Lot"
    assert [w.code for w in grammar.warnings] == ["asset"]  # assets/window.obj is not shipped
    ops = {type(op) for r in module.rules for alt in r.alternatives for op in iter_ops(alt.body)}
    assert ops >= {ir.Extrude, ir.CompFaces, ir.GroupSplit, ir.Case, ir.Stochastic, ir.SetAttr, ir.Report,
                   ir.UseAsset, ir.NotApplied, ir.Center, ir.Translate, ir.Scale, ir.Empty, ir.Symbol}
    consts = [a.name for a in module.attrs if a.const]
    assert consts == ["window_asset", "floor_h", "tile_w"]
    height = next(a for a in module.attrs if a.name == "height")
    assert ("Range", ("min=3", "max=30", "restricted=false")) in height.annotations
    assert grammar.assets == ("builtin:cube", "builtin:quad", "assets/window.obj")
    assert make_plan(grammar).not_applied == ("print", "projectUV", "setupProjection", "texture")
