"""Tests of grammarc.model.lots: a subset of lots by position (take) and by id (select)."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.errors import UsageError
from grammarc.io.lots import lots_from_polygons
from grammarc.model.lots import BadLot

SQUARE = [[0, 0], [10, 0], [10, 10], [0, 10]]


def rings(lots, i: int) -> list[np.ndarray]:
    """The rings of lot i, (k, 3) world coordinates each."""
    o = lots.ring_offsets
    return [lots.vertices[o[r] : o[r + 1]] for r in range(lots.lot_offsets[i], lots.lot_offsets[i + 1])]


def test_take_rebases_offsets_and_slices_attrs():
    squares = [[np.array(SQUARE) + 100 * i] for i in range(3)]
    holed = [
        np.array([[0, 0], [40, 0], [40, 40], [0, 40]]),
        np.array([[10, 10], [10, 30], [30, 30], [30, 10]]),
    ]
    lots = lots_from_polygons([*squares, holed], attrs={"k": [0, 1, 2, 3]}, ids=list("abcd"))
    sub = lots.take(np.array([3, 1]))
    assert sub.ids.tolist() == ["d", "b"] and sub.index.tolist() == [3, 1]
    assert sub.lot_offsets.tolist() == [0, 2, 3] and sub.ring_offsets.tolist() == [0, 4, 8, 12]
    np.testing.assert_array_equal(sub.attrs["k"], [3.0, 1.0])
    for j, i in enumerate([3, 1]):
        for got, want in zip(rings(sub, j), rings(lots, i), strict=True):
            np.testing.assert_array_equal(got, want)
    tail = lots.take(slice(1, None))
    assert tail.ids.tolist() == ["b", "c", "d"] and tail.lot_offsets.tolist() == [0, 1, 2, 4]
    assert len(lots.take(np.array([], dtype=np.int64))) == 0
    assert tail.bad is lots.bad and tail.source == lots.source


@pytest.mark.parametrize("span", [slice(1, 3), slice(0, 4), slice(2, 2), slice(3, 9), slice(1, None)])
def test_a_run_of_lots_is_taken_as_read_only_views_the_same_as_by_their_positions(span):
    """A chunk of a build (a slice) takes views of the lots' arrays, not a gather of them: the same lots
    as taken by their positions, and a write into them raises rather than change every lot's."""
    holed = [np.array([[0, 0], [40, 0], [40, 40], [0, 40]]), np.array([[10, 10], [10, 30], [30, 30], [30, 10]])]
    lots = lots_from_polygons([[np.array(SQUARE) + 100], holed, [np.array(SQUARE)], holed],
                              attrs={"k": [0, 1, 2, 3], "name": list("wxyz")}, ids=list("abcd"))
    run, gathered = lots.take(span), lots.take(np.arange(len(lots))[span])
    for name in ("ids", "index", "vertices", "ring_offsets", "lot_offsets", "street"):
        np.testing.assert_array_equal(getattr(run, name), getattr(gathered, name))
    assert run.attrs.keys() == gathered.attrs.keys()
    assert all(run.attrs[k].tolist() == gathered.attrs[k].tolist() for k in run.attrs)
    assert len(run) == 0 or np.shares_memory(run.vertices, lots.vertices)
    with pytest.raises(ValueError, match="read-only"):
        run.vertices[:1] = 0.0


def test_select_keeps_input_order_and_the_bad_lots_asked_for():
    flat = np.array([[0, 0], [5, 0], [10, 0]])
    lots = lots_from_polygons([[np.array(SQUARE) + 100 * i] for i in range(3)] + [[flat]], ids=list("abcz"))
    assert lots.bad == (BadLot(3, "z", "zero area"),)
    picked = lots.select(["c", "a"])
    assert picked.ids.tolist() == ["a", "c"] and picked.index.tolist() == [0, 2] and picked.bad == ()
    assert lots.select(["z", "b"]).bad == lots.bad
    with pytest.raises(UsageError, match="--select: no lot has the id 'nope', 'x0'"):
        lots.select(["a", "x0", "nope"])
    with pytest.raises(UsageError, match=r"no lot has the id 'x0', .*'x7' \(and 2 more\)$"):
        lots.select([f"x{k}" for k in range(12)])
