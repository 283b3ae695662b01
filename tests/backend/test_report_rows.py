"""backend/report_rows.py: a chunk's report rows aggregated per lot and key, each kind as PRT aggregates it."""

from __future__ import annotations

import numpy as np

from grammarc.backend.report_rows import aggregate_chunk


def test_rows_aggregate_per_lot_and_key_numbered_as_in_the_input():
    names = ["area", "style", "tall", "brick", "tuff"]
    rows = [
        (np.array([0, 1, 0]), np.array([0, 0, 0]), np.array([10.0, 5.0, 20.0]), "num"),
        (np.array([1, 1]), np.array([1, 1]), np.array([4, 3], dtype=np.int32), "str"),  # ids of "tuff", "brick"
        (np.array([0, 0, 0]), np.array([2, 2, 2]), np.array([1.0, 0.0, 0.0]), "bool"),
        (np.array([], dtype=int), np.array([], dtype=int), np.array([]), "num"),  # a report no shape reached
    ]
    per_lot = aggregate_chunk(rows, np.array([7, 9]), names)
    assert set(per_lot) == {7, 9}
    assert per_lot[7]["area"] == {"kind": "num", "n": 2, "sum": 30.0, "min": 10.0, "max": 20.0}
    assert per_lot[9]["area"]["n"] == 1
    # a string keeps its first value as sum, and min and max as text
    assert per_lot[9]["style"] == {"kind": "str", "n": 2, "sum": "tuff", "min": "brick", "max": "tuff"}
    assert (per_lot[7]["tall"]["sum"], per_lot[7]["tall"]["min"], per_lot[7]["tall"]["max"]) == (1.0, 0.0, 1.0)
    assert aggregate_chunk([], np.array([7]), names) == {}
