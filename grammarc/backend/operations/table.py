"""The table of operations: IR node type -> the function that runs it on a batch, and what it declares.

Each operation module registers its functions with ``@operation(ir.Node, ...)`` next to them, so adding an
operation touches its function only. The registration declares what the body runner needs to know without
running it:

- ``writes``: the shape columns (``shapes.COLUMNS``) a returned cursor may hold changed; with
  ``constants.STRICT`` on, the runner checks that every other column holds the values it held
  (``check_writes``);
- ``meshes``: whether it takes roofs (meshes); the runner fails the lots of roofs given to one that does not;
- ``consumes``: whether it replaces its shape (by successors, parts, an instance, or nothing): in CityEngine a
  body without one leaves its shape as a leaf.

An operation returns one of three things: the cursor with new columns (a scope or attribute change),
``Parts`` (shapes for the bodies of its parts, which the runner then runs), or None (it made successors or
records, or nothing).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from grammarc.backend.shapes import COLUMNS, Shapes
from grammarc.ir import nodes as ir

__all__ = ["OPERATIONS", "Operation", "Parts", "check_writes", "operation"]


@dataclass(frozen=True)
class Operation:
    """A registered operation: ``function(ctx, shapes, node)`` and its declarations (module docstring)."""

    function: Callable
    writes: tuple[str, ...]
    meshes: bool
    consumes: bool


#: IR operation node type -> its ``Operation``. ``[``, ``]`` and ``center`` are not here: they act on the
#: body's stack of scopes, which only the body runner holds (``backend.execute``).
OPERATIONS: dict[type, Operation] = {}


def operation(*types: type, writes: tuple[str, ...] = (), meshes: bool = False, consumes: bool = False):
    """Register the decorated function as the operation of the IR node ``types``."""
    unknown = set(writes) - set(COLUMNS)
    if unknown:
        raise ValueError(f"writes names no shape column: {sorted(unknown)} (columns: {', '.join(COLUMNS)})")

    def register(function: Callable) -> Callable:
        for node_type in types:
            if node_type in OPERATIONS:
                raise ValueError(f"`{node_type.__name__}` is already run by {OPERATIONS[node_type].function}")
            OPERATIONS[node_type] = Operation(function, tuple(writes), meshes, consumes)
        return function

    return register


@dataclass(frozen=True, eq=False)
class Parts:
    """Shapes an operation made for the bodies of its parts: body k runs on ``shapes`` rows
    ``offsets[k]:offsets[k + 1]`` (``offsets`` (len(bodies) + 1,) int64).

    ``leaves``, when given, has per body the ``LeafPart`` of a part that only places an asset
    (``backend.leaf_parts``), whose records the runner queues for its symbol when it reaches the part, or
    None for a body that runs.
    """

    bodies: tuple[ir.Body, ...]
    shapes: Shapes
    offsets: np.ndarray
    leaves: tuple = ()


def check_writes(node: ir.Op, writes: tuple[str, ...], before: Shapes, after: Shapes) -> None:
    """Assert that ``after``, the cursor ``node``'s operation returned for ``before``, holds the values of
    ``before`` in every column but ``writes``: the same array (cheap), or equal values (NaN equal to NaN)."""
    for name in COLUMNS:
        if name in writes:
            continue
        old, new = getattr(before, name), getattr(after, name)
        if old is new:
            continue
        if isinstance(old, tuple):
            same = len(old) == len(new) and all(a is b or _equal(a, b) for a, b in zip(old, new))
        else:
            same = _equal(old, new)
        assert same, (f"`{type(node).__name__}` changed the shape column `{name}`, which its operation does not "
                      f"declare (writes={writes}) at {node.span}")


def _equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
