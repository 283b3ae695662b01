"""``grammarc check``: every problem of a grammar, then a summary of it (its rules, start, terminals,
attributes, assets, and with ``--fusion`` what the fused kernels take); and a grammar's warnings, as every
command that compiles one shows them."""

from __future__ import annotations

import sys

from grammarc.diagnostics import render_all


def warn(grammar) -> None:
    if grammar.warnings:
        print(render_all(list(grammar.warnings), grammar.sources), file=sys.stderr)


def run_check(args) -> int:
    from grammarc.build import BuildOptions, compile_source, grammar_source
    from grammarc.ir.nodes import RuleGraph
    from grammarc.ir.printer import print_module

    options = BuildOptions(start=args.start, dialect=args.dialect, workspace=args.workspace,
                           warnings_as_errors=args.warnings_as_errors, max_package_size=args.max_package_size)
    with grammar_source(args.grammar, options) as (source, display, resolved):
        grammar = compile_source(source, display, resolved, derive=False)
    warn(grammar)
    graph = grammar.graph or RuleGraph("-", (), (), frozenset(), frozenset(), {})  # a file without rules
    if args.dump_ir:
        print(print_module(grammar.module))
    print(f"{args.grammar}: ok")
    print(f"  rules:     {len(grammar.module.rules)} ({len(graph.nonterminals)} symbols with rules)")
    print(f"  start:     {graph.start}")
    print(f"  terminals: {_listed(graph.terminals)}")
    print(f"  recursive: {_listed(sorted(graph.recursive))}")
    print(f"  attrs:     {_listed([a.name for a in grammar.module.attrs])}")
    print(f"  assets:    {_listed(grammar.assets)}")
    if args.fusion:
        _fusion_summary(grammar)
    return 0


def _fusion_summary(grammar) -> None:
    """``check --fusion``: what keeps the grammar, and then each symbol, from the fused kernels
    (``backend.fusion.regions``), and the most frequent reasons among the symbols."""
    from collections import Counter

    from grammarc.backend.fusion.regions import grammar_refusals, symbol_refusals
    from grammarc.backend.plan import make_plan

    plan = make_plan(grammar)
    whole = grammar_refusals(plan)
    refused = symbol_refusals(plan)
    fused = [sym.name for sym in plan.symbols if sym.rules and sym.name not in refused]
    print(f"  fusion:    {'the whole grammar is interpreted: ' + '; '.join(whole) if whole else 'allowed'}")
    print(f"  fusible:   {_listed(fused)}" + (" (were the grammar's reasons gone)" if whole and fused else ""))
    for name, why in refused.items():
        print(f"    {name}: {why}")
    tally = Counter(f"{why.what}{f' `{why.name}`' if why.name else ''}" for why in refused.values())
    print("  most frequent: " + (", ".join(f"{what} ({n})" for what, n in tally.most_common(5)) or "-"))


def _listed(names, most: int = 40) -> str:
    """Names for the summary of ``check``: a grammar of thousands of rules shows the first ``most``."""
    names = list(names)
    if not names:
        return "-"
    more = f" and {len(names) - most:,} more" if len(names) > most else ""
    return ", ".join(names[:most]) + more
