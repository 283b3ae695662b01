"""Stochastic rules: every alternative of a rule with several has a probability, and they sum to 1.

Assumes: constants folded, so that ``1/3`` is a number here. Guarantees: a rule with one alternative and no
probability gets probability 1, the ``?`` consequents of a rule (``ir.Alternative.choice``) each 1/n; constant probabilities are non-negative and sum to 1 within
``TOL.probability``. Probabilities that depend on attributes are checked per shape when derived.
"""

from __future__ import annotations

from dataclasses import replace

from grammarc.constants import TOL
from grammarc.diagnostics import Diagnostics
from grammarc.ir import nodes as ir


def check_probabilities(module: ir.Module, diags: Diagnostics) -> ir.Module:
    rules = []
    for rule in module.rules:
        alts = rule.alternatives
        chosen = [a for a in alts if a.choice]
        if chosen and len(chosen) != len(alts):
            diags.error("probability", f"rule `{rule.symbol}` mixes `?` consequents with probabilities",
                        next(a for a in alts if not a.choice).span,
                        hint="a rule's alternatives are either all `?` or all `: probability`")
            # reported once: the `?` ones stand in with an error's placeholder for their probability
            alts = tuple(replace(a, choice=False, prob=ir.placeholder(a.span) if a.prob is None else a.prob)
                         for a in alts)
        elif chosen:  # a build takes one of the consequents, all equally likely
            alts = tuple(replace(a, prob=ir.Num(1.0 / len(alts), a.span)) for a in alts)
        if len(alts) == 1 and alts[0].prob is None:
            alts = (replace(alts[0], prob=ir.Num(1.0, alts[0].span)),)
        missing = [a for a in alts if a.prob is None]
        for a in missing:
            diags.error("probability", f"alternative of stochastic rule `{rule.symbol}` has no probability",
                        a.span, hint="end each alternative with `: probability`")
        constant = [a.prob for a in alts if isinstance(a.prob, ir.Num)]
        for p in constant:
            if p.value < 0:
                diags.error("probability", f"probability {p.value:g} is negative", p.span)
        if not missing and len(constant) == len(alts):
            total = sum(p.value for p in constant)
            if abs(total - 1.0) > TOL.probability:
                listed = " + ".join(f"{p.value:g}" for p in constant)
                diags.error("probability", f"probabilities of `{rule.symbol}` sum to {total:g} "
                            f"({listed}), not 1", rule.span)
        rules.append(rule if alts is rule.alternatives else replace(rule, alternatives=alts))
    if all(a is b for a, b in zip(rules, module.rules)):
        return module
    return replace(module, rules=tuple(rules))
