"""search/tree_picture.py and ``grammarc render tree.json``: the derivation graph, a thumbnail per state."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from grammarc.cli import main
from grammarc.search.tree_picture import FRAME

FIGURE1 = Path(__file__).resolve().parents[2] / "examples" / "gramatica" / "figure1.cga"


def test_a_tree_is_drawn_in_rows_with_its_states_status(tmp_path, capsys):
    tree, picture = tmp_path / "tree.json", tmp_path / "tree.png"
    assert main(["search", str(FIGURE1), "--tree", str(tree), "--workers", "1", "-q"]) == 0
    assert main(["render", str(tree), "-o", str(picture)]) == 0
    assert f"{picture}: 12 states in 4 rows" in capsys.readouterr().err
    pixels = np.asarray(Image.open(picture).convert("RGB")).reshape(-1, 3)
    colours = {tuple(p) for p in pixels}
    # every status of the tree frames a state: consequents, pruned, rejected, solutions
    assert {FRAME["branch"], FRAME["pruned"], FRAME["complete"], FRAME["goal"]} <= colours
    assert FRAME["failed"] not in colours


def test_a_file_that_is_no_tree_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text('{"states": []}')
    assert main(["render", str(bad), "-o", str(tmp_path / "x.png")]) == 2
    assert "not a tree of `grammarc search --tree`" in capsys.readouterr().err


@pytest.mark.parametrize("states", [500])
def test_a_tree_too_large_to_draw_is_refused(tmp_path, capsys, states):
    tree = tmp_path / "tree.json"
    assert main(["search", str(FIGURE1.parent / "malagueira.cga"), "--tree", str(tree), "--workers", "1",
                 "--max-states", str(states), "-q"]) == 0
    assert main(["render", str(tree), "-o", str(tmp_path / "x.png")]) == 2
    assert "is too many to draw (at most 400)" in capsys.readouterr().err
