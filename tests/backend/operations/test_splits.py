"""backend/operations/splits.py in derivations: the paper's Subdiv and Repeat on the sizes of its
section 2, CityEngine's split, and sizes that fail their lot (snapped splits: test_snaps.py, the
layouts of CityEngine's split: test_group_split.py)."""

from __future__ import annotations

import subprocess
import sys
from collections import Counter

import numpy as np
import pytest
from conftest import LOT_ZOO
from derivations import (
    make_lots_polys,
    mesh_faces,
    names,
    of_symbol,
    paper,
    rect,
    rows,
    run,
    same_records,
    totals,
)


def test_split_index_numbers_the_floors_from_the_bottom(write):
    r = run(write, 'Lot --> extrude(10) split(y){ ~3 : Floor }*\n'
                   'Floor --> report("floor" + split.index, split.total) Kind\n'
                   'Kind -->\n    case split.index == 0 : Ground.\n    else : Upper.\n', [rect(5, 5)])
    assert Counter(names(r)) == {"Ground": 1, "Upper": 2}
    ground, upper = r["xform"][rows(r, "Ground")], r["xform"][rows(r, "Upper")]
    assert ground[0, 1, 3] == 0 and (upper[:, 1, 3] > 3).all()
    np.testing.assert_allclose(r["xform"][:, 1, 1], 10 / 3, rtol=1e-6)
    t = totals(r)
    assert [t[f"floor{i}_sum"] for i in range(3)] == [3, 3, 3]


def test_split_along_z_with_absolute_and_floating_parts(write):
    r = run(write, "Lot --> extrude(3) split(z){ 2 : Front | ~1 : Middle | 2 : Back }\n", [rect(4, 10)])
    assert names(r) == ["Front", "Middle", "Back"]
    np.testing.assert_allclose(r["xform"][:, 2, 2], [2, 6, 2])
    np.testing.assert_allclose(r["xform"][:, 2, 3], [-10, -8, -2])


def test_subdiv_relative_sizes_on_widths_12_and_10(write):
    """Paper section 2: Subdiv("X",2,1r,1r,2) gives 2,4,4,2 on width 12 and 2,3,3,2 on width 10."""
    r = paper(write, 'floor ~> S(1r, 3, 1r) Subdiv("X",2,1r,1r,2){ B | A | A | B }\n'
                   'A ~> I("cube")\nB ~> I("cube")\n', [rect(12, 5), rect(10, 5)])
    for lot, want in ((0, [2, 4, 4, 2]), (1, [2, 3, 3, 2])):
        rows = r["lot"] == lot
        order = np.argsort(r["xform"][rows, 0, 3])
        np.testing.assert_allclose(r["xform"][rows, 0, 0][order], want)
        np.testing.assert_allclose(r["xform"][rows, 0, 3][order], np.cumsum([0, *want[:-1]]))
    # B at both ends, A in the middle
    rows = r["lot"] == 0
    symbols = r["symbols"][r["symbol"][rows][np.argsort(r["xform"][rows, 0, 3])]]
    assert list(symbols) == ["B", "A", "A", "B"]


def test_subdiv_facade_of_12_8(write):
    """Paper section 2: Subdiv("Y",3.5,0.3,3,3,3) on a facade 12.8 high: four floors and a ledge."""
    r = paper(write, 'lot ~> S(1r, 12.8, 1r) Comp("sideface", 0){ fac }\n'
                   'fac ~> Subdiv("Y",3.5,0.3,3,3,3){ floor | ledge | floor | floor | floor }\n',
            [rect(10, 10)])
    heights = r["xform"][:, 1, 1]
    bottoms = r["xform"][:, 1, 3]
    order = np.argsort(bottoms)
    np.testing.assert_allclose(heights[order], [3.5, 0.3, 3, 3, 3])
    np.testing.assert_allclose(bottoms[order], [0, 3.5, 3.8, 6.8, 9.8])
    assert list(r["symbols"][r["symbol"][order]]) == ["floor", "ledge", "floor", "floor", "floor"]
    # leaves of a flat scope are quads
    assert set(r["assets"][r["asset"]]) == {"builtin:quad"}


@pytest.mark.parametrize("width, count", [(12, 6), (11, 6), (10.5, 6), (2, 1), (0.5, 1)])
def test_repeat_counts_ceil(write, width, count):
    """Paper section 2: Repeat("X",2) makes ceil(Scope.sx/2) elements of equal, adjusted size."""
    r = paper(write, 'floor ~> S(1r, 3, 1r) Repeat("X", 2){ B }\nB ~> I("cube")\n', [rect(width, 4)])
    assert len(r["asset"]) == count
    np.testing.assert_allclose(r["xform"][:, 0, 0], width / count)
    np.testing.assert_allclose(np.sort(r["xform"][:, 0, 3]), np.arange(count) * width / count, atol=1e-5)


def test_repeat_xy_grid_and_alternating_parts(write):
    r = paper(write, 'f ~> S(1r, 4, 1r) Comp("sideface", 0){ g }\ng ~> Repeat("XY", 2, 1){ A | B }\n',
            [rect(6, 6)])
    assert len(r["asset"]) == 3 * 4
    assert of_symbol(r, "A").sum() == 6 and of_symbol(r, "B").sum() == 6


def test_nan_split_size_lot_is_reported(write):
    r = paper(write, 'lot ~> S(1r, 2, 1r) Subdiv("X", 1, sqrt(Scope.sx - 11)){ a | b }\n',
            [rect(12, 5), rect(10, 5)])
    assert list(np.unique(r["lot"])) == [0]
    assert r["bad"][0].index == 1 and "Subdiv" in r["bad"][0].reason


def test_a_negative_subdiv_size_of_every_shape_fails_their_lots(write):
    """A size negative for every shape (a constant, one row for the batch) fails the lots of all of them:
    it gave an IndexError where the batch held more than one shape (a facade's four sides)."""
    r = paper(write, 'attr w = 2\nlot ~> S(1r, 3, 1r) Comp("sidefaces"){ f }\nf ~> Subdiv("X", -2, 1r){ a | b }\n'
                     'a ~> I("cube")\nb ~> I("cube")\n', [rect(10, 10)] * 2)
    assert len(r["lot"]) == 0
    assert [b.reason.split(" in rule")[0] for b in r["bad"]] == ["`Subdiv` has a negative or NaN size (-2, 1)"] * 2


@pytest.mark.parametrize("text", [
    'Lot --> split(x){ tile : A. }*\n',
    'Lot --> split(x){ ~tile : A. }*\n',
    'Lot --> split(x){ 1 : A. | { tile : B. | ~tile : C. }* | 1 : A. }\n',
    'Lot --> splitArea(x){ tile : A. }*\n',
])
def test_a_split_of_too_many_or_too_small_parts_fails_its_lot_only(write, text):
    """A repeat of a size too small for --max-shapes (or for int64's count, or too small to lay at all,
    which made nothing and said nothing) fails its lot, counted before anything is made; the others
    derive as they would alone."""
    tiles = np.array([2.0, 1e-7, 2.0, 1e-18, 1e-9])
    r = run(write, "attr tile = 2\n" + text, [rect(30, 20)] * 5, lot_attrs={"tile": tiles})
    alone = run(write, "attr tile = 2\n" + text, [rect(30, 20)])
    assert np.unique(r["lot"]).tolist() == [0, 2] and (r["lot"] == 0).sum() == len(alone["lot"])
    assert [b.index for b in r["bad"]] == [1, 3, 4]
    assert all(b.reason.startswith("more than 2,000,000 shapes (") and "in rule `Lot` at" in b.reason
               for b in r["bad"])
    assert "(beyond counting)" in r["bad"][1].reason


def test_a_repeat_of_a_size_near_float64s_largest_fits_no_time(write):
    """A repetition of 1e308 m fits no time into 10 m: its share of the room overflowed (``left *
    nominal``) to inf, which counted beyond any --max-shapes and failed the lot."""
    r = run(write, 'Lot --> extrude(10) split(y){ 1e308 : A. | ~1 : B. }*\n', [rect(10, 10)])
    assert r["bad"] == () and len(r["xform"]) == 1


def test_a_repeat_whose_count_overflows_fails_its_lot(write):
    """``Repeat("X", 1e-18)`` makes 3e19 elements: more than int64 counts (it gave one element spanning
    the facade), so its lot fails, before anything is allocated."""
    r = paper(write, 'attr w = 2\nlot ~> S(1r, 3, 1r) Repeat("X", w){ tile }\ntile ~> I("cube")\n',
              [rect(30, 20)] * 3, lot_attrs={"w": np.array([2.0, 1e-18, 1e-7])})
    assert np.unique(r["lot"]).tolist() == [0]
    assert [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]] == [
        (1, "more than 2,000,000 shapes (beyond counting)"), (2, "more than 2,000,000 shapes (300,000,000)")]


def test_a_split_of_a_billion_parts_is_refused_in_little_time_and_memory(write, tmp_path):
    """The fuzz's ``split(x){ 1e-7 : A. }*`` on a 30 x 20 lot passed 4 GiB in 10 s: the parts are counted
    and checked against --max-shapes before they are made. Measured in a process of its own (the kernels
    allocate outside tracemalloc's sight)."""
    grammar = write("g.cga", 'version "2022.0"\n@StartRule\nLot --> split(x){ 1e-7 : A. }*\n')
    script = f"""
import resource, sys, time
from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.io.lots import default_lot
grammar = compile_grammar({str(grammar)!r})
derive(grammar, default_lot())  # the kernels loaded
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
started = time.perf_counter()
r = derive(grammar, default_lot())
print(time.perf_counter() - started, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before, len(r["bad"]))
"""
    seconds, grown_kb, bad = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                                            timeout=120, check=True).stdout.split()
    assert bad == "1" and float(seconds) < 1.0 and int(grown_kb) < 50_000



SCOPE_REPORT = 'P --> report("sx", scope.sx) report("sz", scope.sz) report("tx", scope.tx) report("tz", scope.tz) Q\n'


def _scope_of_p(r):
    return {k: v["sum"] for k, v in r["reports"].lots[0].items()}


def _outline(r):
    """The vertices of every mesh face and quad of the records, sorted (the same surface however kept)."""
    quads = [x[:, 3] + x[:, :3] @ c for x in r["xform"].astype(float) for c in ([0, 0, 0], [1, 0, 0], [1, 1, 0],
                                                                                  [0, 1, 0])]
    faces = [v for face in mesh_faces(r) for ring in face for v in ring.astype(float)]
    return np.unique(np.round(np.array(quads + faces).reshape(-1, 3), 6), axis=0)


def test_no_adjust_keeps_a_part_scope_its_slab_of_the_lot_and_its_piece_of_the_geometry(write):
    """The L lot (30 x 10 below, 10 x 10 above on the left), split across its two wings: the part of the
    upper wing is a 10 x 4 piece whose scope is fitted to it, or with noAdjust the whole slab 30 x 4
    (CityEngine's reference: the scopes fill the parent's scope without gaps)."""
    adjusted = run(write, "Lot --> split(z){ 4 : P | ~1 : NIL }\n" + SCOPE_REPORT, make_lots_polys("concave_L"))
    slab = run(write, "Lot --> split(z, noAdjust){ 4 : P | ~1 : NIL }\n" + SCOPE_REPORT,
               make_lots_polys("concave_L"))
    assert _scope_of_p(adjusted) == {"sx": 10, "sz": 4, "tx": 0, "tz": 0}
    assert _scope_of_p(slab) == {"sx": 30, "sz": 4, "tx": 0, "tz": 0}
    np.testing.assert_allclose(_outline(slab), _outline(adjusted))
    np.testing.assert_allclose(_outline(slab), [[0, 0, -20], [0, 0, -16], [10, 0, -20], [10, 0, -16]])


def test_no_adjust_on_a_roof_keeps_the_slab_and_the_cut_mesh(write):
    text = "Lot --> roofHip(30) split(y{}){{ 1 : NIL | ~1 : P }}\n" + SCOPE_REPORT
    adjusted = run(write, text.format(""), [rect(20, 10)])
    slab = run(write, text.format(", noAdjust"), [rect(20, 10)])
    assert _scope_of_p(slab)["sx"] == 20 and _scope_of_p(adjusted)["sx"] < 17
    np.testing.assert_allclose(_outline(slab), _outline(adjusted), atol=1e-6)


def test_no_adjust_changes_nothing_where_the_pieces_fill_their_slabs(write):
    text = "Lot --> extrude(6) split(x{}){{ 4 : A | {{ ~2 : B | 1 : C }}* }}\n"
    lots = [rect(20, 10), rect(13, 7)]
    same_records(run(write, text.format(""), lots), run(write, text.format(", noAdjust"), lots))


def test_no_adjust_derives_a_batch_as_lot_by_lot(write):
    text = "Lot --> split(x, noAdjust){ ~3 : A | 2 : B }*\nA --> split(z, noAdjust){ 3 : C | ~1 : D }\n"
    lots = make_lots_polys("concave_L", "courtyard", "sliver", "rect_12x8")
    same_records(run(write, text, lots), run(write, text, lots, chunk_size=1))


def _areas(write, text, lot):
    """The totals of the areas reported by the parts A (``a``) and B (``b``) of ``text`` on ``lot``."""
    rules = 'A --> report("a", geometry.area) A.\nB --> report("b", geometry.area) B.\n'
    return totals(run(write, text + rules, [lot]))


def test_split_area_parts_have_the_areas_written(write):
    """The reference's rule: an absolute part has exactly its area, a relative one its share of the
    geometry's area, floating parts share the rest; on a triangle the cut is no longer at the share of
    the length (a quarter of its area lies in the first 13.4 % of its width)."""
    triangle = [np.array([[0, 0], [10, 0], [0, 10]], float)]
    for lot, total in ((rect(12, 8), 96.0), (triangle, 50.0), (LOT_ZOO["courtyard"], 1200.0)):
        found = _areas(write, "Lot --> splitArea(x){ '0.25 : A | 5 : B | ~1 : A }\n", lot)
        assert found["b_sum"] == pytest.approx(5.0)
        assert found["a_sum"] == pytest.approx(total - 5.0)
        assert found["a_min"] == pytest.approx(min(0.25 * total, 0.75 * total - 5.0))
    r = run(write, "Lot --> splitArea(x){ '0.25 : A | ~1 : NIL }\nA --> A.\n", [triangle])
    (face,) = mesh_faces(r)
    assert face[0][:, 0].max() == pytest.approx(10 * (1 - np.sqrt(0.75)))


def test_split_area_repeats_in_area(write):
    """``splitArea(z){ 'f : A }*`` gives parts of equal area (the Swiss rule sets' lots); a repeated
    absolute area fits as often as it goes, as a split's length does."""
    triangle = [np.array([[0, 0], [10, 0], [0, 10]], float)]
    found = _areas(write, "Lot --> splitArea(z){ '(1/3) : A }*\n", triangle)
    assert (found["a_n"], found["a_min"], found["a_max"]) == pytest.approx((3, 50 / 3, 50 / 3))
    found = _areas(write, "Lot --> splitArea(x){ 10 : A }*\n", rect(12, 8))
    assert (found["a_n"], found["a_sum"]) == pytest.approx((9, 90.0))


def test_split_area_of_a_roof_is_refused(write):
    records = run(write, "Lot --> roofHip(30) splitArea(x){ '0.5 : A }*\nA --> A.\n", [rect(12, 8)])
    (bad,) = records["bad"]
    assert bad.reason.startswith("`splitArea` of a roof is not supported yet")


def test_a_negative_split_size_counts_as_zero_as_in_prt(write):
    """PRT builds candler's tiles whose ``winSideW = (TileWidth - FrontWindowWidth) / 2`` is negative as if
    it were 0 (the same model for a window as wide as the tile and wider); so does ``split`` here, where a
    part of size 0 makes no shape."""
    r = run(write, "Lot --> extrude(3) split(x){ (-0.5) : A | ~1 : B | -1 : C }\n", [rect(4, 10)])
    assert not r["bad"] and names(r) == ["B"]
    np.testing.assert_allclose(r["xform"][:, 0, 0], [4], atol=1e-6)
    zero = run(write, "Lot --> extrude(3) split(x){ 0 : A | ~1 : B | 0 : C }\n", [rect(4, 10)])
    same_records(r, zero)


def test_a_floating_ground_floor_and_repeated_floors_take_the_count_nearest_their_heights(write):
    """complexpatterns' ``Facade`` on the U lot of a conformance case: ``split(y){ ~4.182 : Floor |
    { ~4.358 : Floor }* }`` on 5.759 m. PRT makes two floors, 2.820 and 2.939 m (stretched by 0.674,
    0.326 from 1), where one floor alone would be stretched by 1.377; grammarc made one."""
    text = "Lot --> extrude(5.759) split(y){ ~4.182 : Floor | { ~4.358 : Floor }* }\n"
    r = run(write, text, [rect(10, 6)])
    np.testing.assert_allclose(r["xform"][:, 1, 1], [2.820, 2.939], atol=1e-3)
    np.testing.assert_allclose(r["xform"][:, 1, 3], [0, 2.820], atol=1e-3)


@pytest.mark.parametrize("width, bars", [(1.3, 1), (1.36, 2), (2.38, 2), (2.42, 3)])
def test_a_floating_repeat_takes_the_count_whose_parts_come_closest_to_their_size(write, width, bars):
    """complexpatterns' railing, ``split(x){ ~1 : VBar }*``: PRT goes from one bar to two at 4/3 m and
    from two to three at 12/5 m, where each part comes as close to 1 m with one count as with the
    other (1.36 m: two of 0.68 rather than one of 1.36; a ratio would have chosen one)."""
    r = run(write, "Lot --> extrude(1) split(x){ ~1 : Bar }*\n", [rect(width, 2)])
    np.testing.assert_allclose(r["xform"][:, 0, 0], [width / bars] * bars, rtol=1e-6)


def test_a_recursive_subdiv_into_a_lots_hole_leaves_the_pieces_that_are_not_in_it(write):
    """Slabs of a holed lot whose every piece is empty (inside the hole) made an IndexError (found by the
    build fuzz): the split keeps the children that have pieces, on both lots."""
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    hole = np.array([[0.25, 0.25], [0.25, 0.75], [0.75, 0.75], [0.75, 0.25]])
    r = paper(write, 'lot ~> Subdiv("X", 3r, 1r, 1r){ r1 | lot | r1 }\nr1 ~> Subdiv("X", 1r){ I("cube") }\n',
              [[square], [square, hole]])
    assert not r["bad"] and set(np.unique(r["lot"]).tolist()) == {0, 1}


@pytest.mark.parametrize("width, made", [(2.0007, ["A", "C"]), (2.0009, ["A", "B", "C"])])
def test_a_split_makes_no_part_of_prts_length_limit_or_shorter(write, width, made):
    """complexpatterns' red windows, ``split(x){ frameW : RedFrame | ~1 : ... | frameW : RedFrame }``, a
    little wider than two frames (PRT through PyPRT on the H lot of conformance case H.42188, frameW made to
    leave the middle 0.2 to 0.85 mm): PRT makes no middle part of 0.799 mm or less and makes one of
    0.805 mm, as on a 30 m facade (borderwallW leaving 0.5 mm and 5 mm); grammarc made every part longer
    than 1e-9 m, 0.4 mm red frames 1.6 m deep among them."""
    r = run(write, "Lot --> extrude(3) split(x){ 1 : A | ~1 : B | 1 : C }\n", [rect(width, 4)])
    assert names(r) == made
    starts = {"A": 0, "B": 1, "C": width - 1}  # C keeps its place: B's room is left empty
    np.testing.assert_allclose(r["xform"][:, 0, 3], [starts[n] for n in made], atol=1e-9)


def test_a_slab_that_cuts_a_prism_apart_keeps_its_pieces_in_one_shape(write):
    """PRT (complexpatterns' balconies on a U whose arms the last slab cuts): the pieces of an extruded
    footprint in one slab are one shape in the box around them, so s() scales them together and the
    railings of the inner sides stand at 0.877 + x * 18.246 / 20 (x 6 and 14: 6.351 and 13.649), not each
    arm on its own (5.123 and 14.877)."""
    u = [np.array([[0, 0], [6, 0], [6, 10], [14, 10], [14, 0], [20, 0], [20, 15], [0, 15]], float)]
    r = run(write, "Lot --> extrude(10) split(z){ ~1 : NIL | 4 : Arms }\nArms --> primitiveCube()\n", [u])
    np.testing.assert_allclose(r["xform"][:, 0, 0], [20.0])  # one shape across both arms
    r = run(write, "Lot --> extrude(10) split(z){ ~1 : NIL | 4 : Arms }\n"
                   "Arms --> s(scope.sx - 1.754, '1, '1) center(x) comp(f){ bottom : Bottom }\n", [u])
    bottoms = [ring for face in mesh_faces(r) for ring in face]
    assert len(bottoms) == 2
    xs = sorted(round(float(x), 3) for ring in bottoms for x in np.unique(ring[:, 0].round(3)))
    assert xs == [0.877, 6.351, 13.649, 19.123]
