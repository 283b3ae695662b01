"""Asset resolution: every name ``I()``, ``i()`` and ``insertAlongUV()`` give resolved in the module's asset
folders.

Assumes: a rule graph (a module without one fails to compile anyway, for the errors that stopped it) and
``Module.roots`` (a module lowered outside the compiler has none, and keeps its names unresolved).
Guarantees: ``Module.assets`` lists the canonical names, the leaf cube and quad first, an asset's index
being its id in the record; ``Module.asset_ids`` gives each name as written its id. A drive path or a
name that leaves the folders is an error, a file that no folder holds (a workspace path too) a warning: the
record keeps its name, and CityEngine too inserts nothing for a missing asset.

A computed ``i(name)`` may insert any asset the grammar can name, so then the assets are also: the string
constants that are asset files (``"facade/window.obj"``), and the asset files that file searches find
(``i(fileRandom("assets/trees/*.glb"))``, ``ir.file_search``): those of each constant query, of each string
constant that is a query of asset files (an attribute holding one), and, for a computed query that begins
with a constant folder (``"assets/" + kind + "/*.obj"``), every asset file under that folder, at most
``MAX_COMPUTED_MATCHES`` of them. They follow the names written, in the module's order and each search's
sorted order, so an asset's id never depends on the lots, chunks or workers.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from grammarc.diagnostics import Diagnostics
from grammarc.errors import AssetError
from grammarc.ir import nodes as ir
from grammarc.ir.asset_names import (
    LEAF_CUBE,
    LEAF_QUAD,
    primitive_asset,
    resolve_asset,
    segment_counts,
    unsupported_format,
)
from grammarc.ir.file_search import ASSET_SUFFIXES, constant_folder, search
from grammarc.ir.traverse import all_exprs, iter_exprs, iter_ops

#: Built-ins whose first argument is a file search whose matches ``i()`` may insert.
SEARCHES = frozenset({"fileRandom", "fileSearch", "filesSearch", "assetBestSize", "assetApproxSize",
                      "assetFitSize", "assetBestRatio", "assetApproxRatio"})
#: The operations that name an asset.
ASSET_OPS = (ir.Insert, ir.UseAsset, ir.InsertAlongUV)
#: The most asset files a computed search registers (every asset file under its constant folder).
MAX_COMPUTED_MATCHES = 1000


def resolve_assets(module: ir.Module, diags: Diagnostics) -> ir.Module:
    if module.roots is None or module.graph is None:
        return module
    ops = list(iter_ops(module))
    named = [(op.asset, op.span) for op in ops if isinstance(op, ASSET_OPS) and op.asset]
    named.extend(_primitives(module, ops, diags))
    if any(isinstance(op, (ir.UseAsset, ir.InsertAlongUV)) and op.name is not None for op in ops):
        # a computed asset name: every string constant that looks like an asset may be one
        queries = _queries(module)
        named.extend((e.value, e.span) for e in all_exprs(module) if isinstance(e, ir.Str)
                     and e.value.lower().endswith(ASSET_SUFFIXES) and not (_wild(e.value) or e.value in queries))
        named.extend(searched(module, queries, diags))
    roots = list(module.roots)
    names = [LEAF_CUBE, LEAF_QUAD]
    ids: dict[str, int] = {}
    # one file is one asset, whichever root names it (a project's root lies inside its workspace)
    by_file: dict = {}
    for name, span in named:
        if name in ids:
            continue
        resolved = resolve_asset(name, roots)
        if resolved.problem:
            diags.error("asset", resolved.problem, span)
            continue
        if resolved.path is not None and unsupported_format(resolved.path):
            diags.error("asset", unsupported_format(resolved.path), span)
        if resolved.missing:
            where = "; a workspace path: --workspace gives the folder of its projects" if name.startswith("/") else ""
            diags.warning("asset", f"asset `{name}` not found in {', '.join(str(r) for r in roots)}; the "
                          f"record keeps its name{where}", span)
        canonical = by_file.setdefault(resolved.path, resolved.name) if resolved.path else resolved.name
        if canonical not in names:
            names.append(canonical)
        ids[name] = names.index(canonical)
    return replace(module, assets=tuple(names), asset_ids=tuple(ids.items()))


def _primitives(module: ir.Module, ops: list, diags: Diagnostics) -> list[tuple[str, object]]:
    """The built-in assets of CityEngine's primitives. Their segment counts choose the mesh, so each must
    be a number or an attribute declared as one (a lot that overrides it to a count the grammar never
    names fails)."""
    declared = {a.name: a.default.value for a in module.attrs if isinstance(a.default, ir.Num)}
    named = []
    for op in ops:
        if not isinstance(op, ir.Primitive):
            continue
        values = [s.value if isinstance(s, ir.Num) else declared.get(s.name) if isinstance(s, ir.AttrRef)
                  else None for s in op.segments]
        if None in values:
            diags.error("unsupported", f"unsupported: primitive{op.kind.title()} with a computed number of "
                        "segments (give a number or an attribute declared as one)", op.span)
        elif primitive_asset(op.kind, segment_counts(values)) is not None:
            named.append((primitive_asset(op.kind, segment_counts(values)), op.span))
    return named


def _queries(module: ir.Module) -> set[str]:
    """The string constants that are file searches: the constant queries of searches, and the constants
    with wildcards (or ``$`` regular expressions) that end as asset files do (``"assets/*.obj"``)."""
    searches = [e.args[0] for e in all_exprs(module) if isinstance(e, ir.Call) and e.func in SEARCHES and e.args]
    given = {q.value for q in searches if isinstance(q, ir.Str)}
    # the pieces of a computed query ("/*.obj" in "assets/" + kind + "/*.obj") are no queries of their own
    pieces = {e.value for q in searches if not isinstance(q, ir.Str) for e in iter_exprs(q) if isinstance(e, ir.Str)}
    wild = {e.value for e in all_exprs(module)
            if isinstance(e, ir.Str) and e.value.lower().endswith(ASSET_SUFFIXES) and _wild(e.value)}
    return given | (wild - pieces)


def _wild(text: str) -> bool:
    """Whether a text is a search rather than a path: it has wildcards or is a ``$`` regular expression."""
    return "*" in text or "?" in text or text.startswith("$")


def _leading_text(expr: ir.Expr) -> str | None:
    """The constant text a computed string begins with: the leftmost constant of a ``+`` chain."""
    while isinstance(expr, ir.Binary) and expr.op == "+":
        expr = expr.left
    return expr.value if isinstance(expr, ir.Str) else None


def searched(module: ir.Module, queries: set[str], diags: Diagnostics) -> list[tuple[str, object]]:
    """(name, span) of the asset files the module's file searches (``queries`` and the computed ones) may
    find, in the module's order."""
    found: list[tuple[str, object, bool]] = []
    for expr in all_exprs(module):
        if isinstance(expr, ir.Call) and expr.func in SEARCHES and expr.args and not isinstance(expr.args[0], ir.Str):
            folder = constant_folder(_leading_text(expr.args[0]) or "")
            if folder:
                found.append((folder + "*", expr.args[0].span, True))
        elif isinstance(expr, ir.Str) and expr.value in queries:
            found.append((expr.value, expr.span, False))
    roots = tuple(Path(r) for r in module.roots)
    named = []
    for text, span, computed in dict.fromkeys(found):  # a walk may meet an expression twice
        try:
            files = search(text, roots)
        except AssetError as error:
            diags.error("asset", str(error), span)
            continue
        assets = [name for name in files if name.lower().endswith(ASSET_SUFFIXES)]
        if computed and len(assets) > MAX_COMPUTED_MATCHES:
            diags.error("asset", f"a computed file search under `{text[:-1]}` may find any of its "
                        f"{len(assets)} asset files, more than {MAX_COMPUTED_MATCHES}; begin it with a "
                        "narrower folder", span)
            continue
        if not files and not computed:
            diags.warning("asset", f"the file search `{text}` finds no file in "
                          f"{', '.join(str(r) for r in roots)}", span)
        named.extend((name, span) for name in assets)
    return named
