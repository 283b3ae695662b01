"""backend/operations/roofing.py in derivations: taper, and the roofs' refusals (the roofs' geometry:
test_mesh_shapes.py)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO
from derivations import (
    rect,
    run,
    totals,
)


def test_taper_makes_a_pyramid_over_the_faces_centre_of_gravity(write):
    """The reference's ``Lot --> taper(10)``: a pyramid of the lot's area times a third of its height; the
    apex over the L's centre of gravity (12.5, 7.5), not its vertices' average (13.3, 10)."""
    text = ('Lot --> taper(10) report("v", geometry.volume) report("y", scope.sy) comp(f){ bottom : B | all : S }\n'
            'B --> report("b", geometry.area) B.\nS --> report("s", geometry.nVertices) S.\n')
    r = run(write, text, [LOT_ZOO["concave_L"]])
    t = totals(r)
    assert (t["v_sum"], t["y_sum"], t["b_sum"]) == (pytest.approx(400 * 10 / 3), 10, pytest.approx(400))
    assert (t["s_n"], t["s_sum"]) == (6, 18)
    apex = r["mesh"].vertices[np.argmax(r["mesh"].vertices[:, 1])]
    np.testing.assert_allclose(apex, [12.5, 10, -7.5], atol=1e-6)


def test_taper_of_a_facade_rises_along_its_normal_into_the_scopes_y(write):
    """The scope's x stays along the facade, its y turns to the facade's normal: a height of 2 is scope.sy.
    A height of 0 leaves the face; a negative one tapers behind it."""
    text = ('Lot --> extrude(10) comp(f){ front : F }\nF --> taper(h) report("x", scope.sx) '
            'report("y", scope.sy) report("z", scope.sz) report("v", geometry.volume) F.\n')
    for h, front, sizes in [(2, 2, (30, 2, 10)), (-2, 0, (30, 2, 10)), (0, 0, (30, 10, 0))]:
        r = run(write, f"const h = {h}\n" + text, [rect(30, 20)])
        t = totals(r)
        assert (t["x_sum"], t["y_sum"], t["z_sum"]) == pytest.approx(sizes)
        assert t["v_sum"] == pytest.approx(30 * 10 * abs(h) / 3)
        if h:
            assert r["mesh"].vertices[:, 2].max() == pytest.approx(front)


def test_taper_of_a_solid_or_a_roof_fails_its_lot_by_name(write):
    for body, reason in [("extrude(3) taper(1)", "`taper` of a solid is not supported yet"),
                         ("roofHip(30) taper(1)", "`taper` of a roof is not supported yet")]:
        (bad,) = run(write, f"Lot --> {body} X.\n", [rect(10, 8)])["bad"]
        assert bad.reason.startswith(reason), bad.reason


@pytest.mark.parametrize("op", ["roofHip", "roofGable", "roofShed", "roofPyramid"])
@pytest.mark.parametrize("angle", [90.0, 180.0, 1e9, -90.0])
def test_a_roof_of_90_degrees_or_more_fails_its_lot_by_name(write, op, angle):
    """The reference gives no roof for a plane of 90 degrees or more (its roof planes never meet): the
    lot is bad, named with the operation, where this gave an IndexError that stopped the build."""
    r = run(write, f"attr a = 30\nLot --> {op}(a) Roof.\n", [rect(30, 20)] * 2, lot_attrs={"a": np.array([30.0, angle])})
    assert np.unique(r["mesh"].lot).tolist() == [0]
    [bad] = r["bad"]
    assert bad.index == 1 and bad.reason.startswith(f"`{op}` with an angle of 90 degrees or more in rule `Lot` at ")
