"""search/states.py: states as columns, their consequents, and a batch of them derived at once."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.io.lots import read_lots
from grammarc.search import Deriving, States

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "gramatica"


def _states(paths: list[list[int]], lot: int = 0) -> States:
    parts = [States.initial(lot)]
    for path in paths:
        state = States.initial(lot)
        parts.append(replace(state, path=np.array([path], np.int32), length=np.array([len(path)])))
    return States.concat(parts)


def test_consequents_extend_each_path_by_each_option_in_order_or_reversed():
    states = replace(_states([[2], [0, 1]]), id=np.array([7, 8, 9]))
    kids = states.consequents(np.array([2, 0, 3]))
    assert [k.tolist()[:n] for k, n in zip(kids.path, kids.length)] == [[0], [1], [0, 1, 0], [0, 1, 1], [0, 1, 2]]
    assert kids.parent.tolist() == [7, 7, 9, 9, 9]
    reverse = states.consequents(np.array([2, 0, 3]), reverse=True)
    assert [k.tolist()[:n] for k, n in zip(reverse.path, reverse.length)] == [[1], [0], [0, 1, 2], [0, 1, 1], [0, 1, 0]]


def test_concat_pads_paths_with_minus_one():
    states = _states([[2], [0, 1, 1]])
    assert states.path.tolist() == [[-1, -1, -1], [2, -1, -1], [0, 1, 1]]


def test_a_batch_too_large_for_its_budget_is_halved_and_numbers_its_records_on():
    deriving = Deriving(make_plan(compile_grammar(EXAMPLES / "figure1.cga")), read_lots(EXAMPLES / "figure1.geojson"))
    states = _states([[2, 2], [1, 1, 1], [2], [0, 0]])
    whole, (records,) = deriving.derive(states, records=True, first=10)
    small = replace(deriving, chunk_budget=3)
    halves, chunks = small.derive(states, records=True, first=10)
    assert len(chunks) > 1
    for name in ("options", "site", "cost", "goal", "prune"):
        np.testing.assert_array_equal(getattr(whole, name), getattr(halves, name))
    assert whole.options.tolist() == [3, 0, 0, 3, 3]
    np.testing.assert_array_equal(np.concatenate([c.lot for c in chunks]), records.lot)
    assert set(records.lot.tolist()) == {11, 12, 13, 14}  # the root has no leaf yet; numbered from 10
