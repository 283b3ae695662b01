"""Assets and occluders: the paper's ``I(name)`` (an instance on the scope, the shape's end), CityEngine's
``i(name)`` (the shape's geometry becomes the asset) and ``label(name)`` (the shape's solid an occluder).

Reads: the scope (``origin``, ``size``, ``frame``), ``geom``, ``lot``, ``dynamic`` (colour, trim planes,
occluding ancestors). Writes: ``i`` the ``geom``, its mark as inserted (``dynamic``), and the scope's
``origin`` and ``size`` in the insert modes that keep the asset's size; ``label`` the ``dynamic`` ancestors.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend import terminals
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.occlusion import add_occluders, interned_texts, occluder_label, with_ancestor
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Z_UP, Shapes, asset_geom
from grammarc.ir import nodes as ir


@operation(ir.Insert, meshes=True, consumes=True)
def insert(ctx: Context, cursor: Shapes, op: ir.Insert) -> None:
    """The paper's ``I(name)``: an instance of the asset on the scope (a solid one occludes)."""
    if ctx.plan.occluders:
        add_occluders(ctx.chunk, cursor, occluder_label(ctx.plan, ctx.symbol))
    terminals.emit_instances(ctx, cursor, ctx.plan.grammar.asset_ids[op.asset], ctx.symbol)


@operation(ir.UseAsset, writes=("origin", "size", "geom", "dynamic"), meshes=True)
def use_asset(ctx: Context, cursor: Shapes, op: ir.UseAsset) -> Shapes:
    """The geometry becomes the asset placed by the insert mode (``placed``), inserted geometry, which its
    leaves' trim planes cut; a computed up axis or mode is read per shape."""
    asset = asset_ids(ctx, cursor, op, "i")
    up = op.up == "zUp" if op.up_by is None else _chosen(ctx, cursor, op.up_by, ir.UP_AXES, "up axis", op) == 1
    mode = ir.INSERT_MODES.index(op.mode) if op.mode_by is None else \
        _chosen(ctx, cursor, op.mode_by, ir.INSERT_MODES, "insert mode", op)
    return terminals.marked_inserted(ctx.plan, placed(ctx, cursor, asset, up, mode, op.span), True)


def asset_ids(ctx: Context, cursor: Shapes, op: ir.UseAsset | ir.InsertAlongUV, verb: str) -> np.ndarray:
    """The asset ids (n,) int32 that ``op`` inserts: its asset's, or those its ``name`` computes per shape (a
    shape whose name is no asset of the grammar fails, the error naming ``verb``)."""
    plan = ctx.plan
    if op.name is None:
        return np.full(len(cursor), plan.grammar.asset_ids[op.asset], dtype=np.int32)
    names = evaluate_array(op.name, ctx.env(cursor), dtype=np.int32)
    distinct, inverse = np.unique(names, return_inverse=True)
    asset = np.array([plan.asset_of_string.get(int(s), -1) for s in distinct], dtype=np.int32)[inverse.reshape(-1)]
    bad = asset < 0
    if bad.any():
        texts = list(plan.strings.ids)

        def refused(i: int) -> str:
            name = texts[int(names[i])]
            # the assets a computed name may take are found when compiling (``passes.assets``)
            why = ("a file search that found nothing" if not name else "not an asset of the grammar: a computed "
                   "name is a string constant of an asset file, or a file a search may find")
            return f"`{verb}` of `{name}`, {why}"
        ctx.fail_each(cursor, bad, refused, op.span)
    return asset


def _chosen(ctx: Context, cursor: Shapes, expr: ir.Expr, allowed: tuple[str, ...], what: str,
            op: ir.UseAsset) -> np.ndarray:
    """The index (n,) int64 in ``allowed`` of each shape's value of the string ``expr``; a shape whose
    value is none of them fails."""
    ids = np.broadcast_to(evaluate_array(expr, ctx.env(cursor), dtype=np.int32), (len(cursor),))
    distinct, inverse = np.unique(ids, return_inverse=True)
    texts = interned_texts(ctx.plan, distinct)
    index = np.array([allowed.index(t) if t in allowed else -1 for t in texts], dtype=np.int64)[inverse.reshape(-1)]
    bad = index < 0
    if bad.any():
        inverse = inverse.reshape(-1)
        ctx.fail_each(cursor, bad, lambda i: f"`i` with {what} `{texts[inverse[i]]}`, not one of {', '.join(allowed)}",
                      op.span)
    return np.maximum(index, 0)


def placed(ctx: Context, cursor: Shapes, asset: np.ndarray, up, mode, span) -> Shapes:
    """The shapes with asset ids ``asset`` (n,) int32 as their geometry, and their scopes as the insert
    mode makes them (CityEngine's reference of ``i``): ``mode`` an index into ``ir.INSERT_MODES``, one or
    (n,) one a shape;

    - ``alignSizeAndPosition``: the asset fitted to the scope, which is unchanged (a cube is the scope box
      itself);
    - ``keepSizeAndPosition``: the scope becomes the asset's bounding box, in the asset's own units and
      at its own position, both read along the scope's axes (as ``s(0, 0, 0)`` then ``i`` would);
    - ``keepSizeAlignPosition``: the scope gets the asset's size, centred on the old scope in x and z and
      standing on its y = 0.

    ``up`` (a bool, or (n,) one a shape) is ``zUp``: the asset turns -90 degrees about x before it is
    placed (its z is the scope's y), so its bounding box does too.
    """
    geom = np.where(asset == 0, -1, asset_geom(asset, np.where(up, Z_UP, 0))).astype(np.int32)  # 0: builtin:cube
    if np.all(mode == 0):
        return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)
    low, high = _bounds(ctx, cursor, asset, up, mode, span)
    size = high - low
    offset = np.where(np.reshape(mode == 1, (-1, 1)), low, (cursor.size - size) * np.array([0.5, 0.0, 0.5]))
    if np.any(mode == 0):  # modes chosen per shape: the aligned ones keep their scopes
        fitted = np.reshape(mode == 0, (-1, 1))
        offset, size = np.where(fitted, 0.0, offset), np.where(fitted, cursor.size, size)
    return scope_at(ctx, cursor, offset, size, geom)


def scope_at(ctx: Context, cursor: Shapes, offset: np.ndarray, size: np.ndarray, geom: np.ndarray) -> Shapes:
    """The shapes with their scopes moved by ``offset`` (n, 3) along their own axes, of size ``size``
    (n, 3) and geometry ``geom`` (n,)."""
    axes = ctx.chunk.frames.data[cursor.frame]  # (n, 3, 3): row j is scope axis j
    origin = cursor.origin + np.einsum("nj,njr->nr", offset, axes)
    return cursor.with_scope(origin, size, cursor.frame, geom)


def _bounds(ctx: Context, cursor: Shapes, asset: np.ndarray, up, mode, span) -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest corners (n, 3) of the shapes' assets' bounding boxes in their own units,
    turned z-up where ``up`` (one, or (n,)) says; each asset read once. A shape whose asset cannot be
    loaded fails, unless its ``mode`` (one, or (n,)) fits the asset to the scope (its row stays 0)."""
    need = np.broadcast_to(mode != 0, asset.shape)
    ids, inverse = np.unique(np.where(need, asset, -1), return_inverse=True)
    table = np.zeros((len(ids), 2, 3))
    modes = np.broadcast_to(mode, asset.shape)
    for k, a in enumerate(ids.tolist()):
        mesh = None if a < 0 else ctx.asset_mesh(a)
        if a >= 0 and mesh is None:
            problem = ctx.asset_problem(a)
            ctx.fail_each(cursor, need & (asset == a), lambda i, problem=problem: "`i(..., "
                          f"{ir.INSERT_MODES[int(modes[i])]})` needs the asset's size: {problem}", span)
        if mesh is not None:
            table[k] = mesh.bounds
    rows = inverse.reshape(-1)
    low, high = table[rows, 0], table[rows, 1]
    if np.any(up):  # (x, y, z) -> (x, z, -y): the highest y becomes the lowest z
        turned = np.reshape(up, (-1, 1))
        low, high = (np.where(turned, np.stack([low[:, 0], low[:, 2], -high[:, 1]], axis=1), low),
                     np.where(turned, np.stack([high[:, 0], high[:, 2], -low[:, 1]], axis=1), high))
    return low, high


@operation(ir.Label, writes=("dynamic",), meshes=True)
def label(ctx: Context, cursor: Shapes, op: ir.Label) -> Shapes:
    """``label(name)``: the shape's solid is an occluder with that label, and its own ancestor; any
    shape is a labelled shape that the context queries (``minimumDistance``, ``contextCount``) see."""
    name = op.name.value if isinstance(op.name, ir.Str) else \
        interned_texts(ctx.plan, evaluate_array(op.name, ctx.env(cursor), dtype=np.int32))
    return with_ancestor(ctx.plan, cursor, add_occluders(ctx.chunk, cursor, name, scopes=True))
