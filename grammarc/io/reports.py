"""Reports out: the per-lot and total values of ``report()`` as JSON or CSV, beside the output."""

from __future__ import annotations

import contextlib
import csv
import json
from pathlib import Path

from grammarc.atomic import replacing
from grammarc.model.reports import Reports

__all__ = ["staged_reports", "write_reports"]


def write_reports(reports: Reports, path: Path, ids: dict[int, str] | None = None) -> None:
    """The per-lot tables and the total, as JSON (``{"total": {...}, "lots": {index: {...}},
    "ids": {index: id}}``) or, for a ``.csv`` path, as one table: a row per lot (its input number and
    id) and a last row ``total``, a column per ``key_n``/``_sum``/``_avg``/``_min``/``_max``, empty where
    a lot did not report the key. Written atomically."""
    with staged_reports(reports, path, ids):
        pass


@contextlib.contextmanager
def staged_reports(reports: Reports, path: Path, ids: dict[int, str] | None = None):
    """``write_reports`` for a block that puts the output in place: the reports are written under a
    temporary name before it runs (a failure to write them raises before the output is in place) and
    renamed onto ``path`` when it ends; a block that raises leaves ``path`` as it was."""
    ids = ids or {}
    lots = {lot: reports.table(reports.lots[lot]) for lot in sorted(reports.lots)}
    total = reports.table(reports.totals())
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
        yield


def _cell(value) -> str:
    """A CSV cell: numbers as Python's shortest repr, booleans as true/false, as JSON writes them."""
    return json.dumps(value) if isinstance(value, bool) else str(value)
