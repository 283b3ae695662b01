"""model/reports.py: the reports of every lot merged into the city's totals, in PRT's flat form."""

from __future__ import annotations

from grammarc.model.reports import Reports, entry_values


def _reports() -> Reports:
    reports = Reports()
    reports.add({0: {"area": {"kind": "num", "n": 2, "sum": 30.0, "min": 10.0, "max": 20.0},
                     "style": {"kind": "str", "n": 1, "sum": "brick", "min": "brick", "max": "brick"}}})
    reports.add({1: {"area": {"kind": "num", "n": 1, "sum": 5.0, "min": 5.0, "max": 5.0},
                     "style": {"kind": "str", "n": 2, "sum": "adobe", "min": "adobe", "max": "tuff"},
                     "tall": {"kind": "bool", "n": 3, "sum": 1.0, "min": 0.0, "max": 1.0}}})
    return reports


def test_totals_merge_the_lots_by_key():
    totals = _reports().totals()
    assert totals["area"] == {"kind": "num", "n": 3, "sum": 35.0, "min": 5.0, "max": 20.0}
    # a string keeps its first lot's first value as sum, and compares as text for min and max
    assert totals["style"] == {"kind": "str", "n": 3, "sum": "brick", "min": "adobe", "max": "tuff"}
    assert totals["tall"]["n"] == 3


def test_table_is_prts_flat_form_typed_as_reported():
    reports = _reports()
    table = reports.table(reports.totals())
    assert list(table)[:5] == ["area_n", "area_sum", "area_avg", "area_min", "area_max"]
    assert table["area_avg"] == 35.0 / 3 and table["style_avg"] == "brick"
    # booleans: sum and max any, min all, avg the majority (1 of 3 is not)
    assert (table["tall_sum"], table["tall_min"], table["tall_max"], table["tall_avg"]) == (True, False, True, False)
    assert entry_values({"kind": "bool", "n": 2, "sum": 1.0, "min": 0.0, "max": 1.0})["avg"] is True


def test_no_lot_reported_is_false():
    assert not Reports() and _reports()
