"""backend/choices.py: a set of consequents takes a search state's choice, or a draw from the shape's stream."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from operations.derivations import names, paper, rect

from grammarc.backend.choices import Choices, consequent

LOTS = [rect(10, 6)] * 300


def test_a_state_takes_its_path_in_order_and_stops_beyond_it():
    choices = Choices(np.array([[2, 1, 0], [1, 0, 0]], np.int32), np.array([3, 1]))
    # lot 0 twice and lot 1 once in one batch: lot 0's shapes take its first two choices, in their order
    assert choices.pick(np.array([0, 1, 0]), 3, site=7).tolist() == [2, 1, 1]
    assert choices.options.tolist() == [0, 0]
    # lot 0's third choice is its last; lot 1 has no second: it stops here, at 4 options of site 9
    assert choices.pick(np.array([1, 0]), 4, site=9).tolist() == [0, 0]
    assert choices.options.tolist() == [0, 4] and choices.site.tolist() == [-1, 9]
    assert choices.stopped.tolist() == [False, True]
    # a stopped lot keeps the choice it stopped at
    choices.pick(np.array([1, 0]), 2, site=11)
    assert choices.options.tolist() == [2, 4] and choices.site.tolist() == [11, 9]


def test_a_build_draws_each_option_alike_from_the_shapes_stream():
    key = np.arange(30_000, dtype=np.uint64) * np.uint64(0x9E3779B97F4A7C15)
    picked = consequent(None, False, np.zeros(len(key), np.int32), key, 5, 3)
    assert picked.tolist() == consequent(None, False, np.zeros(len(key), np.int32), key, 5, 3).tolist()
    assert np.bincount(picked, minlength=3) / len(key) == pytest.approx([1 / 3] * 3, abs=0.02)
    assert (picked != consequent(None, False, np.zeros(len(key), np.int32), key, 6, 3)).any()  # sites differ


def test_a_search_grammar_builds_with_choose_drawn_per_lot(write):
    grammar = 'lot ~> Subdiv("X", choose(1, 2, 3), 1r){ a | b }\ngoal: count("a") > 0\n'
    r = paper(write, grammar, LOTS, seed=4)
    # a quad's transform spans the lot's depth (6) and the part's width
    widths = np.round(np.linalg.norm(r["xform"][np.array(names(r)) == "a"][:, :, :2], axis=1).min(axis=1), 6)
    counts = Counter(widths.tolist())
    assert set(counts) == {1.0, 2.0, 3.0} and min(counts.values()) > 60
    again = paper(write, grammar, LOTS, seed=4, chunk_size=7)
    np.testing.assert_array_equal(r["xform"], again["xform"])
    assert not np.array_equal(r["xform"], paper(write, grammar, LOTS, seed=5)["xform"])


def test_question_mark_consequents_build_equally_likely(write):
    r = paper(write, "lot ~> a ?\n    ~> b ?\n    ~> c ?\n", LOTS, seed=1)
    counts = Counter(names(r))
    assert set(counts) == {"a", "b", "c"} and min(counts.values()) > 70

