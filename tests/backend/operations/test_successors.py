"""backend/operations/successors.py in derivations: successor symbols, leaves and ``NIL``."""

from __future__ import annotations

from derivations import (
    names,
    rect,
    run,
)


def test_a_successor_without_rules_is_the_leaf(write):
    r = run(write, "Lot --> extrude(4) Mass\n", [rect(12, 8)])
    assert names(r) == ["Mass"]


def test_a_dotted_leaf_is_not_derived_further(write):
    r = run(write, "Lot --> extrude(4) Mass.\nMass --> s('0.5, '1, '1) Half\n", [rect(12, 8)])
    assert names(r) == ["Mass"] and r["xform"][0, 0, 0] == 12


def test_an_unreached_lot_rule_with_nil_emits_nothing(write):
    r = run(write, "Lot --> NIL\n", [rect(12, 8)])
    assert len(r["asset"]) == 0

