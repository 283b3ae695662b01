"""backend/operations/reset.py in derivations: ``resetGeometry`` sets shapes back to their lot's initial
shape, keeping what rules set and dropping trim planes."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO
from derivations import names, rect, run, totals


def test_reset_geometry_sets_back_from_the_lot_each_time(write):
    """The reference's example: setbacks applied recursively, each from the lot (a remainder of 30 x 20,
    24 x 14, 18 x 8), the colour set before them kept."""
    text = ('Lot --> color("#FFAA00") Rec(0, 0)\n'
            "Rec(sum, k) --> resetGeometry() setback(k * 3){ all : NIL | remainder : Floor(sum + geometry.area, k) }\n"
            "Floor(sum, k) --> case k < 3 : report(\"a\", geometry.area) report(\"g\", sum) report(\"c\", material.color.g) t(0, k * 10, 0) "
            "extrude(10) F. Rec(sum, k + 1)\n  else : NIL\n")
    r = run(write, text, [rect(30, 20)])
    t = totals(r)
    assert (t["a_n"], t["a_sum"], t["g_sum"]) == (3, 600 + 336 + 144, 600 + 936 + 1080)
    assert t["c_sum"] == pytest.approx(3 * 170 / 255)
    np.testing.assert_allclose(np.sort(r["xform"][:, 1, 3]), [0, 10, 20])


@pytest.mark.parametrize("before", ["extrude(10) comp(f){ front : A }\nA --> ", "roofHip(30) ", "split(x){ 5 : A }\nA --> "])
def test_reset_geometry_of_a_face_a_roof_or_a_split_part_is_the_lot(write, before):
    text = f'Lot --> {before}resetGeometry() report("x", scope.sx) report("a", geometry.area) X.\n'
    for lot, x, area in [(rect(30, 20), 30, 600), (LOT_ZOO["concave_L"], 30, 400)]:
        t = totals(run(write, text, [lot]))
        assert (t["x_sum"], t["a_sum"]) == (x, pytest.approx(area))


def test_reset_geometry_drops_the_trim_planes_of_a_comp(write):
    """A cube past the side faces' corners is trimmed there (mesh faces); after resetGeometry it is an
    instance, as it is on the lot itself."""
    grow = "s(40, 5, 30) center(xz) primitiveCube() X."
    trimmed = run(write, f"Lot --> extrude(10) comp(f){{ side : t(0, 0, -5) {grow} }}\n", [rect(30, 20)])
    assert len(trimmed["mesh"].face_offsets) > 1
    reset = run(write, f"Lot --> extrude(10) comp(f){{ side : resetGeometry() {grow} }}\n", [rect(30, 20)])
    assert len(reset["mesh"].face_offsets) == 1 and names(reset) == ["X"] * 4
