"""Numeric functions and random draws. Angles of trigonometric functions are degrees, as in CGA.

Transcendental functions run in a numba loop rather than numpy's SIMD kernels, so a value never depends on
its position in the batch.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from grammarc.backend.functions.table import function
from grammarc.backend.streams import draw

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: Codes of the functions computed by ``elementwise``.
_MATH = {"sin": 0, "cos": 1, "tan": 2, "asin": 3, "acos": 4, "atan": 5, "exp": 6, "log": 7, "sqrt": 8}


@function("rand")
def rand(call, args, env: Env):
    u = draw(env.plan.sequential_random, env.shapes.key, call.site)
    if not args:
        return u
    low, high = (0.0, args[0]) if len(args) == 1 else args
    return low + (np.subtract(high, low)) * u


@function("p")
def probability(call, args, env: Env):
    return draw(env.plan.sequential_random, env.shapes.key, call.site) < np.asarray(args[0], dtype=np.float64)


@function("isnan", "isinf")
def is_special(call, args, env: Env):
    return (np.isnan if call.func == "isnan" else np.isinf)(np.asarray(args[0], dtype=np.float64))


@function("log10")
def log10(call, args, env: Env):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log10(np.asarray(args[0], dtype=np.float64))


@function("print")
def value_of(call, args, env: Env):
    return args[0]


@function("floor", "ceil", "abs")
def rounding(call, args, env: Env):
    return getattr(np, call.func)(args[0])


@function("round")
def round_half_away(call, args, env: Env):
    x = np.asarray(args[0], dtype=np.float64)
    return np.copysign(np.floor(np.abs(x) + 0.5), x)


@function("min", "max")
def extreme(call, args, env: Env):
    return (np.minimum if call.func == "min" else np.maximum)(args[0], args[1])


@function("pow")
def power(call, args, env: Env):
    with np.errstate(invalid="ignore", over="ignore"):
        return np.power(np.asarray(args[0], dtype=np.float64), args[1])


@function("atan2")
def atan2(call, args, env: Env):
    y, x = np.broadcast_arrays(np.asarray(args[0], np.float64), np.asarray(args[1], np.float64))
    return _atan2_deg(np.ascontiguousarray(y).ravel(), np.ascontiguousarray(x).ravel()).reshape(y.shape)


@function(*_MATH)
def transcendental(call, args, env: Env):
    x = np.atleast_1d(np.asarray(args[0], dtype=np.float64))
    out = elementwise(_MATH[call.func], np.ascontiguousarray(x))
    return out if np.ndim(args[0]) else float(out[0])


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
