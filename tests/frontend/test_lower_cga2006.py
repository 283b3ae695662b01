"""frontend/lower_cga2006.py: operations, their arities and the constructs that are not supported yet.

Each case is a one-rule grammar and the exact errors (line, column, message) that lowering and the IR
passes report for it: no error may hide another, and none may cascade from one already reported.
"""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics, render
from grammarc.frontend.parse import parse_source
from grammarc.ir.pipeline import run_passes

FILE = "g.cga"


def diagnose(text: str) -> Diagnostics:
    diags = Diagnostics()
    run_passes(parse_source(text, FILE, diags), diags, check=True)
    return diags


def errors(text: str) -> list[tuple[int, int, str]]:
    return sorted((d.span.line, d.span.col, d.message) for d in diagnose(text) if d.is_error)


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
    # arities of operations
    ("a ~> T(1, 2)", [(1, 6, "`T` takes 3 arguments, got 2")]),
    ("a ~> S(1, 2, 3, 4)", [(1, 6, "`S` takes 3 arguments, got 4")]),
    ("a ~> R(1, 2)", [(1, 6, "`R` takes 3 arguments, got 2")]),
    ("a ~> Rx(1, 2)", [(1, 6, "`Rx` takes 1 argument, got 2")]),
    ('a ~> I("cube", 2)', [(1, 6, "`I` takes 1 argument, got 2")]),
    ("a ~> I(cube)", [(1, 8, "`I` expects an asset name as a string literal")]),
    ("a ~> floor(1, 2)", []),  # a successor symbol, not the function: it has no rule, see the warning test
    ("a ~> T(floor(1, 2), 0, 0)", [(1, 8, "`floor` takes 1 argument, got 2")]),
    ("a ~> T(rand(1, 2, 3), 0, 0)", [(1, 8, "`rand` takes 0 to 2 arguments, got 3")]),
    # splits
    ('a ~> Subdiv("Y", 1, 2){ b }', [(1, 6, "`Subdiv` has 2 parts but 1 successor in its body")]),
    ('a ~> Subdiv("Y", 1){ b | c }', [(1, 6, "`Subdiv` has 1 parts but 2 successors in its body")]),
    ('a ~> Subdiv("XY", 1, 2){ b | c }', [(1, 6, "`Subdiv` has 4 cells but 2 successors in its body")]),
    ('a ~> Subdiv("Y"){ b }', [(1, 6, "`Subdiv` takes an axis and at least one size, got 1 argument")]),
    ('a ~> Subdiv("Y", 1)', [(1, 6, "`Subdiv` needs a body `{ A | B | ... }`")]),
    ('a ~> Repeat("XY", 1){ b }', [(1, 6, '`Repeat("XY", ...)` takes 2 sizes, got 1')]),
    ('a ~> Repeat("X", 1, 2){ b }', [(1, 6, '`Repeat("X", ...)` takes 1 size, got 2')]),
    ('a ~> Repeat("X"){ b }', [(1, 6, "`Repeat` takes an axis and a size per axis, got 1 argument")]),
    ('a ~> Repeat("X", 1r){ b }', [(1, 18, "a relative size like `1r` is only allowed in `S` and `Subdiv`")]),
    ('a ~> Subdiv("Q", 1){ b }',
     [(1, 13, 'unknown split axis "Q", expected one of X, Y, Z, XY, XZ, YZ, XYZ, XS, YS, ZS')]),
    ("a ~> Subdiv(Y, 1){ b }", [(1, 13, "`Subdiv` expects an axis as a string literal")]),
    ("a ~> T(1, 2, 3){ b }", [(1, 6, "`T` takes no `{...}` body")]),
    # component splits
    ('a ~> Comp("edge"){ b }', [(1, 6, '`Comp("edge")` takes 2 arguments, got 1')]),
    ('a ~> Comp("faces", 2){ b }', [(1, 6, '`Comp("faces")` takes 1 argument, got 2')]),
    ('a ~> Comp("facez"){ b }', [(1, 11, 'unknown component type "facez" (did you mean `face`?)')]),
    ('a ~> Comp("wibble"){ b }', [(1, 11, 'unknown component type "wibble"')]),
    ("a ~> Comp(){ b }", [(1, 6, "`Comp` takes a component type, got no arguments")]),
    ('a ~> Comp("edge", "x"){ b }', [(1, 19, 'a component index must be a num, got a str')]),
    # relative sizes are for S and Subdiv only
    ("a ~> T(1r, 0, 0)", [(1, 8, "a relative size like `1r` is only allowed in `S` and `Subdiv`")]),
    ("a ~> R(0, 0.5r, 0)", [(1, 11, "a relative size like `1r` is only allowed in `S` and `Subdiv`")]),
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


def test_snap_shapes_and_snapped_splits_lower_as_the_paper_writes_them():
    from grammarc.ir import nodes as ir
    from grammarc.ir.printer import print_op

    module = run_passes(parse_source(
        'a ~> Repeat("YS", 3){ b Snap("XZ") }\n'
        'b ~> Subdiv("XS", 1r, 2, 7r, "tilesnap"){ c | d SnapLines("Y", "entrancesnap") | c }\n',
        FILE, Diagnostics()), Diagnostics(), check=True)
    repeat = module.rules[0].alternatives[0].body[0]
    split = module.rules[1].alternatives[0].body[0]
    assert isinstance(repeat, ir.Repeat) and repeat.snap and repeat.snap_label is None
    assert split.snap and split.snap_label == "tilesnap" and len(split.sizes) == 3
    assert print_op(repeat) == 'Repeat("YS", 3){ b Snap("XZ") }'
    assert print_op(split.parts[1][1]) == 'SnapLines("Y", "entrancesnap")'


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


@pytest.mark.parametrize("text, expected", [
    ('a : Shape.occ(1) == "none" ~> b', [(1, 5, ('`Shape.occ` takes "all", "active", "noparent" or a label, '
                                               'and optionally "distance" and a distance'))]),
    ('a ~> b Snap("W")', [(1, 13, 'unknown snap axes "W", expected one of XZ, ZX, XY, YX, YZ, ZY, X, Y, Z')]),
    ('a ~> b Snap("X", "a", "b")', [(1, 8, "`Snap` takes 1 or 2 arguments, got 3")]),
    ('a ~> b SnapLines(3)', [(1, 18, "`SnapLines` expects the axes of its plane as a string literal")]),
    ('a ~> Repeat("WS", 2){ b }', [(1, 13, ('unknown split axis "WS", expected one of X, Y, Z, XY, XZ, YZ, XYZ, '
                                           'XS, YS, ZS'))]),
])
def test_snap_errors(text, expected):
    assert errors(text) == expected


def test_errors_inside_nested_bodies_are_found():
    text = 'a ~> Subdiv("Y", 1, 1r){ Subdiv("X", 1r){ Subdv("Z", 1){ c } } | Comp("edge"){ d } }'
    assert errors(text) == [
        (1, 43, "unknown operation `Subdv` (did you mean `Subdiv`?)"),
        (1, 66, '`Comp("edge")` takes 2 arguments, got 1'),
    ]


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
