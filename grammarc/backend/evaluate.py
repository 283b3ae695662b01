"""Expressions evaluated on a whole batch of shapes at once.

``evaluate`` returns a numpy array with one value per shape, or a Python scalar when the value is the same
for every shape (constants); callers broadcast. Numbers are float64, booleans bool, strings int32 ids of
``Plan.strings``. Angles of trigonometric functions are degrees, as in CGA. Transcendental functions run in
a numba loop rather than numpy's SIMD kernels, so a value never depends on its position in the batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from grammarc.backend.chunk import Chunk
from grammarc.backend.random import uniform
from grammarc.backend.shapes import Shapes
from grammarc.ir import nodes as ir


@dataclass(frozen=True, eq=False)
class Env:
    """What an expression can read: the shapes (scope, params, keys) and their chunk (attributes)."""

    shapes: Shapes
    chunk: Chunk
    strings: dict[str, int]


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
        column = env.chunk.attrs[expr.name]
        return column[env.shapes.lot]
    if isinstance(expr, ir.ScopeRef):
        return _scope_field(expr.field, env)
    if isinstance(expr, ir.Unary):
        value = evaluate(expr.operand, env)
        return np.logical_not(value) if expr.op == "!" else np.negative(value)
    if isinstance(expr, ir.Binary):
        left, right = evaluate(expr.left, env), evaluate(expr.right, env)
        if expr.op == "&&":
            return np.logical_and(left, right)
        if expr.op == "||":
            return np.logical_or(left, right)
        if expr.op in _COMPARE:
            return _COMPARE[expr.op](left, right)
        with np.errstate(divide="ignore", invalid="ignore"):
            return _ARITH[expr.op](np.asarray(left, dtype=np.float64), right)
    if isinstance(expr, ir.Call):
        return _call(expr, env)
    raise TypeError(f"cannot evaluate {expr!r}")


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
    # Translation relative to the lot's own scope, along the lot's axes (CityEngine's object coordinates).
    lot = shapes.lot
    offset = shapes.origin - env.chunk.lot_origin[lot]
    return np.einsum("nj,nj->n", offset, env.chunk.lot_axes[lot, axis])


def _call(expr: ir.Call, env: Env):
    args = [evaluate(a, env) for a in expr.args]
    f = expr.func
    if f == "rand":
        u = uniform(env.shapes.key, expr.site)
        if not args:
            return u
        low, high = (0.0, args[0]) if len(args) == 1 else args
        return low + (np.subtract(high, low)) * u
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


@njit(cache=True)
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


@njit(cache=True)
def _atan2_deg(y, x):
    out = np.empty_like(y)
    for i in range(len(y)):
        out[i] = np.arctan2(y[i], x[i]) * 180.0 / np.pi
    return out
