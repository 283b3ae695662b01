"""CityEngine's array functions (``ir.functions.ARRAY_FUNCTIONS``) on ``backend.arrays.Arrays``."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend import arrays
from grammarc.backend.functions.strings import is_string, string_ranks
from grammarc.backend.functions.table import function

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
    return arrays.find_first(*args)
