"""ir/nodes.py: every node declares its children, and the declarations agree with the fields' types.

The walkers (``traverse``, ``passes.types``, ``printer``) see only the declared children: a field that
holds IR but is not declared would be skipped by all of them without a word.
"""

from __future__ import annotations

import dataclasses
import types
from typing import Union, get_args, get_origin, get_type_hints

import pytest
from node_zoo import DATACLASSES, EXPRESSIONS, NODE_CLASSES, OPERATIONS, STRUCTURE, Zoo

from grammarc.ir import nodes as ir

#: Classes of IR whose fields hold IR.
_IR = {*get_args(ir.Expr), *get_args(ir.Op), ir.Size, ir.Alternative, ir.Rule, ir.AttrDecl, ir.Objective}


def _holds(hint) -> ir.Holds | None:
    """What an annotated field holds, from its type alone; None: no IR."""
    args = [a for a in get_args(hint) if a is not type(None)]
    if get_origin(hint) in (Union, types.UnionType):
        if set(args) <= _IR:
            return ir.Holds.EXPRS if set(args) <= {*get_args(ir.Expr)} else None
        return _holds(args[0]) if len(args) == 1 else None
    if get_origin(hint) is tuple:
        if hint == ir.Body:
            return ir.Holds.BODY
        inner = [_holds(a) for a in args if a is not Ellipsis]
        if args[-1] is Ellipsis and inner == [ir.Holds.BODY]:
            return ir.Holds.BODIES
        if args[-1] is Ellipsis and get_args(args[0])[-1:] == (ir.Body,):
            return ir.Holds.BRANCHES
        if args[-1] is Ellipsis and args[0] in (ir.Alternative, ir.Rule, ir.AttrDecl, ir.Objective):
            return ir.Holds.NODES
        return ir.Holds.EXPRS if ir.Holds.EXPRS in inner else None
    return ir.Holds.EXPRS if hint is ir.Size else None


def test_every_class_is_an_expression_an_operation_or_the_structure_around_them():
    records = {ir.Child, ir.RuleGraph}
    assert set(DATACLASSES) == {*EXPRESSIONS, *OPERATIONS, *STRUCTURE, *records}
    assert not set(EXPRESSIONS) & set(OPERATIONS)


@pytest.mark.parametrize("cls", NODE_CLASSES, ids=lambda c: c.__name__)
def test_every_field_that_holds_ir_is_declared_with_what_it_holds(cls):
    hints = get_type_hints(cls)
    declared = dict(ir.children(cls))
    holding = {f.name: _holds(hints[f.name]) for f in dataclasses.fields(cls)}
    assert {name: spec.holds for name, spec in declared.items()} == {k: v for k, v in holding.items() if v}


@pytest.mark.parametrize("cls", NODE_CLASSES, ids=lambda c: c.__name__)
def test_a_checked_child_is_named_for_its_type_errors(cls):
    node = Zoo().node(cls)
    for name, spec in ir.children(cls):
        want, what = spec.want_of(node), spec.what_of(node)
        assert want is None or isinstance(want, ir.Type), name
        if spec.want is not None and want is not None:
            assert what and all(isinstance(w, str) and w for w in (what if isinstance(what, tuple) else [what]))
        if spec.holds not in (ir.Holds.EXPRS, ir.Holds.BRANCHES):
            assert spec.want is None, f"{name} holds no expression of its own to check"


def test_children_are_read_once_per_class():
    assert ir.children(ir.Split) is ir.children(ir.Split)
    assert [name for name, _ in ir.children(ir.Split)] == ["sizes", "parts"]
    assert ir.children(ir.Num) == ()
