"""ir/printer.py: IR as canonical text ($param, @attr, every binary parenthesized, one rule per line)."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from grammarc.diagnostics import NO_SPAN, Diagnostics, Span
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_body, print_expr, print_module, print_op, print_rule

N = ir.Num
ABS, REL = ir.SizeKind.ABSOLUTE, ir.SizeKind.RELATIVE


@pytest.mark.parametrize("expr, text", [
    (N(3.0), "3"),
    (N(0.5), "0.5"),
    (N(-2.0), "-2"),
    (N(1e-7), "1e-07"),
    (ir.Str("cube"), '"cube"'),
    (ir.Bool(True), "true"),
    (ir.Bool(False), "false"),
    (ir.Name("h"), "h"),
    (ir.Param(0, "h"), "$h"),
    (ir.AttrRef("height"), "@height"),
    (ir.ScopeRef("sx"), "Scope.sx"),
    (ir.Unary("-", ir.AttrRef("h")), "-@h"),
    (ir.Unary("!", ir.Binary("<", N(1.0), N(2.0))), "!(1 < 2)"),
    (ir.Binary("+", N(1.0), ir.Binary("*", N(2.0), N(3.0))), "(1 + (2 * 3))"),
    (ir.Binary("&&", ir.Bool(True), ir.Bool(False)), "(true && false)"),
    (ir.Call("rand", ()), "rand()"),
    (ir.Call("atan2", (N(1.0), ir.Param(1, "x"))), "atan2(1, $x)"),
])
def test_print_expr(expr, text):
    assert print_expr(expr) == text


@pytest.mark.parametrize("op, text", [
    (ir.Symbol("b", ()), "b"),
    (ir.Symbol("b", (N(1.0), ir.Str("x"))), 'b(1, "x")'),
    (ir.Empty(), "ε"),
    (ir.Push(), "["),
    (ir.Pop(), "]"),
    (ir.Translate((N(1.0), N(2.0), N(3.0))), "T(1, 2, 3)"),
    (ir.Rotate((N(0.0), N(90.0), N(0.0))), "R(0, 90, 0)"),
    (ir.Scale((ir.Size(REL, N(1.0)), ir.Size(ABS, ir.AttrRef("h")), ir.Size(REL, N(0.5)))),
     "S(1r, @h, 0.5r)"),
    (ir.Insert("win.obj"), 'I("win.obj")'),
    (ir.Split((1,), (ir.Size(ABS, N(3.5)), ir.Size(REL, N(1.0))), ((ir.Symbol("a", ()),), ())),
     'Subdiv("Y", 3.5, 1r){ a | ε }'),
    (ir.Split((0, 2), (ir.Size(ABS, N(1.0)),), ((ir.Symbol("a", ()), ir.Symbol("b", ())),)),
     'Subdiv("XZ", 1){ a b }'),
    (ir.Repeat((0, 1), (N(1.0), N(2.0)), ((ir.Symbol("a", ()),),)), 'Repeat("XY", 1, 2){ a }'),
    (ir.Comp("sidefaces", None, ((ir.Symbol("f", ()),), (ir.Symbol("g", ()),))),
     'Comp("sidefaces"){ f | g }'),
    (ir.Comp("edge", N(3.0), ((ir.Symbol("A", ()),),)), 'Comp("edge", 3){ A }'),
])
def test_print_op(op, text):
    assert print_op(op) == text


def test_print_body_and_empty_body():
    assert print_body((ir.Push(), ir.Symbol("a", ()), ir.Pop())) == "[ a ]"
    assert print_body(()) == ""


def test_print_rule():
    rule = ir.Rule(
        symbol="a", params=("h", "w"), guard=ir.Binary(">", ir.Param(0, "h"), N(9.0)),
        alternatives=(ir.Alternative((ir.Symbol("b", ()),), N(0.5)), ir.Alternative((), N(0.5))),
        priority=0, label="1",
    )
    assert print_rule(rule) == "a(h, w) : ($h > 9) ~> b : 0.5 ~> ε : 0.5"
    bare = ir.Rule("a", (), None, (ir.Alternative((ir.Symbol("b", ()),), None),), 0)
    assert print_rule(bare) == "a ~> b"


def test_print_module_groups_priorities():
    def rule(symbol, priority):
        return ir.Rule(symbol, (), None, (ir.Alternative((), None),), priority)

    rules = (rule("a", 0), rule("b", 0), rule("c", 2), rule("d", 0))
    module = ir.Module("g", (ir.AttrDecl("h", N(3.0)),), rules, "a")
    assert print_module(module).splitlines() == [
        "attr h = 3", "PRIORITY 0:", "a ~> ε", "b ~> ε", "PRIORITY 2:", "c ~> ε", "PRIORITY 0:", "d ~> ε"]
    assert print_module(ir.Module("g", (), (), None)) == ""


def test_print_rejects_non_nodes():
    with pytest.raises(TypeError):
        print_expr(ir.Empty())
    with pytest.raises(TypeError):
        print_op(N(1.0))
    with pytest.raises(TypeError):
        print_op("T(1, 2, 3)")


@dataclass(frozen=True, slots=True)
class MirrorScope:
    """An operation the printer has no format for: it prints from its declared children."""

    axes: tuple[ir.Expr, ...] = ir.child(ir.Type.BOOL, "a mirror flag")
    span: Span = NO_SPAN


@dataclass(frozen=True, slots=True)
class Shatter:
    cga_name = "shatterInto"  # not its class name in lower camel case

    sizes: tuple[ir.Size, ...] = ir.child(ir.Type.NUM, "a size")
    mode: str = ir.child()  # a plain argument, declared so that it prints
    by_volume: bool = ir.child()
    seed: ir.Expr | None = ir.child(ir.Type.NUM, "a seed")
    parts: tuple[ir.Body, ...] = ir.child(holds=ir.Holds.BODIES)
    span: Span = NO_SPAN
    site: int = 0  # not a child: not printed


def test_an_operation_without_a_format_prints_from_its_declared_children():
    flags = (ir.Bool(True), ir.Bool(False), ir.AttrRef("flip"))
    assert print_op(MirrorScope(flags)) == "mirrorScope(true, false, @flip)"
    shatter = Shatter((ir.Size(REL, N(1.0)), ir.Size(ABS, N(2.5))), "cells", True, None,
                      ((MirrorScope(flags[:1]), ir.Symbol("a", ())), ()), site=7)
    assert print_op(shatter) == 'shatterInto(1r, 2.5, cells, true){ mirrorScope(true) a | ε }'
    assert print_body((ir.Push(), shatter, ir.Pop())) == f"[ {print_op(shatter)} ]"


def test_branches_and_a_body_without_a_format_print_in_braces():
    @dataclass(frozen=True, slots=True)
    class Pick:
        branches: tuple[tuple[ir.Expr, ir.Body], ...] = ir.child(ir.Type.BOOL, "a condition",
                                                                holds=ir.Holds.BRANCHES)
        default: ir.Body = ir.child(holds=ir.Holds.BODY)
        span: Span = NO_SPAN

    pick = Pick(((ir.Bool(True), (ir.Symbol("a", ()),)), (ir.AttrRef("b"), ())), (ir.Symbol("c", ()),))
    assert print_op(pick) == "pick(){ true: a | @b: ε | c }"


@pytest.mark.parametrize("text", [
    '1: A ; [ T(0,0,6) S(8,10,18) I("cube") ] T(6,0,0) S(7,13,18) I("cube")',
    'fac ~> Subdiv("Y",3.5,0.3,1r){ floor | ledge | Subdiv("X", 1r, 2){ a | ε } }',
    ('a : Scope.sx > 2 && !(Scope.sy < 1) ~> Repeat("XY", 1, 2){ b | c } : 0.25 '
     '~> Comp("edge", 2){ d } : 0.75\nb ~> d\nc ~> d'),
    "a ~> Rx(10) b(1 + Scope.sz * rand(0.3, 0.5), 2) : 0.5 ~> ε : 0.5",
])
def test_printed_rules_without_names_parse_back_to_themselves(text):
    def printed(source):
        diags = Diagnostics()
        module = run_passes(parse_source(source, "g", diags), diags, check=True)
        assert not diags.has_errors
        return print_rule(module.rules[0])

    once = printed(text)
    assert printed(once) == once
