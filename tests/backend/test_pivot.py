"""backend/pivot.py: ``setPivot``'s corners and axes, and the pivot in derivations: a component split and the
alignments make the new scope the pivot, ``scope.t``/``scope.r``, ``pivot.*`` and ``convert`` read it, and ``r``
adds its angles to the scope's angles in it."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from operations.derivations import rect, rotated_rectangle, run, totals

from grammarc.backend.pivot import AXIS_MAPS, CORNERS, corner_axes


@pytest.mark.parametrize("axis_map, corner", list(itertools.product(sorted(AXIS_MAPS), range(8))))
def test_a_pivot_is_right_handed_and_points_into_the_scope_from_its_corner(axis_map, corner):
    ends, turn = corner_axes(axis_map, np.array([corner]))
    assert ends[0].tolist() == CORNERS[corner].tolist()
    m = turn[0]
    np.testing.assert_array_equal(m @ m.T, np.eye(3))
    assert np.linalg.det(m) == pytest.approx(1.0)
    # each new axis is an old one, reversed where the corner is at that one's far end
    old = np.argmax(np.abs(m), axis=1)
    assert sorted(old) == [0, 1, 2]
    assert all(m[k, old[k]] == (-1 if ends[0][old[k]] else 1) for k in range(3))
    # the new y is the old axis the map names, whatever the corner
    assert old[1] == AXIS_MAPS[axis_map][1]


@pytest.mark.parametrize("axis_map, rows", [("xyz", [0, 1, 2]), ("yzx", [1, 2, 0]), ("zxy", [2, 0, 1])])
def test_at_corner_0_the_axis_map_renames_the_scope_axes(axis_map, rows):
    _, turn = corner_axes(axis_map, np.array([0, 8]))  # 8 is corner 0 again
    np.testing.assert_array_equal(turn[0], np.eye(3)[rows])
    np.testing.assert_array_equal(turn[1], turn[0])


REPORT = " ".join(f'report("{f}", {name})' for f, name in [
    ("tx", "scope.tx"), ("ty", "scope.ty"), ("tz", "scope.tz"), ("rx", "scope.rx"), ("ry", "scope.ry"),
    ("rz", "scope.rz"), ("px", "pivot.px"), ("py", "pivot.py"), ("pz", "pivot.pz"), ("oy", "pivot.oy")])


def _read(write, ops, lots=None):
    t = totals(run(write, f"Lot --> {ops} {REPORT} X\n", lots or [rect(12, 8)]))
    return {k[:-4]: v for k, v in t.items() if k.endswith("_sum")}


def test_set_pivot_makes_the_corner_the_pivot_and_the_scope_zero_in_it(write):
    """The reference: after setPivot the scope has zero translation and rotation relative to the pivot; the
    pivot's position and angles are in object coordinates (the lot's scope: 12 x 3 x 8 here)."""
    got = _read(write, "extrude(3) setPivot(xyz, 6)")
    assert [got[k] for k in ("tx", "ty", "tz", "rx", "ry", "rz")] == pytest.approx([0] * 6, abs=1e-9)
    assert [got[k] for k in ("px", "py", "pz")] == pytest.approx([12, 3, 8])
    # corner 1, at the end of x: x along the old z, z along the old -x, a quarter turn about y
    got = _read(write, "extrude(3) setPivot(xyz, 1) t(1, 0, 0)")
    assert (got["px"], got["pz"], got["oy"]) == pytest.approx((12, 0, -90))
    assert (got["tx"], got["ty"], got["tz"], got["ry"]) == pytest.approx((1, 0, 0, 0), abs=1e-9)


def test_a_component_and_an_aligned_scope_are_their_pivots(write):
    """comp's default zUp aligns pivot and scope, and so do the alignments (scope.t and scope.r zero):
    a facade's scope.tx is no longer the lot's, and translating in the pivot moves along the facade."""
    got = _read(write, "extrude(3) comp(f){ right : t(0, 1, 0) A }\nA -->")
    assert [got[k] for k in ("tx", "ty", "tz", "rx", "ry", "rz")] == pytest.approx([0, 1, 0, 0, 0, 0], abs=1e-9)
    assert (got["px"], got["pz"], got["oy"]) == pytest.approx((12, 8, 90))
    got = _read(write, "r(0, 30, 0) t(1, 2, 3) alignScopeToAxes(y)")
    assert [got[k] for k in ("tx", "ty", "tz", "rx", "ry", "rz")] == pytest.approx([0] * 6, abs=1e-9)
    got = _read(write, "r(0, 30, 0) t(1, 2, 3) alignScopeToGeometryBBox(xz)")
    assert [got[k] for k in ("tx", "ty", "tz", "rx", "ry", "rz")] == pytest.approx([0] * 6, abs=1e-9)
    # resetGeometry gives back the lot's scope, which is the lot's pivot
    got = _read(write, "extrude(3) setPivot(xyz, 6) resetGeometry()")
    assert [got[k] for k in ("tx", "ty", "tz", "rx", "ry", "rz", "px", "py", "pz")] == pytest.approx([0] * 9,
                                                                                                  abs=1e-9)
    lot = [rotated_rectangle()]
    moved = run(write, "Lot --> extrude(3) comp(f){ front : translate(rel, pivot, 2, 0, 0) X }\n", lot)
    plain = run(write, "Lot --> extrude(3) comp(f){ front : t(2, 0, 0) X }\n", lot)
    np.testing.assert_allclose(moved["xform"], plain["xform"], atol=1e-9)


def test_r_adds_to_the_angles_of_a_scope_turned_before(write):
    """r is rotate(rel, pivot, ...): two r's add their angles, about the pivot's axes, in xyz order (the
    pivot is kept where a grammar turns with an r of several angles; without it the second r would turn about
    the first one's axes)."""
    lot = [rotated_rectangle()]
    got = _read(write, "extrude(4) r(10, 0, 0) r(0, 20, 0) r(0, 0, 30)", lot)
    assert (got["rx"], got["ry"], got["rz"]) == pytest.approx((10, 20, 30))
    once = run(write, "Lot --> extrude(4) r(10, 20, 30) X\n", lot)["xform"]
    twice = run(write, "Lot --> extrude(4) r(0, 20, 0) r(10, 0, 30) X\n", lot)["xform"]
    np.testing.assert_allclose(twice, once, atol=1e-9)
    rotated = run(write, "Lot --> extrude(4) rotate(rel, pivot, 0, 20, 0) rotate(rel, pivot, 10, 0, 30) X\n",
                  lot)["xform"]
    np.testing.assert_allclose(rotated, once, atol=1e-9)
    # a comp's face is its pivot: r adds to the face's own zero angles
    face = run(write, "Lot --> extrude(4) comp(f){ front : r(0, 10, 15) r(5, 0, 0) X }\n", lot)["xform"]
    direct = run(write, "Lot --> extrude(4) comp(f){ front : r(5, 10, 15) X }\n", lot)["xform"]
    np.testing.assert_allclose(face, direct, atol=1e-9)


def test_rotate_scope_adds_to_the_angles_in_the_pivot(write):
    first = run(write, "Lot --> extrude(4) rotateScope(0, 90, 0) rotateScope(30, 0, 0) X\n", [rect(12, 8)])
    both = run(write, "Lot --> extrude(4) rotateScope(30, 90, 0) X\n", [rect(12, 8)])
    np.testing.assert_allclose(first["xform"], both["xform"], atol=1e-6)


def test_a_pivot_corner_picked_by_the_compass_is_the_same_corner_of_every_lot(write):
    """As the Roman rule sets do: the pivot's turn about y, in quarter turns, added to a corner index picks
    the same compass corner (here the north-west one) of a lot drawn east first and one drawn north first,
    and leaves both scopes facing the same way."""
    turn = "floor((convert(y, pivot, world, orient, 0, 0, 0) + 45) / 90)"
    index = f"{turn} - floor({turn} / 4) * 4"
    lots = [rect(12, 8), rotated_rectangle(90.0, w=12.0, h=8.0, at=(0.0, 0.0))]
    r = run(write, f"Lot --> alignScopeToGeometry(yUp, 0, 0) setPivot(xyz, {index}) extrude(1) X\n", lots)
    x = r["xform"].astype(float)
    # map (0, 8) and (-8, 12): world x = map x, z = -map y
    np.testing.assert_allclose(x[:, :, 3], [[0, 0, -8], [-8, 0, -12]], atol=1e-9)
    np.testing.assert_allclose(x[:, :, 0] / np.linalg.norm(x[:, :, 0], axis=1)[:, None], [[1, 0, 0]] * 2,
                               atol=1e-9)


def test_yzx_at_corner_3_stands_an_extruded_facade_piece_upright(write):
    """A piece of facade extruded out of the wall has its scope's y out of the wall and z down from the top;
    setPivot(yzx, 3) makes the old z, reversed from the ground, the new y: a column 10 m tall."""
    r = run(write, "Lot --> extrude(10) comp(f){ front : split(x){ ~1 : W. | 1 : C | ~1 : W. } }\n"
                   "C --> extrude(1) setPivot(yzx, 3) s(0.5, '1, 0.5) X\n", [rect(12, 8)])
    (x,) = r["xform"][np.array(r["symbols"][r["symbol"]]) == "X"].astype(float)
    np.testing.assert_allclose(x[:, 1], [0, 10, 0], atol=1e-9)  # y: 10 m straight up
    assert x[1, 3] == pytest.approx(0.0)  # from the ground
