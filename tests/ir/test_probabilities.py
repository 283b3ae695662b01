"""ir/passes/probabilities.py: stochastic alternatives have probabilities that sum to 1."""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.passes.probabilities import check_probabilities
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_rule

FILE = "g.cga"


def checked(text: str) -> tuple[ir.Module, Diagnostics]:
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags), diags, check=True)
    return module, diags


def errors(text: str) -> list[tuple[int, int, str]]:
    return [(d.span.line, d.span.col, d.message) for d in checked(text)[1] if d.is_error]


@pytest.mark.parametrize("text, expected", [
    ("a ~> b", "a ~> b : 1"),
    ("a ~> b : 1", "a ~> b : 1"),
    ("a ~> b : 0.5 ~> c : 0.5", "a ~> b : 0.5 ~> c : 0.5"),
    ("a ~> b : 1/3 ~> c : 1/3 ~> d : 1/3", "a ~> b : 0.333333 ~> c : 0.333333 ~> d : 0.333333"),
    ("a ~> b : 0.1 ~> c : 0.2 ~> d : 0.7", "a ~> b : 0.1 ~> c : 0.2 ~> d : 0.7"),  # 0.1+0.2 is not 0.3
    ("a ~> b : 1 ~> c : 0", "a ~> b : 1 ~> c : 0"),
    # probabilities that depend on attributes are checked per shape when derived
    ("attr p = 0.7\na ~> b : p ~> c : 1 - p", "a ~> b : @p ~> c : (1 - @p)"),
    ("attr p = 0.7\na ~> b : p ~> c : 0.9", "a ~> b : @p ~> c : 0.9"),
])
def test_accepted(text, expected):
    module, diags = checked(text)
    assert not diags.has_errors
    assert print_rule(module.rules[-1]) == expected


def test_single_alternative_gets_probability_one_with_its_span():
    module, _ = checked("a ~> b")
    alt = module.rules[0].alternatives[0]
    assert alt.prob == ir.Num(1.0, alt.span)


@pytest.mark.parametrize("text, expected", [
    ("a ~> b : 0.5 ~> c : 0.3", [(1, 1, "probabilities of `a` sum to 0.8 (0.5 + 0.3), not 1")]),
    ("a ~> b : 0.5 ~> c : 0.3 ~> d : 0.3",
     [(1, 1, "probabilities of `a` sum to 1.1 (0.5 + 0.3 + 0.3), not 1")]),
    ("a ~> b : 0.5", [(1, 1, "probabilities of `a` sum to 0.5 (0.5), not 1")]),
    ("x ~> y\na ~> b : 0.5\n  ~> c", [(3, 3, "alternative of stochastic rule `a` has no probability")]),
    ("a ~> b ~> c", [(1, 3, "alternative of stochastic rule `a` has no probability"),
                     (1, 8, "alternative of stochastic rule `a` has no probability")]),
    ("a ~> b : -0.5 ~> c : 1.5", [(1, 10, "probability -0.5 is negative")]),
    ("a ~> b : -0.5 ~> c : 1", [(1, 10, "probability -0.5 is negative"),
                                (1, 1, "probabilities of `a` sum to 0.5 (-0.5 + 1), not 1")]),
])
def test_errors(text, expected):
    assert errors(text) == expected


def test_missing_probability_has_a_hint():
    _, diags = checked("a ~> b : 0.5 ~> c")
    [d] = diags
    assert d.hint == "end each alternative with `: probability`"


def test_probability_rule_of_a_continuation_at_column1():
    assert errors("a ~> b : 0.5\n~> c : 0.25\n; d : 0.25") == []
    assert errors("a ~> b : 0.5\n~> c : 0.25") == [
        (1, 1, "probabilities of `a` sum to 0.75 (0.5 + 0.25), not 1")]


def test_every_probability_set_returns_the_same_module():
    diags = Diagnostics()
    module = run_passes(parse_source("a ~> b : 0.5 ~> c : 0.5", FILE, diags), diags, check=True,
                        stop_after="fold")
    assert check_probabilities(module, diags) is module
    assert not diags


def test_consequents_written_with_a_question_mark_are_equally_likely():
    module, diags = checked("a ~> b ?\n  ~> c ?\n  ~> d ?")
    assert not diags.has_errors
    assert print_rule(module.rules[0]) == "a ~> b ? ~> c ? ~> d ?"
    assert [alt.prob.value for alt in module.rules[0].alternatives] == [pytest.approx(1 / 3)] * 3


def test_consequents_and_probabilities_do_not_mix():
    assert errors("a ~> b ?\n  ~> c : 0.5") == [(2, 3, "rule `a` mixes `?` consequents with probabilities")]
