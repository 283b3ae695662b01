"""backend/functions/coordinates.py and its lowering: ``convert`` between the scope, pivot, object and
world systems, ``initialShape.name``, ``initialShape.startRule`` and ``initialShape.origin.o*``.

The reference's ``convert`` example runs on a lot of the CityEngine scene that the page does not give; its
orientation in world, (-10, 23.46, 0) after ``r(-10, 70, 0)``, says that the lot is turned -46.54 degrees
about the vertical. The same steps run here on such a lot, whose systems are known: its scope x axis is map
(cos a, sin a), world (cos a, 0, -sin a), and its scope origin the lot's corner map (0, 4) turned."""

from __future__ import annotations

import math

import numpy as np
import pytest
from backend.operations.derivations import per_lot, rect, rotated_rectangle, run

from grammarc.errors import GrammarError

#: The reference example's steps, with its ``r(-10, 70, 0)`` as CityEngine turns it: about the scope's
#: fixed x, then y (``backend.euler``), that is about y, then the new x.
EXAMPLE = "Lot --> extrude(3) t('0.2, 0, '0.7) s('0.5, '1, '0.5) r(0, 70, 0) r(-10, 0, 0) A\n"
TURN = -46.54
C, S = math.cos(math.radians(TURN)), math.sin(math.radians(TURN))


def reported(write, text: str, lots=None, **options) -> list[dict]:
    """Per lot, the reported key -> value (its sum) of ``text``."""
    r = run(write, text, lots or [rotated_rectangle(TURN, w=10.0, h=4.0, at=(5.0, 5.0))], **options)
    return [{k[:-4]: v for k, v in table.items() if k.endswith("_sum")} for table in per_lot(r).values()]


def components(name: str, call: str) -> str:
    return " ".join(f'report("{name}{c}", convert({c}, {call}))' for c in "xyz")


def test_the_reference_example_on_a_turned_lot(write):
    got, = reported(write, EXAMPLE + "A --> " + components("w", "scope, world, pos, 0, 0, 0")
                    + components("p", "scope, pivot, pos, 0, 0, 0") + components("o", "scope, world, orient, 0, 0, 0")
                    + ' report("tx", scope.tx) report("tz", scope.tz) X\n')
    # the scope origin moved by 0.2 of the lot's 10 m and 0.7 of its 4 m, in the lot's (pivot) system
    assert (got["px"], got["py"], got["pz"]) == pytest.approx((2.0, 0.0, 2.8))
    assert (got["px"], got["pz"]) == pytest.approx((got["tx"], got["tz"]))
    # in world: the lot's scope origin (map (5, 5) + 4 m along its turned map y) plus those along its axes
    origin = np.array([5 - 4 * S, 0, -(5 + 4 * C)])
    world = origin + 2.0 * np.array([C, 0, -S]) + 2.8 * np.array([S, 0, C])
    assert (got["wx"], got["wy"], got["wz"]) == pytest.approx(tuple(world))
    # the orientation in world, as the reference prints it: -10 about x, and 70 plus the lot's turn about y
    assert (got["ox"], got["oy"], got["oz"]) == pytest.approx((-10.0, 23.46, 0.0), abs=1e-9)


def test_scope_elevation_is_the_height_of_the_scope_origin(write):
    got, = reported(write, "Lot --> extrude(6) t(0, 2.5, 0) comp(f){ top : Top }\n"
                    'Top --> report("e", scope.elevation) report("w", convert(y, scope, world, pos, 0, 0, 0)) X\n')
    assert got["e"] == pytest.approx(8.5)
    assert got["e"] == got["w"]


def test_the_array_form_is_the_three_components(write):
    got, = reported(write, EXAMPLE + 'A --> report("n", size(convert(scope, world, pos, [1, 2, 3]))) '
                    + " ".join(f'report("a{i}", convert(scope, world, pos, [1, 2, 3])[{i}])' for i in range(3))
                    + components("c", "scope, world, pos, 1, 2, 3") + " X\n")
    assert got["n"] == 3
    assert [got[f"a{i}"] for i in range(3)] == [got[f"c{c}"] for c in "xyz"]


@pytest.mark.parametrize("kind, value", [("pos", "[1, -2, 3]"), ("orient", "[10, 20, 30]")])
@pytest.mark.parametrize("system", ["world", "object", "pivot"])
def test_converting_there_and_back_gives_the_value(write, kind, value, system):
    there = f"convert(scope, {system}, {kind}, {value})"
    got, = reported(write, EXAMPLE + "A --> " + " ".join(
        f'report("{c}", convert({system}, scope, {kind}, {there})[{i}])' for i, c in enumerate("xyz")) + " X\n")
    assert [got[c] for c in "xyz"] == pytest.approx(eval(value), abs=1e-9)


def test_the_pivot_is_the_object_system_and_scope_angles_are_its_orientation(write):
    got, = reported(write, "Lot --> extrude(2) t(1, 2, 3) r(0, 25, 0) "
                    + components("p", "scope, pivot, pos, 1, 1, 1") + components("o", "scope, object, pos, 1, 1, 1")
                    + ' report("ry", scope.ry) report("cy", convert(y, scope, object, orient, 0, 0, 0)) X\n')
    assert [got[f"p{c}"] for c in "xyz"] == pytest.approx([got[f"o{c}"] for c in "xyz"])
    assert got["cy"] == pytest.approx(got["ry"]) and got["ry"] == pytest.approx(25.0)


def test_positions_of_shapes_in_one_batch_convert_each_in_its_own_scope(write):
    """A split's parts are one batch: each part's scope origin lands at its own place in world."""
    got = reported(write, "Lot --> split(x) { 1 : A }*\nA --> report(\"x\", convert(x, scope, world, pos, 0.5, 0, 0)) "
                   "report(\"z\", convert(z, scope, world, pos, 0, 0, 0)) X\n", [rect(4, 2)])
    # the four parts' origins are at world x = 0, 1, 2, 3; their centres half a metre on; z is the lot's -2
    one, = got
    assert one["x"] == pytest.approx(0.5 + 1.5 + 2.5 + 3.5) and one["z"] == pytest.approx(4 * -2.0)


def test_initial_shape_name_start_rule_and_orientation(write):
    got = reported(write, '@StartRule\nParcel --> report(initialShape.name + " " + initialShape.startRule, 1) '
                   'report("oy", initialShape.origin.oy) report("ox", initialShape.origin.ox) X\n',
                   [rotated_rectangle(30.0), rect(3, 3)])
    assert [sorted(k for k in g if " " in k) for g in got] == [["0 Parcel"], ["1 Parcel"]]
    assert [g["oy"] for g in got] == pytest.approx([30.0, 0.0]) and [g["ox"] for g in got] == [0.0, 0.0]


@pytest.mark.parametrize("call", ["convert(w, scope, world, pos, 0, 0, 0)", "convert(x, scope, world, 0, 0, 0)",
                                  "convert(x, scope, earth, pos, 0, 0, 0)", 'convert("x", scope, world, pos, 0, 0, 0)',
                                  "convert(scope, world, angle, [0, 0, 0])"])
def test_convert_takes_its_keywords(write, call):
    with pytest.raises(GrammarError, match="unsupported: convert with these arguments") as error:
        reported(write, f'Lot --> report("k", {call}) X\n')
    assert len([d for d in error.value.diagnostics if d.is_error]) == 1
