"""backend/trim_reads.py: the comp(f) sites whose faces' trim planes something may read, followed through
successors, nested comps, brackets, branches and recursion; where none does, the records are the same
without them."""

from __future__ import annotations

from dataclasses import replace

import pytest
from operations.derivations import VERSION, rect, run, same_records

from grammarc import build
from grammarc.backend.operations import OPERATIONS
from grammarc.backend.plan import make_plan
from grammarc.backend.trim_reads import HANDS_ON, makes_planes, unread_plane_sites
from grammarc.compiler import compile_grammar
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_ops


def kept(write, text):
    """Per ``comp(f)`` site of ``text``, in source order: its rule's symbol and whether its faces get planes
    (whether something may read them)."""
    grammar = compile_grammar(write("g.cga", VERSION + text))
    unread = unread_plane_sites(grammar.module, grammar.graph.start)
    return [(rule.symbol, op.site not in unread) for rule in grammar.module.rules for op in iter_ops(rule)
            if makes_planes(op)]


FACADE = ("Lot --> extrude(10) comp(f){{ side : Facade | top : Roof }}\n"
          "Facade --> split(y){{ 3 : Floor }}*\n"
          "Floor --> Tile\n"
          "Tile --> s('1, '1, 0.3) {tile}\n"
          "Roof --> extrude(1) comp(f){{ side : Parapet }}\n"
          "Parapet --> color(1, 0, 0)\n")


@pytest.mark.parametrize(("tile", "read"), [
    ('i("builtin:cube")', True),  # cut where its leaf is placed
    ("primitiveCube()", True),
    ("trim()", True),
    ('i("builtin:cube") Tile.', True),  # a leaf of inserted geometry
    ("color(1, 0, 0)", False),  # a leaf of the face's own geometry
    ("primitiveQuad() extrude(1)", False),  # an extrusion is the shape's own geometry again
    ("resetGeometry() trim()", False),  # the lot's geometry, without planes
])
def test_planes_are_read_by_inserts_and_trim_reached_through_successors(write, tile, read):
    """The facade's planes reach the tile through a split and two successors; the roof's comp(f) faces end as
    leaves of their own geometry."""
    assert kept(write, FACADE.format(tile=tile)) == [("Lot", read), ("Roof", False)]


@pytest.mark.parametrize(("wall", "sites"), [
    # the inner comp gives its faces planes of their own
    ("extrude(1) comp(f){ side : Cornice }", [("Lot", False), ("Wall", True)]),
    ("comp(e){ all : Cornice }", [("Lot", True)]),  # edges keep their face's
    ("offset(-1) comp(f){ inside : Cornice }", [("Lot", True)]),  # so do an offset's faces (no site of planes)
    ("split(x){ 2 : Cornice }*", [("Lot", True)]),
])
def test_a_comp_f_hides_the_planes_of_the_comp_before_it(write, wall, sites):
    text = f"Lot --> extrude(10) comp(f){{ side : Wall }}\nWall --> {wall}\nCornice --> i(\"builtin:cube\")\n"
    assert kept(write, text) == sites


@pytest.mark.parametrize(("wall", "read"), [
    ("[ primitiveCube() ] X", False),  # `]` gives back the face, its own geometry
    ("[ primitiveCube() X ] Y", True),
    ("[ resetGeometry() ] trim()", True),  # and its planes
    ("[ resetGeometry() trim() ] X", False),
    ("primitiveCube() [ extrude(1) ] X", True),  # the cube, inserted
])
def test_brackets_give_back_the_planes_and_the_geometry(write, wall, read):
    assert kept(write, f"Lot --> extrude(10) comp(f){{ side : Wall }}\nWall --> {wall}\n") == [("Lot", read)]


@pytest.mark.parametrize(("wall", "read"), [
    ("case scope.sx > 5 : Plain else : Cube", True),
    ("case scope.sx > 5 : Plain else : Plain", False),
    ("30% : Plain else : Cube", True),
    ("30% : Plain 20% : NIL else : Plain", False),
])
def test_every_branch_of_case_and_stochastic_blocks(write, wall, read):
    text = f"Lot --> extrude(10) comp(f){{ side : Wall }}\nWall --> {wall}\nPlain --> color(1, 0, 0)\n" \
           "Cube --> primitiveCube()\n"
    assert kept(write, text) == [("Lot", read)]


@pytest.mark.parametrize(("band", "read"), [("color(1, 0, 0)", False), ("primitiveCube()", True)])
def test_recursion_reads_where_some_finite_derivation_does(write, band, read):
    """Walls split into bands and the rest of the wall, again and again, through two symbols."""
    text = ("Lot --> extrude(10) comp(f){ side : Wall }\nWall --> split(y){ 3 : Band | ~1 : Rest }\n"
            f"Rest --> case scope.sy > 3 : Wall else : NIL\nBand --> {band}\n")
    assert kept(write, text) == [("Lot", read)]


@pytest.mark.parametrize(("lot", "read"), [
    ("extrude(10) Mass", False),
    ("[ primitiveCube() Mass ] extrude(10) Mass", True),  # the faces of a cube are inserted geometry
])
def test_shapes_may_arrive_inserted_from_any_of_their_callers(write, lot, read):
    """A face with no rule is a leaf: cut at its planes where it is inserted geometry."""
    assert kept(write, f"Lot --> {lot}\nMass --> comp(f){{ side : Face }}\n") == [("Mass", read)]


@pytest.mark.parametrize(("guarded", "read"), [(True, True), (False, False)])
def test_a_shape_no_rule_applies_to_is_a_leaf(write, guarded, read):
    """A rule with a guard (the IR's; CityEngine's rules have none): where every rule of the face has one, a
    face none applies to is a leaf, cut at its planes (the faces of a cube are inserted geometry)."""
    grammar = compile_grammar(write("g.cga", VERSION + "Lot --> primitiveCube() comp(f){ side : Face }\n"
                                    "Face --> extrude(1) X\n"))
    module = grammar.module
    if guarded:
        module = replace(module, rules=tuple(replace(rule, guard=ir.Bool(False)) if rule.symbol == "Face" else rule
                                             for rule in module.rules))
    site = next(op.site for op in iter_ops(module.rules[0]) if makes_planes(op))
    assert (site not in unread_plane_sites(module, grammar.graph.start)) is read


def test_a_site_the_start_rule_does_not_reach_keeps_its_planes(write):
    text = "Lot --> extrude(10) X\nOrphan --> extrude(1) comp(f){ side : Plain }\nPlain --> color(1, 0, 0)\n"
    assert kept(write, text) == [("Orphan", True)]


@pytest.mark.parametrize("text", [
    # a ledge mitred at the planes of the facade's comp, a parapet's planes unread
    FACADE.format(tile="s('1.2, '1, '1) center(x) primitiveCube()"),
    # a cube's faces, inserted, and a window reveal's, not
    ("Lot --> primitiveCube() s('1, 6, '1) comp(f){ side : Face }\n"
    "Face --> split(x){ 2 : Reveal | ~1 : Face. }\nReveal --> extrude(-0.3) comp(f){ side : Plain }\n"
    "Plain --> color(1, 0, 0)\n"),
    ("Lot --> extrude(10) comp(f){ side : [ extrude(1) comp(f){ side : Plain } ] s('1.4, '1, 0.5) center(x) "
    "primitiveCube() }\nPlain --> color(1, 0, 0)\n"),
])
def test_sites_whose_planes_are_unread_make_the_same_records_without_them(write, monkeypatch, text):
    grammar = compile_grammar(write("g.cga", VERSION + text))
    assert make_plan(grammar).unread_planes
    lots = [rect(12, 8), rect(5, 20)]
    skipping = run(write, text, lots)
    monkeypatch.setattr(build, "make_plan", lambda g: replace(make_plan(g), unread_planes=frozenset()))
    same_records(run(write, text, lots), skipping)


def test_only_grammars_with_trim_planes_have_sites_without_them(write):
    plain = make_plan(compile_grammar(write("g.cga", VERSION + "Lot --> extrude(1) comp(f){ side : X }\n")))
    assert plain.trim_slot is None and not plain.unread_planes


def test_the_operations_that_hand_their_shape_on_are_those_the_table_declares():
    assert HANDS_ON == {node for node, entry in OPERATIONS.items() if entry.consumes}
