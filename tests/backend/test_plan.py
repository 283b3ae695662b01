"""backend/plan.py: the plan holds the columns the derivation adds to a grammar's shapes, where it needs them."""

from __future__ import annotations

from operations.derivations import VERSION

from grammarc.backend.plan import make_plan
from grammarc.backend.slots import (
    ANCESTORS,
    COLOR_SLOT,
    PIVOT_SLOTS,
    RING_START,
    TRIM_INSERTED,
    TRIM_PLANES,
    TRIM_SWITCH,
    uv_slots,
)
from grammarc.compiler import compile_grammar


def plan_of(write, text):
    return make_plan(compile_grammar(write("g.cga", VERSION + text)))


def test_columns_of_colours_trims_and_occluders_only_where_the_grammar_needs_them(write):
    plain = plan_of(write, "Lot --> extrude(3) X\n")
    assert (plain.color_slot, plain.trim_slot, plain.trim_switch, plain.occluders) == (None, None, None, False)
    colour = plan_of(write, "Lot --> color(1, 0, 0) X\n")
    assert colour.color_slot == colour.dynamic[COLOR_SLOT]
    trims = plan_of(write, 'Lot --> extrude(3) comp(f){ side : i("builtin:cube") X }\n')
    assert trims.trim_slot == trims.dynamic[TRIM_PLANES] and trims.trim_switch is None
    assert trims.inserted_slot == trims.dynamic[TRIM_INSERTED] and plain.inserted_slot is None
    # a primitive is inserted geometry too: a grammar whose inserts are all primitives has trim planes
    primitives = plan_of(write, "Lot --> extrude(3) comp(f){ side : primitiveCube(1, 1, 1) X }\n")
    assert primitives.trim_slot is not None and primitives.inserted_slot is not None
    switch = plan_of(write, 'Lot --> set(trim.vertical, false) extrude(3) comp(f){ side : i("builtin:cube") X }\n')
    assert switch.trim_switch == switch.dynamic[TRIM_SWITCH]
    # one id column for all the planes, whose rows are wider where the grammar may turn horizontal ones on
    assert (trims.horizontal_planes, trims.trim_width) == (False, 8)
    assert not any(name.startswith("trim.") for name in trims.dynamic if name not in (TRIM_PLANES, TRIM_INSERTED))
    shallow = 'Lot --> set(trim.horizontal, {}) extrude(3) comp(f){{ side : i("builtin:cube") X }}\n'
    on, off = plan_of(write, shallow.format("true")), plan_of(write, shallow.format("false"))
    assert (on.horizontal_planes, on.trim_width, off.horizontal_planes, off.trim_width) == (True, 24, False, 8)
    labelled = plan_of(write, 'Lot --> label("mass") X\n')
    assert labelled.occluders and ANCESTORS[0] in labelled.dynamic


def test_texture_columns_only_for_the_sets_the_grammar_names(write):
    """Two id columns per texture set an operation, a split or a query names; none without texture space
    (its shapes carry nothing more, and its splits copy nothing more)."""
    assert plan_of(write, "Lot --> extrude(3) X\n").uv_slots == {}
    plan = plan_of(write, "Lot --> setupProjection(2, scope.xy, 1, 1) projectUV(2) "
                   "split(v, unitSpace, 0){ 1 : A | ~1 : B }\nA --> report(\"u\", geometry.uMax(5)) A.\n")
    assert sorted(plan.uv_slots) == [0, 2, 5]
    for uv_set, start in plan.uv_slots.items():
        assert [plan.dynamic[name] for name in uv_slots(uv_set)] == [start, start + 1]


def test_pivot_columns_only_where_the_grammar_uses_the_pivot(write):
    """The pivot rides with the shapes of a grammar that sets it, reads it (``scope.t*``, ``scope.r*``,
    ``pivot.*``, ``convert``), moves in it or turns with an ``r`` of several angles; not with single turns."""
    for text in ("Lot --> extrude(3) r(0, 30, 0) X\n", "Lot --> r(0, 0, 0) rotateScope(0, 90, 0) X\n",
                 'Lot --> report("x", convert(x, scope, world, pos, 0, 0, 0)) X\n'):
        assert plan_of(write, text).pivot_slot is None, text
    for text in ("Lot --> setPivot(yzx, 2) X\n", "Lot --> r(10, 0, 20) X\n", "Lot --> rotateScope(0, 90, 5) X\n",
                 'Lot --> report("t", scope.tx) X\n', 'Lot --> report("o", pivot.oy) X\n',
                 "Lot --> set(scope.ry, 30) X\n", "Lot --> translate(rel, pivot, 1, 0, 0) X\n"):
        plan = plan_of(write, text)
        assert [plan.dynamic[name] - plan.pivot_slot for name in PIVOT_SLOTS] == [0, 1, 2, 3], text



def test_the_box_ring_column_only_where_the_grammar_turns_scopes_and_numbers_edges(write):
    """A box's ring corner (``backend.box_rings``) rides with the shapes of a grammar that turns scopes and
    numbers edges or cuts faces; a grammar that does only one of the two pays nothing."""
    for text in ("Lot --> rotateScope(0, 90, 0) X\n", "Lot --> setback(2){ front : A | remainder : B }\n",
                 "Lot --> alignScopeToAxes(y) extrude(3) X\n"):
        assert plan_of(write, text).ring_slot is None, text
    for text in ("Lot --> rotateScope(0, 90, 0) setback(2){ front : A | remainder : B }\n",
                 "Lot --> alignScopeToAxes(y) extrude(3) comp(f){ side : A }\n",
                 "Lot --> alignScopeToGeometry(yUp, 0, 0) offset(-1) comp(f){ inside : A }\n"):
        plan = plan_of(write, text)
        assert plan.ring_slot == plan.dynamic[RING_START], text
