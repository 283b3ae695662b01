"""backend/attributes.py: the attribute columns of the lots: defaults, lot properties of the right
type, ``--attr`` overrides, constants."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from operations.derivations import (
    VERSION,
    names,
    paper,
    per_lot,
    rect,
    run,
    totals,
)

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.errors import UsageError
from grammarc.io.lots import lots_from_polygons, read_lots


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


def test_a_boolean_property_is_a_bool_and_makes_a_lot_of_a_number_attribute_bad(write, tmp_path):
    """GeoJSON's ``true`` for ``attr height = 10`` makes its lot bad, as the README says of a property of
    the wrong type (it was taken as 1); for ``attr flat = false`` it is the boolean it says."""
    path = tmp_path / "lots.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{i}", "properties": props, "geometry": {"type": "Polygon", "coordinates": [
            [[0, 0], [5, 0], [5, 5], [0, 5], [0, 0]]]}}
        for i, props in enumerate([{"height": 12, "flat": True}, {"height": True}, {"flat": False}])]}))
    grammar = compile_grammar(write("g.cga", 'attr height = 10\nattr flat = false\n'
                                             'lot : flat ~> S(1r, 1, 1r) I("cube")\n'
                                             'lot ~> S(1r, height, 1r) I("cube")\n'))
    r = derive(grammar, read_lots(path))
    np.testing.assert_allclose(r["xform"][:, 1, 1], [1, 10])
    assert [(b.index, b.reason) for b in r["bad"]] == [(1, 'attribute `height` is "true", not a num')]



# --------------------------------------------------------------------------------------------------- arrays


def test_array_attributes_come_from_lot_arrays(write):
    """A lot's JSON array (rows as lists of lists, a single value as a 1x1 array) replaces the default."""
    given = np.empty(4, dtype=object)
    given[:] = ["[1, 2, 3]", None, "[[1, 2], [3, 4]]", "7"]
    r = run(write, "attr a = [9, 9]\nLot --> report(\"n\", size(a)) report(\"rows\", nRows(a)) "
            "report(\"last\", a[size(a) - 1]) X\n", [rect(2, 2)] * 4, lot_attrs={"a": given})
    reports = per_lot(r)
    assert [(reports[k]["n_sum"], reports[k]["rows_sum"], reports[k]["last_sum"]) for k in sorted(reports)] == \
        [(3, 1, 3), (2, 1, 9), (4, 2, 4), (1, 1, 7)]


def test_lot_array_of_the_wrong_type_makes_its_lot_bad(write):
    given = np.empty(3, dtype=object)
    given[:] = ['["a", "b"]', "[1, 2]", "[[1], [2, 3]]"]
    r = run(write, "attr a = [0]\nLot --> extrude(a[0] + 1) X\n", [rect(2, 2)] * 3, lot_attrs={"a": given})
    assert [b.index for b in r["bad"]] == [0, 2]
    assert 'attribute `a` is ["a", "b"], not a num[]' in r["bad"][0].reason
    np.testing.assert_allclose(r["xform"][:, 1, 1], [2])


def test_attr_override_of_an_array_is_refused(write):
    grammar = compile_grammar(write("g.cga", VERSION + "attr a = [1]\nLot --> X\n"))
    with pytest.raises(UsageError, match="`a` is an array"):
        derive(grammar, lots_from_polygons([rect(1, 1)]), BuildOptions(attrs={"a": 2.0}))


FIXTURES = Path(__file__).parents[1] / "frontend" / "grammars" / "cityengine" / "arrays"


def test_geojson_array_properties_override_array_attributes_in_a_build(tmp_path):
    """tower_floors.cga built from a GeoJSON file whose features give their floor heights as arrays."""
    def feature(i, props):
        ring = [[20 * i, 0], [20 * i + 10, 0], [20 * i + 10, 10], [20 * i, 10], [20 * i, 0]]
        return {"type": "Feature", "id": f"lot{i}", "properties": props,
                "geometry": {"type": "Polygon", "coordinates": [ring]}}

    path = tmp_path / "lots.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        feature(0, {"floorHeights": [5, 3.5, 3.5, 3]}), feature(1, {}), feature(2, {"floorHeights": [2, 6]}),
        feature(3, {"floorHeights": ["tall"]})]}))
    grammar = compile_grammar(FIXTURES / "tower_floors.cga")
    first = derive(grammar, read_lots(path))
    again = derive(grammar, read_lots(path))
    for key in ("xform", "asset", "lot", "symbol"):
        np.testing.assert_array_equal(first[key], again[key])
    assert [b.id for b in first["bad"]] == ["lot3"]
    reports = per_lot(first)
    assert [reports[k]["floors_sum"] for k in sorted(reports)] == [4, 3, 2]
    assert [reports[k]["tallest floor_sum"] for k in sorted(reports)] == [5, 4, 6]
    heights = {}  # per lot, the top of its ground floors
    for lot, xform, name in zip(first["lot"], first["xform"], names(first)):
        if name == "GroundFloor":
            heights.setdefault(int(lot), set()).add(round(float(xform[1, 1]), 6))
    assert heights == {0: {5.0}, 1: {4.0}, 2: {2.0}}


def test_palette_fixture_picks_colours_by_a_lot_attribute(write):
    grammar = compile_grammar(FIXTURES / "palette.cga")
    styles = np.empty(3, dtype=object)
    styles[:] = ["glass", "plaster", "stone"]
    r = derive(grammar, lots_from_polygons([rect(4, 4)] * 3, attrs={"style": styles}))
    assert not r["bad"]
    reports = per_lot(r)
    assert [reports[k]["style column_sum"] for k in sorted(reports)] == [2, 1, -1]
