"""What legal IR is, stage by stage, and a checker for it.

After ``lower``: every node has a span in the module's file; split sites are unique.
After ``resolve``: no ``Name`` is left; every ``AttrRef`` names a declared attribute.
After ``types``: every symbol with rules has parameter types, one per parameter.
After ``probabilities``: every alternative has a probability.
After ``rulegraph``: the module has the graph of its start symbol, whose symbols with rules are the rules'.
After ``assets`` (for a module with asset folders): the leaf cube and quad are assets 0 and 1, and every
name ``I()`` gives has the id of an asset.
``verify`` returns the violations (an empty list for legal IR); the pipeline runs it between passes when
``GRAMMARC_STRICT`` is set, and the tests do.
"""

from __future__ import annotations

from grammarc.ir import nodes as ir
from grammarc.ir.asset_names import LEAF_CUBE, LEAF_QUAD
from grammarc.ir.traverse import all_exprs, iter_ops

STAGES = ("lower", "resolve", "types", "fold", "probabilities", "rulegraph", "assets")


def verify(module: ir.Module, stage: str) -> list[str]:
    done = STAGES[: STAGES.index(stage) + 1]
    problems: list[str] = []
    sites: set[int] = set()
    param_types = dict(module.param_types)
    attr_names = {a.name for a in module.attrs}
    for rule in module.rules:
        where = f"rule `{rule.symbol}` (line {rule.span.line})"
        for alt in rule.alternatives:
            if "probabilities" in done and alt.prob is None:
                problems.append(f"{where}: alternative without probability")
            for op in iter_ops(alt.body):
                site = getattr(op, "site", None)
                if site is not None and isinstance(op, (ir.Split, ir.Repeat, ir.Comp, ir.Symbol)):
                    if site in sites:
                        problems.append(f"{where}: site {site} used twice")
                    sites.add(site)
        if "types" in done and len(param_types.get(rule.symbol, ())) != len(rule.params):
            problems.append(f"{where}: parameter types missing")
        for sub in all_exprs(rule):
            if "resolve" in done and isinstance(sub, ir.Name):
                problems.append(f"{where}: unresolved name `{sub.name}`")
            if "resolve" in done and isinstance(sub, ir.AttrRef) and sub.name not in attr_names:
                problems.append(f"{where}: undeclared attribute `{sub.name}`")
            if isinstance(sub, ir.Param) and sub.index >= len(rule.params):
                problems.append(f"{where}: parameter index {sub.index} out of range")
            if sub.span.file not in (module.file, *module.imported) and sub.span.line != 0:
                problems.append(f"{where}: span from another file {sub.span}")
    if "rulegraph" in done:
        problems += _graph_problems(module)
    if "assets" in done and module.roots is not None and module.graph is not None:  # no rules: no assets
        problems += _asset_problems(module)
    return problems


def _graph_problems(module: ir.Module) -> list[str]:
    graph = module.graph
    if graph is None:  # a CityEngine file of declarations only has none (``passes.rulegraph``)
        return [] if not module.rules and module.dialect == "cityengine" else ["module: no rule graph"]
    problems = []
    if graph.start != module.start:
        problems.append(f"module: the graph starts at `{graph.start}`, the module at `{module.start}`")
    if graph.nonterminals != tuple(dict.fromkeys(r.symbol for r in module.rules)):
        problems.append("module: the graph's symbols with rules are not the rules'")
    return problems


def _asset_problems(module: ir.Module) -> list[str]:
    problems = []
    if module.assets[:2] != (LEAF_CUBE, LEAF_QUAD):
        problems.append("module: assets 0 and 1 are not the leaf cube and quad")
    ids = dict(module.asset_ids)
    for op in iter_ops(module):
        named = isinstance(op, (ir.Insert, ir.UseAsset, ir.InsertAlongUV)) and op.asset
        if named and not 0 <= ids.get(op.asset, -1) < len(module.assets):
            problems.append(f"module: asset `{op.asset}` at {op.span} has no id")
    return problems
