"""CityEngine's ``split`` in a kernel (``fusion.group_splits``): each form written as it should be, and laid
as the interpreter lays it."""

from __future__ import annotations

from test_fused import assert_same, both, cityengine_lots

from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar

#: ``F`` (the lot's shape, split from its polygon) inlines ``A``, ``A2`` and ``B`` (each named once): a split
#: without repeat groups, two repeated as a whole whose sizes all float, and one with repeat groups among
#: fixed parts.
FORMS = """
version "2023.0"
Lot --> split(x){ ~100: F }*
F --> s('1, 8, '1) split(x){ 1: A | ~2: B | '0.2: A2 }
A --> split(y){ ~1.5: C. | ~0.5: D. }*
A2 --> split(y){ ~1: C. }*
B --> split(y){ 0.5: C. | { ~1: D. | 0.2: C. }* | 0.5: D. }
"""


def test_each_form_is_written_as_it_should_be(write):
    plan = make_plan(compile_grammar(write("g.cga", FORMS)))
    root = plan.symbol_ids["F"]
    text = plan.fused[root].source.text.split("def derive(")[-1]
    assert text.count("plan_row(") == text.count("lay_row(") == 1  # ``B``, whose groups are laid by calls
    assert text.count("repetitions(") == 2  # ``A`` and ``A2``, written out around PRT's rounding


def test_each_form_lays_the_interpreters_parts(write, monkeypatch):
    fused, interpreted = both(write, monkeypatch, FORMS, cityengine_lots())
    assert fused["kernels"] == 1 and len(fused["asset"]) > 100
    assert_same(fused, interpreted)
