"""The environment of an expression: what a built-in function or an operator may read of a batch."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from grammarc.backend.chunk import Chunk
from grammarc.backend.shapes import Shapes

if TYPE_CHECKING:
    from grammarc.backend.plan import Plan


@dataclass(frozen=True, eq=False)
class Env:
    """What an expression can read: the shapes (scope, params, keys, set attributes), their chunk (lot
    attributes, geometry) and the plan (interned strings, which attributes are set per shape)."""

    shapes: Shapes
    chunk: Chunk
    plan: Plan

    @property
    def strings(self) -> dict[str, int]:
        return self.plan.strings.ids
