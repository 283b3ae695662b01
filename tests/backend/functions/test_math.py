"""backend/functions/math.py: the reference's math functions that ``test_evaluate`` does not cover."""

from __future__ import annotations

from backend.operations.derivations import per_lot, rect, run


def test_isinf_tells_infinities_from_numbers_and_nan(write):
    r = run(write, 'attr v = 0\nLot --> report("k", isinf(1 / v) && isinf(-1 / v) && !isinf(v) && !isinf(log(v - 1))) '
            "X\n", [rect(2, 2)])
    assert [t["k_sum"] for t in per_lot(r).values()] == [1.0]
