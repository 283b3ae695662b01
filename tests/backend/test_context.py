"""backend/context.py: what a chunk's operations share: failures naming the rule, the asset meshes of trims."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_lots
from operations.derivations import paper, rect

from grammarc.backend.context import Context
from grammarc.backend.derive import initial_chunk
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS
from grammarc.errors import AssetError, LimitError, LotFailure


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


def test_runaway_branching_recursion_stops_with_the_rule(write):
    with pytest.raises(LimitError, match=r"`grow`.*--max-shapes"):
        paper(write, "grow ~> T(0,1,0) grow grow\n", [rect(5, 5)])

