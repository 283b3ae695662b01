"""What a region's kernel is written around: the sites where it emits records (``Emit``) or hands shapes off
(``Handoff``), the ``Block`` of each symbol it derives (when the runner emits their records), and the
``Scope``, the names of the variables that hold a shape in its code (``codegen``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple


@dataclass(frozen=True)
class Emit:
    """Records of ``asset`` made at emission ``site`` by ``symbol``: the instances of an ``I`` or of the
    asset an ``i`` made a leaf's geometry (the symbol whose rule it is in), or a leaf's cubes or quads (the
    leaf's symbol: ``leaf``, as ``terminals.emit_leaves`` emits them, textured; a cube cut at its trim
    planes where its geometry was ``inserted`` by an ``i`` in the region, else where its root's was). The
    per-shape columns (``Plan.dynamic`` slots) ``written`` are the region's (``Scope.written``), the others
    their root's."""

    site: int
    asset: int
    symbol: int
    leaf: bool = False
    inserted: bool = False
    written: tuple[int, ...] = ()


@dataclass(frozen=True)
class Handoff:
    """Shapes of ``symbol`` made at hand-off ``site``: successors the region does not derive, which wait for
    their symbol's turn as the interpreter's would (``regions.Fusible.inlined``). Their geometry is
    ``geom`` (``Shapes.geom``: -1 their scope, or the asset an ``i`` made it), ``inserted`` where an ``i``
    in the region made it (``slots.TRIM_INSERTED``), else as their root's; their columns ``written`` as
    ``Emit``'s."""

    site: int
    symbol: int
    geom: int = -1
    inserted: bool = False
    written: tuple[int, ...] = ()


@dataclass
class Block:
    """What one symbol of a region emits when its rules run, in the interpreter's order: records (``Emit``),
    shapes handed on (``Handoff``) and the blocks of the symbols it derives. Its sites and those of its
    blocks are the range ``first`` to ``last``, its hand-off sites ``first_handoff`` to ``last_handoff``
    (sites are numbered in this order)."""

    symbol: int
    events: list = field(default_factory=list)
    first: int = 0
    last: int = 0
    first_handoff: int = 0
    last_handoff: int = 0


class Scope(NamedTuple):
    """Where the generated code holds a shape: the names of its origin's and size's variables (per axis)
    and of its parameters' values; the expression of its random key (``backend.random``: a split child's
    mixes its parent's with the split's site and its index, a successor's with its site and 0), computed
    only where a shape draws or is handed off; in CityEngine's dialect the variable of its state in PRT's
    stream (``backend.prt_random``), which the operations that make shapes move on. And its geometry,
    known where the code is written: -1 its scope, or the id of the asset an ``i`` made it; whether an
    ``i`` inserted it (``builtin:cube`` leaves the scope's box as its geometry, but inserted); and the
    per-shape columns the region wrote (``set``, ``color``), in the order of their slots: (slot, the
    variable of its value as a float64, a string's interned id) pairs."""

    origin: tuple[str, str, str]
    size: tuple[str, str, str]
    params: tuple[str, ...]
    key: str
    asset: int = -1
    inserted: bool = False
    written: tuple[tuple[int, str], ...] = ()
