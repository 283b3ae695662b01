"""backend/derive.py: whole derivations: the paper's own figures and examples (section 2 and 4 of the
CGA paper), CityEngine's building fixture, records that depend on the seed and never on the chunking,
bad lots."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from conftest import LOT_ZOO, make_lots
from operations.derivations import (
    assets,
    names,
    paper,
    rect,
    same_records,
    totals,
)

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar

BUILDING = Path(__file__).resolve().parents[1] / "frontend" / "grammars" / "cityengine" / "building.cga"


def _same_with_reports(a, b):
    for key in ("asset", "xform", "lot", "symbol"):
        np.testing.assert_array_equal(a[key], b[key])
    np.testing.assert_array_equal(a["mesh"].vertices, b["mesh"].vertices)
    np.testing.assert_array_equal(a["mesh"].lot, b["mesh"].lot)
    assert a["reports"].lots == b["reports"].lots


def test_building_fixture_derives(write):
    grammar = compile_grammar(BUILDING)
    lots = make_lots("rect_12x8", "concave_L", "courtyard", "square")
    r = derive(grammar, lots, BuildOptions(seed=3))
    assert r["bad"] == ()
    count = Counter(names(r))
    meshes = Counter(str(s) for s in r["symbols"][r["mesh"].symbol])
    assert {"Wall", "Glass", "Shutter", "Door", "Roof"} <= set(count)
    assert count["Glass"] > 1.5 * count["Shutter"]  # 70 % : 30 %
    assert set(assets(r)) == {"builtin:quad", "builtin:cube", "assets/window.obj"}
    # ledges run past the corners, where the facades' trim planes cut them into mitred meshes
    assert "Ledge" not in count and meshes["Ledge"] > 0
    # the L and the courtyard have polygon roofs
    assert sorted(set(r["mesh"].lot[r["symbols"][r["mesh"].symbol] == "Roof"])) == [1, 2]
    t = totals(r)
    assert t["lot.area_sum"] == pytest.approx(96 + 400 + 1200 + 100)
    assert t["mass.volume_sum"] == pytest.approx(15 * (96 + 400 + 1200 + 100))


def test_records_do_not_depend_on_the_chunk_size_and_repeat_with_the_seed(write):
    grammar = compile_grammar(BUILDING)
    lots = make_lots("rect_12x8", "concave_L", "courtyard", "square", "rect_12x8")
    whole = derive(grammar, lots, BuildOptions(seed=7))
    _same_with_reports(whole, derive(grammar, lots, BuildOptions(seed=7, chunk_size=1)))
    _same_with_reports(whole, derive(grammar, lots, BuildOptions(seed=7, chunk_size=2)))
    other = derive(grammar, lots, BuildOptions(seed=8))
    assert not np.array_equal(whole["asset"], other["asset"])


def test_mass_model_of_figure_3(write):
    """Paper section 2: A ~> [T(0,0,6) S(8,10,18) I(cube)] T(6,0,0) S(7,13,18) I(cube) T(0,0,16) ..."""
    r = paper(write, 'A ~> [ T(0,0,6) S(8,10,18) I("cube") ] T(6,0,0) S(7,13,18) I("cube") '
                   'T(0,0,16) S(8,15,8) I("cylinder")\n', [rect(30, 20)])
    assert list(r["assets"][r["asset"]]) == ["builtin:cube", "builtin:cube", "builtin:cylinder"]
    x = r["xform"]
    np.testing.assert_allclose(np.diagonal(x[:, :, :3], axis1=1, axis2=2), [[8, 10, 18], [7, 13, 18],
                                                                            [8, 15, 8]])
    np.testing.assert_allclose(x[:, :, 3], [[0, 0, 6 - 20], [6, 0, 0 - 20], [6, 0, 16 - 20]])


SECTION_4 = """
attr building_height = 14
attr window_spacing = 3
attr window_width = 1.2
attr window_height = 1.6
attr window_depth = 0.25
attr door_width = 1.5
attr door_height = 2.4
attr door_depth = 0.3
PRIORITY 1:
1: footprint ~> S(1r,building_height,1r) facades
PRIORITY 2:
2: facades ~> Comp("sidefaces"){ facade }
3: facade : Scope.sx > 12
     ~> Subdiv("X",1r,door_width*1.5){ tiles | entrance } : 0.5
     ~> Subdiv("X",door_width*1.5,1r){ entrance | tiles } : 0.5
4: facade ~> tiles
5: tiles ~> Repeat("X",window_spacing){ tile }
6: tile ~> Subdiv("X",1r,window_width,1r){ wall |
      Subdiv("Y",2r,window_height,1r){ wall | window | wall } | wall }
8: window ~> S(1r,1r,window_depth) I("win.obj")
9: entrance ~> Subdiv("X",1r,door_width,1r){ wall |
      Subdiv("Y",door_height,1r){ door | wall } | wall }
10: door ~> S(1r,1r,door_depth) I("door.obj")
11: wall ~> I("wall.obj")
"""


def test_section_4_building_on_concave_footprint_with_hole(write):
    """Paper section 4 rules 1-11 (occlusion and visibility guards replaced) on an L with a courtyard."""
    l_with_hole = [
        np.array([[0, 0], [30, 0], [30, 12], [14, 12], [14, 24], [0, 24]], float),
        np.array([[3, 3], [3, 9], [9, 9], [9, 3]], float),
    ]
    r = paper(write, SECTION_4, [l_with_hole, rect(20, 10)])
    assets = r["assets"][r["asset"]]
    assert {"win.obj", "door.obj", "wall.obj"} <= set(assets)
    # one facade per edge, hole edges included: 6 + 4 on the L, 4 on the rectangle
    lot0 = r["lot"] == 0
    facade_normals = set()
    for rows in (lot0 & (assets == "win.obj"),):
        n = np.cross(r["xform"][rows, :, 0], r["xform"][rows, :, 1])
        facade_normals |= {tuple(np.round(v / np.linalg.norm(v), 3)) for v in n}
    assert len(facade_normals) == 4  # windows face +x, -x, +z, -z (hole walls face inwards)
    # every instance stays within the footprint's box and the building height
    lo = r["xform"][:, :, 3].min(axis=0)
    assert lo[1] >= -1e-4 and r["xform"][:, 1, 3].max() <= 14 + 1e-4
    # doors only on facades longer than 12 m, one per such facade
    # the L's outer edges are 30, 12, 16, 12, 14 and 24 long, the hole's 6: four are longer than 12
    assert (lot0 & (assets == "door.obj")).sum() == 4
    # windows: Repeat ceil(width/3) tiles per facade minus the entrance parts, each one window
    assert (assets == "win.obj").sum() > 20
    assert not r["bad"]


def test_same_seed_same_records_and_chunking_does_not_matter(write):
    """The door side of rule 3 is random: records depend on the seed, never on the chunking."""
    polygons = [LOT_ZOO[n] for n in ("square", "concave_L", "courtyard", "rect_12x8")] * 5
    base = paper(write, SECTION_4, polygons, seed=7)
    same_records(base, paper(write, SECTION_4, polygons, seed=7))
    same_records(base, paper(write, SECTION_4, polygons, seed=7, chunk_size=1))
    same_records(base, paper(write, SECTION_4, polygons, seed=7, chunk_size=3))
    same_records(base, paper(write, SECTION_4, polygons, seed=7, chunk_size=2, workers=2))
    other = paper(write, SECTION_4, polygons, seed=8)
    assert not np.array_equal(base["xform"], other["xform"])


def test_chunk_split_on_budget_keeps_records(write):
    polygons = [rect(12, 8)] * 6
    base = paper(write, SECTION_4, polygons)
    same_records(base, paper(write, SECTION_4, polygons, chunk_budget=50))


def test_bad_lots_from_input_are_listed(write):
    r = paper(write, 'lot ~> S(1r, 3, 1r) I("cube")\n',
            [rect(5, 5), [np.array([[0, 0], [2, 2], [2, 0], [0, 2]], float)], rect(4, 4)])
    assert list(np.unique(r["lot"])) == [0, 2]
    assert [b.index for b in r["bad"]] == [1]


@pytest.mark.parametrize("rule", [
    'lot ~> S(1r, 3, Scope.sx - 10) I("cube")\n',  # a negative size (``fail_negative``)
    'lot ~> T(0, 0, 1e40 * (10 - Scope.sx)) I("cube")\n',  # beyond any coordinate (``refuse_far``)
])
def test_a_bad_lots_reason_quotes_its_own_value_whatever_the_chunking(write, rule):
    """Lots that fail alike, each by its own value: each lot's reason quotes its own, however the lots are
    chunked (it quoted the first of its chunk's, which made the reasons depend on the chunking)."""
    polygons = [rect(w, 4) for w in (3, 12, 5, 7, 11)]
    reasons = {chunk_size: [b.reason for b in paper(write, rule, polygons, chunk_size=chunk_size)["bad"]]
               for chunk_size in (1, 2, 16)}
    assert reasons[1] == reasons[2] == reasons[16]
    assert len(reasons[1]) >= 3 and len(set(reasons[1])) == len(reasons[1])


def test_zoo_lots_all_derive(write):
    lots = make_lots("square", "rect_12x8", "concave_L", "courtyard", "sliver")
    grammar = compile_grammar(write("g.cga", SECTION_4))
    r = derive(grammar, lots)
    assert set(np.unique(r["lot"])) == {0, 1, 2, 3, 4}

