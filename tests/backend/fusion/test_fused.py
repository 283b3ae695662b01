"""Deriving with fused kernels: the records, their order and the failures are the interpreter's
(``GRAMMARC_FUSION=off``), where fused and interpreted symbols meet, where kernels decline a batch, and at
the shape limit."""

from __future__ import annotations

import os
from dataclasses import fields, replace

import numpy as np
import pytest
from conftest import make_lots

from grammarc.backend import execute
from grammarc.backend.fusion import codegen, compiled
from grammarc.backend.fusion.fused import derive as derive_fused
from grammarc.backend.fusion.fused import preload
from grammarc.backend.fusion.regions import SWITCH
from grammarc.backend.plan import make_plan
from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS
from grammarc.io.lots import lots_from_polygons
from grammarc.model.records import MeshChunk

#: ``side`` turns its scope (no kernel does) and hands shapes to ``pane``, a leaf insert that the fused
#: ``bay`` inlines too: pane's pending list mixes both; ``bay``'s guards pick rules per shape.
MIXED = """
attr bay_w = 2.5
lot ~> S(1r, 7, 1r) Comp("sidefaces"){ side }
side ~> Subdiv("X", 1r, 2, 1r){ bay | R(0, 0, 0) pane | bay }
bay : Scope.sx > 3 ~> Repeat("X", bay_w){ Subdiv("Y", 1r, 1.2, 0.4){ pane | glass | pane } }
bay : Scope.sx > 1 ~> Subdiv("Y", 2, 1r){ glass | T(0, 0, 0.1) pane }
bay ~> I("cube")
glass ~> S(1r, 1r, 0.05) T(0, 0, -0.05) I("cube")
pane ~> I("quad")
"""

#: Parameters (of the root, and passed on) and brackets: the root ``facade`` takes its storeys from ``lot``.
PASSED_ON = """
attr sill = 0.9
lot ~> S(1r, 9, 1r) Comp("sidefaces"){ facade(3) }
facade(floors) ~> Repeat("Y", Scope.sy / floors){ storey(floors, 0.6) }
storey(k, w) ~> [ T(0, 0, w * 0.1) S(1r, 0.2, 0.3) I("cube") ] Subdiv("X", 1r, k * 0.4, 1r){ I("quad") | bay(w + sill) | I("quad") }
bay(h) ~> Subdiv("Y", h, 1r){ I("quad") | [ S(1r, 1r, 0.1) I("cube") ] T(0, 0, -0.1) I("quad") }
"""

#: The layouts' edges: absolute parts longer than the scope (cut, then dropped), relative parts left nothing,
#: a repeat of two parts, flat scopes (no repeat element on a zero extent), attribute sizes.
EDGES = """
attr pier = 4
lot ~> S(1r, 6, 1r) Comp("sidefaces"){ facade }
facade ~> Subdiv("X", pier, 1r, pier, 1r){ Repeat("Y", 1.1){ a | b } | S(1r, 1r, 0) Repeat("Z", 1){ I("cube") } | c | I("quad") }
a ~> S(1r, 0.5r, 1r) I("cube")
b ~> T(0, 0, 0.3) I("quad")
c ~> Subdiv("Y", 5, 0.5, 1r, 2){ I("cube") | I("quad") | I("cube") | I("quad") }
"""

#: ``Subdiv`` of a computed size that goes negative on narrow facades: the interpreter fails those lots.
NEGATIVE = """
lot ~> S(1r, 6, 1r) Comp("sidefaces"){ facade }
facade ~> Subdiv("X", Scope.sx - 9, 1r){ part | part }
part ~> Repeat("Y", 3){ I("quad") }
"""


#: Leaves, cubes and quads (``terminals.emit_leaves``) of one batch: ``row``, named twice, is its own region,
#: whose batch holds the lot's flat scopes and boxes; every flat axis of a quad, two flat axes (no record),
#: and leaves reached through an inlined symbol.
LEAVES = """
lot ~> Subdiv("Z", 1r, 1r){ row | S(1r, 2, 1r) row }
row ~> Repeat("X", 2){ wall | S(0, 1r, 1r) wall | S(1r, 1r, 0) wall | S(1r, 1r, 0.5) T(0, 1, 0) roof | S(0, 0, 1r) wall | bay }
bay ~> Subdiv("Y", 1r, 1r){ wall | S(1r, 1r, 0.2) roof }
"""

#: Hand-offs: ``cell``, named from several places, takes its parameter from ``lot``'s kernel and is its own
#: region; ``pick`` is the interpreter's (a stochastic rule, ``rand``), whose draws need the keys the kernels
#: hand on, and whose pending list mixes shapes of both kernels.
HANDOFF = """
attr w = 2
lot ~> Subdiv("Z", 1r, 1r){ Repeat("X", w){ cell(1.5) | cell(0.5) } | [ T(0, 1, 0) cell(2) ] S(1r, 3, 1r) Subdiv("X", 1r, 2){ pick | cell(1) } }
cell(h) ~> S(1r, h, 1r) Repeat("X", 1){ pick | [ S(1r, 1r, 0.3) pick ] I("cube") }
pick ~> I("cube") : 0.5
     ~> S(1r, rand(1, 2), 1r) I("quad") : 0.5
"""

#: Draws: stochastic rules and ``rand`` in the root, in an inlined symbol (``cell``) and in one handed off
#: (``pick``), and ``min`` and ``max``; ``lot``'s probabilities do not sum to 1 on lots wider than 11 m.
RANDOM = """
lot ~> Subdiv("Z", 1r, min(Scope.sz * 0.5, 4)){ Repeat("X", 1.5){ cell } | S(1r, max(rand(1, 3), 2), 1r) Repeat("X", 2){ pick } } : 0.9
    ~> Repeat("X", rand(1, 2)){ pick } : 0.1 + max(Scope.sx - 11, 0)
cell ~> S(1r, rand(2), 1r) Subdiv("Y", 1r, rand(0.5, 1)){ pick | I("cube") } : 0.3
     ~> [ T(0, rand(), 0) I("quad") ] pick : 0.5
     ~> ε : 0.2
pick ~> Repeat("X", 0.7){ I("cube") } : 0.5
     ~> S(1r, rand(1, 2), 1r) I("quad") : 0.5
"""

#: Splits along several axes: a cell numbered by its part (``Subdiv``) or element (``Repeat``) along each axis,
#: the first fastest, its body the number modulo the bodies; a repeat of one body and of two, the keys handed
#: to ``post`` (a region of its own) and drawn from in ``bed`` and ``pick``; ``flat``'s first batch holds a
#: scope of no height, whose y makes no element: the interpreter derives that batch.
AXES = """
attr w = 2.5
lot ~> S(1r, 4, 1r) Subdiv("X", 1r, 1r, 1r){ yard | S(1r, 0, 1r) flat | flat }
yard ~> Subdiv("XZ", 0.45, 1r, 0.45){ post | ε | post | ε | court | ε | post | ε | post }
court ~> Repeat("XZ", w, 3){ bed | pick }
bed ~> S(1r, rand(0.2, 0.6), 1r) I("cube")
post ~> Repeat("XY", 0.2, 1.5){ I("quad") }
flat ~> Repeat("XYZ", 2, 1, 3){ I("cube") | I("quad") }
pick ~> I("cube") : 0.5
     ~> S(1r, rand(1, 2), 1r) I("quad") : 0.5
"""

#: Recursion: ``shrink`` names itself (once) and is handed off to itself, round after round.
RECURSIVE = """
lot ~> Subdiv("X", 1r, 1r){ half | I("cube") }
half ~> Repeat("Z", 3){ shrink }
shrink : Scope.sx > 1 ~> Subdiv("X", 1r, 1r){ S(1r, 2, 1r) shrink | I("quad") }
shrink ~> I("cube")
"""

#: CityEngine's dialect: splits with floating, relative and absolute sizes and repeat groups (two that take
#: their repetitions in turns in ``Facade``; ``Bay``'s first size goes negative, taken as 0), a body's end a
#: leaf (``Pier``'s, ``Yard.``, the asset ``Win`` inserts), ``case``, brackets and ``NIL``, which move PRT's
#: stream on;
#: ``Chimney`` (stochastic) and ``Glass`` (``rand``) are the interpreter's, whose draws need the states the
#: kernel hands on, ``Glass`` its shapes' geometry (the door) too; ``Pier``, named from several places, is
#: handed off.
CITYENGINE = """
version "2023.0"
attr w = 5
attr gap = 0.5

@StartRule
Lot --> split(x) { ~w : Strip }*
Strip --> split(z) { 1 : Yard. | { ~6 : House | gap : NIL }* | '0.1 : s('1, 0.2, '1) }
House --> s('1, 4, '0.8) [ t(0, 4, 0) s('0.5, 1, '0.5) Chimney ] NIL Front
Front --> split(x) { 1 : Pier | { ~3 : Bay }* | 0.6 : Pier | { ~2 : Bay }* | 1 : Pier }
Bay --> split(y) { scope.sy - 3.5 : Pier | ~1.5 : Win | 0.3 : i("builtin:cube") Sill. }
Win --> case scope.sx > 1.4 : [ t(0, 0, -0.2) s('1, '1, 0.2) ] i("door.obj") Glass
        case scope.sy > 2 : split(x) { ~1 : Pier | 0.1 : NIL }*
        else : s('1, '1, 0.5)
Pier --> s('1, '1, '1)
Chimney --> 50% : s('1, rand(1, 2), '1)
            else : t(0, 1, 0)
Glass --> s('1, rand(0.5, 1), '1)
"""


#: Draws from PRT's stream inside the kernels, in the interpreter's order: in split sizes and scale
#: arguments (``rand``, several on one line), in ``case`` conditions (``p``: a later condition draws only
#: where the earlier ones did not hold), stochastic choices, and a successor's argument; ``Mark`` is
#: handed off and draws in the interpreter, after the kernel's draws moved its parent's state on.
CITYENGINE_DRAWS = """
version "2023.0"
attr depth = 0.4

@StartRule
Lot --> split(x) { ~rand(3, 5) : Strip | rand() * 0.5 : NIL }*
Strip --> split(z) { { ~rand(4, 6) + rand(0, 1) : Unit }* | 1 : Mark }
Unit --> case p(0.3) : s('1, rand(2, 5), '1) Mark
         case p(0.5) : split(x) { ~1 : Cell(rand(1, 2)) }*
         else : 40% : [ t(0, rand(), 0) Mark ] s('1, rand(1, 2) * depth + 1, '1)
                25% : NIL
                else : split(y) { ~rand(1, 2) : Mark }*
Cell(h) --> s('1, h, '1) split(y) { ~1 : Mark | rand(0, 0.5) : 20% : Mark else : s('1, '1, 0) }
Mark --> s('1, '1, rand(0.1, 0.3)) i("builtin:cube")
"""


#: Shapes that carry per-shape columns through the kernels, made by the interpreter before them: a colour
#: (the front), a texture channel and coordinates (the sides), an attribute ``set`` per face and read in
#: ``case``s, and trim planes (``comp(f)`` before inserts). ``Edge``'s cube, which an ``i`` inserted, stands
#: over the facade's end and is cut at its trim plane; ``Ledge``'s box, as long, is the extrusion's and is not.
#: ``Sill`` and ``Pier``, named twice, are handed off, inserted after an ``i`` and not after the other;
#: ``Sill`` colours its box, cut where it stands over the facade's other end.
CARRIED = """
version "2023.0"
attr street = false
attr floor_h = 3

@StartRule
Lot --> extrude(10) comp(f) { front : set(street, true) color("#ff8000") Facade | side : Side | top : Roof. }
Side --> setupProjection(0, scope.xy, 4, 3) projectUV(0) set(material.colormap, "brick.jpg") Facade
Facade --> split(y) { ~floor_h : Floor }*
Floor --> case street : split(x) { 0.6 : Edge | { ~2 : Tile | 0.5 : i("builtin:cube") Pier }* | 0.6 : s('1.8, '1, 0.4) i("builtin:cube") Sill }
          else : split(x) { 0.4 : s('3, '1, 0.4) t('-1, 0, 0) Ledge. | { ~3 : Tile }* }
Tile --> split(x) { 0.2 : Pier | ~1 : s('1, '1, 0.3) Win | 0.2 : Sill }
Edge --> s('1.8, '1, 0.4) t('-0.4, 0, 0) i("builtin:cube")
Win --> case street : t(0, 0, -0.2) Pane
        else : s('1, '0.5, '1) Pane
Pane --> s('1, '1, 0) Glass.
Pier --> t(0, 0, -0.1)
Sill --> color("#00ff00")
"""


#: Columns a region writes: ``set`` of a number read back (``level``), of a boolean (``street``, which ``Band``,
#: handed off, reads), of a string constant and a string attribute (texture channels); ``color`` of three
#: components (clipped), of a constant and of a string attribute; a string attribute compared with a
#: constant; ``reverseNormals``, which changes nothing.
#: ``Pier``, ``Corner`` and ``Glass``, named once, are inlined; ``Floor`` and ``Band``, named more often, are
#: handed off with the columns written before.
WRITTEN = """
version "2023.0"
attr street = false
attr floor_h = 3
attr wall = "#c0b090"
attr tex = "wall.jpg"
attr level = 0

@StartRule
Lot --> extrude(10) comp(f) { front : set(street, true) Facade | side : Facade | top : Roof. }
Facade --> split(y) { floor_h : Floor | ~1 : set(level, level + 3) Floor }
Floor --> split(x) { { ~2 : Tile | 0.5 : color(wall) Pier }* | 0.6 : set(material.colormap, tex) color(wall) Corner }
Tile --> case level > 2 && tex != "none.jpg" : color(0.2, 0.4 + level / 10, 1.2) reverseNormals split(y) { ~1 : texture("glass.jpg") Glass | 0.3 : Band }
         else : set(street, false) color("#abc") split(x) { 0.2 : Band | ~1 : s('1, '1, 0.3) i("builtin:cube") Win. | 0.2 : Band }
Band --> case street : color("#ff0000") else : NIL
Pier --> t(0, 0, -0.1) Band
Corner --> s('1, '1, 0.2)
Glass --> set(material.dirtmap, "dirt.jpg")
"""


#: ``center`` on the body's first scope (a rule's, a split part's, a case branch's, an inlined symbol's),
#: on the last push's, and again on the first after a ``]``; on one axis, two and three.
CENTERED = """
version "2023.0"
attr sill = 0.2

@StartRule
Lot --> extrude(8) comp(f) { front : r(10, 5, 20) Facade | side : Facade }
Facade --> split(y) { ~3 : Floor }*
Floor --> split(x) { ~2.5 : s('1, '1, 0.5) center(z) Tile }*
Tile --> s('0.6, '0.5, 0.3) center(xy) Window
         [ t(0, 0.2, 0) s('1, sill, 0.4) center(x) i("builtin:cube") Sill. ]
         [ s(1, 1, 1) [ s('0.5, '0.5, '1) center(xyz) Mark ] t(0.1, 0, 0.3) center(z) Mark ]
Window --> case scope.sx > 1.4 : split(x) { ~1 : s('0.8, '1, 0.1) center(x) Pane. }*
           else : t(0.3, 0, 0) s('0.5, '1, '1) center(y) Pane.
Mark --> color("#808080")
"""

#: Parameters of strings and booleans: a string attribute's, constants and parameters passed on, compared, set
#: and coloured with; the facades' come from the interpreter (their kernel takes the ids), the bands' are
#: handed back to it.
PARAMETERS = """
version "2023.0"
attr tex = "wall.jpg"
attr hue = "#c0b090"

@StartRule
Lot --> extrude(8) comp(f) { front : Facade("brick.jpg", true) | side : Facade(tex, false) }
Facade(image, front) --> split(y) { ~3 : Floor(image, front) }*
Floor(image, front) --> split(x) { ~2.5 : Tile(image, front, "#abcdef") | 0.5 : Pier(image) }*
Tile(image, front, tint) --> case image == "brick.jpg" && front : texture(image) color(tint) split(y) { ~1 : Glass | 0.3 : Band(image) }
                             else : color(hue) split(x) { 0.2 : Band(tex) | ~1 : set(material.dirtmap, image) Win. | 0.2 : Band("band.jpg") }
Band(name) --> case name != "band.jpg" : texture(name) else : color("#ff0000")
Pier(name) --> set(material.colormap, name) t(0, 0, -0.1) Band(name)
Glass --> set(material.dirtmap, "dirt.jpg")
"""

def cityengine_lots():
    widths = np.linspace(4, 31, 10)
    return lots_from_polygons([[np.array([[0, 0], [w, 0], [w, 7 + w / 3], [0, 7 + w / 3]])] for w in widths],
                              ids=[f"w{w:g}" for w in widths])


@pytest.fixture(autouse=True)
def fused_always(monkeypatch):
    """Kernels for every batch, however small (``regions.COMPILE_AT``)."""
    monkeypatch.setenv(SWITCH, "always")

def both(write, monkeypatch, text: str, lots, **options) -> tuple[dict, dict]:
    """The records fused and interpreted; the fused ones with ``"kernels"``: how many batches kernels derived."""
    path = write("g.cga", text)
    taken = []

    def counted(ctx, region, shapes):
        taken.append(derive_fused(ctx, region, shapes))
        return taken[-1]

    monkeypatch.setattr(execute, "derive_fused", counted)
    fused = derive(compile_grammar(path), lots, BuildOptions(**options))
    fused["kernels"] = sum(taken)
    monkeypatch.setenv(SWITCH, "off")
    interpreted = derive(compile_grammar(path), lots, BuildOptions(**options))
    monkeypatch.delenv(SWITCH)
    return fused, interpreted


def assert_same(fused: dict, interpreted: dict) -> None:
    for column in ("asset", "xform", "lot", "symbol", "color", "material", "uv"):
        assert (column in fused) == (column in interpreted), column
        if column in fused:
            np.testing.assert_array_equal(fused[column], interpreted[column], err_msg=column)
    for column in fields(MeshChunk):  # the leaves that are faces: polygons, inserts cut at trim planes
        ours, theirs = getattr(fused["mesh"], column.name), getattr(interpreted["mesh"], column.name)
        assert (ours is None) == (theirs is None), column.name
        if ours is not None:
            np.testing.assert_array_equal(ours, theirs, err_msg=column.name)
    assert [(b.id, b.reason) for b in fused["bad"]] == [(b.id, b.reason) for b in interpreted["bad"]]


def test_fused_and_interpreted_symbols_meet_in_the_interpreter_order(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", MIXED)))
    assert {plan.symbols[k].name for k in plan.fused} == {"bay"}
    fused, interpreted = both(write, monkeypatch, MIXED, make_lots("square", "rect_12x8", "concave_L", "courtyard"))
    assert len(fused["asset"]) > 200 and fused["kernels"]
    assert_same(fused, interpreted)


def test_leaves_are_the_cubes_and_quads_of_the_interpreter_in_its_order(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", LEAVES)))
    assert {plan.symbols[k].name for k in plan.fused} == {"lot", "row", "bay"}
    fused, interpreted = both(write, monkeypatch, LEAVES, make_lots("square", "rect_12x8", "sliver"))
    assert fused["kernels"] and {0, 1} <= set(fused["asset"].tolist())
    assert_same(fused, interpreted)


def test_shapes_handed_off_are_the_interpreters_with_their_keys_and_parameters(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", HANDOFF)))
    assert {plan.symbols[k].name for k in plan.fused} == {"lot", "cell"}
    fused, interpreted = both(write, monkeypatch, HANDOFF, make_lots("square", "rect_12x8"))
    assert fused["kernels"] == 2 and len(fused["asset"]) > 50
    assert_same(fused, interpreted)


def test_shapes_handed_off_are_as_deep_as_the_interpreters(write, monkeypatch):
    # ``pick`` reaches the depth first, from ``cell``: the failure names it
    fused, interpreted = both(write, monkeypatch, HANDOFF, make_lots("square", "rect_12x8"),
                              limits=replace(LIMITS, max_depth=2))
    assert fused["bad"] and "`pick`" in fused["bad"][0].reason
    assert_same(fused, interpreted)


@pytest.mark.parametrize("widest", [11, 12])
def test_draws_are_the_interpreters(write, monkeypatch, widest):
    plan = make_plan(compile_grammar(write("g.cga", RANDOM)))
    assert {plan.symbols[k].name for k in plan.fused} == {"lot", "cell", "pick"}
    widths = np.linspace(5, widest, 16)
    lots = lots_from_polygons([[np.array([[0, 0], [w, 0], [w, 9], [0, 9]])] for w in widths],
                              ids=[f"w{w:g}" for w in widths])
    fused, interpreted = both(write, monkeypatch, RANDOM, lots)
    assert fused["kernels"] and bool(fused["bad"]) == (widest > 11) and len(fused["asset"]) > 200
    assert_same(fused, interpreted)


def test_recursion_is_derived_round_after_round(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", RECURSIVE)))
    assert {plan.symbols[k].name for k in plan.fused} == {"lot", "half", "shrink"}
    fused, interpreted = both(write, monkeypatch, RECURSIVE, make_lots("square", "rect_12x8"))
    assert fused["kernels"] > 3 and len(fused["asset"]) >= 30
    assert_same(fused, interpreted)


def test_splits_along_several_axes_are_the_interpreters(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", AXES)))
    assert {plan.symbols[k].name for k in plan.fused} == {"lot", "yard", "court", "post", "flat"}
    fused, interpreted = both(write, monkeypatch, AXES, cityengine_lots())
    assert fused["kernels"] == 2 and len(fused["asset"]) > 1000  # ``lot``'s and ``post``'s; ``flat``'s declined
    assert_same(fused, interpreted)

def test_parameters_and_brackets(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", PASSED_ON)))
    assert {plan.symbols[k].name for k in plan.fused} == {"facade", "storey", "bay"}
    fused, interpreted = both(write, monkeypatch, PASSED_ON, make_lots("square", "concave_L", "courtyard"))
    assert len(fused["asset"]) > 100 and fused["kernels"]
    assert_same(fused, interpreted)


def test_the_edges_of_the_layouts(write, monkeypatch):
    fused, interpreted = both(write, monkeypatch, EDGES, make_lots("square", "rect_12x8", "concave_L", "courtyard"))
    assert len(fused["asset"]) > 100 and fused["kernels"]
    assert_same(fused, interpreted)


def test_a_batch_the_interpreter_would_fail_is_left_to_it(write, monkeypatch):
    fused, interpreted = both(write, monkeypatch, NEGATIVE, make_lots("square", "rect_12x8", "concave_L"))
    assert fused["bad"] and "negative" in fused["bad"][0].reason
    assert len(fused["asset"]) and fused["kernels"]
    assert_same(fused, interpreted)


@pytest.mark.parametrize("max_shapes", [40, 5000])
def test_shapes_count_as_the_interpreter_counts_them(write, monkeypatch, max_shapes):
    text = NEGATIVE.replace("Scope.sx - 9", "1")
    fused, interpreted = both(write, monkeypatch, text, make_lots("square", "concave_L"),
                             limits=replace(LIMITS, max_shapes=max_shapes))
    assert_same(fused, interpreted)
    assert bool(fused["bad"]) == (max_shapes == 40)


@pytest.mark.parametrize("far", ["S(1r, 1e39, 1r)", "T(0, -1e39, 0)"])
def test_a_scope_beyond_any_coordinate_is_left_to_the_interpreter_which_fails_its_lot(write, monkeypatch, far):
    """A scale or move past float32's largest number: the kernel hands the batch back, and the lot fails
    where the interpreter fails it (``Context.refuse_far``), the records the interpreter's."""
    text = NEGATIVE.replace("Subdiv(\"X\", Scope.sx - 9, 1r){ part | part }", f"{far} part")
    fused, interpreted = both(write, monkeypatch, text, make_lots("square", "rect_12x8"))
    assert fused["bad"] and all("beyond any coordinate" in b.reason for b in fused["bad"])
    assert_same(fused, interpreted)


def test_preload_loads_the_kernels_an_earlier_build_compiled_and_compiles_none(write, monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))  # a cache folder where nothing is compiled yet
    monkeypatch.setattr(compiled, "_KERNELS", {})
    path = write("g.cga", 'lot ~> Repeat("X", 2){ I("cube") }\n')
    plan = make_plan(compile_grammar(path))
    [region] = plan.fused.values()
    assert list(preload(plan)) == [] and region.source.text not in compiled._KERNELS
    derive(compile_grammar(path), make_lots("square"), BuildOptions())  # compiles the kernel
    monkeypatch.setattr(compiled, "_KERNELS", {})  # as in the next build's process
    assert len(list(preload(plan))) == 1 and region.source.text in compiled._KERNELS


def test_cityengine_dialect_splits_leaves_and_prt_stream_are_the_interpreters(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", CITYENGINE)))
    assert {plan.symbols[k].name for k in plan.fused} == {"Lot", "Strip", "House", "Front", "Bay", "Win"}
    fused, interpreted = both(write, monkeypatch, CITYENGINE, cityengine_lots())
    assert fused["kernels"] >= 2 and len(fused["asset"]) > 300
    names = [plan.grammar.module.assets[a] for a in np.unique(fused["asset"])]
    assert "door.obj" in names and "builtin:cube" in names and "builtin:quad" in names
    assert_same(fused, interpreted)


@pytest.mark.parametrize(("split", "made", "failing"), [
    ("{ ~3 : Bay }*", "{ ~3 : Bay | min(scope.sx - 5, 0) / min(scope.sx - 5, 0) : Pier }*", 5),
    ("{ ~3 : Bay }*", "{ tiny : Pier }* | { ~3 : Bay }*", 10),
    ("{ ~w : Strip }*", "{ ~w * tiny : Strip }*", 10),
])
def test_a_cityengine_split_the_interpreter_fails_is_left_to_it(write, monkeypatch, split, made, failing):
    """A NaN size (0 / 0 on strips 5 m wide or more), or parts beyond --max-shapes (repetitions of 1e-200 m,
    fixed or floating): the kernel declines its batch, and the interpreter fails those lots."""
    text = CITYENGINE.replace("attr gap", "attr tiny = 1e-200\nattr gap").replace(split, made)
    fused, interpreted = both(write, monkeypatch, text, cityengine_lots())
    assert len(fused["bad"]) == failing
    assert_same(fused, interpreted)


def test_cityengine_shapes_of_their_own_geometry_are_left_to_the_interpreter(write, monkeypatch):
    fused, interpreted = both(write, monkeypatch, CITYENGINE, make_lots("concave_L", "square"))
    assert fused["kernels"] == 1  # the square's lot; the L's shapes are polygons
    assert_same(fused, interpreted)


@pytest.mark.parametrize("seed", [0, 3])
def test_cityengine_draws_are_the_interpreters(write, monkeypatch, seed):
    plan = make_plan(compile_grammar(write("g.cga", CITYENGINE_DRAWS)))
    assert {plan.symbols[k].name for k in plan.fused} == {"Lot", "Strip", "Unit", "Cell"}
    fused, interpreted = both(write, monkeypatch, CITYENGINE_DRAWS, cityengine_lots(), seed=seed)
    assert fused["kernels"] and len(fused["asset"]) > 300
    assert_same(fused, interpreted)


def test_cityengine_shapes_carry_their_columns_through_the_kernels(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", CARRIED)))
    assert {plan.symbols[k].name for k in plan.fused} == {"Facade", "Floor", "Tile"}
    fused, interpreted = both(write, monkeypatch, CARRIED, cityengine_lots())
    assert fused["kernels"] >= 2 and len(fused["asset"]) > 1000
    assert {"color", "material", "uv"} <= fused.keys() and len(fused["mesh"].lot)  # cut: faces
    assert len(np.unique(fused["color"], axis=0)) == 3  # white, orange, green
    assert_same(fused, interpreted)


def test_cityengine_regions_write_the_columns_they_set(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", WRITTEN)))
    assert {plan.symbols[k].name for k in plan.fused} == {"Facade", "Floor", "Tile"}
    written = {plan.symbols[k].name: region.source.written for k, region in plan.fused.items()}
    assert {name: {k for k, slot in plan.dynamic.items() if slot in slots} for name, slots in written.items()} == {
        "Facade": {"level"},  # its floors handed off with their levels
        "Floor": {"street", "#color", "material.colormap", "material.dirtmap"},
        "Tile": {"street", "#color", "material.colormap", "material.dirtmap"}}
    fused, interpreted = both(write, monkeypatch, WRITTEN, cityengine_lots())
    assert fused["kernels"] >= 2 and len(fused["asset"]) > 500
    colors = {tuple(c) for c in fused["color"].tolist()}
    assert {(192, 176, 144, 255), (170, 187, 204, 255), (255, 0, 0, 255)} <= colors  # wall, "#abc", Band's
    assert (51, 178, 255, 255) in colors  # 0.2, the upper floor's 0.7 (178.5, rounded to even), 1.2 clipped
    assert_same(fused, interpreted)


def test_cityengine_regions_centre_scopes_as_the_interpreter_does(write, monkeypatch):
    """The records, and the origins of the shapes handed to ``Mark`` to the bit (a record's float32 hides
    the last bits of a sum's order): the front facades are turned, so that no axis has a zero."""
    plan = make_plan(compile_grammar(write("g.cga", CENTERED)))
    assert {plan.symbols[k].name for k in plan.fused} == {"Facade", "Floor", "Tile", "Window"}
    origins = {"always": [], "off": []}
    apply = execute.apply

    def watched(ctx, sym, shapes):
        if sym.name == "Mark":
            origins[os.environ[SWITCH]].append(shapes.origin.copy())
        apply(ctx, sym, shapes)

    monkeypatch.setattr(execute, "apply", watched)
    fused, interpreted = both(write, monkeypatch, CENTERED, cityengine_lots())
    assert fused["kernels"] and len(fused["asset"]) > 500  # the facades' kernel, its symbols all inlined
    assert_same(fused, interpreted)
    handed, derived = (np.concatenate(origins[mode]) for mode in ("always", "off"))
    assert len(handed) > 500 and np.array_equal(handed.view(np.int64), derived.view(np.int64))

def test_cityengine_regions_take_and_hand_off_parameters_of_strings_and_booleans(write, monkeypatch):
    plan = make_plan(compile_grammar(write("g.cga", PARAMETERS)))
    assert {plan.symbols[k].name for k in plan.fused} == {"Facade", "Floor", "Tile"}
    fused, interpreted = both(write, monkeypatch, PARAMETERS, cityengine_lots())
    assert fused["kernels"] and len(fused["asset"]) > 500
    # the tiles' and bands' textures, the strings handed to them, and the windows' dirt maps
    assert {"brick.jpg", "wall.jpg", "dirt.jpg"} <= set(np.unique(fused["material"]).tolist())
    assert (255, 0, 0, 255) in {tuple(c) for c in fused["color"].tolist()}  # the bands of "band.jpg"
    assert_same(fused, interpreted)

def test_a_region_past_its_most_lines_hands_off_the_symbols_it_would_inline(write, monkeypatch):
    """``codegen.MAX_LINES``: the facades' region, which inlines floors, tiles and windows, hands off the
    largest of them (its floors) until its function fits; the records stay the interpreter's."""

    def facade(plan):
        (region,) = (r for k, r in plan.fused.items() if plan.symbols[k].name == "Facade")
        return region.source

    whole = facade(make_plan(compile_grammar(write("g.cga", CENTERED))))
    lines = whole.text.count("\n") - whole.text[:whole.text.index("def derive(")].count("\n")
    monkeypatch.setattr(codegen, "MAX_LINES", lines // 2)
    cut = facade(make_plan(compile_grammar(write("g.cga", CENTERED))))
    assert cut.text.count("\n") - cut.text[:cut.text.index("def derive(")].count("\n") <= lines // 2
    assert (whole.sites, cut.sites, cut.handoffs) == (6, 0, 1)  # its floors handed off, with all below them
    fused, interpreted = both(write, monkeypatch, CENTERED, cityengine_lots())
    assert fused["kernels"] >= 2  # the facades', and the floors' of their own
    assert_same(fused, interpreted)

def test_a_colour_that_is_none_fails_its_lot_as_the_interpreter_fails_it(write, monkeypatch):
    fused, interpreted = both(write, monkeypatch, WRITTEN, cityengine_lots(), attrs={"wall": "brick"})
    # the facades' kernel derives; the floors', which colour their corners, hands its batch to the interpreter
    assert fused["kernels"] == 1 and len(fused["bad"]) == len(cityengine_lots())
    assert "is not a colour" in fused["bad"][0].reason
    assert_same(fused, interpreted)
