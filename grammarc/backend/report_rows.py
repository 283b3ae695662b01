"""CityEngine's ``report(key, value)``: a chunk's report rows aggregated per lot.

As PRT does, each key aggregates into ``key_n``, ``key_sum``, ``key_avg``, ``key_min`` and ``key_max``
(``model.reports``). Numbers aggregate as numbers; booleans as booleans (sum and max: any, min: all, avg: the
majority); strings keep the first value reported for sum and avg and compare as text for min and max. A
chunk's rows are grouped by (lot, key) with one sort.
"""

from __future__ import annotations

import numpy as np


def aggregate_chunk(rows: list[tuple], lot_index: np.ndarray, names: list[str]) -> dict[int, dict]:
    """Per lot (numbered as in the input): {key: {"kind", "n", "sum", "min", "max"}} from report rows."""
    result: dict[int, dict] = {}
    for kind in ("num", "bool", "str"):
        parts = [(lot, key, value) for lot, key, value, k in rows if k == kind and len(lot)]
        if not parts:
            continue
        lot = np.concatenate([p[0] for p in parts]).astype(np.int64)
        key = np.concatenate([p[1] for p in parts]).astype(np.int64)
        value = np.concatenate([p[2] for p in parts])
        group = lot * (int(key.max()) + 1) + key
        order = np.argsort(group, kind="stable")
        group, lot, key, value = group[order], lot[order], key[order], value[order]
        starts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
        counts = np.diff(np.r_[starts, len(group)])
        sums = np.add.reduceat(value, starts)
        lows = np.minimum.reduceat(value, starts)
        highs = np.maximum.reduceat(value, starts)
        for s, n, total, low, high in zip(starts, counts, sums, lows, highs):
            entry = {"kind": kind, "n": int(n), "sum": float(total), "min": float(low), "max": float(high)}
            if kind == "str":
                texts = [names[int(v)] for v in value[s:s + n]]
                entry.update(sum=texts[0], min=min(texts), max=max(texts))
            result.setdefault(int(lot_index[lot[s]]), {})[names[int(key[s])]] = entry
    return result
