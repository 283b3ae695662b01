"""Assets and occluders: the paper's ``I(name)`` (an instance on the scope, the shape's end), CityEngine's
``i(name)`` (the shape's geometry becomes the asset) and ``label(name)`` (the shape's solid an occluder).

Reads: the scope (``origin``, ``size``, ``frame``), ``geom``, ``lot``, ``dynamic`` (colour, trim planes,
occluding ancestors). Writes: ``i`` the ``geom``; ``label`` the ``dynamic`` ancestors.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend import terminals
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.occlusion import add_occluders, occluder_label, with_ancestor
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes, asset_geom
from grammarc.ir import nodes as ir


@operation(ir.Insert, meshes=True, consumes=True)
def insert(ctx: Context, cursor: Shapes, op: ir.Insert) -> None:
    """The paper's ``I(name)``: an instance of the asset on the scope (a solid one occludes)."""
    if ctx.plan.occluders:
        add_occluders(ctx.chunk, cursor, occluder_label(ctx.plan, ctx.symbol))
    terminals.emit_instances(ctx, cursor, ctx.plan.grammar.asset_ids[op.asset], ctx.symbol)


@operation(ir.UseAsset, writes=("geom",), meshes=True)
def use_asset(ctx: Context, cursor: Shapes, op: ir.UseAsset) -> Shapes:
    """The geometry becomes the asset fitted to the scope (a cube is the scope box itself)."""
    plan = ctx.plan
    if op.name is None:
        asset = np.full(len(cursor), plan.grammar.asset_ids[op.asset], dtype=np.int32)
    else:
        names = evaluate_array(op.name, ctx.env(cursor), dtype=np.int32)
        distinct, inverse = np.unique(names, return_inverse=True)
        asset = np.array([plan.asset_of_string.get(int(s), -1) for s in distinct], dtype=np.int32)[inverse.reshape(-1)]
        bad = asset < 0
        if bad.any():
            name = list(plan.strings.ids)[int(names[np.flatnonzero(bad)[0]])]
            # the assets a computed name may take are found when compiling (``passes.assets``)
            why = ("a file search that found nothing" if not name else "not an asset of the grammar: a computed "
                   "name is a string constant of an asset file, or a file a search may find")
            ctx.fail(cursor, bad, f"`i` of `{name}`, {why}", op.span)
    geom = np.where(asset == 0, -1, asset_geom(asset)).astype(np.int32)  # asset 0 is builtin:cube
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)


@operation(ir.Label, writes=("dynamic",), meshes=True)
def label(ctx: Context, cursor: Shapes, op: ir.Label) -> Shapes:
    """``label(name)``: the shape's solid is an occluder with that label, and its own ancestor."""
    return with_ancestor(ctx.plan, cursor, add_occluders(ctx.chunk, cursor, op.name))
