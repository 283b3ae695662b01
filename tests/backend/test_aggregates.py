"""backend/aggregates.py: a search state's aggregates over its leaves, and its goal, prune and heuristic."""

from __future__ import annotations

import numpy as np
import pytest
from operations.derivations import rect

from grammarc.backend.choices import Choices
from grammarc.backend.derive import derive_chunk
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS
from grammarc.io.lots import lots_from_polygons
from grammarc.search import Deriving

GRAMMAR = """attr least = 1
lot ~> S(1r, 2, 1r) Subdiv("Z", 1, 2, choose(3, 1)){ a | a | b }
goal: count("a") == 2 && sum(Scope.sz of "a") == 3 && min(Scope.sz of "a") == least && max(Scope.sz of "a") == 2
      && mean(Scope.sz of "a") == 1.5 && area("b") == 12 && volume("b") == 24 && count(Scope.sz > 1 of "a") == 1
prune: count("a") > 5
heuristic: min(Scope.sx of "c") + 0 * count("b")
cost: Scope.sx
"""


def _derived(write, path, length):
    plan = make_plan(compile_grammar(write("g.cga", GRAMMAR)))
    choices = Choices(np.array(path, np.int32), np.array(length), Deriving(plan, None).aggregates)
    derive_chunk(plan, lots_from_polygons([rect(4, 6)] * len(length)), seed=0, limits=LIMITS, overrides={},
                 chunk_budget=10**6, choices=choices, records=False)
    return choices


def test_aggregates_goal_prune_and_heuristic_of_complete_and_partial_states(write):
    choices = _derived(write, [[0], [1], [0]], [1, 1, 0])
    assert choices.options.tolist() == [0, 0, 2]  # the third state stops at choose(3, 1)
    assert choices.goal.tolist() == [True, False, False]  # b is 1 deep in the second: area 4
    assert choices.prune.tolist() == [False, False, False]
    assert np.isnan(choices.heuristic).all()  # the min of no shapes
    assert choices.cost.tolist() == [4.0, 4.0, 4.0]  # one rule application on a 4 wide lot


def test_a_stopped_state_has_the_leaves_made_before_its_stop(write):
    choices = _derived(write, [[0]], [0])
    # the split's parts are made after its sizes are chosen: the stopped state has no leaf yet
    index = [a.func for a in choices.aggregates].index("sum")
    assert choices.value(index).tolist() == [0.0]
    assert choices.value([a.func for a in choices.aggregates].index("mean")) == pytest.approx(np.nan, nan_ok=True)
