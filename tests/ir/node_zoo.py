"""An instance of every IR node class, built from its field annotations, for tests that must cover them all.

The classes are found in ``grammarc.ir.nodes``, not listed, so a new node is covered when it is added.
Every expression a node holds directly is a sentinel of its own (a ``Name`` whose name starts with
``MARK``), and every body holds operations with a sentinel of their own (successors ``MARK(sentinel)``),
so a test can tell which ones a walk reached.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import operator
import types
from enum import Enum
from typing import Union, get_args, get_origin, get_type_hints

from grammarc.diagnostics import NO_SPAN, Span
from grammarc.ir import nodes as ir

#: Every dataclass of the module.
DATACLASSES = tuple(c for c in vars(ir).values() if isinstance(c, type) and dataclasses.is_dataclass(c)
                    and c.__module__ == ir.__name__)
EXPRESSIONS = tuple(c for c in DATACLASSES if c in get_args(ir.Expr))
OPERATIONS = tuple(c for c in DATACLASSES if c in get_args(ir.Op))
#: The nodes that are neither: the parts of operations and the top level.
STRUCTURE = (ir.Size, ir.Alternative, ir.Rule, ir.AttrDecl, ir.Objective, ir.Module)
NODE_CLASSES = EXPRESSIONS + OPERATIONS + STRUCTURE
#: Plain fields whose value decides what a node means to the type checker: a valid value each.
PLAIN = {(ir.Unary, "op"): "-", (ir.Binary, "op"): "+", (ir.Call, "func"): "max",
         (ir.ContextRef, "name"): "split.index", (ir.Occlusion, "kind"): "inside",
         (ir.Aggregate, "func"): "sum", (ir.Objective, "kind"): "goal"}


MARK = "§"


class Zoo:
    """Builds nodes, numbering the sentinels it puts in them."""

    def __init__(self) -> None:
        self.count = itertools.count()

    def sentinel(self) -> ir.Name:
        k = next(self.count)
        return ir.Name(f"{MARK}{k}", Span("g.cga", k + 1, 1, k + 1, 2))

    def node(self, cls: type):
        """An instance of ``cls``: every declared child filled, other fields valid or left at defaults."""
        hints = get_type_hints(cls)
        declared = dict(ir.children(cls))
        values = {}
        for f in dataclasses.fields(cls):
            if f.name in declared:
                values[f.name] = self.value(hints[f.name])
            elif (cls, f.name) in PLAIN:
                values[f.name] = PLAIN[cls, f.name]
            elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                values[f.name] = self.value(hints[f.name])
        return cls(**values)

    def value(self, hint):
        """A value of the annotated type: a sentinel for an expression, one operation for a body."""
        args = get_args(hint)
        if _same(hint, ir.Expr):
            return self.sentinel()
        if get_origin(hint) in (Union, types.UnionType) and type(None) in args:
            rest = tuple(a for a in args if a is not type(None))
            return self.value(rest[0] if len(rest) == 1 else functools.reduce(operator.or_, rest))
        if _same(hint, ir.Op):
            return ir.Symbol(MARK, (self.sentinel(),))
        if get_origin(hint) is tuple:
            if len(args) == 2 and args[1] is Ellipsis:
                return (self.value(args[0]), self.value(args[0]))
            return tuple(self.value(a) for a in args)
        if hint is ir.Size:
            return ir.Size(ir.SizeKind.ABSOLUTE, self.sentinel())
        if dataclasses.is_dataclass(hint):
            return self.node(hint)
        if isinstance(hint, type) and issubclass(hint, Enum):
            return next(iter(hint))
        return {str: "all", int: 0, bool: False, float: 0.0, Span: NO_SPAN}[hint]


def _same(hint, union) -> bool:
    return get_origin(hint) in (Union, types.UnionType) and set(get_args(hint)) == set(get_args(union))


def sentinels(value) -> list[ir.Name]:
    """The sentinels in a value, in field order, nested bodies included (the test's own walk)."""
    if isinstance(value, ir.Name) and value.name.startswith(MARK):
        return [value]
    if isinstance(value, tuple):
        return [s for v in value for s in sentinels(v)]
    if dataclasses.is_dataclass(value):
        return [s for f in dataclasses.fields(value) for s in sentinels(getattr(value, f.name))]
    return []
