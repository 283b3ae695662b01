"""A region's generated source and its order of emission."""

from __future__ import annotations

from pathlib import Path

from grammarc.backend.fusion import codegen
from grammarc.backend.fusion.codegen import generate
from grammarc.backend.fusion.compiled import digest, load
from grammarc.backend.fusion.regions import Fusible
from grammarc.backend.fusion.sites import Block, Emit
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar

ROOT = Path(__file__).resolve().parents[3]


def facade_plan():
    return make_plan(compile_grammar(ROOT / "benchmarks" / "facade.cga"))


def test_sites_are_numbered_in_the_interpreter_order_of_emission():
    plan = facade_plan()
    source = generate(Fusible(plan), plan.symbol_ids["facade"])
    floor, = source.block.events
    tile, = floor.events
    names = [plan.symbols[b.symbol].name for b in tile.events]
    # Subdiv("X"){ wall | Subdiv("Y"){ wall | window | wall } | wall }: parts in order, nested parts in place
    assert names == ["wall", "wall", "window", "wall", "wall"]
    assert [b.events for b in tile.events] == [[Emit(k, b.events[0].asset, b.symbol)] for k, b in enumerate(tile.events)]
    assert (source.block.first, source.block.last, source.sites) == (0, 5, 5)
    assert isinstance(tile, Block) and (tile.first, tile.last) == (0, 5)
    assert source.attrs == ("floor_h", "tile_w") and source.depth == 3


def test_the_source_is_a_function_of_the_region():
    plan, again = facade_plan(), facade_plan()
    texts = {generate(Fusible(p), p.symbol_ids["tile"]).text for p in (plan, again)}
    assert len(texts) == 1
    text = texts.pop()
    assert digest(text) != digest(generate(Fusible(plan), plan.symbol_ids["floor"]).text)
    module, path = load(text)
    assert path.read_text() == text and callable(module.derive)


def test_a_change_to_the_functions_kernels_call_changes_their_text(monkeypatch):
    """numba's cache of a kernel holds the machine code of what it calls, and does not see that change."""
    plan = facade_plan()
    before = generate(Fusible(plan), plan.symbol_ids["tile"]).text
    assert codegen.called_code() in before
    monkeypatch.setattr(codegen, "CALLED", codegen.CALLED[:-1])
    codegen.called_code.cache_clear()
    try:
        assert generate(Fusible(plan), plan.symbol_ids["tile"]).text != before
    finally:
        monkeypatch.undo()
        codegen.called_code.cache_clear()
