"""ir/traverse.py: one walk of every node, driven by the children the nodes declare.

Every expression, operation and structural class of ``ir`` is built with a sentinel in each expression
it holds and in its nested bodies (``node_zoo``), and every walk must reach each sentinel.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import pytest
from node_zoo import EXPRESSIONS, MARK, NODE_CLASSES, OPERATIONS, Zoo, sentinels

from grammarc.diagnostics import NO_SPAN, Span
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import (
    all_exprs,
    iter_exprs,
    iter_nodes,
    iter_ops,
    op_exprs,
    rewrite_body,
    rewrite_expr,
    rewrite_module,
    rewrite_node,
    rewrite_ops,
    rewrite_rule,
    sub_bodies,
)

N = ir.Num


def _renamed(expr: ir.Expr) -> ir.Expr:
    """A sentinel renamed, anything else as it is."""
    return replace(expr, name=expr.name + "'") if isinstance(expr, ir.Name) and expr.name[0] == MARK else expr


def _names(exprs) -> list[str]:
    return sorted(e.name for e in sentinels(exprs))


@pytest.mark.parametrize("cls", NODE_CLASSES, ids=lambda c: c.__name__)
def test_every_walk_reaches_every_sentinel(cls):
    node = Zoo().node(cls)
    every = sentinels(node)
    assert bool(every) == bool(ir.children(cls)), "the zoo fills every child"
    assert _names(tuple(all_exprs(node))) == _names(tuple(every))  # each once
    rewrite = rewrite_expr if cls in EXPRESSIONS else rewrite_node
    renamed = rewrite(node, _renamed)
    assert _names(renamed) == sorted(s.name + "'" for s in every)
    assert (renamed is node) == (not every)
    assert rewrite(node, lambda e: e) is node  # nothing changed: the same object


@pytest.mark.parametrize("cls", EXPRESSIONS, ids=lambda c: c.__name__)
def test_iter_exprs_gives_an_expression_and_its_children(cls):
    expr = Zoo().node(cls)
    assert list(iter_exprs(expr)) == [expr, *sentinels(expr)]


@pytest.mark.parametrize("cls", OPERATIONS, ids=lambda c: c.__name__)
def test_an_operation_holds_its_own_expressions_and_nests_bodies(cls):
    op = Zoo().node(cls)
    bodies = sub_bodies(op)
    nested = [s for body in bodies for s in sentinels(body)]
    assert list(op_exprs(op)) == [s for s in sentinels(op) if all(s is not n for n in nested)]
    assert list(iter_ops((op,))) == [op, *(inner for body in bodies for inner in body)]
    assert all(inner.name == MARK for body in bodies for inner in body)
    assert len(bodies) == sum({ir.Holds.BODY: 1, ir.Holds.BODIES: 2, ir.Holds.BRANCHES: 2}.get(spec.holds, 0)
                              for _, spec in ir.children(cls))


@pytest.mark.parametrize("cls", OPERATIONS, ids=lambda c: c.__name__)
def test_rewrite_ops_reaches_every_nested_operation(cls):
    op = Zoo().node(cls)
    emptied = rewrite_ops((op,), lambda o: ir.Empty(o.span) if getattr(o, "name", None) == MARK else o)
    assert [type(o) for o in iter_ops(emptied)] == [cls, *(ir.Empty for body in sub_bodies(op) for _ in body)]
    assert rewrite_ops((op,), lambda o: o)[0] is op


def test_empty_bodies_are_bodies():
    case = ir.Case(((ir.Bool(True), ()),), ())
    assert sub_bodies(case) == ((), ())
    assert sub_bodies(ir.Split((0,), (), ())) == ()


def test_the_rewrite_is_bottom_up_and_keeps_what_did_not_change():
    kept = ir.Binary("*", ir.Param(0, "x"), N(2.0))
    expr = ir.Binary("+", kept, ir.Unary("-", N(1.0)))
    seen = []

    def fold(e):
        seen.append(type(e).__name__)
        return N(-1.0) if isinstance(e, ir.Unary) else e

    new = rewrite_expr(expr, fold)
    assert seen == ["Param", "Num", "Binary", "Num", "Unary", "Binary"]
    assert new.left is kept and new.right == N(-1.0)


def test_the_named_rewrites_are_the_one_rewrite():
    zoo = Zoo()
    rule, module, body = zoo.node(ir.Rule), zoo.node(ir.Module), (zoo.node(ir.Split),)
    assert sentinels(rewrite_rule(rule, _renamed)) == [_renamed(s) for s in sentinels(rule)]
    assert sentinels(rewrite_module(module, _renamed)) == [_renamed(s) for s in sentinels(module)]
    assert sentinels(rewrite_body(body, _renamed)) == [_renamed(s) for s in sentinels(body)]


def test_a_nodes_own_expressions_come_before_those_below_it():
    module = Zoo().node(ir.Module)
    attrs, rules = module.attrs, module.rules
    alt = rules[0].alternatives[0]
    # attributes first; a rule's guard, then per alternative its probability, then its body
    assert list(all_exprs(module))[:6] == [attrs[0].default, attrs[1].default, rules[0].guard, alt.prob,
                                           alt.body[0].args[0], alt.body[1].args[0]]
    assert [type(n) for n in iter_nodes(rules[0])] == [ir.Rule, *[ir.Alternative, ir.Symbol, ir.Symbol] * 2]
    assert list(iter_ops(module)) == [op for r in rules for a in r.alternatives for op in a.body]
    case = Zoo().node(ir.Case)
    (c1, b1), (c2, b2) = case.branches
    assert list(all_exprs(case)) == [c1, c2, *(op.args[0] for op in (*b1, *b2, *case.default))]


def test_a_new_node_is_walked_from_its_declarations_alone():
    @dataclass(frozen=True, slots=True)
    class Twist:
        angle: ir.Expr = ir.child(ir.Type.NUM, "an angle")
        parts: tuple = ir.child(holds=ir.Holds.BODIES)
        span: Span = NO_SPAN

    a, h = ir.Name(MARK + "a"), ir.Name(MARK + "h")
    twist = Twist(a, ((ir.Extrude(h),), ()))
    assert list(op_exprs(twist)) == [a]
    assert sub_bodies(twist) == twist.parts
    assert list(all_exprs((twist,))) == [a, h]
    assert rewrite_node(twist, _renamed) == Twist(_renamed(a), ((ir.Extrude(_renamed(h)),), ()))
