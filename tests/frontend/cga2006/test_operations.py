"""frontend/cga2006/operations.py: the paper's operations, their arities, bodies, axes and components.

Accepted operations are checked as one-liners, grammar text -> canonical IR text after all passes; errors
as the exact (line, column, message) that lowering and the IR passes report.
"""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.cga2006.operations import OPERATIONS, PART_OPERATIONS
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes

from .lowered import FILE, errors, rules


@pytest.mark.parametrize("text, expected", [
    # scope rules
    ("a ~> T(0,0,6) S(8,10,18) R(0,90,0)", "a ~> T(0, 0, 6) S(8, 10, 18) R(0, 90, 0) : 1"),
    ("a ~> Rx(10) Ry(20) Rz(30)", "a ~> R(10, 0, 0) R(0, 20, 0) R(0, 0, 30) : 1"),
    ("a ~> S(1r, 0.5r, 2)", "a ~> S(1r, 0.5r, 2) : 1"),
    ('a ~> I("cube") I("win.obj")', 'a ~> I("cube") I("win.obj") : 1'),
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
])
def test_operations_lower(text, expected):
    assert rules(text) == [expected]


@pytest.mark.parametrize("text, expected", [
    # arities of operations
    ("a ~> T(1, 2)", [(1, 6, "`T` takes 3 arguments, got 2")]),
    ("a ~> S(1, 2, 3, 4)", [(1, 6, "`S` takes 3 arguments, got 4")]),
    ("a ~> R(1, 2)", [(1, 6, "`R` takes 3 arguments, got 2")]),
    ("a ~> Rx(1, 2)", [(1, 6, "`Rx` takes 1 argument, got 2")]),
    ('a ~> I("cube", 2)', [(1, 6, "`I` takes 1 argument, got 2")]),
    ("a ~> I(cube)", [(1, 8, "`I` expects an asset name as a string literal")]),
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
])
def test_operation_errors(text, expected):
    assert errors(text) == expected


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


# ---------------------------------------------------------------------------------------------- the tables


def test_each_operation_name_is_in_one_table():
    assert not OPERATIONS.keys() & PART_OPERATIONS.keys()


def test_a_body_after_an_operation_without_parts_is_an_error_and_the_operation_stays():
    diags = Diagnostics()
    module = run_passes(parse_source("a ~> T(1, 2, 3){ b } c", FILE, diags), diags)
    assert [d.message for d in diags if d.is_error] == ["`T` takes no `{...}` body"]
    assert [type(op) for op in module.rules[0].alternatives[0].body] == [ir.Translate, ir.Symbol]
