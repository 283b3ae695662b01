"""Asset resolution: every name ``I()`` and ``i()`` give resolved in the module's asset folders.

Assumes: a rule graph (a module without one fails to compile anyway, for the errors that stopped it) and
``Module.roots`` (a module lowered outside the compiler has none, and keeps its names unresolved).
Guarantees: ``Module.assets`` lists the canonical names, the leaf cube and quad first, an asset's index
being its id in the record; ``Module.asset_ids`` gives each name as written its id. A name that is
absolute or leaves the folders is an error, a file that no folder holds a warning (the record keeps its
name).
"""

from __future__ import annotations

from dataclasses import replace

from grammarc.diagnostics import Diagnostics
from grammarc.ir import nodes as ir
from grammarc.ir.asset_names import LEAF_CUBE, LEAF_QUAD, resolve_asset, unsupported_format
from grammarc.ir.traverse import all_exprs, iter_ops

#: File endings of assets that a computed ``i(name)`` may name: string constants ending so are resolved.
ASSET_SUFFIXES = (".obj", ".glb", ".gltf", ".dae", ".fbx", ".3ds")


def resolve_assets(module: ir.Module, diags: Diagnostics) -> ir.Module:
    if module.roots is None or module.graph is None:
        return module
    ops = list(iter_ops(module))
    named = [(op.asset, op.span) for op in ops if isinstance(op, (ir.Insert, ir.UseAsset)) and op.asset]
    if any(isinstance(op, ir.UseAsset) and op.name is not None for op in ops):
        # a computed asset name: every string constant that looks like an asset may be one
        named.extend((e.value, e.span) for e in all_exprs(module)
                     if isinstance(e, ir.Str) and e.value.lower().endswith(ASSET_SUFFIXES))
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
            diags.warning("asset", f"asset `{name}` not found in {', '.join(str(r) for r in roots)}; the "
                          "record keeps its name", span)
        canonical = by_file.setdefault(resolved.path, resolved.name) if resolved.path else resolved.name
        if canonical not in names:
            names.append(canonical)
        ids[name] = names.index(canonical)
    return replace(module, assets=tuple(names), asset_ids=tuple(ids.items()))
