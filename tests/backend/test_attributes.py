"""backend/attributes.py: the attribute columns of the lots: defaults, lot properties of the right
type, ``--attr`` overrides, constants."""

from __future__ import annotations

import math

import numpy as np
import pytest
from operations.derivations import (
    VERSION,
    paper,
    rect,
    run,
    totals,
)

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.errors import UsageError
from grammarc.io.lots import lots_from_polygons


def test_stochastic_attribute_default_frequencies(write):
    n = 10_000
    r = run(write, 'attr roof = 30% : "flat" 20% : "gable" else : "hip"\nLot --> report(roof, 1)\n',
            [rect(1, 1)] * n)
    t = totals(r)
    for key, p in (("flat", 0.3), ("gable", 0.2), ("hip", 0.5)):
        assert abs(t[f"{key}_n"] - p * n) < 4 * math.sqrt(n * p * (1 - p)), t


def test_lot_properties_override_attributes_but_not_constants(write):
    r = run(write, "attr h = 3\nconst w = 2\nLot --> extrude(h) s(w, '1, '1) X\n", [rect(4, 4)] * 2,
            lot_attrs={"h": np.array([5.0, 6.0]), "w": np.array([9.0, 9.0])})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [5, 6])
    np.testing.assert_allclose(r["xform"][:, 0, 0], [2, 2])


def test_attr_override_of_a_constant_is_refused(write):
    grammar = compile_grammar(write("g.cga", VERSION + "attr h = 3\nconst w = 2\nLot --> extrude(h) X\n"))
    lots = lots_from_polygons([rect(4, 4)])
    r = derive(grammar, lots, BuildOptions(attrs={"h": 8.0}))
    assert r["xform"][0, 1, 1] == 8
    with pytest.raises(UsageError, match="constant"):
        derive(grammar, lots, BuildOptions(attrs={"w": 8.0}))


def test_attr_override_beats_lot_and_default(write):
    text = 'attr height = 10\nlot ~> S(1r, height, 1r) I("cube")\n'
    r = paper(write, text, [rect(5, 5)] * 2, lot_attrs={"height": [4.0, float("nan")]},
            attrs={"height": 7.0})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [7, 7])
    r = paper(write, text, [rect(5, 5)] * 2, lot_attrs={"height": [4.0, float("nan")]})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [4, 10])


def test_string_attributes_select_rules(write):
    """Puuc rules 20-21: the frieze rule chosen by a string control parameter read per lot."""
    text = """
attr frieze_decoration = "none"
lot : frieze_decoration == "none" ~> plain
lot : frieze_decoration == "colonettes" ~> S(1r, 1, 1r) Repeat("X", 1){ colonette }
lot ~> other
colonette ~> I("cylinder")
"""
    r = paper(write, text, [rect(4, 4)] * 3, lot_attrs={"frieze_decoration": ["colonettes", None, "x"]})
    assert list(r["symbols"][r["symbol"][r["lot"] == 0]]) == ["colonette"] * 4
    assert list(r["symbols"][r["symbol"][r["lot"] == 1]]) == ["plain"]
    assert list(r["symbols"][r["symbol"][r["lot"] == 2]]) == ["other"]


def test_lot_attribute_of_the_wrong_type_makes_its_lot_bad(write):
    text = 'attr height = 10\nlot ~> S(1r, height, 1r) I("cube")\n'
    r = paper(write, text, [rect(5, 5)] * 3, lot_attrs={"height": ["12", "tall", None]})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [12, 10])
    assert [b.index for b in r["bad"]] == [1]
    assert 'attribute `height` is "tall", not a num' in r["bad"][0].reason

