"""Values a shape carries or reports: ``set(attr, value)``, ``color()``, the opacity, ``resetMaterial`` and
CityEngine's ``report``.

``set``, ``color`` and ``set(material.opacity)`` give the shape (and so its successors and parts) a new
value in its ``dynamic`` column (the colour and opacity share one: ``backend.materials``); ``report`` adds
rows to the chunk's reports (``backend.report_rows``). Reads: what their expressions read, and ``lot``
(reports). Writes: ``set``, ``color`` and the opacity the ``dynamic`` column of their value,
``resetMaterial`` the colour and texture channel columns.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate, evaluate_array
from grammarc.backend.materials import hex_colors, with_opacity, with_transparency_of
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes
from grammarc.backend.slots import WHITE_RGB
from grammarc.ir import nodes as ir


@operation(ir.SetAttr, writes=("dynamic",), meshes=True)
def set_attr(ctx: Context, cursor: Shapes, op: ir.SetAttr) -> Shapes:
    index = ctx.plan.dynamic[op.name]
    column = cursor.dynamic[index]
    value = evaluate_array(op.value, ctx.env(cursor), dtype=column.dtype)
    dynamic = cursor.dynamic[:index] + (value,) + cursor.dynamic[index + 1:]
    return Shapes(cursor.origin, cursor.size, cursor.frame, cursor.geom, cursor.lot, cursor.key,
                  cursor.depth, cursor.params, dynamic)


@operation(ir.SetColor, writes=("dynamic",), meshes=True)
def set_color(ctx: Context, cursor: Shapes, op: ir.SetColor) -> Shapes:
    """The shape's colour as 0xRRGGBB: from components in [0, 1], or parsed from "#rrggbb"."""
    env = ctx.env(cursor)
    n = len(cursor)
    if len(op.values) == 3:
        parts = [np.clip(np.round(np.broadcast_to(evaluate_array(v, env), (n,)) * 255), 0, 255)
                 for v in op.values]
        packed = parts[0] * 65536 + parts[1] * 256 + parts[2]
    else:
        ids = np.broadcast_to(evaluate_array(op.values[0], env, dtype=np.int32), (n,))
        packed = hex_colors(ctx.plan.strings)[ids]
        bad = np.isnan(packed)
        if bad.any():
            names = list(ctx.plan.strings.ids)
            ctx.fail_each(cursor, bad, lambda i: f'color("{names[int(ids[i])]}") is not a colour "#rrggbb"', op.span)
    index = ctx.plan.color_slot
    packed = with_transparency_of(packed.astype(np.float64), cursor.dynamic[index])
    dynamic = cursor.dynamic[:index] + (packed,) + cursor.dynamic[index + 1:]
    return replace(cursor, dynamic=dynamic)


@operation(ir.SetOpacity, writes=("dynamic",), meshes=True)
def set_opacity(ctx: Context, cursor: Shapes, op: ir.SetOpacity) -> Shapes:
    """The shape's opacity, in the colour column beside its colour (``backend.materials``)."""
    index = ctx.plan.color_slot
    opacity = np.broadcast_to(evaluate_array(op.value, ctx.env(cursor)), (len(cursor),))
    dynamic = cursor.dynamic[:index] + (with_opacity(cursor.dynamic[index], opacity),) + cursor.dynamic[index + 1:]
    return replace(cursor, dynamic=dynamic)


@operation(ir.ResetMaterial, writes=("dynamic",), meshes=True)
def reset_material(ctx: Context, cursor: Shapes, op: ir.ResetMaterial) -> Shapes:
    """The colour white and opaque, the texture channels none: the columns the grammar carries as a lot
    starts them (a material attribute it carries no column of has its default already)."""
    plan = ctx.plan
    n = len(cursor)
    dynamic = list(cursor.dynamic)
    if plan.color_slot is not None:
        dynamic[plan.color_slot] = np.full(n, WHITE_RGB)
    for _, slot in plan.material_slots:
        dynamic[slot] = np.full(n, plan.strings.ids[""], dtype=np.int32)
    return replace(cursor, dynamic=tuple(dynamic))


@operation(ir.SetMaterial, writes=("dynamic",), meshes=True)
def set_material(ctx: Context, cursor: Shapes, op: ir.SetMaterial) -> Shapes:
    """Each name of the shapes' arrays set to the value after it, in the array's order (a later one wins):
    ``color.r|g|b`` and ``opacity`` as numbers, a texture channel (``colormap``...) as its path. The other
    attributes (``specular.r``, ``shininess``...) have no effect, as ``set`` of them has none. Each
    distinct name and value is read once."""
    plan = ctx.plan
    array = evaluate(op.material, ctx.env(cursor))
    texts = list(plan.strings.ids)
    pairs = array.sizes // 2
    owner = np.repeat(np.arange(len(cursor)), pairs)
    at = array.offsets[:-1][owner] + 2 * (np.arange(len(owner)) - np.repeat(np.cumsum(pairs) - pairs, pairs))
    names, values = array.values[at], array.values[at + 1]
    dynamic = list(cursor.dynamic)
    packed = dynamic[plan.color_slot].copy()
    for name_id in np.unique(names).tolist():
        name = texts[name_id]
        rows = names == name_id
        field = f"material.{name}"
        if field in plan.dynamic and field.endswith("map"):
            column = dynamic[plan.dynamic[field]].copy()
            column[owner[rows]] = values[rows]  # later pairs are written last: they win
            dynamic[plan.dynamic[field]] = column
        elif name in ("color.r", "color.g", "color.b", "opacity"):
            number = _numbers(texts, values[rows])
            bad = np.isnan(number)
            if bad.any():
                ctx.fail(cursor, np.isin(np.arange(len(cursor)), owner[rows][bad]),
                         f"setMaterial: `{name}` is not a number (`{texts[int(values[rows][bad][0])]}`)", op.span)
            shapes = owner[rows]
            if name == "opacity":
                packed[shapes] = with_opacity(packed[shapes], number)
            else:
                shift = 16 - 8 * "rgb".index(name[-1])
                value = packed[shapes].astype(np.int64)
                byte = np.clip(np.round(number * 255), 0, 255).astype(np.int64)
                packed[shapes] = (value & ~(255 << shift)) + (byte << shift)
    dynamic[plan.color_slot] = packed
    return replace(cursor, dynamic=tuple(dynamic))


def _numbers(texts: list[str], ids: np.ndarray) -> np.ndarray:
    """The numbers (k,) float64 that interned strings ``ids`` (k,) spell (NaN where one does not)."""
    distinct, inverse = np.unique(ids, return_inverse=True)
    return np.array([_number(texts[int(i)]) for i in distinct])[inverse.reshape(-1)]


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


@operation(ir.Report, meshes=True)
def report(ctx: Context, cursor: Shapes, op: ir.Report) -> None:
    env = ctx.env(cursor)
    key = evaluate_array(op.key, env, dtype=np.int32)
    value = evaluate(op.value, env)
    ctx.chunk.outputs.reports.append(report_rows(cursor.lot, key, value, len(cursor)))


def report_rows(lot: np.ndarray, key, value, n: int) -> tuple:
    """One ``report`` call's rows: lot (n,), key ids (n,), values (n,) float64 and the value kind
    ("num", "bool" or "str"; strings as their ids)."""
    key = np.broadcast_to(np.asarray(key, dtype=np.int32), (n,))
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, np.ndarray) and value.dtype == bool):
        kind = "bool"
    elif isinstance(value, (int, np.integer)) or (isinstance(value, np.ndarray) and value.dtype == np.int32):
        kind = "str"
    else:
        kind = "num"
    values = np.broadcast_to(np.asarray(value, dtype=np.float64), (n,))
    return lot, key, values, kind
