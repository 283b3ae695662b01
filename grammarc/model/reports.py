"""The values of CityEngine's ``report(key, value)``: per lot, and over the whole city.

The derivation aggregates a chunk's rows per lot (``backend.report_rows``); ``Reports`` collects the lots of
every chunk and merges them into the totals, in PRT's flat form (``key_n``, ``key_sum``, ``key_avg``,
``key_min``, ``key_max``). ``io.reports`` writes them beside the output.
"""

from __future__ import annotations


class Reports:
    """Collects the per-lot reports of all chunks: {lot number: {key: aggregate}}."""

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


def entry_values(e: dict) -> dict:
    """n, sum, avg, min, max of one aggregated key, typed as the reported values were."""
    n = e["n"]
    if e["kind"] == "str":
        return {"n": float(n), "sum": e["sum"], "avg": e["sum"], "min": e["min"], "max": e["max"]}
    if e["kind"] == "bool":
        return {"n": float(n), "sum": e["sum"] > 0, "avg": e["sum"] / n >= 0.5, "min": e["min"] > 0,
                "max": e["max"] > 0}
    return {"n": float(n), "sum": e["sum"], "avg": e["sum"] / n, "min": e["min"], "max": e["max"]}
