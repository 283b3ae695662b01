"""CityEngine's ``split`` in a kernel (``fusion.group_splits``): each form written as it should be, and laid
as the interpreter lays it."""

from __future__ import annotations

import numpy as np
from test_fused import assert_same, both, fused_always  # noqa: F401 - an autouse fixture

from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.io.lots import lots_from_polygons

#: ``F`` (the lot's shape, split from its polygon) inlines the others (each named once), which split it
#: again along x, on widths that vary with the lot's: a split without repeat groups (``F``'s own); splits with
#: one group: repeated as a whole (``A``, ``A2``), among floating parts as window rows are written (``H``),
#: beside a floating part that may leave it no repetition (``K``), of fixed sizes only, what they leave a
#: gap (``G``); and a split of two groups (``B``), which the interpreter's row functions lay.
FORMS = """
version "2023.0"
Lot --> split(x){ ~100: F }*
F --> s('1, 8, '1) split(x){ 1: A | ~2: B | '0.2: A2 | 1.5: G | ~3: H | ~1: K }
A --> split(x){ ~1.5: C. | ~0.5: D. }*
A2 --> split(x){ ~1: C. }*
B --> split(x){ 0.5: C. | { ~1: D. | 0.2: C. }* | 0.5: D. | { ~2: C. }* }
G --> split(x){ { 0.7: C. | 0.2: D. }* | ~1: C. | '0.1: D. }
H --> split(x){ 0.3: C. | { ~1.2: D. | 0.25: C. }* | ~1.2: D. | 0.3: C. }
K --> split(x){ ~0.6: C. | { ~0.5: D. }* }
"""


def lots():
    """Forty rectangles from 3 to 42 m wide: the forms' extents, and so their roundings, vary with them."""
    widths = np.linspace(3, 42, 40)
    return lots_from_polygons([[np.array([[0, 0], [w, 0], [w, 9], [0, 9]])] for w in widths],
                              ids=[f"w{w:g}" for w in widths])


def test_each_form_is_written_as_it_should_be(write):
    plan = make_plan(compile_grammar(write("g.cga", FORMS)))
    root = plan.symbol_ids["F"]
    text = plan.fused[root].source.text.split("def derive(")[-1]
    assert text.count("plan_row(") == text.count("lay_row(") == 1  # ``B``, whose groups are laid by calls
    assert text.count("repetitions(") == 5  # the splits of one group, written out around PRT's rounding


def test_each_form_lays_the_interpreters_parts(write, monkeypatch):
    fused, interpreted = both(write, monkeypatch, FORMS, lots())
    assert fused["kernels"] == 1 and len(fused["asset"]) > 1000
    assert_same(fused, interpreted)
