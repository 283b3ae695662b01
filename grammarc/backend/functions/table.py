"""The table of built-in functions: name -> the function that computes it on a batch of shapes.

Each family module registers its functions with ``@function("name", ...)`` beside them. A function is
``f(call, args, env)``: its IR node (for its site and span), its arguments already evaluated (a numpy array
per shape, a Python scalar when the same for every shape, or ``Arrays``) and the expression environment
(``evaluate.Env``). It returns a value of the same kinds. Strings are interned ids (``Plan.strings``): a
string function computes once per distinct argument (``distinct``) and gathers, never once per shape.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from grammarc.ragged import row_groups

__all__ = ["FUNCTIONS", "distinct", "function", "groups"]

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
    inverse, first = _tuples(columns)
    results = np.array([compute(*(c[row].item() for c in columns)) for row in first.tolist()], dtype=dtype)
    return results[inverse]


def groups(n: int, *args) -> Iterator[tuple[tuple, np.ndarray]]:
    """Each distinct tuple of argument values (as ``distinct`` takes them) among ``n`` shapes and the (k,)
    int64 shapes holding it, for a function that computes per group rather than per value."""
    if n == 0:
        return
    if all(np.ndim(a) == 0 for a in args):  # constants: one group
        yield tuple(a.item() if isinstance(a, np.generic) else a for a in args), np.arange(n)
        return
    columns = np.broadcast_arrays(*(np.asarray(a) for a in args))
    inverse, first = _tuples(columns)
    order = np.argsort(inverse, kind="stable")
    starts = np.searchsorted(inverse[order], np.arange(len(first)))
    keys = [tuple(c[row].item() for c in columns) for row in first.tolist()]
    yield from zip(keys, np.split(order, starts[1:]))


def _tuples(columns: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Each shape's tuple among the distinct ones (n,) int64 and a shape holding each (g,) int64, from one
    lexsort of the values' bits (equal bits, equal values: NaNs are one value)."""
    bits = np.stack([np.ascontiguousarray(c, dtype=np.float64).view(np.int64) for c in columns], axis=1)
    return row_groups(bits)
