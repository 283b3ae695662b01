"""Expressions evaluated on a whole batch of shapes at once.

``evaluate`` returns a numpy array with one value per shape, or a Python scalar when the value is the same
for every shape (constants); callers broadcast. Numbers are float64, booleans bool, strings int32 ids of
``Plan.strings``. CityEngine's arrays are ``backend.arrays.Arrays``, one array per shape. Angles of trigonometric functions are degrees, as in CGA. Transcendental functions run in
a numba loop rather than numpy's SIMD kernels, so a value never depends on its position in the batch.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from grammarc.backend import arrays, occlusion
from grammarc.backend.arrays import Arrays
from grammarc.backend.chunk import Chunk
from grammarc.backend.random import uniform
from grammarc.backend.shapes import Shapes
from grammarc.errors import LotFailure
from grammarc.geometry.measure import area_and_volume, is_rectangular, vertex_and_face_counts
from grammarc.ir import nodes as ir

if TYPE_CHECKING:
    from grammarc.backend.plan import Plan


@dataclass(frozen=True, eq=False)
class Env:
    """What an expression can read: the shapes (scope, params, keys, set attributes), their chunk (lot
    attributes, geometry) and the plan (interned strings, which attributes are set per shape)."""

    shapes: Shapes
    chunk: Chunk
    plan: Plan

    @property
    def strings(self) -> dict[str, int]:
        return self.plan.strings.ids


_ARITH = {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "%": np.fmod}
_COMPARE = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal,
            "==": np.equal, "!=": np.not_equal}
#: Codes of the functions computed by ``elementwise``.
_MATH = {"sin": 0, "cos": 1, "tan": 2, "asin": 3, "acos": 4, "atan": 5, "exp": 6, "log": 7, "sqrt": 8}


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
        return env.shapes.dynamic[env.plan.dynamic[expr.name]]
    if isinstance(expr, ir.Occlusion):
        distance = evaluate(expr.distance, env) if expr.distance is not None else None
        return occlusion.query(expr, env, distance)
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
            return _COMPARE[expr.op](left, right)
        if expr.op == "+" and (_is_string(left) or _is_string(right)):
            return concatenate(left, right, env.plan.strings)
        with np.errstate(divide="ignore", invalid="ignore"):
            return _ARITH[expr.op](np.asarray(left, dtype=np.float64), right)
    if isinstance(expr, ir.Call):
        return _call(expr, env)
    if isinstance(expr, (ir.ArrayLit, ir.Range, ir.Index)):
        return _ARRAY_EXPRESSIONS[type(expr)](expr, env)
    raise TypeError(f"cannot evaluate {expr!r}")


# -------------------------------------------------------------------------------------------------- arrays


def _as_arrays(value, env: Env) -> Arrays:
    """A value as arrays: an array stays, a scalar is the 1x1 array of its value per shape."""
    if isinstance(value, Arrays):
        return value
    dtype = np.int32 if _is_string(value) else np.asarray(value).dtype
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
    elif op == "+" and (_is_string(a) or _is_string(b)):
        values = concatenate(a, b, env.plan.strings)
    elif op in _COMPARE:
        if op not in ("==", "!=") and _is_string(a):  # strings in order of their text
            ranks = _string_ranks(env)
            a, b = ranks[a], ranks[b]
        values = _COMPARE[op](a, b)
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            values = _ARITH[op](np.asarray(a, dtype=np.float64), b)
    values = np.broadcast_to(values, owner.shape) if np.ndim(values) == 0 else values
    return Arrays(np.asarray(values), shape.offsets, shape.columns)


_ARRAY_EXPRESSIONS = {ir.ArrayLit: _array_literal, ir.Range: _colon, ir.Index: _index}


def _string_ranks(env: Env) -> np.ndarray:
    """(strings,) int64 the rank of each interned string's text in sorted order."""
    names = list(env.plan.strings.ids)
    ranks = np.empty(len(names), dtype=np.int64)
    ranks[np.argsort(np.array(names, dtype=object), kind="stable")] = np.arange(len(names))
    return ranks


def _array_call(f: str, args: list, env: Env):
    """CityEngine's array functions (``ir.ARRAY_FUNCTIONS``) on evaluated arguments."""
    if f == "isNull":
        if _is_string(args[0]):
            null = env.plan.strings.ids.get("\ue000", -1)
            return np.equal(args[0], null)
        return np.isnan(np.asarray(args[0], dtype=np.float64))
    array = args[0]
    if f == "size":
        return array.sizes.astype(np.float64)
    if f == "nRows":
        return array.rows.astype(np.float64)
    if f == "nColumns":
        return array.columns.astype(np.float64)
    if f == "transpose":
        return arrays.transpose(array)
    ranks = _string_ranks(env) if array.values.dtype == np.int32 else None
    if f == "sortIndices":
        return arrays.sort_indices(array, ranks)
    if f == "sortRowIndices":
        return arrays.sort_row_indices(array, ranks)
    return arrays.find_first(array, *args[1:])


def _is_string(value) -> bool:
    """String values are interned ids: Python ints or int32 arrays (numbers are float, flags bool)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)) or (
        isinstance(value, np.ndarray) and value.dtype == np.int32)


def format_value(value, is_string: bool, names: list[str]) -> str:
    """A value as CityEngine prints it in strings: 3.0 -> "3", 2.5 -> "2.5", True -> "true"."""
    if is_string:
        return names[int(value)]
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)


def concatenate(left, right, strings) -> np.ndarray | int:
    """CityEngine's ``+`` on strings, per shape: once per distinct pair of operands, then spread."""
    names = list(strings.ids)
    left_str, right_str = _is_string(left), _is_string(right)
    a, b = np.broadcast_arrays(np.asarray(left), np.asarray(right))
    if a.ndim == 0:
        text = format_value(a[()], left_str, names) + format_value(b[()], right_str, names)
        return strings.intern(text)
    pairs = np.stack([a.astype(np.float64), b.astype(np.float64)], axis=1)
    distinct, inverse = np.unique(pairs, axis=0, return_inverse=True)
    # the pairs are numbers: flags get their type back, to print as true/false
    as_left = bool if a.dtype == np.bool_ else float
    as_right = bool if b.dtype == np.bool_ else float
    ids = np.array([strings.intern(format_value(as_left(x), left_str, names)
                                   + format_value(as_right(y), right_str, names))
                    for x, y in distinct], dtype=np.int32)
    return ids[inverse.reshape(-1)]


def list_item(items, index, strings) -> np.ndarray | int:
    """CityEngine's ``listItem(list, index)``: item ``index`` of a ``;``-separated string list ("" out of
    range), once per distinct pair of list and index."""
    names = list(strings.ids)
    a, b = np.broadcast_arrays(np.asarray(items), np.asarray(index, dtype=np.float64))

    def item(text: str, i: float) -> int:
        parts = text.split(";")
        k = int(np.floor(i)) if np.isfinite(i) else -1
        return strings.intern(parts[k] if 0 <= k < len(parts) else "")

    if a.ndim == 0:
        return item(names[int(a[()])], float(b[()]))
    pairs = np.stack([a.astype(np.float64), b], axis=1)
    distinct, inverse = np.unique(pairs, axis=0, return_inverse=True)
    ids = np.array([item(names[int(x)], y) for x, y in distinct], dtype=np.int32)
    return ids[inverse.reshape(-1)]


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
    if name[0] == "r":
        return _scope_angles(env)[:, axis]
    # Translation relative to the lot's own scope, along the lot's axes (CityEngine's object coordinates).
    lot = shapes.lot
    offset = shapes.origin - env.chunk.lot_origin[lot]
    return np.einsum("nj,nj->n", offset, env.chunk.lot_axes[lot, axis])


def _scope_angles(env: Env) -> np.ndarray:
    """The scope's rotation relative to its lot's scope, as angles (n, 3) in degrees about x, then y,
    then z (the order of ``R``): the inverse of ``operations.scope._rotation``."""
    relative = np.einsum("nij,nkj->nik", env.chunk.frames[env.shapes.frame],
                         env.chunk.lot_axes[env.shapes.lot])  # rows: new axes in the lot's frame
    # relative = Rz @ Ry @ Rx with rows as in operations.scope._rotation; read the angles off its entries
    ry = np.degrees(np.arcsin(np.clip(-relative[:, 0, 2], -1.0, 1.0)))
    rx = np.degrees(np.arctan2(relative[:, 1, 2], relative[:, 2, 2]))
    rz = np.degrees(np.arctan2(relative[:, 0, 1], relative[:, 0, 0]))
    return np.stack([rx, ry, rz], axis=1)


def _call(expr: ir.Call, env: Env):
    args = [evaluate(a, env) for a in expr.args]
    f = expr.func
    if f in ir.ARRAY_FUNCTIONS:
        return _array_call(f, args, env)
    if f == "rand":
        u = uniform(env.shapes.key, expr.site)
        if not args:
            return u
        low, high = (0.0, args[0]) if len(args) == 1 else args
        return low + (np.subtract(high, low)) * u
    if f == "p":
        return uniform(env.shapes.key, expr.site) < np.asarray(args[0], dtype=np.float64)
    if f == "fileRandom":
        return uniform(env.chunk.lot_key[env.shapes.lot], 0x5F11E)
    if f in ("geometry.nVertices", "geometry.nFaces"):
        vertices, faces = vertex_and_face_counts(env.shapes.size, env.shapes.geom, env.chunk.polygons,
                                                  env.chunk.meshes)
        return vertices if f == "geometry.nVertices" else faces
    if f == "len":
        names = list(env.plan.strings.ids)
        ids = np.asarray(args[0])
        distinct, inverse = np.unique(np.atleast_1d(ids), return_inverse=True)
        lengths = np.array([len(names[int(i)]) for i in distinct], dtype=np.float64)[inverse.reshape(-1)]
        return lengths if ids.ndim else float(lengths[0])
    if f == "geometry.isRectangular":
        return is_rectangular(env.shapes.size, env.shapes.geom, env.chunk.polygons,
                              float(np.max(args[0])) if np.size(args[0]) else 0.0)
    if f in ("geometry.area", "geometry.volume"):
        area, volume = area_and_volume(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
        return area if f == "geometry.area" else volume
    if f == "isnan":
        return np.isnan(np.asarray(args[0], dtype=np.float64))
    if f == "log10":
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.log10(np.asarray(args[0], dtype=np.float64))
    if f == "str":
        return concatenate(env.plan.strings.intern(""), args[0], env.plan.strings)
    if f == "float":
        return _to_float(args[0], env)
    if f == "listItem":
        return list_item(args[0], args[1], env.plan.strings)
    if f == "bool":
        return np.asarray(args[0]) != 0
    if f in ("floor", "ceil", "abs"):
        return getattr(np, f)(args[0])
    if f == "round":
        x = np.asarray(args[0], dtype=np.float64)
        return np.copysign(np.floor(np.abs(x) + 0.5), x)
    if f in ("min", "max"):
        return (np.minimum if f == "min" else np.maximum)(args[0], args[1])
    if f == "pow":
        with np.errstate(invalid="ignore", over="ignore"):
            return np.power(np.asarray(args[0], dtype=np.float64), args[1])
    if f == "atan2":
        y, x = np.broadcast_arrays(np.asarray(args[0], np.float64), np.asarray(args[1], np.float64))
        return _atan2_deg(np.ascontiguousarray(y).ravel(), np.ascontiguousarray(x).ravel()).reshape(y.shape)
    x = np.atleast_1d(np.asarray(args[0], dtype=np.float64))
    out = elementwise(_MATH[f], np.ascontiguousarray(x))
    return out if np.ndim(args[0]) else float(out[0])


def _to_float(value, env: Env):
    """``float(x)``: numbers stay, booleans become 0/1, strings are parsed (NaN when not a number)."""
    if not _is_string(value):
        return np.asarray(value, dtype=np.float64)
    names = list(env.plan.strings.ids)
    ids = np.atleast_1d(np.asarray(value))
    distinct, inverse = np.unique(ids, return_inverse=True)
    parsed = []
    for i in distinct:
        try:
            parsed.append(float(names[int(i)]))
        except ValueError:
            parsed.append(np.nan)
    out = np.array(parsed)[inverse.reshape(-1)]
    return out if np.ndim(value) else float(out[0])


@njit(cache=True, nogil=True)
def elementwise(code, x):
    """Elementwise function ``code`` (see ``_MATH``) of x : (n,) float64, degrees for trigonometry."""
    out = np.empty_like(x)
    rad = np.pi / 180.0
    for i in range(len(x)):
        v = x[i]
        if code == 0:
            out[i] = np.sin(v * rad)
        elif code == 1:
            out[i] = np.cos(v * rad)
        elif code == 2:
            out[i] = np.tan(v * rad)
        elif code == 3:
            out[i] = np.arcsin(v) / rad
        elif code == 4:
            out[i] = np.arccos(v) / rad
        elif code == 5:
            out[i] = np.arctan(v) / rad
        elif code == 6:
            out[i] = np.exp(v)
        elif code == 7:
            out[i] = np.log(v) if v > 0 else (-np.inf if v == 0 else np.nan)
        else:
            out[i] = np.sqrt(v) if v >= 0 else np.nan
    return out


@njit(cache=True, nogil=True)
def _atan2_deg(y, x):
    out = np.empty_like(y)
    for i in range(len(y)):
        out[i] = np.arctan2(y[i], x[i]) * 180.0 / np.pi
    return out
