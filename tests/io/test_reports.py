"""io/reports.py: the reports written beside the output, as JSON or as one CSV table."""

from __future__ import annotations

import csv
import json

from grammarc.io.reports import write_reports
from grammarc.model.reports import Reports


def _reports() -> Reports:
    reports = Reports()
    reports.add({3: {"area": {"kind": "num", "n": 1, "sum": 12.5, "min": 12.5, "max": 12.5}}})
    reports.add({7: {"area": {"kind": "num", "n": 2, "sum": 3.0, "min": 1.0, "max": 2.0},
                     "roof": {"kind": "bool", "n": 1, "sum": 1.0, "min": 1.0, "max": 1.0}}})
    return reports


def test_json_holds_the_total_each_lot_and_its_id(tmp_path):
    path = tmp_path / "city.reports.json"
    write_reports(_reports(), path, {3: "a", 7: "b"})
    data = json.loads(path.read_text())
    assert data["total"]["area_n"] == 3.0 and data["total"]["area_sum"] == 15.5
    assert data["lots"]["3"] == {"area_n": 1.0, "area_sum": 12.5, "area_avg": 12.5, "area_min": 12.5,
                                 "area_max": 12.5}
    assert data["lots"]["7"]["roof_max"] is True and data["ids"] == {"3": "a", "7": "b"}
    assert [p.name for p in tmp_path.iterdir()] == ["city.reports.json"]  # no temporary left


def test_csv_is_a_row_per_lot_then_the_total(tmp_path):
    path = tmp_path / "areas.csv"
    write_reports(_reports(), path, {3: "a"})
    rows = list(csv.reader(path.open()))
    assert rows[0][:4] == ["lot", "id", "area_n", "area_sum"] and "roof_max" in rows[0]
    assert rows[1][:2] == ["3", "a"] and rows[1][rows[0].index("roof_max")] == ""  # lot 3 did not report it
    assert rows[2][:2] == ["7", ""] and rows[2][rows[0].index("roof_max")] == "true"
    assert rows[3][:4] == ["total", "", "3.0", "15.5"]
