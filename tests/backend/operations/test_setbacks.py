"""backend/operations/setbacks.py in derivations: setback, setbackPerEdge, setbackToArea, shapeL/U/O and
massing's tiers, innerRectangle."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO
from derivations import (
    names,
    per_lot,
    rect,
    run,
    same_records,
    totals,
)

AREA_REPORTS = ('A --> report("a", geometry.area) A.\nB --> report("b", geometry.area) B.\n'
                'R --> report("r", geometry.area) R.\n')


@pytest.mark.parametrize("op, strips, remainder", [
    # the front edge is the lot's first edge, 30 long; its strip is 5 deep, the left one 11 wide
    ("shapeL(5, 11)", 30 * 5 + 11 * 15, 19 * 15),
    ("shapeU(5, 3, 11)", 30 * 5 + 11 * 15 + 3 * 15, 16 * 15),
    ("shapeO(2, 2, 2, 2)", 600 - 26 * 16, 26 * 16),
])
def test_shape_l_u_o_on_a_rectangle(write, op, strips, remainder):
    r = run(write, f"Lot --> {op}{{ shape : A | remainder : R }}\n" + AREA_REPORTS, [rect(30, 20)])
    t = totals(r)
    assert (t["a_n"], t["r_n"]) == (1, 1)
    assert (t["a_sum"], t["r_sum"]) == (pytest.approx(strips), pytest.approx(remainder))


def test_setback_of_all_edges_on_concave_and_holed_lots(write):
    """The L's strip is one piece; the courtyard's one ring around the lot: a hole's edges do not move, as
    PRT sets back none (massing's shapeL/U and tier setbacks on holed faces), and the remainder keeps
    the hole (was: a second ring around the hole)."""
    r = run(write, "Lot --> setback(2){ all : A | remainder : R }\n" + AREA_REPORTS,
            [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]])
    lots = per_lot(r)
    assert lots[0]["a_sum"] == pytest.approx(400 - 216) and lots[0]["r_sum"] == pytest.approx(216)
    assert lots[1]["a_n"] == 1 and lots[1]["a_sum"] == pytest.approx(1600 - 36 * 36)
    assert lots[1]["r_sum"] == pytest.approx(36 * 36 - 400)


def test_shape_l_and_tier_setbacks_of_a_holed_face_leave_the_hole_alone(write):
    """PRT's massing on a 30 m square with a 10 m courtyard: shapeL's strips (12 m) run along the outline
    only and the hole cuts them (the L is 576 - 36 m²: the hole's corner inside it); per-edge distances
    past the outline's edges (comp.index 4..7, "0;0;4;3") move none of the hole's, so the tier top keeps
    a 23 x 23 m remainder around the courtyard (was: every edge facing front or left moved, the hole's
    too, and the L took the whole face; two of the hole's edges moved 4 and 3 m)."""
    lot = [np.array([[0, 0], [30, 0], [30, 30], [0, 30]], float),
           np.array([[10, 10], [10, 20], [20, 20], [20, 10]], float)]
    t = totals(run(write, "Lot --> shapeL(12, 12){ shape : A | remainder : R }\n" + AREA_REPORTS, [lot]))
    assert t["a_sum"] == pytest.approx(576 - 36) and t["r_sum"] == pytest.approx(18 * 18 - 64)
    tier = 'Lot --> setback(comp(fe){ all : float(listItem("4;4;3;3;0;0;4;3", comp.index)) }) { all : A | remainder : R }\n'
    assert totals(run(write, tier + AREA_REPORTS, [lot]))["r_sum"] == pytest.approx(23 * 23 - 100)


def test_tier_setback_of_an_l_whose_short_end_folds(write):
    """massing's tier setback ("4;4;0;0;0;0") on its shapeL of a 10 x 6 m lot offset by 0.5: the L's 3 m
    end moves 4 m, its strip folds, and the front's moved line runs on to the arm past the kept edge: PRT
    leaves the 5.4 x 1 m rectangle (was 5.48: the folded quad's triangle cut a corner off the terrace)."""
    lot = [np.array([[0, 0], [9, 0], [9, 3], [5.4, 3], [5.4, 5], [0, 5]], float)]
    tier = 'Lot --> setback(comp(fe){ all : float(listItem("4;4;0;0;0;0", comp.index)) }) { all : A | remainder : R }\n'
    t = totals(run(write, tier + AREA_REPORTS, [lot]))
    assert (t["a_sum"], t["r_sum"]) == (pytest.approx(37.8 - 5.4), pytest.approx(5.4))


def test_setback_of_a_facade_selects_its_top_and_bottom_edges(write):
    r = run(write, "Lot --> extrude(10) comp(f){ front : F }\n"
                   "F --> setback(1){ top : A | bottom : B | remainder : R }\n" + AREA_REPORTS, [rect(30, 20)])
    t = totals(r)
    assert (t["a_sum"], t["b_sum"], t["r_sum"]) == (30, 30, 240)


def test_setback_leaves_its_parts_to_cityengine_leaf_rules(write):
    r = run(write, "Lot --> setback(3){ front : Yard | remainder : extrude(6) Mass }\n", [rect(30, 20)])
    assert sorted(names(r)) == ["Mass", "Yard"]


def test_setback_of_an_edge_shorter_than_its_distance_reaches_the_kept_edge_beside_it(write):
    """massing's terrace on the end of a narrow arm: edges 0 and 1 set back 4 m, edge 1 only 1.5 m long
    and meeting the kept edge 2 at 81 degrees. Its strip ends where its end lines cross, and the two
    strips cover the whole lot as PRT's terrace does (was: a sliver of remainder beside edge 2)."""
    arm = [np.array([[10, 0], [0, 0], [0, -1.5], [10, -3]], float)]
    text = ('Lot --> setback(comp(fe){ all : float(listItem("4;4;0;0", comp.index)) }) { all : T | remainder : R }\n'
            'T --> report("t", geometry.area)\nR --> report("r", geometry.area)\n')
    t = totals(run(write, text, [arm]))
    assert t["t_sum"] == pytest.approx(22.5)
    assert t.get("r_sum", 0.0) == pytest.approx(0.0, abs=1e-9)


def test_setback_without_parts_is_the_face_set_back_all_round(write):
    """``setback(d)`` alone, as public files write it: the remainder of ``setback(d){ all : ... }``."""
    text = 'Lot --> setback(2) report("a", geometry.area) report("x", scope.sx)\n'
    t = totals(run(write, text, [rect(12, 8)]))
    assert (t["a_sum"], t["x_sum"]) == (pytest.approx(8 * 4), pytest.approx(8))


def test_inner_rectangle_and_remainder_tile_the_lot_in_the_lot_frame(write):
    text = ("Lot --> innerRectangle(scope){ shape : A | remainder : B }\n"
            'A --> report("a", geometry.area) X\nB --> report("b", geometry.area) Y\n')
    r = run(write, text, [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]])
    t = per_lot(r)
    assert t[0]["a_sum"] == pytest.approx(300) and t[0]["b_sum"] == pytest.approx(100)
    assert t[1]["a_sum"] == pytest.approx(400) and t[1]["b_sum"] == pytest.approx(800)
    assert t[1]["b_n"] == 1  # the rest of the ring is one piece (a U)


def test_inner_rectangle_by_edge_finds_a_rotated_lot_whole(write):
    angle = np.radians(30)
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    lot = [np.array([[0, 0], [25, 0], [25, 15], [0, 15]], float) @ turn.T]
    found = {}
    for align in ("edge", "scope"):
        # the lot's scope runs along its first edge; aligned with the world's axes, scope and edge differ
        text = f'Lot --> alignScopeToAxes() innerRectangle({align}){{ shape : A }}\nA --> report("a", geometry.area)\n'
        found[align] = totals(run(write, text, [lot]))["a_sum"]
    assert found["edge"] == pytest.approx(375.0) and found["scope"] < 300


def test_setback_per_edge_evaluates_its_distance_for_each_edge(write):
    """The reference's example: distances from an array by ``comp.index`` (edges in the face's order: the
    lot's front first, then right, back, left), the same as ``setback(comp(fe){ all : ... })``."""
    text = ("const ds = [3, 2, 1, 0]\nd = ds[comp.index]\n"
            "Lot --> setbackPerEdge(d){ all : A | remainder : R }\n" + AREA_REPORTS)
    t = totals(run(write, text, [rect(30, 20)]))
    assert (t["a_sum"], t["r_sum"]) == (pytest.approx(600 - 28 * 16), pytest.approx(28 * 16))
    same = text.replace("setbackPerEdge(d)", "setback(comp(fe){ all : d })")
    same_records(run(write, text, [rect(30, 20)]), run(write, same, [rect(30, 20)]))


def test_setback_to_area_leaves_the_remainder_its_area(write):
    """The reference's examples: a square of 400 m2 set back to 100 (the same distance all round: a
    square of 10), an area to set back instead of one to keep, and an L whose front and left edges move."""
    text = 'Lot --> setbackToArea(100){ all : NIL | remainder : Q }\nQ --> report("q", geometry.area) report("x", scope.sx)\n'
    t = totals(run(write, text, [rect(20, 20)]))
    assert t["q_sum"] == pytest.approx(100, rel=1e-8) and t["x_sum"] == pytest.approx(10)
    t = totals(run(write, "Lot --> setbackToArea(geometry.area - 300){ all : A }\n" + AREA_REPORTS, [rect(30, 20)]))
    assert t["a_sum"] == pytest.approx(300, rel=1e-8)
    t = totals(run(write, "Lot --> setbackToArea(150){ front : A | left : B | remainder : R }\n" + AREA_REPORTS,
                   [LOT_ZOO["concave_L"]]))
    assert t["r_sum"] == pytest.approx(150, rel=1e-8) and t["a_sum"] + t["b_sum"] == pytest.approx(250, rel=1e-8)


def test_setback_to_area_raises_the_minimums_by_one_offset_up_to_the_maximums(write):
    """Front (edge 0) at least 4 (by index or by selector): front and back move 4 + c and c, c = 3 leaving
    30 x 10. Maximums of 1 leave more than the area asked, as does a face smaller than it (nothing moves
    but the minimums)."""
    text = "Lot --> setbackToArea(300, [4, 0, 0, 0]){ front : F | back : B | remainder : R }\n" \
        'F --> report("f", geometry.area)\nB --> report("b", geometry.area)\nR --> report("r", geometry.area)\n'
    t = totals(run(write, text, [rect(30, 20)]))
    assert (t["f_sum"], t["b_sum"], t["r_sum"]) == (pytest.approx(210), pytest.approx(90), pytest.approx(300))
    by_selector = text.replace("[4, 0, 0, 0]", "comp(fe){ front : 4 | all : 0 }")
    same_records(run(write, text, [rect(30, 20)]), run(write, by_selector, [rect(30, 20)]))
    t = totals(run(write, text.replace("[4, 0, 0, 0]", "[0], [1, 0, 1]"), [rect(30, 20)]))
    assert (t["f_sum"], t["b_sum"], t["r_sum"]) == (pytest.approx(30), pytest.approx(30), pytest.approx(540))
    t = totals(run(write, text.replace("300, [4, 0, 0, 0]", "700"), [rect(30, 20)]))
    assert (t.get("f_n", 0), t["r_sum"]) == (0, pytest.approx(600))


def test_setback_to_area_of_a_solid_or_a_roof_fails_its_lot_by_name(write):
    for body, reason in [("extrude(3) setbackToArea(10)", "`setbackToArea` of a solid is not supported yet"),
                         ("roofHip(30) setbackToArea(10)", "`setbackToArea` of a roof is not supported yet"),
                         ("setbackToArea(-1)", "`setbackToArea` with an area that is not a positive number")]:
        (bad,) = run(write, f"Lot --> {body}{{ all : A | remainder : R }}\n", [rect(10, 8)])["bad"]
        assert bad.reason.startswith(reason), bad.reason


#: massing's footprint (``{footprint}``) and first tier (``{distances}`` per edge) after an offset (the kit's
#: massing rule package, reduced).
MASSING_TIER = """
Lot --> offset(-{offset}) comp(f){{ inside : Space }}
Space --> rotateScope(0, {orientation}, 0) alignScopeToAxes(y) {footprint}
Footprint --> extrude(12.2) comp(f){{ top : Top }}
Top --> setback(comp(fe){{ all : float(listItem("{distances}", comp.index)) }}) {{ all : T | remainder : R }}
T --> report("t", geometry.area)
R --> report("r", geometry.area)
"""


SPLIT_FOOTPRINT = "split(z){{ '{coverage} : Footprint | ~1 : NIL }}"


T_LOT = [np.array([[0, 0], [30, 0], [30, 20], [16, 20], [16, 30], [10, 30], [10, 20], [0, 20]], float)]


def _massing_tier(write, lot, **fields):
    t = totals(run(write, MASSING_TIER.format(**fields), [lot]))
    return t["t_sum"], t.get("r_sum", 0.0)


@pytest.mark.parametrize("lot, offset, orientation, coverage, terrace, remainder", [
    (T_LOT, 4, 0, 1, 176, 88),
    (T_LOT, 4, 90, 0.5, 88, 44),
    ([np.array([[14.406894270, -5.510212092], [20.305712965, 6.879814355], [-7.461061809, 20.099412460],
                [-13.359880504, 7.709386014], [-3.390871145, 2.963199310], [-15.980567771, -23.480514629],
                [-8.151811715, -27.207739327], [4.437884911, -0.764025388]])], 4.916, 90, 0.204, 11.476, 5.129),
])
def test_an_inset_whose_arm_closed_splits_its_run_on_the_arm_centre_line(write, lot, offset, orientation,
                                                                          coverage, terrace, remainder):
    """A T's stem that the offset closes leaves a vertex on the bar's inset edge, where the stem's centre
    line crosses it, and the tier's per-edge setback moves that edge's two parts by edges 2 and 3's
    distances: PRT's terraces and remainders (the harness's T.18003 last; was: the vertex where a moved
    side of the stem crosses the edge, 176 / 88 m² became 144 / 120)."""
    footprint = SPLIT_FOOTPRINT.format(coverage=coverage)
    assert _massing_tier(write, lot, offset=offset, orientation=orientation, footprint=footprint,
                         distances="4;0;4;4;0") == (pytest.approx(terrace, abs=2e-3), pytest.approx(remainder, abs=2e-3))


def test_shape_u_that_covers_its_face_numbers_its_edges_as_the_face(write):
    """massing's shapeU at 96.7 % coverage on the harness's convex.18196: its strips cover the face, and
    where two meet on an edge the snap leaves their seam half a nanometre off the edge's line; the seam
    goes all the same, so the tier numbers the edges as the face's, as PRT does (was: the seam a vertex,
    the edges after it one place on: 108.5 / 68.6 m²)."""
    lot = [np.array([[0.430184124, 14.652312455], [-14.164624001, 1.523659906], [-13.931906806, 0.719325577],
                     [-9.704342417, -6.559701915], [-6.409414739, -10.744167533], [-3.499063128, -11.872745259],
                     [16.195570709, -4.481595230], [12.420123124, 0.670553400]])]
    footprint = "shapeU(0.967 * scope.sz, 0.967 * scope.sx, 0.967 * scope.sx){ shape : Footprint | remainder : NIL }"
    assert _massing_tier(write, lot, offset=3.805, orientation=270, footprint=footprint,
                         distances="4;4;3;3;0;0;4;3") == (pytest.approx(118.166, rel=1e-4),
                                                          pytest.approx(56.551 + 2.348, rel=1e-4))


@pytest.mark.parametrize("first, terrace", [
    ("4;0;4;4", 8.0),  # the jog carried along its line: PRT's tier starts at edge 2's moved line, 8 m long
    ("4;0;4;0", 4.0),  # edge 3 kept too: at edge 2's moved line, not at edge 3's kept vertex it runs through
    ("3;0;4;4", 10.0),  # the jog's far end moved further: it vanishes, the tier starts at edge 0's moved line
])
def test_tier_setback_past_a_kept_jog_starts_where_prt_starts_it(write, first, terrace):
    """massing's two tiers on a 20 x 6 m block whose 0.6 m jog after edge 0 is kept, its second tier setting
    back its edge 0 alone by 1 m: PRT's terrace measured through PyPRT (massing.tartu.8's second tier; the
    first was 10 m^2 where PRT's is 8)."""
    block = [np.array([[20, 5.4], [10, 5.4], [10, 6], [6, 6], [6, 6.6], [4, 6.6], [4, 6], [0, 6], [0, 0], [20, 0]],
                      float)]
    text = (f'Lot --> setback(comp(fe){{ all : float(listItem("{first};0;0;0;0;0;0", comp.index)) }})'
            '{ all : A | remainder : R }\n'
            'R --> setback(comp(fe){ all : float(listItem("1", comp.index)) }) { all : T | remainder : S }\n'
            'T --> report("t", geometry.area)\n')
    assert totals(run(write, text, [block]))["t_sum"] == pytest.approx(terrace)


def test_tier_setback_past_a_swept_arm_starts_where_prt_starts_it(write):
    """massing's two tiers on a 12 x 11 m block whose 1.4 m wide arm's end (edge 0) its first tier sets back
    4 m, past the arm's 3.5 m top (the last edge), the second tier setting back its edge 0 alone by 1 m: PRT's
    terrace is the strip along the edge before the last, 4.8 m^2, measured through PyPRT (was 1.2, along
    edge 0's moved line; massing.seoul.37's second tier)."""
    block = [np.array([[0, 8.2], [0, 6.8], [1.7, 6.8], [1.7, 3], [12, 3], [12, 14], [5, 14], [5, 13], [3.5, 13],
                       [3.5, 8.2]], float)]
    text = ('Lot --> setback(comp(fe){ all : float(listItem("4;0;4;4;0;0;0;0;0;0", comp.index)) })'
            '{ all : A | remainder : R }\n'
            'R --> setback(comp(fe){ all : float(listItem("1", comp.index)) }) { all : T | remainder : S }\n'
            'T --> report("t", geometry.area)\n')
    assert totals(run(write, text, [block]))["t_sum"] == pytest.approx(4.8)


#: The harness's holes.43809 (3 cm walls between four holes and the outline, after massing's offset) and
#: holes.43669 (four holes whose ends lie on one line), with massing's attributes.
HOLED_LOTS = {
    "holes.43809": ([np.array([[28.447266718, -16.358252619], [4.625587899, 31.783369973],
                               [-28.85942844, 15.214146472], [-5.037749621, -32.927476121]]),
                     np.array([[16.213406449, -7.429576378], [7.302412105, 10.578798679],
                               [9.478723148, 11.65569181], [18.389717492, -6.352683247]]),
                     np.array([[-0.52910172, -15.714188129], [-9.507937149, 2.431288092],
                               [-5.709473306, 4.310862996], [3.269362123, -13.834613225]]),
                     np.array([[-8.900355805, -19.856494004], [-19.205291215, 0.968919483],
                               [-15.936152829, 2.586570913], [-5.631217419, -18.238842574]]),
                     np.array([[7.842152365, -11.571882253], [-2.528698499, 9.386740858],
                               [0.153852654, 10.714134256], [10.524703518, -10.244488855]])], 4.044, 90, 0.443),
    "holes.43669": ([np.array([[-34.289722811, 11.239262623], [4.456837645, -34.648222832],
                               [33.298402915, -10.294928219], [-5.448157542, 35.592557236]]),
                     np.array([[2.435884743, 22.598604959], [12.21616943, 11.015830488],
                               [8.818497175, 8.14689766], [-0.961787512, 19.729672131]]),
                     np.array([[-11.984897892, 10.421957653], [2.929003339, -7.240550135],
                               [-0.052281588, -9.757893055], [-14.966182818, 7.904614732]]),
                     np.array([[-19.195289209, 4.333633999], [-3.910658524, -13.767928049],
                               [-6.763472104, -16.176792094], [-22.048102789, 1.924769954]]),
                     np.array([[-4.774506574, 16.510281306], [11.603392096, -2.886036152],
                               [8.774834301, -5.274419052], [-7.603064369, 14.121898406]])], 7.232, 0, 0.066),
}


@pytest.mark.parametrize("name", sorted(HOLED_LOTS))
def test_a_holed_lot_s_tier_is_the_same_wherever_the_lot_lies(write, name):
    """massing's shapeO and first tier on a holed lot at its own place and moved 2 km away, as the harness
    spreads its batches: the same terrace and remainder, piece for piece. Rounding leaves the moved lot's
    scope coordinates up to 1e-13 m off; GEOS's overlay cut off a face's vertex 1e-14 m outside a strip's
    line (holes.43809: 316 faces for 346) and its inset's vertices on a run of closed channels moved
    (holes.43669: 6564.5 m² of building at home, 5334.8 away; PRT's 5346.8 both ways)."""
    rings, offset, orientation, coverage = HOLED_LOTS[name]
    c = f"{coverage} * scope.sz, {coverage} * scope.sx"
    fields = {"offset": offset, "orientation": orientation, "distances": "3;0;3;3;0",
              "footprint": f"shapeO({c}, {c}){{ shape : Footprint | remainder : NIL }}"}
    home = totals(run(write, MASSING_TIER.format(**fields), [rings]))
    for shift in ((2000.0, 0.0), (0.0, 2000.0), (-6000.0, 4000.0)):
        away = totals(run(write, MASSING_TIER.format(**fields), [[ring + shift for ring in rings]]))
        assert (away["t_n"], away.get("r_n", 0)) == (home["t_n"], home.get("r_n", 0))
        assert away["t_sum"] == pytest.approx(home["t_sum"], rel=1e-9)
        assert away.get("r_sum", 0.0) == pytest.approx(home.get("r_sum", 0.0), rel=1e-9)
