"""backend/execute.py: rules applied to batches (guards, stochastic alternatives, the depth limit) and
bodies run (push and pop; in CityEngine a body without a successor leaves its shape)."""

from __future__ import annotations

import numpy as np
from operations.derivations import (
    assets,
    names,
    of_symbol,
    paper,
    rect,
    run,
)


def test_paper_notation_scale_alone_emits_nothing(write):
    """The paper notation: a body without a successor or an insert emits nothing."""
    r = run(write, "lot ~> S(1r, 10, 1r)\n", [rect(12, 8)], version=False)
    assert len(r["asset"]) == 0 and len(r["mesh"].lot) == 0


def test_operations_that_make_no_successor_still_leave_the_shape(write):
    r = run(write, 'attr h = 1\nLot --> extrude(4) color("#ff0000") set(h, 2) report("k", 1) print(h)\n',
            [rect(12, 8)])
    assert assets(r) == ["builtin:cube"] and names(r) == ["Lot"]


def test_nil_and_a_pushed_successor(write):
    r = run(write, "Lot --> extrude(4) [ t(0, 4, 0) s('1, 1, '1) Roof ] NIL\n", [rect(12, 8)])
    assert names(r) == ["Roof"]
    np.testing.assert_allclose(r["xform"][0, :, 3], [0, 4, -8])


def test_brackets_whose_shapes_all_vanish_give_the_shapes_back_at_their_end(write):
    """The footprint of a face seen edge-on (its scope turned upright) is empty; the shape comes back at
    `]` and goes on, alone in its chunk as among others (candler's roof pipes were lost on small lots
    derived alone)."""
    text = ("Lot --> case scope.sx < 10 : rotateScope(90, 0, 0) X else : X\n"
            "X --> [ footprint() A ] [ footprint() [ B ] C ] Roof\n")
    assert names(run(write, text, [rect(2, 2)])) == ["Roof"]
    assert names(run(write, text, [rect(2, 2), rect(300, 300)])) == ["Roof", "A", "B", "C", "Roof"]


def test_parametric_recursion_with_guards_and_lot_attributes(write):
    text = """
attr height = 10
attr floor_h = 3
lot ~> S(1r, height, 1r) stack(height)
stack(h) : h >= 2 * floor_h ~> Subdiv("Y", floor_h, 1r){ floor | stack(h - floor_h) }
stack(h) ~> floor
floor ~> I("cube")
"""
    heights = [10.0, 30.0, 7.0, float("nan")]
    r = paper(write, text, [rect(10, 10)] * 4, lot_attrs={"height": heights})
    per_lot = np.bincount(r["lot"], minlength=4)
    # lot 3 has no height: the default 10 applies
    np.testing.assert_array_equal(per_lot, [3, 10, 2, 3])
    top = r["xform"][:, 1, 3] + r["xform"][:, 1, 1]
    np.testing.assert_allclose([top[r["lot"] == i].max() for i in range(4)], [10, 30, 7, 10])


STOCHASTIC = """
lot ~> a : 0.5
    ~> b : 0.3
    ~> c(rand(2, 4)) : 0.2
c(x) ~> S(x, 1, 1) I("cube")
"""


def test_stochastic_frequencies_over_10k_lots(write):
    r = paper(write, STOCHASTIC, [rect(1, 1)] * 10_000)
    counts = {s: int(of_symbol(r, s).sum()) for s in ("a", "b", "c")}
    # binomial standard deviations: 50, 46, 40; allow 4 of them
    assert abs(counts["a"] - 5000) < 200 and abs(counts["b"] - 3000) < 184 and abs(counts["c"] - 2000) < 160
    widths = r["xform"][of_symbol(r, "c"), 0, 0]
    assert 2 <= widths.min() and widths.max() <= 4 and abs(widths.mean() - 3) < 0.05


def test_runaway_linear_recursion_fails_its_lot_at_depth(write):
    """--max-depth fails the lots whose shapes are still pending there; the others derive."""
    text = "attr n = 0\nlot : n > 0 ~> T(0,1,0) lot\nlot ~> I(\"cube\")\n"
    r = paper(write, text, [rect(5, 5)] * 3, lot_attrs={"n": np.array([1.0, 0.0, 0.0])})
    assert r["lot"].tolist() == [1, 2]
    [bad] = r["bad"]
    assert bad.index == 0 and bad.reason.endswith(
        "/g.cga:2:1: a runaway recursion? Raise the limit with --max-depth N.")
    assert bad.reason.startswith("reached --max-depth 256 in rule `lot` at ")


def test_push_pop_and_rotation(write):
    r = paper(write, 'A ~> [ Rz(90) S(2, 1, 1) I("cube") ] R(0, 90, 0) S(3, 1, 1) I("cube")\n', [rect(5, 5)])
    x = r["xform"]
    # Rz(90): scope x turns to world +y, y to world -x
    np.testing.assert_allclose(x[0, :, 0], [0, 2, 0], atol=1e-12)
    np.testing.assert_allclose(x[0, :, 1], [-1, 0, 0], atol=1e-12)
    # Ry(90): x turns towards -z
    np.testing.assert_allclose(x[1, :, 0], [0, 0, -3], atol=1e-6)
    np.testing.assert_allclose(x[0, :, 3], x[1, :, 3])



def test_an_operation_that_sizes_or_places_a_scope_beyond_any_coordinate_fails_its_lot(write):
    """As the build fuzz test found it: ``extrude(1e308)`` then ``offset`` of its side faces stopped the build
    where GEOS's arithmetic overflowed. A scope past float32's largest number makes no record: the
    operation that makes it fails its lot, named, and the other lots are derived."""
    text = ("attr h = 1\nattr x = 0\nLot --> extrude(h) t(x, 0, 0) comp(f){ side : Side }\n"
            "Side --> offset(-0.1, inside) A.\n")
    r = run(write, text, [rect(10, 10)] * 3, lot_attrs={"h": np.array([1.0, 1e308, 1.0]),
                                                        "x": np.array([0.0, 0.0, -1e39])})
    assert [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]] == [
        (1, "a scope sized or placed beyond any coordinate (1e+308)"),
        (2, "a scope sized or placed beyond any coordinate (1e+39)")]
    assert np.unique(r["lot"]).tolist() == [0]
