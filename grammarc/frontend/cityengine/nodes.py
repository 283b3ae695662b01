"""The intermediate nodes of CityEngine CGA lowering: declarations, split parts and pending operations
that ``lowering`` builds statement by statement and ``assembly`` puts together.
"""

from __future__ import annotations

from dataclasses import dataclass

from grammarc.diagnostics import Span
from grammarc.ir import nodes as ir


@dataclass(frozen=True, slots=True)
class Annotated:
    annotations: tuple[tuple[str, tuple[str, ...]], ...]
    declaration: object


@dataclass(frozen=True, slots=True)
class RuleDef:
    name: str
    params: tuple[str, ...]
    body: ir.Body
    span: Span
    site: int


@dataclass(frozen=True, slots=True)
class FunctionDef:
    name: str
    params: tuple[str, ...]
    value: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class PendingOffset:
    """``offset(d)`` before the ``comp(f)`` that takes its inside and border faces."""

    distance: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class EdgeDistances:
    """``comp(fe){ sel: d | ... }`` as ``setback``'s argument: a distance per edge selector."""

    values: tuple[tuple[str, ir.Expr], ...]
    span: Span


@dataclass(frozen=True, slots=True)
class EdgeTable:
    """``const name = comp(fe){ sel: d | ... }``: distances per edge selector that a ``setback(name)``
    takes (``assembly.edge_tables``)."""

    name: str
    distances: EdgeDistances


@dataclass(frozen=True, slots=True)
class Import:
    """``import prefix : "file.cga" (...)`` (or without a prefix): the file's rules, attributes, constants
    and functions, named ``prefix.Name``; an attribute the importing file declares too takes the importing file's value
    (forwarding) unless the parentheses protect it: ``(a, b)`` protects ``a`` and ``b``, ``()`` every
    attribute. ``(a = value)`` sets the imported ``a`` to a value of the importing file's scope, and
    ``(Ext --> ...)`` redefines the imported rule ``Ext`` (an extension) as ``prefix.Ext --> ...`` in the
    importing file would."""

    prefix: str | None
    path: str
    span: Span
    protected: tuple[str, ...] = ()
    protect_all: bool = False
    values: tuple[ir.AttrDecl, ...] = ()
    extensions: tuple[RuleDef, ...] = ()


@dataclass(frozen=True, slots=True)
class Style:
    """``style Name``: the attributes after it redefine the defaults for that style."""

    name: str
    span: Span


@dataclass(frozen=True, slots=True)
class Sized:
    """A split part's size or an argument with its kind (absolute, ``'`` relative, ``~`` floating)."""

    kind: ir.SizeKind
    value: ir.Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Part:
    size: Sized
    body: ir.Body
    merged: bool
    span: Span


@dataclass(frozen=True, slots=True)
class Group:
    parts: tuple
    span: Span


def as_body(value) -> ir.Body:
    return value if isinstance(value, tuple) else (value,)
