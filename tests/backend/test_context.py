"""backend/context.py: what a chunk's operations share: failures naming the rule, the asset meshes of trims."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import make_lots
from operations.derivations import paper, rect

from grammarc.backend.context import Context
from grammarc.backend.derive import initial_chunk
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS
from grammarc.errors import AssetError, LotFailure


def context(write, load_asset=None) -> Context:
    grammar = compile_grammar(write("g.cga", 'version "2022.0"\nLot --> i("window.obj") Wall\n'))
    chunk, _ = initial_chunk(make_lots("square", "concave_L"), seed=0)
    return Context(make_plan(grammar, load_asset=load_asset), chunk, LIMITS, 10**9)


def test_fail_names_the_rule_being_applied_and_the_lots(write):
    ctx = context(write)
    _, shapes = initial_chunk(make_lots("square", "concave_L"), seed=0)
    ctx.symbol = ctx.plan.symbol_ids["Lot"]
    with pytest.raises(LotFailure, match=r"^too tall in rule `Lot` at here$") as failure:
        ctx.fail(shapes, np.array([False, True]), "too tall", "here")
    assert failure.value.lots.tolist() == [1]


def test_asset_meshes_come_from_the_plans_loader_once_each(write):
    """The derivation reads no asset file itself: trims ask the loader the plan was made with, once per
    asset and chunk; an asset no root holds has no mesh (its inserts stay whole)."""
    calls = []

    def load_asset(name, roots):
        calls.append(name)
        if name == "window.obj":
            raise AssetError("no root holds it")
        return f"mesh of {name}"

    ctx = context(write, load_asset)
    window = ctx.plan.grammar.asset_ids["window.obj"]
    assert ctx.asset_mesh(0) == ctx.asset_mesh(0) == "mesh of builtin:cube"
    assert ctx.asset_mesh(window) is None and ctx.asset_mesh(window) is None
    assert calls == ["builtin:cube", "window.obj"]


def test_runaway_branching_recursion_fails_its_lot_only_with_the_rule_and_count(write):
    """--max-shapes is a limit per lot: the lot over it is bad (its message with the rule, its place and
    its own count), the others derive as they would alone."""
    text = "attr n = 0\nlot : n > 0 ~> T(0,1,0) lot lot\nlot ~> I(\"cube\")\n"
    r = paper(write, text, [rect(5, 5)] * 3, limits=LIMITS.__class__(max_shapes=1000),
              lot_attrs={"n": np.array([0.0, 1.0, 0.0])})
    assert r["lot"].tolist() == [0, 2]
    [bad] = r["bad"]
    assert bad.index == 1
    assert re.fullmatch(r"more than 1,000 shapes \(1,022\) in rule `lot` at \S*/g\.cga:2:29: a runaway grammar\? "
                        r"Raise the limit with --max-shapes N\.", bad.reason), bad.reason


def test_the_shape_limit_fails_each_lot_over_it_with_its_own_count(write):
    ctx = context(write)
    ctx.symbol = ctx.plan.symbol_ids["Lot"]
    ctx.limits = LIMITS.__class__(max_shapes=10)
    with pytest.raises(LotFailure) as failure:
        ctx.check_shape_limit(np.array([11.0, 10.0, 2.0**63]), "g.cga:2:1")
    assert failure.value.lots.tolist() == [0, 2]
    assert [failure.value.reason(k) for k in range(2)] == [
        f"more than 10 shapes ({n}) in rule `Lot` at g.cga:2:1: a runaway grammar? Raise the limit with "
        "--max-shapes N." for n in ("11", "beyond counting")]



def test_counts_beyond_counting_of_several_shapes_fail_their_lots(write):
    """A repeat of a 1e-306 m element makes ``MAX_COUNT`` children on each shape: two of them overflowed
    int64 to a negative sum, which passed the limit and failed the allocation (the build fuzz)."""
    text = "attr h = 12\nattr w = 1e308\nlot ~> Repeat(\"X\", (h / w) * 12){ r4 }\n"
    r = paper(write, text, [rect(1, 1)] * 2)
    assert [b.index for b in r["bad"]] == [0, 1]
    assert all("(beyond counting)" in b.reason for b in r["bad"])
