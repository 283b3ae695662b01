"""What legal IR is, stage by stage, and a checker for it.

After ``lower``: every node has a span in the module's file; split sites are unique.
After ``resolve``: no ``Name`` is left; every ``AttrRef`` names a declared attribute.
After ``types``: every symbol with rules has parameter types, one per parameter.
After ``probabilities``: every alternative has a probability.
``verify`` returns the violations (an empty list for legal IR); the pipeline runs it between passes when
``GRAMMARC_STRICT`` is set, and the tests do.
"""

from __future__ import annotations

from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_exprs, iter_ops, op_exprs

STAGES = ("lower", "resolve", "types", "fold", "probabilities")


def verify(module: ir.Module, stage: str) -> list[str]:
    done = STAGES[: STAGES.index(stage) + 1]
    problems: list[str] = []
    sites: set[int] = set()
    param_types = dict(module.param_types)
    attr_names = {a.name for a in module.attrs}
    for rule in module.rules:
        where = f"rule `{rule.symbol}` (line {rule.span.line})"
        exprs = [rule.guard] if rule.guard is not None else []
        for alt in rule.alternatives:
            if "probabilities" in done and alt.prob is None:
                problems.append(f"{where}: alternative without probability")
            if alt.prob is not None:
                exprs.append(alt.prob)
            for op in iter_ops(alt.body):
                site = getattr(op, "site", None)
                if site is not None and isinstance(op, (ir.Split, ir.Repeat, ir.Comp, ir.Symbol)):
                    if site in sites:
                        problems.append(f"{where}: site {site} used twice")
                    sites.add(site)
                exprs.extend(op_exprs(op))
        if "types" in done and len(param_types.get(rule.symbol, ())) != len(rule.params):
            problems.append(f"{where}: parameter types missing")
        for e in exprs:
            for sub in iter_exprs(e):
                if "resolve" in done and isinstance(sub, ir.Name):
                    problems.append(f"{where}: unresolved name `{sub.name}`")
                if "resolve" in done and isinstance(sub, ir.AttrRef) and sub.name not in attr_names:
                    problems.append(f"{where}: undeclared attribute `{sub.name}`")
                if isinstance(sub, ir.Param) and sub.index >= len(rule.params):
                    problems.append(f"{where}: parameter index {sub.index} out of range")
                if sub.span.file not in (module.file, *module.imported) and sub.span.line != 0:
                    problems.append(f"{where}: span from another file {sub.span}")
    return problems
