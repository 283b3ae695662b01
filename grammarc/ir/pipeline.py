"""The passes, in order. This file is the compiler's middle on one screen.

Each pass takes a module and a diagnostics list and returns a module. All passes run even after an error,
so that one ``grammarc check`` lists every problem; errors become placeholders that later passes accept.
The analyses are passes too: what they find travels with the module they return (``Module.graph``,
``Module.assets``), so the checked module is everything the backend needs.
"""

from __future__ import annotations

from grammarc.constants import STRICT
from grammarc.diagnostics import Diagnostics
from grammarc.ir import nodes as ir
from grammarc.ir.passes.assets import resolve_assets
from grammarc.ir.passes.fold import fold_constants
from grammarc.ir.passes.probabilities import check_probabilities
from grammarc.ir.passes.resolve import resolve_names
from grammarc.ir.passes.rulegraph import rule_graph
from grammarc.ir.passes.types import infer_types
from grammarc.ir.verify import verify

PASSES = (
    ("resolve", resolve_names),         # Name -> Param | AttrRef; unknown identifiers
    ("types", infer_types),             # expression types, arities, parameter types
    ("fold", fold_constants),           # constant subexpressions -> constants
    ("probabilities", check_probabilities),  # stochastic alternatives sum to 1
    ("rulegraph", rule_graph),          # the start rule; reachable, recursive and terminal symbols
    ("assets", resolve_assets),         # I() names -> canonical asset names and ids
)


def run_passes(module: ir.Module, diags: Diagnostics, *, check: bool = STRICT,
               stop_after: str | None = None) -> ir.Module:
    """Run the passes in order (up to ``stop_after``); with ``check``, verify the IR after each."""
    if check:
        _assert_legal(module, "lower")
    for name, run in PASSES:
        module = run(module, diags)
        if check and not diags.has_errors:
            _assert_legal(module, name)
        if name == stop_after:
            break
    return module


def _assert_legal(module: ir.Module, stage: str) -> None:
    problems = verify(module, stage)
    if problems:
        raise AssertionError(f"illegal IR after {stage}:\n" + "\n".join(problems))
