"""backend/plan.py: the plan holds the columns the derivation adds to a grammar's shapes, where it needs them."""

from __future__ import annotations

from operations.derivations import VERSION

from grammarc.backend.plan import make_plan
from grammarc.backend.slots import ANCESTORS, COLOR_SLOT, TRIM_SLOTS, TRIM_SWITCH
from grammarc.compiler import compile_grammar


def plan_of(write, text):
    return make_plan(compile_grammar(write("g.cga", VERSION + text)))


def test_columns_of_colours_trims_and_occluders_only_where_the_grammar_needs_them(write):
    plain = plan_of(write, "Lot --> extrude(3) X\n")
    assert (plain.color_slot, plain.trim_slot, plain.trim_switch, plain.occluders) == (None, None, None, False)
    colour = plan_of(write, "Lot --> color(1, 0, 0) X\n")
    assert colour.color_slot == colour.dynamic[COLOR_SLOT]
    trims = plan_of(write, 'Lot --> extrude(3) comp(f){ side : i("builtin:cube") X }\n')
    assert trims.trim_slot == trims.dynamic[TRIM_SLOTS[0]] and trims.trim_switch is None
    switch = plan_of(write, 'Lot --> set(trim.vertical, false) extrude(3) comp(f){ side : i("builtin:cube") X }\n')
    assert switch.trim_switch == switch.dynamic[TRIM_SWITCH]
    labelled = plan_of(write, 'Lot --> label("mass") X\n')
    assert labelled.occluders and ANCESTORS[0] in labelled.dynamic
