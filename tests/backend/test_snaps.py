"""Snap shapes (paper section 3.3): the planes of a lot, where they cross a scope, the snapped Repeat and
Subdiv of Fig. 9, and floors aligned over the solids of one building (Fig. 10, 15)."""

from __future__ import annotations

import numpy as np
import pytest
from operations.derivations import names, rect, run

from grammarc.backend.kernels.split import snap_subdiv
from grammarc.backend.snaps import SnapStore

TOL = 1e-9
UP = np.array([[0.0, 1.0, 0.0]])


def test_planes_cross_a_scope_of_their_own_lot_across_its_axis_once_each():
    store = SnapStore()
    store.add(np.array([0, 0, 0, 1]), np.array([[0, 3.0, 0], [5, 3.0, 9], [0, 6.0, 0], [0, 4.0, 0]]),
              np.tile(UP, (4, 1)), None)
    store.add(np.array([0]), np.array([[2.0, 0, 0]]), np.array([[1.0, 0, 0]]), "tilesnap")  # across x
    lot = np.array([0, 1, 0])
    origin = np.zeros((3, 3))
    axis = np.array([[0, 1.0, 0], [0, 1.0, 0], [1.0, 0, 0]])
    offsets, at = store.across(lot, origin, axis, np.array([10.0, 10.0, 10.0]), None, TOL)
    assert offsets.tolist() == [0, 2, 3, 4] and at.tolist() == [3.0, 6.0, 4.0, 2.0]  # 3 twice: once
    offsets, at = store.across(lot, origin, axis, np.array([5.0, 10.0, 10.0]), "tilesnap", TOL)
    assert offsets.tolist() == [0, 0, 0, 1] and at.tolist() == [2.0]
    offsets, _ = store.across(lot, origin, axis, np.array([3.0, 3.0, 3.0]), "nothing", TOL)
    assert offsets.tolist() == [0, 0, 0, 0]


def test_fig9_a_snapped_repeat_repeats_each_side_of_the_snap_line(write):
    """10 m with 3 m elements: 4 of 2.5 m; a snap line at 4 m: 2 of 2 m, then 2 of 3 m."""
    text = ('PRIORITY 1:\nstart ~> lot lot2\n'
            'lot ~> S(10, 3, 0) Subdiv("X", 4, 6){ rest | marker Snap("Y") }\n'
            'PRIORITY 2:\nlot2 ~> S(10, 3, 0) Repeat("{axis}", 3){ el }\n')
    for axis, pos, length in (("X", [0, 2.5, 5, 7.5], [2.5] * 4), ("XS", [0, 2, 4, 7], [2, 2, 3, 3])):
        r = run(write, text.replace("{axis}", axis), [rect(20, 10)], version=False)
        el = np.array(names(r)) == "el"
        np.testing.assert_allclose(r["xform"][el, 0, 3], pos, atol=1e-6)
        np.testing.assert_allclose(r["xform"][el, 0, 0], length, atol=1e-6)


def test_fig9_a_snapped_subdiv_moves_only_the_line_nearest_the_snap():
    """Parts of 3, 3, 4 m: a snap at 5.2 m moves the line at 6 m; the first part keeps its size."""
    parent = np.zeros(3, dtype=np.int64)
    pos, length = np.array([0.0, 3.0, 6.0]), np.array([3.0, 3.0, 4.0])
    snap_subdiv(parent, pos, length, np.array([0, 1]), np.array([5.2]))
    np.testing.assert_allclose(pos, [0, 3, 5.2])
    np.testing.assert_allclose(length, [3, 2.2, 4.8])
    # two snaps wanting the same line: the nearer moves it
    pos, length = np.array([0.0, 3.0, 6.0]), np.array([3.0, 3.0, 4.0])
    snap_subdiv(parent, pos, length, np.array([0, 2]), np.array([5.0, 6.5]))
    np.testing.assert_allclose(pos, [0, 3, 6.5])


def test_floors_of_two_solids_of_one_building_share_the_taller_ones_levels(write):
    """Fig. 10: the tall solid's floors leave snap planes; the low one's snapped Repeat meets them."""
    text = ('PRIORITY 1:\nlot ~> Subdiv("X", 1r, 1r){ tall | low }\n'
            'tall ~> S(1r, 10, 1r) Repeat("Y", 3){ floor Snap("XZ") }\n'
            'PRIORITY 2:\nlow ~> S(1r, 8, 1r) Repeat("YS", 2){ lowfloor }\n')
    r = run(write, text, [rect(20, 10)], version=False)
    y = r["xform"][:, 1, 3].astype(float)
    tall = np.sort(y[np.array(names(r)) == "floor"])
    low = np.sort(y[np.array(names(r)) == "lowfloor"])
    np.testing.assert_allclose(tall, [0, 2.5, 5, 7.5], atol=1e-6)
    assert all(np.isclose(low, level, atol=1e-6).any() for level in tall)
    np.testing.assert_allclose(low, [0, 1.25, 2.5, 3.75, 5, 6.25, 7.5], atol=1e-6)


def test_a_labelled_snap_line_moves_the_nearest_split_of_a_labelled_subdiv(write):
    """Rule 6 and 16 of section 5: the entrance's SnapLines("Y", label) at 4 and 6 m; a later
    Subdiv("XS", ..., label) of 3, 4, 3 m moves its lines at 3 and 7 m there."""
    text = ('PRIORITY 1:\nstart ~> lot lot2\n'
            'lot ~> S(10, 3, 0) Subdiv("X", 4, 2, 4){ wall | entrance SnapLines("Y", "door") | wall }\n'
            'PRIORITY 2:\nlot2 ~> S(10, 3, 0) Subdiv("XS", 3, 4, 3, "door"){ a | b | c }\n')
    r = run(write, text, [rect(20, 10)], version=False)
    x = r["xform"][:, 0, 3].astype(float)
    width = r["xform"][:, 0, 0].astype(float)
    got = {n: (x[i], width[i]) for i, n in enumerate(names(r)) if n in "abc"}
    assert got["a"] == pytest.approx((0, 4)) and got["b"] == pytest.approx((4, 2))
    assert got["c"] == pytest.approx((6, 4))


def test_shapes_of_one_batch_snap_to_the_planes_of_those_before_them(write):
    """The paper derives one shape at a time: of two volumes whose floors are repeated by one batch,
    the first's floors (above a 2 m base) set the levels the second's snap to."""
    text = """
lot ~> S(1r, 10, 1r) Subdiv("X", 1r, 1r){ f | g }
f ~> Subdiv("Y", 2, 1r){ base | floors }
g ~> floors
floors ~> Repeat("YS", 3){ fl Snap("XZ") }
"""
    r = run(write, text, [rect(20, 20), rect(20, 20)], version=False)
    fl = np.array(names(r)) == "fl"
    x, bottom = r["xform"][fl][:, 0, 3], r["xform"][fl][:, 1, 3]
    for lot in (0, 1):
        mine = r["lot"][fl] == lot
        f_levels = np.sort(bottom[mine & (x == 0)])
        g_levels = np.sort(bottom[mine & (x == 10)])
        np.testing.assert_allclose(f_levels, [2, 2 + 8 / 3, 2 + 16 / 3], atol=1e-5)
        np.testing.assert_allclose(g_levels, [0, *f_levels], atol=1e-5)
