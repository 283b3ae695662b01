"""search/run.py and ``grammarc search``: the solutions as a record numbered in the order found, the
limits said, the workers."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from grammarc.cli import main
from grammarc.io.npz import read_instances

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "gramatica"
FIGURE1 = EXAMPLES / "figure1.cga"


def test_solutions_are_a_record_numbered_in_the_order_found(tmp_path, capsys):
    out = tmp_path / "solutions.npz"
    assert main(["search", str(FIGURE1), "--strategy", "astar", "--emit", str(out), "--workers", "1"]) == 0
    assert "astar: 2 solutions from 12 states of 1 lots" in capsys.readouterr().err
    record = read_instances(out)
    search = record["meta"]["search"]
    assert [(s["solution"], s["lot"], s["path"], s["cost"]) for s in search["solutions"]] == [
        (0, "rectangle", [2, 2], 9.0), (1, "rectangle", [1, 1, 1], 12.0)]
    assert search["strategy"] == "astar" and search["states"] == 12 and search["limited"] == []
    # solution 0 is two strips 3 high, solution 1 three strips 2 high: the lot column numbers them
    strips = record["symbols"][record["symbol"]] == "strip"
    assert np.bincount(record["lot"][strips]).tolist() == [2, 3]


def test_max_states_is_said_even_quiet(tmp_path, capsys):
    assert main(["search", str(EXAMPLES / "malagueira.cga"), "--max-states", "30", "--workers", "1", "-q"]) == 0
    err = capsys.readouterr().err
    assert "grammarc: lot T2: stopped at --max-states 30 (30 states derived, 0 solutions)" in err
    assert "lot T3: stopped at --max-states 30" in err


def test_workers_find_the_same_solutions(tmp_path):
    found = []
    for workers in ("1", "2"):
        out = tmp_path / f"w{workers}.npz"
        assert main(["search", str(EXAMPLES / "malagueira.cga"), "--strategy", "dfs", "--batch", "8",
                     "--workers", workers, "--emit", str(out), "-q"]) == 0
        found.append(read_instances(out))
    assert found[0]["meta"]["search"]["solutions"] == found[1]["meta"]["search"]["solutions"]
    np.testing.assert_array_equal(found[0]["xform"], found[1]["xform"])


def test_a_cityengine_grammar_is_refused(tmp_path, capsys):
    grammar = tmp_path / "ce.cga"
    grammar.write_text('version "2022.0"\nLot --> extrude(3)\n', encoding="utf-8")
    assert main(["search", str(grammar), "--workers", "1"]) == 2
    assert "search takes grammars in the paper notation" in capsys.readouterr().err
