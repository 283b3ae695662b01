"""backend/functions/tables.py: ``readTextFile``, ``readStringTable`` and ``readFloatTable`` on files of
the grammar's folders. The table is the reference example's (floorData.csv, its values as the page prints
them), written in this test's own words."""

from __future__ import annotations

import codecs
import os

import pytest
from backend.operations.derivations import per_lot, rect, run

from grammarc.backend.functions import tables
from grammarc.backend.functions.tables import _delimiter, _table

FLOORS = ("Floor,Height,Color,Usage,Setback\n0,10,#00FF00,Pomp,0.5\n1,7,#0000FF,Helpdesk,0.75\n"
          "2,5,#AAAAAA,Party,0.75\n3,5,#AAAAAA,Party,0.75\n4,7,#FF0000,Living,0.1\n")


def reported(write, body: str, lots=1) -> list[dict]:
    """Per lot, the reported key -> value of a rule ``Lot --> body X``."""
    r = run(write, f"Lot --> {body} X\n", [rect(2, 2)] * lots)
    return [{k[:-4]: v for k, v in table.items() if k.endswith("_sum")} for table in per_lot(r).values()]


def test_the_reference_example(write):
    """The page prints the 6 x 5 table with its header as row 0, and 0.75 as the element at row 1, column 4,
    which that print shows at row 2 (row 1 ends in 0.5): arrays count from 0, so the print is what is kept."""
    write("floorData.csv", FLOORS)
    got, = reported(write, 'report("s", readStringTable("floorData.csv")[2, 4]) '
                    'report("f", readFloatTable("floorData.csv")[2, 4]) '
                    'report("rows", nRows(readStringTable("floorData.csv"))) '
                    'report("cols", nColumns(readFloatTable("floorData.csv"))) '
                    'report("head", readStringTable("floorData.csv")[0, 3]) '
                    'report("colour", readStringTable("floorData.csv")[4, 2]) '
                    'report("word", isnan(readFloatTable("floorData.csv")[2, 3]))')
    assert got == {"s": "0.75", "f": 0.75, "rows": 6.0, "cols": 5.0, "head": "Usage", "colour": "#AAAAAA",
                   "word": 1.0}


def test_a_path_per_shape_reads_each_file_once(write, monkeypatch):
    write("a.csv", "1;2\n3;4\n")
    write("b.csv", "5\t6\t7\n")
    reads = []
    read = tables._text.__wrapped__
    monkeypatch.setattr(tables, "_text", lambda *key: reads.append(key[0].name) or read(*key))
    tables._table.cache_clear()
    r = run(write, 'Lot --> split(x) { 0.5 : A }*\nA --> report("v", readFloatTable(case split.index % 2 == 0: '
                   '"a.csv" else: "b.csv")[0, 1] + 10 * nColumns(readFloatTable(case split.index % 2 == 0: '
                   '"a.csv" else: "b.csv"))) X\n', [rect(2, 2)])
    table, = per_lot(r).values()
    assert table["v_n"] == 4 and table["v_sum"] == 2 * (2 + 20) + 2 * (6 + 30)
    assert sorted(set(reads)) == ["a.csv", "b.csv"] and len(reads) == 2


def test_text_files_keep_their_text(write, tmp_path):
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "dos.txt").write_bytes(b"one\r\ntwo\rthree\x07\tfour\n")
    (tmp_path / "notes" / "wide.txt").write_bytes(codecs.BOM_UTF16_LE + "h\u00e9llo".encode("utf-16-le"))
    got, = reported(write, 'report("dos", readTextFile("notes/dos.txt")) report("wide", readTextFile("notes/wide.txt")) '
                           'report("n", len(readTextFile("notes/dos.txt")))')
    assert got["dos"] == "one\ntwo\nthree?\tfour\n" and got["wide"] == "h\u00e9llo" and got["n"] == 20


@pytest.mark.parametrize("text, rows", [
    # commas; blanks around cells are trimmed, quoted cells keep their delimiter, short rows are filled
    ('a, b,c\n"x, y",2\n\n', [["a", "b", "c"], ["x, y", "2", ""]]),
    # semicolons win over the decimal commas they come with
    ("1,5;2,5\n3;4,25\n", [["1,5", "2,5"], ["3", "4,25"]]),
    # commas over the string lists some cells hold
    ("use,colours\nshop,#FF0000;#00FF00\nhome,#0000FF\n", [["use", "colours"], ["shop", "#FF0000;#00FF00"],
                                                             ["home", "#0000FF"]]),
    ("a\tb c\t1\n", [["a", "b c", "1"]]),
    ("  Floor   Height\n      0       10\n", [["Floor", "Height"], ["0", "10"]]),
    ("one\ntwo\n", [["one"], ["two"]]),
    ("", []),
])
def test_tables_find_their_delimiter(tmp_path, text, rows):
    path = tmp_path / "t.csv"
    path.write_text(text, encoding="utf-8")
    stat = path.stat()
    table = _table(path, stat.st_mtime_ns, stat.st_size)
    assert [list(table.cells[i * table.columns:(i + 1) * table.columns]) for i in range(table.rows)] == rows


def test_delimiters_in_order_of_preference():
    assert _delimiter(["a;b,c", "d;e,f"]) == ";"
    assert _delimiter(["a,b", "c;d,e"]) == ","
    assert _delimiter(["abc"]) is None


def test_an_edited_file_is_read_again(write, tmp_path):
    path = write("t.csv", "1,2\n")
    assert reported(write, 'report("v", readFloatTable("t.csv")[0, 1])') == [{"v": 2.0}]
    path.write_text("1,2,3\n", encoding="utf-8")
    os.utime(path, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns + 10**9))
    assert reported(write, 'report("v", readFloatTable("t.csv")[0, 2])') == [{"v": 3.0}]


def test_files_outside_the_grammars_folders_or_missing_fail_their_lots(write, tmp_path):
    outside = tmp_path.parent / "secret.txt"
    outside.write_text("no", encoding="utf-8")
    for path in ("../secret.txt", str(outside), "missing.csv"):
        r = run(write, f'Lot --> report("v", readTextFile("{path}")) X\n', [rect(2, 2)])
        assert r["reports"].lots == {} and len(r["bad"]) == 1, path
        assert "is not a file of the grammar's folders" in r["bad"][0].reason


def test_files_too_large_are_refused_before_they_are_read(write, monkeypatch):
    write("big.txt", "x" * 100)
    monkeypatch.setattr(tables, "MAX_FILE_BYTES", 99)
    r = run(write, 'Lot --> report("v", readTextFile("big.txt")) X\n', [rect(2, 2)])
    assert "larger than" in r["bad"][0].reason
