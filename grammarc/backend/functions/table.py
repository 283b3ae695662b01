"""The table of built-in functions: name -> the function that computes it on a batch of shapes.

Each family module registers its functions with ``@function("name", ...)`` beside them. A function is
``f(call, args, env)``: its IR node (for its site and span), its arguments already evaluated (a numpy array
per shape, a Python scalar when the same for every shape, or ``Arrays``) and the expression environment
(``evaluate.Env``). It returns a value of the same kinds. Strings are interned ids (``Plan.strings``): a
string function computes once per distinct argument (``distinct``) and gathers, never once per shape.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["FUNCTIONS", "distinct", "function"]

#: Function name (as in ``ir.functions.FUNCTIONS``) -> its implementation.
FUNCTIONS: dict[str, Callable] = {}


def function(*names: str):
    """Register the decorated function as the implementation of the built-ins ``names``."""
    def register(implementation: Callable) -> Callable:
        for name in names:
            if name in FUNCTIONS:
                raise ValueError(f"`{name}` is already computed by {FUNCTIONS[name]}")
            FUNCTIONS[name] = implementation
        return implementation

    return register


def distinct(compute: Callable, *args, dtype=np.float64):
    """``compute(*values)`` once per distinct tuple of argument values, spread over the shapes.

    The arguments are scalars or arrays of one value per shape (numbers, flags or interned ids); the
    result is a scalar when they all are, else an array of ``dtype``. This is how a function that is not
    vectorized on its own (a text operation, a file lookup) runs on a batch.
    """
    if all(np.ndim(a) == 0 for a in args):
        return compute(*(a.item() if isinstance(a, np.generic) else a for a in args))
    columns = np.broadcast_arrays(*(np.asarray(a) for a in args))
    kinds = [c.dtype for c in columns]
    stacked = np.stack([c.astype(np.float64) for c in columns], axis=1)
    keys, inverse = np.unique(stacked, axis=0, return_inverse=True)
    results = np.array([compute(*(_typed(v, kind) for v, kind in zip(key, kinds))) for key in keys], dtype=dtype)
    return results[inverse.reshape(-1)]


def _typed(value: float, kind: np.dtype):
    """A value of a stacked key back in its own type: a flag as bool, an id as int, a number as float."""
    if kind == np.bool_:
        return bool(value)
    if np.issubdtype(kind, np.integer):
        return int(value)
    return float(value)
