"""CityEngine's ``report(key, value)``: values aggregated per lot and over the whole city.

As PRT does, each key aggregates into ``key_n``, ``key_sum``, ``key_avg``, ``key_min`` and ``key_max``.
Numbers aggregate as numbers; booleans as booleans (sum and max: any, min: all, avg: the majority);
strings keep the first value reported for sum and avg and compare as text for min and max. A chunk's rows
are grouped by (lot, key) with one sort; the per-lot tables then merge into the totals.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from grammarc.io.atomic import replacing


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


class Reports:
    """Collects the per-lot reports of all chunks and writes them beside the output."""

    def __init__(self) -> None:
        self.lots: dict[int, dict] = {}

    def add(self, per_lot: dict[int, dict]) -> None:
        self.lots.update(per_lot)

    def __bool__(self) -> bool:
        return bool(self.lots)

    def totals(self) -> dict[str, dict]:
        merged: dict[str, dict] = {}
        for lot in sorted(self.lots):
            for key, entry in self.lots[lot].items():
                if key not in merged:
                    merged[key] = dict(entry)
                    continue
                m = merged[key]
                m["n"] += entry["n"]
                if entry["kind"] == "str":
                    m["min"], m["max"] = min(m["min"], entry["min"]), max(m["max"], entry["max"])
                else:
                    m["sum"] += entry["sum"]
                    m["min"], m["max"] = min(m["min"], entry["min"]), max(m["max"], entry["max"])
        return merged

    def table(self, entries: dict[str, dict]) -> dict:
        """PRT's flat form: ``key_n``, ``key_sum``, ``key_avg``, ``key_min``, ``key_max``."""
        out = {}
        for key in sorted(entries):
            e = entry_values(entries[key])
            for suffix in ("n", "sum", "avg", "min", "max"):
                out[f"{key}_{suffix}"] = e[suffix]
        return out

    def write(self, path: Path, ids: dict[int, str] | None = None) -> None:
        """The per-lot tables and the total, as JSON (``{"total": {...}, "lots": {index: {...}},
        "ids": {index: id}}``) or, for a ``.csv`` path, as one table: a row per lot (its input number and
        id) and a last row ``total``, a column per ``key_n``/``_sum``/``_avg``/``_min``/``_max``, empty where
        a lot did not report the key. Written atomically."""
        ids = ids or {}
        lots = {lot: self.table(self.lots[lot]) for lot in sorted(self.lots)}
        total = self.table(self.totals())
        with replacing(path) as tmp:
            if path.suffix.lower() == ".csv":
                with open(tmp, "w", newline="") as out:
                    table = csv.writer(out)
                    table.writerow(["lot", "id", *total])
                    for lot, row in lots.items():
                        table.writerow([lot, ids.get(lot, ""), *(_cell(row.get(key, "")) for key in total)])
                    table.writerow(["total", "", *(_cell(v) for v in total.values())])
            else:
                data = {"total": total, "lots": {str(lot): row for lot, row in lots.items()},
                        "ids": {str(lot): ids[lot] for lot in lots if lot in ids}}
                tmp.write_text(json.dumps(data, indent=1, sort_keys=False) + "\n")


def _cell(value) -> str:
    """A CSV cell: numbers as Python's shortest repr, booleans as true/false, as JSON writes them."""
    return json.dumps(value) if isinstance(value, bool) else str(value)


def entry_values(e: dict) -> dict:
    """n, sum, avg, min, max of one aggregated key, typed as the reported values were."""
    n = e["n"]
    if e["kind"] == "str":
        return {"n": float(n), "sum": e["sum"], "avg": e["sum"], "min": e["min"], "max": e["max"]}
    if e["kind"] == "bool":
        return {"n": float(n), "sum": e["sum"] > 0, "avg": e["sum"] / n >= 0.5, "min": e["min"] > 0,
                "max": e["max"] > 0}
    return {"n": float(n), "sum": e["sum"], "avg": e["sum"] / n, "min": e["min"], "max": e["max"]}
