"""Expressions evaluated on a whole batch of shapes at once.

``evaluate`` returns a numpy array with one value per shape, or a Python scalar when the value is the same
for every shape (constants); callers broadcast. Numbers are float64, booleans bool, strings int32 ids of
``Plan.strings``. CityEngine's arrays are ``backend.arrays.Arrays``, one array per shape. Built-in functions
are computed by ``backend.functions``.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend import arrays, euler, materials, occlusion
from grammarc.backend.arrays import Arrays
from grammarc.backend.choices import consequent
from grammarc.backend.env import Env
from grammarc.backend.functions import FUNCTIONS
from grammarc.backend.functions.strings import as_string, concatenate, is_string, string_ranks
from grammarc.backend.pivot import pivot_frames, pivot_system, relative_angles
from grammarc.errors import LotFailure
from grammarc.ir import nodes as ir

_ARITH = {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "%": np.fmod}
_COMPARE = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal,
            "==": np.equal, "!=": np.not_equal}


def evaluate(expr: ir.Expr, env: Env):
    if isinstance(expr, (ir.Num, ir.Bool)):
        return expr.value
    if isinstance(expr, ir.Str):
        return env.strings[expr.value]
    if isinstance(expr, ir.Param):
        return env.shapes.params[expr.index]
    if isinstance(expr, ir.AttrRef):
        index = env.plan.dynamic.get(expr.name)
        if index is not None and env.shapes.dynamic:
            return env.shapes.dynamic[index]
        column = env.chunk.attrs[expr.name]
        return column.take(env.shapes.lot) if isinstance(column, Arrays) else column[env.shapes.lot]
    if isinstance(expr, ir.ContextRef):
        if expr.name in materials.COLOR_FIELDS:
            slot = env.plan.color_slot
            return materials.channel(expr.name, env.shapes.dynamic[slot] if slot is not None else None)
        return env.shapes.dynamic[env.plan.dynamic[expr.name]]
    if isinstance(expr, ir.Occlusion):
        distance, which, named = (None if e is None else evaluate(e, env) for e in (expr.distance, expr.which, expr.named))
        return occlusion.query(expr, env, distance, which, named)
    if isinstance(expr, ir.Select):
        cond = evaluate(expr.cond, env)
        then, other = evaluate(expr.then, env), evaluate(expr.other, env)
        if isinstance(then, Arrays):
            return arrays.choose(cond, then, other)
        return np.where(cond, then, other)
    if isinstance(expr, ir.ScopeRef):
        return _scope_field(expr.field, env)
    if isinstance(expr, ir.Unary):
        value = evaluate(expr.operand, env)
        if isinstance(value, Arrays):  # `.-a`, `.!a`
            values = np.logical_not(value.values) if expr.op == ".!" else np.negative(value.values)
            return Arrays(values, value.offsets, value.columns)
        return np.logical_not(value) if expr.op == "!" else np.negative(value)
    if isinstance(expr, ir.Binary):
        left, right = evaluate(expr.left, env), evaluate(expr.right, env)
        if expr.op.startswith("."):
            return _elementwise(expr, left, right, env)
        if expr.op == "&&":
            return np.logical_and(left, right)
        if expr.op == "||":
            return np.logical_or(left, right)
        if isinstance(left, Arrays):  # `==` and `!=` of whole arrays (``passes.types``)
            same = arrays.equal(left, right)
            return same if expr.op == "==" else ~same
        if expr.op in _COMPARE:
            return _compare(expr.op, left, right, env)
        if expr.op == "+" and (is_string(left) or is_string(right)):
            return concatenate(left, right, env.plan.strings)
        with np.errstate(divide="ignore", invalid="ignore"):
            return _ARITH[expr.op](np.asarray(left, dtype=np.float64), right)
    if isinstance(expr, ir.Call):
        return _call(expr, env)
    if isinstance(expr, (ir.ArrayLit, ir.Range, ir.Index)):
        return _ARRAY_EXPRESSIONS[type(expr)](expr, env)
    if isinstance(expr, ir.Choose):
        return _choose(expr, env)
    if isinstance(expr, ir.Aggregate):  # of a search state, read by the search statements (``aggregates``)
        choices = env.chunk.choices
        return choices.value(choices.aggregates.index(expr))[env.shapes.lot]
    raise TypeError(f"cannot evaluate {expr!r}")


def _compare(op: str, left, right, env: Env):
    """A comparison of two values: numbers (and truth values, 1 or 0) by value; strings by their text, in
    its order for ``<``...; a string and a number or a truth value as strings, the other written as ``str``
    writes it (``passes.types``), so that no string id is ever compared with a number."""
    if is_string(left) != is_string(right):
        left, right = as_string(left, env.plan.strings), as_string(right, env.plan.strings)
    if op not in ("==", "!=") and is_string(left):
        ranks = string_ranks(env)
        left, right = ranks[left], ranks[right]
    return _COMPARE[op](left, right)


# -------------------------------------------------------------------------------------------------- arrays


def _as_arrays(value, env: Env) -> Arrays:
    """A value as arrays: an array stays, a scalar is the 1x1 array of its value per shape."""
    if isinstance(value, Arrays):
        return value
    dtype = np.int32 if is_string(value) else np.asarray(value).dtype
    return arrays.from_scalars(value, len(env.shapes), dtype)


def _checked(result: tuple[Arrays, np.ndarray], env: Env, what: str, span) -> Arrays:
    """The arrays of an array function, or ``LotFailure`` for the lots of the shapes it failed on."""
    value, bad = result
    if bad.any():
        raise LotFailure(f"{what} at {span}", np.unique(env.shapes.lot[bad]))
    return value


def _array_literal(expr: ir.ArrayLit, env: Env) -> Arrays:
    rows = []
    for row in expr.rows:
        pieces = [_as_arrays(evaluate(e, env), env) for e in row]
        rows.append(pieces[0] if len(pieces) == 1 else _checked(
            arrays.concatenate_row(pieces), env, "the values of an array row differ in their rows", expr.span))
    if len(rows) == 1:
        return rows[0]
    return _checked(arrays.stack_rows(rows), env, "the rows of an array differ in length", expr.span)


def _colon(expr: ir.Range, env: Env) -> Arrays:
    base, step, limit = (evaluate(e, env) for e in (expr.base, expr.step, expr.limit))
    return _checked(arrays.colon(base, step, limit, len(env.shapes)), env,
                    f"a range of more than {arrays.MAX_ELEMENTS} elements", expr.span)


def _index(expr: ir.Index, env: Env):
    """``a[i]``, ``a[i, j]``: elements for number indices, arrays when an index is an array."""
    array = evaluate(expr.array, env)
    default = env.plan.strings.intern("") if array.values.dtype == np.int32 else array.values.dtype.type(0)
    index = evaluate(expr.index, env)
    if expr.column is None:
        if isinstance(index, Arrays):
            return arrays.gather(array, index, default)
        return arrays.item(array, index, default)
    column = evaluate(expr.column, env)
    if isinstance(index, Arrays) or isinstance(column, Arrays):
        return arrays.gather_cells(array, _as_arrays(index, env), _as_arrays(column, env), default)
    return arrays.cell(array, index, column, default)


def _elementwise(expr: ir.Binary, left, right, env: Env) -> Arrays:
    """``a .+ b``, ``a .< b``...: the operator on each element of an array and the element at the same
    place of the other array (of equal dimensions) or the shape's scalar; shaped as the array."""
    shape = left if isinstance(left, Arrays) else right
    owner = shape.owner()
    bad = np.zeros(len(shape), dtype=bool)

    def elements(value):
        nonlocal bad
        if not isinstance(value, Arrays):
            return value if np.ndim(value) == 0 else np.asarray(value)[owner]
        bad |= (value.sizes != shape.sizes) | (value.columns != shape.columns)
        return value.values[np.where(bad[owner], 0, value.offsets[:-1][owner] + shape.position())] \
            if len(value.values) else value.values
    a, b = elements(left), elements(right)
    if bad.any():
        raise LotFailure(f"`{expr.op}` on arrays of different dimensions at {expr.span}",
                         np.unique(env.shapes.lot[bad]))
    op = expr.op[1:]
    if op == "&&" or op == "||":
        values = (np.logical_and if op == "&&" else np.logical_or)(a, b)
    elif op == "+" and (is_string(a) or is_string(b)):
        values = concatenate(a, b, env.plan.strings)
    elif op in _COMPARE:
        values = _compare(op, a, b, env)
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            values = _ARITH[op](np.asarray(a, dtype=np.float64), b)
    values = np.broadcast_to(values, owner.shape) if np.ndim(values) == 0 else values
    return Arrays(np.asarray(values), shape.offsets, shape.columns)


_ARRAY_EXPRESSIONS = {ir.ArrayLit: _array_literal, ir.Range: _colon, ir.Index: _index}


def evaluate_array(expr: ir.Expr, env: Env, dtype=np.float64) -> np.ndarray:
    """``evaluate`` broadcast to one value per shape."""
    value = np.asarray(evaluate(expr, env), dtype=dtype)
    if value.ndim == 0:
        return np.full(len(env.shapes), value, dtype=dtype)
    return value


def _scope_field(name: str, env: Env):
    axis = "xyz".index(name[1])
    shapes = env.shapes
    if name[0] == "s":
        return shapes.size[:, axis]
    if name[0] == "o":
        return env.chunk.lot_origin[shapes.lot, axis]
    # Translation and angles relative to the pivot (``backend.pivot``): the lot's own scope, CityEngine's
    # object coordinates, where the grammar keeps no pivot.
    slot = env.plan.pivot_slot
    origin, axes = pivot_system(slot, env.chunk, shapes)
    if name[0] == "r":
        return _scope_angles(env, axes, pivot_frames(slot, shapes))[:, axis]
    return np.einsum("nj,nj->n", shapes.origin - origin, axes[:, axis])


def _scope_angles(env: Env, axes: np.ndarray, frames: np.ndarray | None) -> np.ndarray:
    """The scope's rotation relative to the pivot with ``axes`` (n, 3, 3) and frame ids ``frames`` (None: no
    pivot is kept), as angles (n, 3) in degrees about x, then y, then z (``backend.euler``)."""
    scope_axes = env.chunk.frames[env.shapes.frame]
    if frames is None:
        return euler.angles(np.einsum("nij,nkj->nik", scope_axes, axes))  # rows: new axes in the lot's frame
    return relative_angles(scope_axes, axes, env.shapes.frame == frames)


def _choose(expr: ir.Choose, env: Env) -> np.ndarray:
    """``choose(a, b, ...)``: each shape's option (``backend.choices``)."""
    shapes = env.shapes
    options = [np.broadcast_to(np.asarray(evaluate(o, env)), (len(shapes),)) for o in expr.options]
    picked = consequent(env.chunk.choices, env.plan.sequential_random, shapes.lot, shapes.key, expr.site,
                        len(options))
    return np.stack(options)[picked, np.arange(len(shapes))]


def _call(expr: ir.Call, env: Env):
    return FUNCTIONS[expr.func](expr, [evaluate(a, env) for a in expr.args], env)
