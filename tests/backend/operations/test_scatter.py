"""backend/operations/scatter.py in derivations: point shapes on surfaces, in volumes and scopes, uniform and
gaussian, on every shape kind, deterministic whatever the chunking."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from conftest import LOT_ZOO
from derivations import names, rect, run, same_records

#: A point made visible: a unit cube on its scope, whose record's columns are the point's axes.
CUBE = "s(1, 1, 1) P"


def points(r, symbol="P"):
    """The points (k, 3) and their scope axes (k, 3, 3) (rows) of the ``symbol`` records."""
    x = r["xform"].astype(float)[np.array(names(r)) == symbol]
    return x[:, :, 3], x[:, :, :3].transpose(0, 2, 1)


def test_the_references_uniform_surface_example_puts_n_points_on_the_lot(write):
    """``scatter(surface, 100, uniform) { Leaf }`` on a 30 x 20 lot: 100 points in the lot's plane, its
    scope's axes kept (the surface's normal is the lot's y), and the lot itself goes on."""
    r = run(write, f"Lot --> scatter(surface, 100, uniform) {{ {CUBE} }}\n", [rect(30, 20)])
    p, axes = points(r)
    assert len(p) == 100 and names(r).count("Lot") == 1
    assert np.allclose(p[:, 1], 0.0)
    assert (p[:, 0] >= 0).all() and (p[:, 0] <= 30).all() and (p[:, 2] >= -20).all() and (p[:, 2] <= 0).all()
    assert np.allclose(axes, np.eye(3), atol=1e-6)


def test_uniform_surface_points_are_spread_evenly_by_area(write):
    """A chi-square over 6 x 4 cells of the lot: 4800 points, 200 expected per cell."""
    r = run(write, f"Lot --> scatter(surface, 4800, uniform) {{ {CUBE} }} NIL\n", [rect(30, 20)], seed=7)
    p, _ = points(r)
    counts, _, _ = np.histogram2d(p[:, 0], -p[:, 2], bins=(6, 4), range=((0, 30), (0, 20)))
    chi2 = ((counts - 200) ** 2 / 200).sum()
    assert chi2 < 50  # 23 degrees of freedom: p < 0.001 above 49.7


def test_points_stay_inside_a_concave_lot_and_out_of_its_courtyard(write):
    lots = [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]]
    r = run(write, f"Lot --> scatter(surface, 500, uniform) {{ {CUBE} }} NIL\n", lots)
    p, _ = points(r)
    lot = r["lot"][np.array(names(r)) == "P"]
    for k, rings in enumerate(lots):
        shape = shapely.Polygon(rings[0], rings[1:]).buffer(1e-6)
        mine = p[lot == k]
        assert len(mine) == 500
        assert shapely.contains_xy(shape, mine[:, 0], -mine[:, 2]).all()  # map (x, y) is world (x, 0, -y)


def test_a_box_surface_by_area_and_each_point_turned_to_its_face(write):
    """On a 10 x 10 x 10 box every face has a sixth of the points; y is the face's outward normal."""
    r = run(write, f"Lot --> extrude(10) scatter(surface, 6000, uniform) {{ {CUBE} }} NIL\n", [rect(10, 10)])
    p, axes = points(r)
    normal = axes[:, 1]
    centre = np.array([5.0, 5.0, -5.0])
    assert (np.einsum("ni,ni->n", p - centre, normal) == pytest.approx(5.0, abs=1e-4))
    faces = np.round(normal).astype(int)
    _, counts = np.unique(faces, axis=0, return_counts=True)
    assert len(counts) == 6 and (np.abs(counts - 1000) < 150).all()
    assert np.allclose(np.linalg.det(axes), 1.0, atol=1e-5)


def test_volume_of_a_box_and_of_a_prism_fills_it(write):
    r = run(write, f"Lot --> extrude(10) scatter(volume, 2000, uniform) {{ {CUBE} }} NIL\n",
            [rect(30, 20), LOT_ZOO["concave_L"]])
    p, axes = points(r)
    lot = r["lot"][np.array(names(r)) == "P"]
    assert np.allclose(axes, np.eye(3), atol=1e-6)  # inside a volume a point keeps the parent's axes
    assert (p[:, 1] > 0).mean() > 0.99 and p[:, 1].max() <= 10 and abs(p[:, 1].mean() - 5) < 0.3
    ell = shapely.Polygon(LOT_ZOO["concave_L"][0]).buffer(1e-6)
    mine = p[lot == 1]
    assert shapely.contains_xy(ell, mine[:, 0], -mine[:, 2]).all()  # the L's arms, not its bounding box


def test_volume_of_a_flat_lot_or_a_roof_falls_back_to_the_surface(write):
    flat = run(write, f"Lot --> scatter(volume, 50, uniform) {{ {CUBE} }} NIL\n", [rect(30, 20)])
    assert np.allclose(points(flat)[0][:, 1], 0.0)
    roof = run(write, f"Lot --> roofHip(30) scatter(volume, 200, uniform) {{ {CUBE} }} NIL\n", [rect(30, 20)])
    p, axes = points(roof)
    ridge = 10 * np.tan(np.radians(30))
    assert len(p) == 200 and p[:, 1].max() <= ridge + 1e-6
    # a point on a roof plane stands on it: its height is the plane's at its place
    slope = axes[:, 1]
    assert (np.abs(slope[:, 1]) > 0.5).all()


def test_scope_draws_in_the_scope_box(write):
    r = run(write, f"Lot --> extrude(10) scatter(scope, 1000, uniform) {{ {CUBE} }} NIL\n", [LOT_ZOO["concave_L"]])
    p, _ = points(r)
    assert p.min(axis=0) == pytest.approx([0, 0, -20], abs=0.2)
    assert p.max(axis=0) == pytest.approx([30, 10, 0], abs=0.2)


def test_gaussian_is_centred_on_its_mean_with_its_deviation(write):
    """The reference's examples: gaussian around the centre ('0.16 of the scope), and moved to the left
    with '0.1: x centres on the scope's left side, the half inside it kept (a half-normal), z as before."""
    r = run(write, f"Lot --> scatter(scope, 4000, gaussian) {{ {CUBE} }} NIL\n", [rect(100, 50)])
    p, _ = points(r)
    assert p[:, 0].mean() == pytest.approx(50, abs=0.5) and p[:, 0].std() == pytest.approx(16, rel=0.05)
    assert p[:, 2].mean() == pytest.approx(-25, abs=0.3) and p[:, 2].std() == pytest.approx(8, rel=0.05)
    r = run(write, f"Lot --> scatter(surface, 4000, gaussian, left, '0.1) {{ {CUBE} }} NIL\n", [rect(100, 50)])
    p, _ = points(r)
    assert (p[:, 0] > 0).all() and np.allclose(p[:, 1], 0.0)
    half_normal = 10 * np.sqrt(2 / np.pi), 10 * np.sqrt(1 - 2 / np.pi)
    assert (p[:, 0].mean(), p[:, 0].std()) == (pytest.approx(half_normal[0], rel=0.05),
                                               pytest.approx(half_normal[1], rel=0.05))
    assert p[:, 2].mean() == pytest.approx(-25, abs=0.3) and p[:, 2].std() == pytest.approx(5, rel=0.05)
    r = run(write, f"Lot --> scatter(surface, 4000, gaussian, center, 2) {{ {CUBE} }} NIL\n", [rect(100, 50)])
    p, _ = points(r)
    assert p[:, 0].std() == pytest.approx(2, rel=0.05) and p[:, 2].std() == pytest.approx(2, rel=0.05)


def test_a_wide_gaussian_is_cut_to_the_shape_not_piled_on_its_border(write):
    """'1 of the scope, as public files write it: the points outside the lot are drawn again, so few of
    them lie on its edges; on a concave lot they stay inside it."""
    r = run(write, f"Lot --> scatter(surface, 2000, gaussian, center, '1) {{ {CUBE} }} NIL\n",
            [rect(30, 20), LOT_ZOO["concave_L"]])
    p, _ = points(r)
    lot = r["lot"][np.array(names(r)) == "P"]
    square = p[lot == 0]
    on_edge = (np.abs(square[:, 0]) < 1e-6) | (np.abs(square[:, 0] - 30) < 1e-6) | (np.abs(square[:, 2]) < 1e-6)
    assert on_edge.mean() < 0.01
    ell = shapely.Polygon(LOT_ZOO["concave_L"][0]).buffer(1e-6)
    assert shapely.contains_xy(ell, p[lot == 1, 0], -p[lot == 1, 2]).all()


def test_the_count_is_an_expression_per_shape_truncated(write):
    """``floor(geometry.area / 100)`` as public rule files write it, and 2.7 points are 2."""
    r = run(write, f"Lot --> scatter(surface, geometry.area / 100, uniform) {{ {CUBE} }} NIL\n",
            [rect(30, 20), rect(10, 10), rect(5, 5)])
    lot = r["lot"][np.array(names(r)) == "P"]
    assert np.bincount(lot, minlength=3).tolist() == [6, 1, 0]
    r = run(write, f"Lot --> scatter(surface, 2.7, uniform) {{ {CUBE} }} scatter(scope, -3, uniform) {{ Q }} NIL\n",
            [rect(30, 20)])
    assert names(r) == ["P", "P"]


def test_a_nan_count_fails_the_lot(write):
    r = run(write, f"Lot --> scatter(surface, scope.sy / scope.sy, uniform) {{ {CUBE} }} NIL\n", [rect(30, 20)])
    assert len(r["xform"]) == 0
    assert "`scatter` needs a number of points, got NaN" in r["bad"][0].reason


def test_points_run_their_body_with_their_own_random_stream(write):
    """Each point draws its own ``rand``; the points of a lot do not depend on its neighbours."""
    text = "Lot --> scatter(surface, 50, uniform) { s(rand(1, 2), 1, 1) P } NIL\n"
    r = run(write, text, [rect(30, 20)])
    widths = np.linalg.norm(r["xform"].astype(float)[:, :, 0], axis=1)
    assert len(np.unique(widths.round(6))) == 50


@pytest.mark.parametrize("chunk_size", [1, 2, 5])
def test_records_do_not_depend_on_the_chunking(write, chunk_size):
    lots = [rect(30, 20), LOT_ZOO["concave_L"], LOT_ZOO["courtyard"], LOT_ZOO["square"], rect(12, 8)]
    text = (f"Lot --> extrude(rand(5, 20)) comp(f){{ top: roofHip(25) scatter(surface, 40, gaussian) {{ {CUBE} }} NIL"
            f" | side: scatter(surface, rand(10, 30), uniform) {{ {CUBE} }} | bottom: scatter(volume, 7, uniform)"
            f" {{ {CUBE} }} NIL }}\n")
    same_records(run(write, text, lots), run(write, text, lots, chunk_size=chunk_size))


def test_ten_thousand_points_in_one_batch(write):
    lots = [rect(10 + k, 10) for k in range(100)]
    r = run(write, f"Lot --> scatter(surface, 100, uniform) {{ {CUBE} }} NIL\n", lots)
    p, _ = points(r)
    assert len(p) == 10_000
    lot = r["lot"]
    assert (p[:, 0] <= 10 + lot + 1e-9).all()

