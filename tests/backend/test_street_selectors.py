"""Street selectors in derivations: ``street.front|back|left|right|side`` of setbacks and comp(f), and
the older ``streetSide`` / ``noStreetSide``, from lots whose ``streetWidth`` marks their street edges."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import in_world
from operations.derivations import VERSION, names, rect, totals

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.io.lots import lots_from_polygons

NORTH = [0, 0, 8, 0]  # rect(30, 20)'s edges: south, east, north, west (map y up); the north one is a street
CORNER = [0, 8, 8, 0]  # east and north


def run(write, text, street):
    grammar = compile_grammar(write("g.cga", VERSION + text))
    return in_world(derive(grammar, lots_from_polygons([rect(30, 20)], street=[street]), BuildOptions()))


def box_bounds(record, name):
    """World bounds (2, 3) of the instances of ``name`` (each a unit box placed by its xform)."""
    x = record["xform"][np.array(names(record)) == name].astype(float)
    corners = np.array([[i & 1, i >> 1 & 1, i >> 2 & 1] for i in range(8)], float)
    points = np.einsum("nij,cj->nci", x[:, :, :3], corners) + x[:, None, :, 3]
    return np.array([points.min(axis=(0, 1)), points.max(axis=(0, 1))])


def test_street_front_is_the_street_edge_and_falls_back_to_the_lots_front_without_one(write):
    text = ('Lot --> setback(3){ street.front : A | remainder : B }\n'
            'A --> report("a", geometry.area) extrude(1)\nB --> report("b", geometry.area)\n')
    r = run(write, text, NORTH)
    assert totals(r)["a_sum"] == pytest.approx(90) and totals(r)["b_sum"] == pytest.approx(510)
    np.testing.assert_allclose(box_bounds(r, "A")[:, [0, 2]], [[0, -20], [30, -17]], atol=1e-9)  # north: -z
    r = run(write, text, None)  # no street: object.front, the lot's first edge (south, z = 0)
    np.testing.assert_allclose(box_bounds(r, "A")[:, [0, 2]], [[0, -3], [30, 0]], atol=1e-9)


def test_a_corner_lot_has_two_street_fronts(write):
    text = ('Lot --> setback(2){ street.front : A | remainder : B }\n'
            'A --> report("a", geometry.area)\nB --> report("b", geometry.area)\n')
    t = totals(run(write, text, CORNER))
    assert t["a_sum"] == pytest.approx(2 * 20 + 2 * 30 - 4) and t["b_sum"] == pytest.approx(28 * 18)


def test_comp_f_names_the_faces_of_a_mass_by_the_street(write):
    text = ('Lot --> extrude(10) comp(f){ street.front : F | street.back : K | street.side : S | all : NIL }\n'
            'F --> Front.\nK --> Back.\nS --> Side.\n')
    r = run(write, text, NORTH)
    assert sorted(names(r)) == ["Back", "Front", "Side", "Side"]
    np.testing.assert_allclose(box_bounds(r, "Front")[:, 2], [-20, -20], atol=1e-9)  # the north face
    np.testing.assert_allclose(box_bounds(r, "Back")[:, 2], [0, 0], atol=1e-9)


def test_street_side_and_no_street_side_select_nothing_on_a_lot_without_streets(write):
    text = ('Lot --> setback(2){ noStreetSide : A | remainder : B }\n'
            'A --> report("a", geometry.area)\nB --> report("b", geometry.area)\n')
    t = totals(run(write, text, NORTH))
    assert t["a_sum"] == pytest.approx(60 + 40 + 40 - 8) and t["b_sum"] == pytest.approx(26 * 18)
    t = totals(run(write, text, None))
    assert "a_sum" not in t and t["b_sum"] == pytest.approx(600)


@pytest.mark.parametrize("imported", [False, True])
def test_a_constant_of_edge_distances_sets_back_each_street_side_by_its_own(write, imported):
    """``const d = comp(fe){ street.front : 5 | street.back = 2 | street.side = 1 }`` and ``setback(d)``,
    in the same file or an imported one (``setback(SU.d)``, as the Swiss building rules write it)."""
    table = "const front = 5\nconst d = comp(fe){ street.front : front | street.back = 2 | street.side = 1 }\n"
    use = "Lot --> setback({}){{ all = A | remainder : B }}\n" + \
        'A --> report("a", geometry.area)\nB --> report("b", geometry.area)\n'
    if imported:
        write("setup.cga", VERSION + table)
        text = 'import SU : "setup.cga"\n' + use.format("SU.d")
    else:
        text = table + use.format("d")
    t = totals(run(write, text, NORTH))
    assert t["b_sum"] == pytest.approx((30 - 2) * (20 - 5 - 2))  # the north street 5, south 2, east and west 1
    assert t["a_sum"] == pytest.approx(600 - 28 * 13)
