"""Grammar file -> checked, analysed grammar ready for the backend.

``compile_grammar`` runs the frontend and the IR passes, resolves the assets named by ``I()``, analyses the
rule graph, and raises ``GrammarError`` with every error if there is any. Warnings come back with the
grammar so that the command line can show them.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

from grammarc.diagnostics import Diagnostic, Diagnostics, Span
from grammarc.errors import GrammarError, UsageError
from grammarc.frontend.parse import parse_source
from grammarc.io.assets import LEAF_CUBE, LEAF_QUAD, resolve_asset
from grammarc.ir import nodes as ir
from grammarc.ir.passes.rulegraph import RuleGraph, analyze_rules
from grammarc.ir.pipeline import run_passes
from grammarc.ir.traverse import iter_exprs, iter_ops, op_exprs


@dataclass(frozen=True)
class Grammar:
    path: str
    digest: str
    module: ir.Module
    graph: RuleGraph
    #: Canonical asset names; an asset's index is its id in the record.
    assets: tuple[str, ...]
    #: ``I()`` name as written -> asset id.
    asset_ids: dict[str, int]
    warnings: tuple[Diagnostic, ...]
    sources: dict[str, str]
    #: Folders the assets were resolved in (the grammar's, then ``--assets`` ones), for loading them.
    asset_roots: tuple[Path, ...] = ()


def compile_grammar(path: str | Path, *, text: str | None = None, start: str | None = None,
                    asset_roots: tuple[Path, ...] = (), dialect: str | None = None,
                    display: str | None = None) -> Grammar:
    """Parse, check and analyse a grammar file; raise ``GrammarError`` listing every error.

    ``display`` names the file in diagnostics (a rule file inside a package: ``candler.rpk/rules/x.cga``).
    """
    path = Path(path)
    if text is None:
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            raise UsageError(f"cannot read grammar {path}: {error}") from None
    file = display or str(path)
    diags = Diagnostics()
    sources = {file: text}
    module = parse_source(text, file, diags, dialect, path=path, sources=sources)
    module = run_passes(module, diags)
    if not module.rules and not diags.has_errors:  # rules that failed to parse are not "no rules"
        diags.error("empty", "the grammar has no rules", Span(file, 1, 1, 1, 1))
    start = start or module.start
    graph = None
    if module.rules:
        symbols = {r.symbol for r in module.rules}
        if start not in symbols:
            if diags.has_errors:
                # The start rule may be one that failed to parse: its errors say more than "no rule".
                raise GrammarError(diags, sources)
            raise UsageError(f"start symbol `{start}` has no rule in {file}")
        start_rule = next(r for r in module.rules if r.symbol == start)
        if start_rule.params:
            diags.error("start-params", f"the start rule `{start}` cannot take parameters: a lot "
                        "has no arguments to pass", start_rule.span)
        graph = analyze_rules(module, start, diags)
    roots = (path.parent, *asset_roots)
    assets, asset_ids = _assets(module, list(roots), diags)
    if diags.has_errors:
        raise GrammarError(diags, sources)
    return Grammar(
        path=file,
        digest=hashlib.sha256(text.encode()).hexdigest(),
        module=module,
        graph=graph,
        assets=assets,
        asset_ids=asset_ids,
        warnings=tuple(d for d in diags if not d.is_error),
        sources=sources,
        asset_roots=tuple(roots),
    )


#: File endings of assets that a computed ``i(name)`` may name: string constants ending so are resolved.
ASSET_SUFFIXES = (".obj",)


def _assets(module: ir.Module, roots, diags: Diagnostics) -> tuple[tuple[str, ...], dict[str, int]]:
    names = [LEAF_CUBE, LEAF_QUAD]
    ids: dict[str, int] = {}
    named = []
    for rule in module.rules:
        for alt in rule.alternatives:
            named.extend(op for op in iter_ops(alt.body) if isinstance(op, (ir.Insert, ir.UseAsset))
                         and op.asset)
    if any(isinstance(op, ir.UseAsset) and op.name is not None for rule in module.rules
           for alt in rule.alternatives for op in iter_ops(alt.body)):
        # a computed asset name: every string constant that looks like an asset may be one
        named.extend(ir.UseAsset(e.value, e.span) for e in _strings(module)
                     if e.value.lower().endswith(ASSET_SUFFIXES))
    for op in named:
        if op.asset in ids:
            continue
        resolved = resolve_asset(op.asset, roots)
        if resolved.problem:
            diags.error("asset", resolved.problem, op.span)
            continue
        if resolved.missing:
            diags.warning("asset", f"asset `{op.asset}` not found in "
                          f"{', '.join(str(r) for r in roots)}; the record keeps its name", op.span)
        if resolved.name not in names:
            names.append(resolved.name)
        ids[op.asset] = names.index(resolved.name)
    return tuple(names), ids


def _strings(module: ir.Module):
    """Every string constant of the module (attribute defaults, arguments, conditions)."""
    roots = [a.default for a in module.attrs]
    for rule in module.rules:
        for alt in rule.alternatives:
            for op in iter_ops(alt.body):
                roots.extend(op_exprs(op))
    for root in roots:
        yield from (e for e in iter_exprs(root) if isinstance(e, ir.Str))
