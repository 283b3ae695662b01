"""search/tree.py: the derivation graph, each state with its parent, the choice that made it, its status."""

from __future__ import annotations

import json
from pathlib import Path

from grammarc.cli import main
from grammarc.compiler import compile_grammar
from grammarc.search.tree import choice_sites

FIGURE1 = Path(__file__).resolve().parents[2] / "examples" / "gramatica" / "figure1.cga"


def test_choice_sites_name_each_choose_and_each_set_of_question_marks(write):
    module = compile_grammar(write("g.cga", 'a ~> Subdiv("X", choose(1, 2), 1r){ b | c }\nb ~> d ?\n  ~> e f ?\n')).module
    sites = sorted(choice_sites(module).values(), key=lambda s: s["at"])
    assert sites == [
        {"rule": "a", "at": "1:18", "choice": "choose(1, 2)", "options": ["1", "2"]},
        {"rule": "b", "at": "2:1", "choice": "?", "options": ["d", "e f"]},
    ]


def test_the_tree_names_each_states_parent_rule_and_option(tmp_path):
    tree = tmp_path / "tree.json"
    assert main(["search", str(FIGURE1), "--tree", str(tree), "--workers", "1", "-q"]) == 0
    states = json.loads(tree.read_text())["states"]
    assert [s["id"] for s in states] == list(range(12))
    root, first = states[0], states[1]
    assert (root["parent"], root["made_by"], root["consequents"], root["status"]) == (None, None, 3, "branch")
    assert first["parent"] == 0 and first["path"] == [0]
    assert first["made_by"] == {"rule": "rest", "at": "14:37", "choice": "choose(1, 2, 3)", "option": 0, "value": "1"}
    assert first["status"] == "pruned"  # a strip 1 high
    goals = [s for s in states if s["status"] == "goal"]
    assert [(s["path"], s["solution"]) for s in goals] == [([2, 2], 0), ([1, 1, 1], 1)]  # BFS: by layer
    assert {s["status"] for s in states} == {"branch", "pruned", "complete", "goal"}
    by_id = {s["id"]: s for s in states}
    assert all(by_id[s["parent"]]["path"] == s["path"][:-1] for s in states[1:])
