"""Walk and rebuild IR, driven by the children every node declares (``nodes.child``).

No walker here knows a node type: each reads the node's declared child fields (``nodes.children``) and
what they hold (``nodes.Holds``), so a new node is walked as soon as its class declares its fields.

``rewrite_expr`` applies a function bottom-up and returns the same object when nothing changed, so a pass
can tell whether it did anything by identity; ``rewrite_op``, ``rewrite_body``, ``rewrite_rule`` and
``rewrite_module`` apply an expression rewrite to every expression of an operation, body, rule or module
(descending into nested bodies), ``rewrite_ops`` a rewrite of operations. ``iter_ops``, ``iter_nodes``,
``op_exprs``, ``iter_exprs`` and ``all_exprs`` visit without rebuilding (most of them return lists: the
passes ask them of every rule, some of them repeatedly, and a list is cheaper than a generator chain).

Order: a node's own expressions come before those of the nodes below it (``all_exprs``: a rule's guard,
then per alternative its probability and then its body's operations, each before its nested bodies);
a rewrite goes bottom-up, children in field order.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import get_args

from grammarc.ir import nodes as ir

Holds = ir.Holds
ExprFn = Callable[[ir.Expr], ir.Expr]
OpFn = Callable[[ir.Op], ir.Op]

#: The expression classes: in an argument field, these get the rewrite; other nodes there (``Size``) are
#: walked through as part of the node that holds them.
EXPRESSIONS = frozenset(get_args(ir.Expr))
_PLAIN = frozenset({str, int, float, bool, type(None)})


class _PerClass(dict):
    """Node class -> what a walk needs of its declared children (``make(nodes.children(cls))``), worked
    out on first use: every walk asks it of every node it visits."""

    def __init__(self, make: Callable) -> None:
        super().__init__()
        self.make = make

    def __missing__(self, cls: type):
        made = self[cls] = self.make(ir.children(cls))
        return made


# ------------------------------------------------------------------------------------------------ rewriting


def rewrite_expr(expr: ir.Expr, fn: ExprFn) -> ir.Expr:
    """Rebuild ``expr`` bottom-up with ``fn`` applied to every node (children first)."""
    fields = _EXPR_REWRITES[type(expr)]
    if fields:
        expr = _rebuilt(expr, fields, fn)
    return fn(expr)


def rewrite_node(node, fn: ExprFn):
    """``node`` (an operation, alternative, rule or module) with ``fn`` applied to each of its
    expressions, nested bodies included; the same object if nothing changed."""
    return _rebuilt(node, _EXPR_REWRITES[type(node)], fn)


#: The rewrites by what they take, under the names the callers know.
rewrite_op = rewrite_rule = rewrite_module = rewrite_node


def rewrite_body(body: ir.Body, fn: ExprFn) -> ir.Body:
    """``body`` with ``fn`` applied to every expression of its operations, nested bodies included."""
    return _tuple(body, lambda op: rewrite_node(op, fn))


def rewrite_ops(body: ir.Body, fn: OpFn) -> ir.Body:
    """``body`` with ``fn`` applied to every operation, those of nested bodies first; the same object if
    nothing changed. Expressions are left alone."""
    def op(node: ir.Op) -> ir.Op:
        return fn(_rebuilt(node, _OP_REWRITES[type(node)], fn))

    return _tuple(body, op)


def _rebuilt(node, fields: tuple, fn):
    """``node`` with each of ``fields``' rewrites applied to its field; the same object if none changed."""
    changes = None
    for name, rewrite in fields:
        old = getattr(node, name)
        new = rewrite(old, fn)
        if new is not old:
            if changes is None:
                changes = {}
            changes[name] = new
    return node if changes is None else replace(node, **changes)


def _rewrite_args(value, fn: ExprFn):
    """An argument field's value rebuilt: expressions rewritten, inside tuples and ``Size``s."""
    cls = type(value)
    if cls in EXPRESSIONS:
        return rewrite_expr(value, fn)
    if cls is tuple:
        return _tuple(value, lambda v: _rewrite_args(v, fn))
    if cls in _PLAIN:
        return value
    return rewrite_node(value, fn)


def _pair(pair: tuple, first, second) -> tuple:
    return pair if first is pair[0] and second is pair[1] else (first, second)


_EXPR_REWRITE = {
    Holds.EXPRS: _rewrite_args,
    Holds.BODY: rewrite_body,
    Holds.BODIES: lambda parts, fn: _tuple(parts, lambda b: rewrite_body(b, fn)),
    Holds.BRANCHES: lambda branches, fn: _tuple(branches, lambda br: _pair(
        br, rewrite_expr(br[0], fn), rewrite_body(br[1], fn))),
    Holds.NODES: lambda nodes, fn: _tuple(nodes, lambda n: rewrite_node(n, fn)),
}
#: ``rewrite_ops`` descends into bodies only.
_OP_REWRITE = {
    Holds.BODY: rewrite_ops,
    Holds.BODIES: lambda parts, fn: _tuple(parts, lambda b: rewrite_ops(b, fn)),
    Holds.BRANCHES: lambda branches, fn: _tuple(branches, lambda br: _pair(br, br[0], rewrite_ops(br[1], fn))),
}


def _rewrites(declared, table: dict) -> tuple:
    """(field name, rewrite) of each declared child field that ``table`` has a rewrite for."""
    return tuple((name, table[spec.holds]) for name, spec in declared if spec.holds in table)


#: Per node class: (field name, rewrite) of each child field.
_EXPR_REWRITES = _PerClass(lambda declared: _rewrites(declared, _EXPR_REWRITE))
_OP_REWRITES = _PerClass(lambda declared: _rewrites(declared, _OP_REWRITE))


def _tuple(items: tuple, fn) -> tuple:
    new = tuple(fn(i) for i in items)
    return items if all(a is b for a, b in zip(new, items)) else new


# ------------------------------------------------------------------------------------------------- visiting


def field_exprs(value, holds: ir.Holds) -> list[ir.Expr]:
    """The expressions a child field's ``value`` holds directly: an argument field's (inside tuples and
    ``Size``s), the conditions of branches; none of a body's."""
    found: list[ir.Expr] = []
    if holds is Holds.EXPRS or holds is Holds.BRANCHES:
        _collect(value, holds, found)
    return found


def expr_fields(cls: type) -> tuple[tuple[str, ir.Child], ...]:
    """The declared child fields of a node class that hold expressions of the node's own (arguments,
    branch conditions), as (field name, declaration)."""
    return _EXPR_FIELDS[cls]


def op_exprs(node) -> list[ir.Expr]:
    """The expressions directly held by ``node`` (an operation, or an alternative's probability, a rule's
    guard, an attribute's default, an expression's operands), not those of its nested bodies or nodes."""
    found: list[ir.Expr] = []
    for name, spec in _EXPR_FIELDS[type(node)]:
        _collect(getattr(node, name), spec.holds, found)
    return found


def iter_exprs(expr: ir.Expr) -> Iterator[ir.Expr]:
    """``expr`` and all its sub-expressions, parents first."""
    yield expr
    for sub in op_exprs(expr):
        yield from iter_exprs(sub)


def sub_bodies(op) -> tuple[ir.Body, ...]:
    """The bodies nested in ``op`` (split parts, case and stochastic branches) in field order, empty
    ones too."""
    return tuple(body for name, bodies in _BODY_FIELDS[type(op)] for body in bodies(getattr(op, name)))


def iter_nodes(node) -> list:
    """``node`` (a module, rule, alternative, operation, or a body: a tuple of operations) and every node
    below it but expressions, parents first: rules, alternatives, attribute declarations, operations."""
    found: list = []
    _nodes(node, found, True)
    return found


def iter_ops(node) -> list[ir.Op]:
    """Every operation of a body, or under a module, rule, alternative or operation, nested bodies
    included, in source order."""
    found: list[ir.Op] = []
    _nodes(node, found, False)
    return found


def _nodes(node, found: list, every: bool) -> None:
    """Append ``node`` (a body: its operations) and the nodes below it, parents first; only operations
    unless ``every``. Lists, not generators: the passes ask this of every rule, some of them repeatedly."""
    if type(node) is tuple:
        for op in node:
            found.append(op)
            for name, below in _BELOW_FIELDS[type(op)]:
                for item in below(getattr(op, name)):
                    _nodes(item, found, every)
        return
    if every:
        found.append(node)
    for name, below in _BELOW_FIELDS[type(node)]:
        for item in below(getattr(node, name)):
            _nodes(item, found, every)


def all_exprs(node) -> Iterator[ir.Expr]:
    """Every expression and sub-expression under ``node`` (a module, rule, alternative, operation or
    body): a node's own before those of the nodes below it."""
    for below in iter_nodes(node):
        for expr in op_exprs(below):
            yield from iter_exprs(expr)


def _collect(value, holds: ir.Holds, found: list) -> None:
    """Append the expressions of a field that holds expressions."""
    if holds is Holds.BRANCHES:
        found.extend(cond for cond, _ in value)
        return
    cls = type(value)
    if cls in EXPRESSIONS:
        found.append(value)
    elif cls is tuple:
        for v in value:
            _collect(v, holds, found)
    elif cls not in _PLAIN:  # a Size: its expression is the operation's
        for name, spec in _EXPR_FIELDS[cls]:
            _collect(getattr(value, name), spec.holds, found)


#: The bodies of a field by what it holds.
_BODIES = {
    Holds.BODY: lambda body: (body,),
    Holds.BODIES: lambda parts: parts,
    Holds.BRANCHES: lambda branches: tuple(body for _, body in branches),
}
#: Per node class: the child fields that hold expressions, those that hold bodies, and those below it.
_EXPR_FIELDS = _PerClass(lambda declared: tuple(
    (name, spec) for name, spec in declared if spec.holds in (Holds.EXPRS, Holds.BRANCHES)))
_BODY_FIELDS = _PerClass(lambda declared: tuple(
    (name, _BODIES[spec.holds]) for name, spec in declared if spec.holds in _BODIES))
_BELOW_FIELDS = _PerClass(lambda declared: tuple(
    (name, _BODIES.get(spec.holds, lambda nodes: nodes)) for name, spec in declared
    if spec.holds in _BODIES or spec.holds is Holds.NODES))
