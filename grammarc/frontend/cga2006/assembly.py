"""Assembly of a paper-notation file's lowered statements into one IR module: ``PRIORITY`` blocks give the
rules after them their priority, ``~> successor : prob`` lines add alternatives to the rule before them, the
first rule is the start, and the search statements (``goal:``...) are collected, one of each kind.
"""

from __future__ import annotations

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.cga2006.nodes import ContinuationStatement, PriorityStatement, RuleStatement, Statement
from grammarc.ir import nodes as ir


def assemble(file: str, statements: list[Statement], diags: Diagnostics) -> ir.Module:
    """Statements in source order -> Module: PRIORITY blocks, stochastic continuation lines."""
    attrs: list[ir.AttrDecl] = []
    objectives: dict[str, ir.Objective] = {}
    pending: list[list] = []  # [RuleStatement, alternatives, priority]
    priority = 0
    for st in statements:
        if isinstance(st, PriorityStatement):
            priority = st.value
        elif isinstance(st, ir.AttrDecl):
            if any(a.name == st.name for a in attrs):
                diags.error("duplicate-attr", f"attribute `{st.name}` is declared twice", st.span)
            attrs.append(st)
        elif isinstance(st, ir.Objective):
            if st.kind in objectives:
                diags.error("duplicate-objective", f"`{st.kind}:` is given twice (first at line "
                            f"{objectives[st.kind].span.line})", st.span)
            objectives.setdefault(st.kind, st)
        elif isinstance(st, RuleStatement):
            pending.append([st, list(st.alternatives), priority])
        elif isinstance(st, ContinuationStatement):
            if not pending:
                diags.error("syntax", "a stochastic alternative needs a rule before it", st.span,
                            hint="write `symbol ~> successor : probability` first")
            else:
                pending[-1][1].extend(st.alternatives)
    rules = tuple(
        ir.Rule(
            symbol=st.symbol, params=st.params, guard=st.guard, alternatives=tuple(alts),
            priority=prio, label=st.label, span=st.span, site=st.site,
        )
        for st, alts, prio in pending
    )
    start = rules[0].symbol if rules else None
    return ir.Module(file=file, attrs=tuple(attrs), rules=rules, start=start,
                     objectives=tuple(objectives.values()))
