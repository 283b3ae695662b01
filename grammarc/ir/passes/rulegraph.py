"""The rule graph: which symbols a start symbol reaches, which recurse, which are terminals.

Assumes: names resolved and types checked. Guarantees: the grammar has rules, its start symbol has one,
and ``Module.graph`` holds the ``RuleGraph`` from it; rules the start symbol never reaches are warned
about. Only a CityEngine file may have no rules (then its graph is None): it is a library of attributes,
constants and functions that other files import (``00_config.cga``), which CityEngine reads without
complaint; ``check`` warns that it has nothing to build and ``build`` refuses it (``compiler``). In the
paper's notation a file without rules is an error. A module without a start symbol (a CityEngine file without ``@StartRule``) starts with its first
rule, as CityEngine's inspector does, and says so. A start rule with parameters in a module to derive (one
with asset folders, ``roots``, as the compiler makes it) is a warning here: the grammar is sound, but a lot
has no arguments to pass, so ``build`` needs them from the command line (``--start 'Lot(10)'``, which
``frontend.start`` makes into a rule calling it); a fragment lowered by a test may start anywhere.
A start symbol without a rule is the caller's mistake (``--start``), not the grammar's: a
``UsageError``, unless errors are listed already (the start rule may be one that failed to parse: its
errors say more than "no rule").

A successor symbol without a rule is a leaf, in both notations; CityEngine marks an intended one ``X.``,
but most files write bare leaves (``Wall``, ``Glass``) without rules, so a bare one is warned about
(``undefined-rule``) only when its name looks like a typo of a rule's (``diagnostics.Typos``: one or two
letters off, ``facdes`` for ``facades``, or the letter case), of a rule under the same import prefix, and
is not one of the usual ways of naming leaves beside rules: a prefix of the rule's name or the other way
round (``Window`` beside ``Windows``, ``Tile`` beside ``TileRow``), or a number of a numbered family
(``Bay3`` beside ``Bay1``).

An analysis, not a rewrite: the module comes back with its graph. Recursion is found as strongly
connected components of the symbol graph (Tarjan).
"""

from __future__ import annotations

from dataclasses import replace

from grammarc.diagnostics import Diagnostics, Span, Typos
from grammarc.errors import UsageError
from grammarc.ir import nodes as ir
from grammarc.ir.nodes import RuleGraph
from grammarc.ir.traverse import iter_ops


def rule_graph(module: ir.Module, diags: Diagnostics) -> ir.Module:
    """The pass: the module with ``graph`` from its start symbol, which must have a rule."""
    if not module.rules:
        if diags.has_errors:  # rules that failed to parse are not "no rules"
            return module
        where = Span(module.file, 1, 1, 1, 1)
        if module.dialect == "cityengine":
            diags.warning("no-rules", NO_RULES, where, hint="import it from a file with rules")
        else:
            diags.error("empty", "the grammar has no rules", where)
        return module
    if module.start is None:
        first = module.rules[0]
        if not diags.has_errors:  # a note to a grammar that works: its errors come first
            diags.warning("start-rule", f"no @StartRule: starting with `{first.symbol}`, the first rule",
                          first.span, hint="mark the start rule with @StartRule, or give it with --start")
        module = replace(module, start=first.symbol)
    start = next((r for r in module.rules if r.symbol == module.start), None)
    if start is None:
        if diags.has_errors:
            return module
        raise UsageError(f"start symbol `{module.start}` has no rule in {module.file}")
    if start.params and module.roots is not None:  # a module to derive: lots pass no arguments
        diags.warning("start-params", start_params_message(start), start.span)
    return replace(module, graph=analyze_rules(module, start.symbol, diags))


#: What a CityEngine file without rules is told (``check`` warns, ``build`` refuses: ``compiler``).
NO_RULES = "the grammar has no rules: a file of attributes, constants and functions to import, nothing to build"


def start_params_message(start: ir.Rule) -> str:
    """What to say of a start rule with parameters: a lot has no arguments to pass, the command line does."""
    name = start.symbol.partition("/")[0]  # `Lot/2` when Lot is overloaded by arity
    return (f"the start rule `{start.symbol}` takes parameters ({', '.join(start.params)}): a lot has no "
            f"arguments to pass; build it with --start '{name}(...)' giving their values")


def analyze_rules(module: ir.Module, start: str, diags: Diagnostics) -> RuleGraph:
    nonterminals = tuple(dict.fromkeys(r.symbol for r in module.rules))
    edges: dict[str, list[str]] = {s: [] for s in nonterminals}
    used: dict[str, None] = {}
    for rule in module.rules:
        for op in iter_ops(rule):
            if isinstance(op, ir.Symbol):
                used[op.name] = None
                if not op.leaf:  # `X.` ends the derivation: no edge to X's rules
                    edges[rule.symbol].append(op.name)
    terminals = tuple(s for s in used if s not in edges)
    _warn_undefined(module, nonterminals, edges, diags)
    reachable = _reach(start, edges)
    for rule in module.rules:
        if rule.symbol not in reachable:
            diags.warning("unreachable", f"rule for `{rule.symbol}` is never reached from `{start}`",
                          rule.span)
    frozen = {s: tuple(dict.fromkeys(t)) for s, t in edges.items()}
    recursive = _recursive(frozen)
    _warn_guarded_recursion(module, recursive & reachable, diags)
    return RuleGraph(start, nonterminals, terminals, frozenset(reachable), recursive, frozen)


def _warn_undefined(module: ir.Module, nonterminals, edges, diags: Diagnostics) -> None:
    """A bare successor without a rule whose name looks like a typo of a rule's (module docstring)."""
    by_prefix: dict[str, list[str]] = {}
    for symbol in nonterminals:
        by_prefix.setdefault(symbol.rpartition(".")[0], []).append(symbol)
    rules_of = {prefix: Typos(symbols) for prefix, symbols in by_prefix.items()}
    typos: dict[str, str | None] = {}
    for op in iter_ops(module):
        if not isinstance(op, ir.Symbol) or op.leaf or op.args or op.name in edges:
            continue
        if op.name not in typos:
            prefix = op.name.rpartition(".")[0]
            close = rules_of[prefix].of(op.name) if prefix in rules_of else None
            typos[op.name] = close if close is not None and not _naming_habit(op.name, close) else None
        close = typos[op.name]
        if close is not None:
            hint = f"write `{op.name}.` if it is meant as a leaf" if module.dialect == "cityengine" else ""
            diags.warning("undefined-rule", f"`{op.name}` has no rule, so it is a leaf (did you mean "
                          f"`{close}`?)", op.span, hint=hint)


def _naming_habit(leaf: str, rule: str) -> bool:
    """Whether a leaf beside a rule of a close name is named so on purpose (module docstring)."""
    return rule.startswith(leaf) or leaf.startswith(rule) or \
        leaf.translate(_NO_DIGITS) == rule.translate(_NO_DIGITS)


_NO_DIGITS = str.maketrans("", "", "0123456789")


def _warn_guarded_recursion(module: ir.Module, recursive: frozenset[str], diags: Diagnostics) -> None:
    """In the paper's notation a shape no rule applies to is a leaf: a recursion whose every rule has a
    guard (``row(k) : k < n ~> ... row(k + 1)``) leaves its last shape in the record as a stray box,
    which is seldom meant. CityEngine's rules always apply (``case ... else``), so only the paper's."""
    if module.dialect != "cga2006":
        return
    rules: dict[str, list[ir.Rule]] = {}
    for rule in module.rules:
        rules.setdefault(rule.symbol, []).append(rule)
    for symbol in sorted(recursive):
        if all(rule.guard is not None for rule in rules.get(symbol, ())):
            diags.warning("guarded-recursion", f"every rule of recursive `{symbol}` has a guard: the shape "
                          f"that ends the recursion becomes a leaf (a box in the record); add `{symbol} ~> ε` "
                          "to drop it", rules[symbol][0].span)


def _reach(start: str, edges) -> set[str]:
    seen, stack = {start}, [start]
    while stack:
        for t in edges.get(stack.pop(), ()):
            if t not in seen:
                seen.add(t)
                stack.append(t)
    return seen


def _recursive(edges: dict[str, tuple[str, ...]]) -> frozenset[str]:
    """Symbols in a strongly connected component with a cycle (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    result: set[str] = set()
    counter = 0
    for root, targets in edges.items():
        if root in index:
            continue
        work = [(root, iter(targets))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in edges:
                    continue
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(edges[child])))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        component.append(w)
                        if w == node:
                            break
                    if len(component) > 1 or node in edges[node]:
                        result.update(component)
    return frozenset(result)
