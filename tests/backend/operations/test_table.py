"""backend/operations/table.py: every operation node registered once, with declarations that are checked."""

from __future__ import annotations

import typing
from dataclasses import replace

import numpy as np
import pytest
from conftest import make_lots

from grammarc.backend import execute
from grammarc.backend.operations import OPERATIONS
from grammarc.backend.operations.table import check_writes, operation
from grammarc.backend.shapes import Shapes
from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.ir import nodes as ir


def test_every_operation_node_has_one_function():
    """``[``, ``]`` and ``center`` act on the body's stack, which the runner holds; every other node is in
    the table (a node added without its function fails here)."""
    runner = {ir.Push, ir.Pop, ir.Center}
    assert set(OPERATIONS) == set(typing.get_args(ir.Op)) - runner


def test_a_registration_names_shape_columns_and_a_node_once():
    with pytest.raises(ValueError, match="orgin"):
        operation(ir.Translate, writes=("orgin",))
    with pytest.raises(ValueError, match="already"):
        operation(ir.Translate, writes=("origin",))(lambda ctx, shapes, op: shapes)


@pytest.mark.parametrize("node, body, column", [
    (ir.Translate, "t(1, 0, 0) A", "origin"),
    (ir.SetAttr, "set(h, 2) A", "dynamic"),
], ids=["translate", "set"])
def test_a_wrong_declaration_of_writes_is_caught(write, monkeypatch, node, body, column):
    """With the strict checks on, a column an operation changes without declaring it fails the derivation."""
    monkeypatch.setattr(execute, "STRICT", True)
    text = f'version "2022.0"\nattr h = 1\nLot --> {body}\nA --> primitiveCube()\n'
    grammar = compile_grammar(write("g.cga", text))
    derive(grammar, make_lots("square"), BuildOptions())
    monkeypatch.setitem(OPERATIONS, node, replace(OPERATIONS[node], writes=()))
    with pytest.raises(AssertionError, match=f"`{node.__name__}` changed the shape column `{column}`"):
        derive(grammar, make_lots("square"), BuildOptions())


def test_check_writes_compares_values_where_the_arrays_differ():
    n = 3
    shapes = Shapes(np.zeros((n, 3)), np.ones((n, 3)), np.zeros(n, np.int32), np.full(n, -1, np.int32),
                    np.zeros(n, np.int32), np.arange(n, dtype=np.uint64), np.zeros(n, np.int32),
                    dynamic=(np.full(n, np.nan),))
    node = ir.Translate((ir.Num(1.0),) * 3)
    check_writes(node, (), shapes, shapes.take(np.arange(n)))  # new arrays, the same values (NaN too)
    moved = shapes.with_scope(shapes.origin + 1, shapes.size, shapes.frame, shapes.geom)
    check_writes(node, ("origin",), shapes, moved)
    with pytest.raises(AssertionError, match="`origin`"):
        check_writes(node, ("size",), shapes, moved)
