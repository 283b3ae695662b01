"""``direct``: the lowering of an operation whose arguments are its IR node's fields, which the dialects'
tables of operations name (``cga2006/operations.py``, ``cityengine/operations.py``).

A module of its own, not ``lowering``'s, which imports lark: CityEngine's table of operations is built
wherever a file is assembled (``cityengine.assembly`` checks the file's calls against it), also one whose
statements the lowered cache kept, which needs no lark.
"""

from __future__ import annotations

import dataclasses
import typing
from typing import TYPE_CHECKING

from grammarc.diagnostics import Span
from grammarc.ir import nodes as ir

if TYPE_CHECKING:
    from grammarc.frontend.lowering import LoweringBase


def direct(node: type):
    """The lowering of an operation whose arguments are ``node``'s fields in order, each a plain
    expression: a line ``"report": direct(ir.Report)`` in a dialect's ``OPERATIONS``.

    The fields before ``span`` say how many arguments the operation takes: an ``Expr`` field one, a
    ``tuple[Expr, Expr, Expr]`` field three (``ir.Translate``). A call with another count is an ``arity``
    error and lowers to ``ir.Empty``. A ``site`` field gets the next random-stream site, drawn after the
    arguments' own as everywhere in lowering. A node with any other field before ``span`` needs a handler
    of its own: ``TypeError`` here.
    """
    names = [f.name for f in dataclasses.fields(node)]
    hints = typing.get_type_hints(node)
    widths = []  # per field before span: None for one expression, n for a tuple of n
    for name in names[:names.index("span")]:
        hint = hints[name]
        if hint == ir.Expr:
            widths.append(None)
        elif typing.get_origin(hint) is tuple and all(a == ir.Expr for a in typing.get_args(hint)):
            widths.append(len(typing.get_args(hint)))
        else:
            raise TypeError(f"`{node.__name__}.{name}` is not an expression: lower {node.__name__} "
                            "with a handler of its own")
    count = sum(1 if w is None else w for w in widths)
    random = "site" in names

    def lower(lowering: LoweringBase, op: str, args: tuple, span: Span):
        if not lowering.arity(op, args, (count,), span):
            return ir.Empty(span)
        values = iter([lowering.expr(a) for a in args])
        fields = [next(values) if w is None else tuple(next(values) for _ in range(w)) for w in widths]
        if random:
            return node(*fields, span, site=lowering.site())
        return node(*fields, span)

    lower.__qualname__ = lower.__name__ = f"direct({node.__name__})"
    return lower
