"""CityEngine's array functions (``ir.functions.ARRAY_FUNCTIONS``) on ``backend.arrays.Arrays``."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend import arrays
from grammarc.backend.arrays import Arrays
from grammarc.backend.functions.strings import concatenate, find, is_string, string_ranks, texts
from grammarc.backend.functions.table import FUNCTIONS, distinct, function
from grammarc.ir.functions import ARRAY_CONVERSIONS

if TYPE_CHECKING:
    from grammarc.backend.env import Env


@function("isNull")
def is_null(call, args, env: Env):
    if is_string(args[0]):
        null = env.plan.strings.ids.get("\ue000", -1)
        return np.equal(args[0], null)
    return np.isnan(np.asarray(args[0], dtype=np.float64))


@function("size")
def size(call, args, env: Env):
    return args[0].sizes.astype(np.float64)


@function("nRows")
def rows(call, args, env: Env):
    return args[0].rows.astype(np.float64)


@function("nColumns")
def columns(call, args, env: Env):
    return args[0].columns.astype(np.float64)


@function("transpose")
def transpose(call, args, env: Env):
    return arrays.transpose(args[0])


@function("sortIndices", "sortRowIndices")
def sort_indices(call, args, env: Env):
    array = args[0]
    ranks = string_ranks(env) if array.values.dtype == np.int32 else None
    return (arrays.sort_indices if call.func == "sortIndices" else arrays.sort_row_indices)(array, ranks)


@function("findFirst")
def find_first(call, args, env: Env):
    """The first index of a value in an array, or ce.lib's ``findFirst(text, match)``: ``find(text, match, 0)``."""
    if not isinstance(args[0], Arrays):
        known = texts(env)
        return distinct(lambda text, match: float(find(known[text], known[match], 0)), args[0], args[1])
    return arrays.find_first(*args)


@function("sum")
def total(call, args, env: Env):
    """The sum of a num[], the number of true elements of a bool[], the strings of a str[] concatenated."""
    array = args[0]
    if array.values.dtype != np.int32:
        sums = np.zeros(len(array), dtype=np.float64)
        np.add.at(sums, array.owner(), array.values.astype(np.float64))
        return sums
    # the k-th elements of all arrays appended at once, for k up to the longest array's size
    text = np.full(len(array), env.plan.strings.intern(""), dtype=np.int32)
    for k in range(int(array.sizes.max(initial=0))):
        longer = np.flatnonzero(array.sizes > k)
        text[longer] = concatenate(text[longer], array.values[array.offsets[longer] + k], env.plan.strings)
    return text


@function(*ARRAY_CONVERSIONS)
def convert_elements(call, args, env: Env):
    """``floatArray``, ``boolArray``, ``stringArray``: each element converted as ``float``, ``bool`` and
    ``str`` convert a value; without an argument, an empty array."""
    scalar = ARRAY_CONVERSIONS[call.func]
    dtype = {"float": np.float64, "bool": np.bool_, "str": np.int32}[scalar]
    if not args:
        n = len(env.shapes)
        return Arrays(np.zeros(0, dtype), np.zeros(n + 1, np.int64), np.zeros(n, np.int64))
    array = args[0]
    values = FUNCTIONS[scalar](call, [array.values], env) if len(array.values) else array.values
    return Arrays(np.asarray(values, dtype=dtype), array.offsets, array.columns)
