"""backend/operations/values.py in derivations: ``set`` inherited by successors and parts, undone by
a pop, and ``report`` per lot and in total."""

from __future__ import annotations

import pytest
from derivations import (
    names,
    per_lot,
    rect,
    run,
    totals,
)


def test_set_is_inherited_by_successors_and_seen_by_case(write):
    r = run(write, "attr h = 3\nLot --> set(h, 7) extrude(h) Mass\n"
                   "Mass -->\n    case h > 5 : Tall\n    else : Short\n", [rect(2, 2)])
    assert names(r) == ["Tall"]
    assert r["xform"][0, 1, 1] == 7


def test_set_reaches_split_parts_and_grandchildren(write):
    r = run(write, 'attr floor = -1\nLot --> extrude(9) split(y){ ~3 : Floor }*\n'
                   'Floor --> set(floor, split.index) split(x){ ~1 : Tile }*\n'
                   'Tile --> report("floor" + floor, 1)\n', [rect(4, 4)])
    t = totals(r)
    assert [t[f"floor{i}_n"] for i in range(3)] == [4, 4, 4]


def test_set_inside_push_pop_is_undone_by_the_pop(write):
    r = run(write, 'attr h = 3\nLot --> extrude(1) [ set(h, 7) A ] B\nA --> report("a", h)\n'
                   'B --> report("b", h)\n', [rect(2, 2)])
    assert (totals(r)["a_sum"], totals(r)["b_sum"]) == (7, 3)


def test_reports_per_lot_and_totals(write):
    r = run(write, 'Lot --> report("lots", 1) report("area", geometry.area) report("big", scope.sx > 10)\n'
                   '    report("name", "lot" + scope.sx) extrude(5) comp(f){ side : Side }\n'
                   'Side --> report("side.width", scope.sx)\n', [rect(12, 8), rect(6, 4)])
    lots = per_lot(r)
    assert lots[0]["side.width_n"] == 4 and lots[0]["side.width_sum"] == pytest.approx(40)
    assert (lots[1]["side.width_min"], lots[1]["side.width_max"], lots[1]["side.width_avg"]) == (4, 6, 5)
    t = totals(r)
    assert (t["lots_n"], t["lots_sum"], t["lots_avg"]) == (2, 2, 1)
    assert (t["area_sum"], t["area_min"], t["area_max"], t["area_avg"]) == (120, 24, 96, 60)
    assert (t["side.width_n"], t["side.width_sum"], t["side.width_avg"]) == (8, 60, 7.5)
    # booleans: sum and max any, min all, avg the majority
    assert (t["big_n"], t["big_sum"], t["big_min"], t["big_max"]) == (2, True, False, True)
    assert (lots[1]["big_sum"], lots[1]["big_avg"]) == (False, False)
    # strings: the first value for sum and avg, compared as text for min and max
    assert (t["name_n"], t["name_sum"], t["name_avg"]) == (2, "lot12", "lot12")
    assert (t["name_min"], t["name_max"]) == ("lot12", "lot6")



def test_reset_material_makes_the_colour_white_and_opaque_and_drops_the_textures(write):
    r = run(write, 'Lot --> color(1, 0, 0) set(material.opacity, 0.5) texture("a.png") [ Before ] resetMaterial() After\n'
            'Before --> report("g0", material.color.g) report("o0", material.opacity) '
            'report("m0", case material.colormap == "" : 1 else : 0)\n'
            'After --> report("g1", material.color.g) report("o1", material.opacity) '
            'report("m1", case material.colormap == "" : 1 else : 0)\n', [rect(2, 2)])
    t = totals(r)
    assert [t[f"{k}0_sum"] for k in "gom"] == [0, pytest.approx(0.5, abs=0.01), 0]
    assert [t[f"{k}1_sum"] for k in "gom"] == [1, 1, 1]


MATERIAL_REPORTS = ('A --> report("r", material.color.r) report("g", material.color.g) '
                    'report("o", material.opacity) report("c", case material.colormap == "a.png" : 1 else : 0)\n')


def test_set_material_sets_each_named_attribute(write):
    """The reference's form: names without ``material.``, values as texts; a later pair wins, and an
    attribute grammarc does not carry (``shininess``) changes nothing."""
    r = run(write, 'm = ["color.r", "1", "color.g", "0.2", "color.b", "0", "opacity", "0.5", "colormap", "b.png",\n'
            '     "shininess", "3", "colormap", "a.png"]\nLot --> color(0, 0, 1) setMaterial(m) A\n'
            + MATERIAL_REPORTS, [rect(2, 2)])
    t = totals(r)
    assert [t[f"{k}_sum"] for k in "rgoc"] == [1, pytest.approx(0.2, abs=0.01), pytest.approx(0.5, abs=0.01), 1]


def test_set_material_reads_a_table_of_two_columns(write, tmp_path):
    (tmp_path / "m.csv").write_text("color.r,0\ncolor.g,1\ncolormap,a.png\n")
    r = run(write, 'Lot --> setMaterial(readStringTable("m.csv")) A\n' + MATERIAL_REPORTS, [rect(2, 2)])
    t = totals(r)
    assert [t[f"{k}_sum"] for k in "rgoc"] == [0, 1, 1, 1]


def test_set_material_of_a_value_that_is_no_number_fails_its_lot(write):
    r = run(write, 'Lot --> setMaterial(["opacity", "half"]) A.\n', [rect(2, 2)])
    (bad,) = r["bad"]
    assert "setMaterial: `opacity` is not a number (`half`)" in bad.reason
