"""The intermediate nodes of paper-notation lowering: the statements that ``lowering`` builds one at a time
and ``assembly`` puts together (a rule, the ``~> successor : prob`` lines that continue it, ``PRIORITY``
blocks), and the relative size argument that only some operations take.
"""

from __future__ import annotations

from dataclasses import dataclass

from grammarc.diagnostics import Span
from grammarc.ir import nodes as ir


@dataclass(frozen=True, slots=True)
class Relative:
    """A relative size argument (``1r``): only S and Subdiv accept it."""

    value: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class RuleStatement:
    label: str | None
    symbol: str
    params: tuple[str, ...]
    guard: ir.Expr | None
    alternatives: tuple[ir.Alternative, ...]
    span: Span
    site: int


@dataclass(frozen=True, slots=True)
class ContinuationStatement:
    """``~> successor : prob`` lines that add alternatives to the rule before them."""

    alternatives: tuple[ir.Alternative, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class PriorityStatement:
    value: int
    span: Span


Statement = RuleStatement | ContinuationStatement | PriorityStatement | ir.AttrDecl | ir.Objective
