"""String functions and CityEngine's conversions between strings, numbers and flags.

A string value is an interned id (``Plan.strings``): an ``int`` or an int32 array, where numbers are
float64 and flags bool (``is_string`` tells them apart). Text is made once per distinct argument
(``table.distinct``) and interned.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.table import distinct, function

if TYPE_CHECKING:
    from grammarc.backend.env import Env


def is_string(value) -> bool:
    """String values are interned ids: Python ints or int32 arrays (numbers are float, flags bool)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)) or (
        isinstance(value, np.ndarray) and value.dtype == np.int32)


def format_value(value, is_str: bool, names: list[str]) -> str:
    """A value as CityEngine prints it in strings: 3.0 -> "3", 2.5 -> "2.5", True -> "true"."""
    if is_str:
        return names[int(value)]
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)


def concatenate(left, right, strings) -> np.ndarray | int:
    """CityEngine's ``+`` on strings, per shape: once per distinct pair of operands, then spread."""
    names = list(strings.ids)
    left_str, right_str = is_string(left), is_string(right)
    return distinct(lambda a, b: strings.intern(format_value(a, left_str, names) + format_value(b, right_str, names)),
                    left, right, dtype=np.int32)


@function("str")
def to_string(call, args, env: Env):
    return concatenate(env.plan.strings.intern(""), args[0], env.plan.strings)


@function("float")
def to_float(call, args, env: Env):
    """``float(x)``: numbers stay, booleans become 0/1, strings are parsed (NaN when not a number)."""
    value = args[0]
    if not is_string(value):
        return np.asarray(value, dtype=np.float64)
    names = list(env.plan.strings.ids)

    def parse(i: int) -> float:
        try:
            return float(names[i])
        except ValueError:
            return np.nan
    return distinct(parse, value)


@function("bool")
def to_bool(call, args, env: Env):
    return np.asarray(args[0]) != 0


@function("len")
def length(call, args, env: Env):
    names = list(env.plan.strings.ids)
    return distinct(lambda i: float(len(names[i])), args[0])


def string_ranks(env: Env) -> np.ndarray:
    """(strings,) int64 the rank of each interned string's text in sorted order."""
    names = list(env.plan.strings.ids)
    ranks = np.empty(len(names), dtype=np.int64)
    ranks[np.argsort(np.array(names, dtype=object), kind="stable")] = np.arange(len(names))
    return ranks
