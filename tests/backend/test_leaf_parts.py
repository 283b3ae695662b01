"""Split parts whose symbol only places an asset: the same records, in the same order, as the general path
(a copy of each grammar whose leaf rules carry a guard that always holds, which the shortcut refuses)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import LOT_ZOO, make_lots

from grammarc.backend.fusion.regions import SWITCH
from grammarc.backend.plan import make_plan
from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS

ROOT = Path(__file__).resolve().parents[2]
FACADE = (ROOT / "benchmarks" / "facade.cga").read_text()
MIXED = """
lot ~> S(1r, 9, 1r) Comp("sidefaces"){ facade }
facade ~> Repeat("Y", 3){ Subdiv("X", 1r, 1.5, 1r){ wall | Repeat("Y", 0.5){ sill } | pier(2) } }
sill ~> T(0.1, 0, -0.3) S(1r, 0.7r, 0.3) I("cube")
wall ~> S(1r, 1r, 0) I("quad")
pier(k) ~> S(1r, 1r, k * 0.1) I("cube")
"""

@pytest.fixture(autouse=True)
def interpreted(monkeypatch):
    """The interpreter's own paths are compared here: fused kernels would derive both grammars."""
    monkeypatch.setenv(SWITCH, "off")


def guarded(text: str) -> str:
    """The grammar with a guard that always holds on each rule that only places an asset."""
    return re.sub(r"^(\w+) ~>(.*I\()", r"\1 : 1 + 1 > 0.5 ~>\2", text, flags=re.MULTILINE)


def both(write, text, lots, **options):
    fast = derive(compile_grammar(write("fast.cga", text)), lots, BuildOptions(**options))
    general = derive(compile_grammar(write("general.cga", guarded(text))), lots, BuildOptions(**options))
    return fast, general


@pytest.mark.parametrize("text", [FACADE, MIXED], ids=["facade", "mixed"])
def test_the_records_are_those_of_the_general_path(write, text):
    lots = make_lots("square", "rect_12x8", "concave_L", "courtyard")
    assert make_plan(compile_grammar(write("g.cga", text))).leaf_inserts
    assert not make_plan(compile_grammar(write("h.cga", guarded(text)))).leaf_inserts
    fast, general = both(write, text, lots)
    assert len(fast["asset"]) > 500
    for column in ("asset", "xform", "lot", "symbol"):
        np.testing.assert_array_equal(fast[column], general[column], err_msg=column)


def test_which_symbols_qualify(write):
    grammar = compile_grammar(write("g.cga", """
attr w = 2
lot ~> Subdiv("X", 1r, 1r, 1r, 1r, 1r, 1r){ a | b | c | d | e | f(1) }
a ~> I("cube")
b ~> S(1r, 2, 0.5) T(0, 0, -0.5) I("cube")
c ~> S(1r, w, 1r) I("cube")
d ~> S(1r, 1r, 1r) S(1r, 1r, 1r) I("cube")
e ~> I("cube") : 0.5
  ~> I("quad") : 0.5
f(x) ~> I("cube")
"""))
    plan = make_plan(grammar)
    assert sorted(plan.symbols[k].name for k in plan.leaf_inserts) == ["a", "b", "f"]
    np.testing.assert_array_equal(plan.leaf_inserts[plan.symbol_ids["b"]].offset, [0, 0, -0.5])


def test_limits_are_reported_as_by_the_general_path(write):
    lots = make_lots("square")
    messages = []
    for text in (FACADE, guarded(FACADE)):
        for limits in (LIMITS.__class__(**{**vars(LIMITS), "max_shapes": 300}),
                       LIMITS.__class__(**{**vars(LIMITS), "max_depth": 5})):
            [bad] = derive(compile_grammar(write("g.cga", text)), lots, BuildOptions(limits=limits))["bad"]
            messages.append(re.sub(r"\(\d+\)", "", bad.reason))
    assert messages[:2] == messages[2:]
    assert LOT_ZOO  # the zoo's lots are the ones derived above
