"""backend/operations/control.py in derivations: ``case`` and ``p%`` blocks."""

from __future__ import annotations

import math
from collections import Counter

from derivations import (
    names,
    rect,
    run,
)


def test_case_on_scope_size(write):
    r = run(write, "Lot -->\n    case scope.sx > 10 : Big\n    case scope.sx > 5 : Mid\n    else : Small\n",
            [rect(12, 8), rect(8, 8), rect(4, 4), rect(10, 2)])
    assert names(r) == ["Big", "Mid", "Small", "Mid"]


def test_stochastic_block_frequencies(write):
    n = 10_000
    r = run(write, "Lot -->\n    30% : A\n    else : B\n", [rect(1, 1)] * n)
    count = Counter(names(r))
    sigma = math.sqrt(n * 0.3 * 0.7)
    assert abs(count["A"] - 0.3 * n) < 4 * sigma and count["A"] + count["B"] == n

