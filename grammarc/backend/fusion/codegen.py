"""The numba source of a region's kernel, written from its IR, and the order its records are emitted in.

A region (``regions``) becomes one function over its root's batch, a loop over the parent shapes with the
rules of the root and of the symbols it inlines written out as nested code: a split is a loop over its
children (or one block per ``Subdiv`` part), a guard an ``if``, a successor the code of its symbol's rules
where the region inlines it and else a *hand-off site* (its shapes written out), an ``I`` or a leaf an
*emission site*. The scope travels in local variables (origin and size per axis; the frame stays the
parent's: no operation of a region turns it), the random key as an expression evaluated only where a shape
is handed off. The runner calls it twice (one function to compile, not two). Counting, ``sites[k]`` adds
up the records site k makes and ``handoffs[k]`` the shapes hand-off site k makes; ``made`` the shapes each
parent makes (as the interpreter counts them for --max-shapes), and ``bad`` flags parents the interpreter
would fail (a negative size, a repeat beyond the limit). Writing, ``sites[k]`` is site k's next row, where
its record goes, and ``handoffs[k]`` likewise. Records (and shapes) of one site thus come in the parents'
order and, within a parent, in the order of its children: the order the interpreter gives them
(``backend.fusion``).

The arithmetic is the interpreter's, operation by operation, in the same order (``kernels.split`` lays
the parts, ``kernels.scope`` places children and writes transforms, ``operations.scope`` moves and sizes):
every record and shape has the same bits. The region's ``Block`` tree tells the runner when each site's
records and shapes are due: a site of the root at once, a site of an inlined symbol when that symbol's turn
comes.

CityEngine's dialect: a ``split`` is laid by the interpreter's own kernels (``kernels.split.plan_row`` and
``lay_row``), called on the one parent; a shape's state in PRT's stream is a variable that
successors, ``[`` and ``NIL`` move on with ``prt_random``'s steps, and a split's pieces start where their
parent's stream stands after the pieces before them; a body that hands its shape to nothing ends in a leaf
of its rule's symbol, an instance of the asset where an ``i`` made it one.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import math
from dataclasses import dataclass, field
from itertools import count
from pathlib import Path
from typing import NamedTuple

from grammarc.backend.fusion.regions import ENDING, SIZES, Fusible, applied_rules
from grammarc.backend.kernels.split import MAX_COUNT, group_arrays
from grammarc.backend.shapes import asset_geom
from grammarc.constants import TOL
from grammarc.ir import nodes as ir
from grammarc.ir.asset_names import LEAF_CUBE, LEAF_QUAD


@dataclass(frozen=True)
class Emit:
    """Records of ``asset`` made at emission ``site`` by ``symbol``: the instances of an ``I`` or of the
    asset an ``i`` made a leaf's geometry (the symbol whose rule it is in), or a leaf's cubes or quads (the
    leaf's symbol: ``leaf``, as ``terminals.emit_leaves`` emits them, textured; a cube cut at its trim
    planes where its geometry was ``inserted`` by an ``i`` in the region, else where its root's was)."""

    site: int
    asset: int
    symbol: int
    leaf: bool = False
    inserted: bool = False


@dataclass(frozen=True)
class Handoff:
    """Shapes of ``symbol`` made at hand-off ``site``: successors the region does not derive, which wait for
    their symbol's turn as the interpreter's would (``regions.Fusible.inlined``). Their geometry is
    ``geom`` (``Shapes.geom``: -1 their scope, or the asset an ``i`` made it), ``inserted`` where an ``i``
    in the region made it (``slots.TRIM_INSERTED``), else as their root's."""

    site: int
    symbol: int
    geom: int = -1
    inserted: bool = False


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
    known where the code is written: -1 its scope, or the id of the asset an ``i`` made it; and whether an
    ``i`` inserted it (``builtin:cube`` leaves the scope's box as its geometry, but inserted)."""

    origin: tuple[str, str, str]
    size: tuple[str, str, str]
    params: tuple[str, ...]
    key: str
    asset: int = -1
    inserted: bool = False


@dataclass(frozen=True)
class Source:
    """A region's generated module: its text, the root's ``Block``, the attributes its functions take (in
    order), its numbers of sites and of hand-off sites, the most parameters a shape handed off has, how
    many symbols deep it reaches below its root, and whether it writes the root row each record and shape
    handed off comes from (``carries``: where the grammar's shapes carry per-shape columns, ``Plan.dynamic``,
    which pass unchanged from a root to everything the region makes of it: ``regions``)."""

    text: str
    block: Block
    attrs: tuple[str, ...]
    sites: int
    handoffs: int
    params: int
    depth: int
    carries: bool


#: The modules whose compiled functions a kernel calls (``HEADER``'s imports).
CALLED = ("grammarc.backend.kernels.split", "grammarc.backend.prt_random", "grammarc.backend.random")


@functools.cache
def called_code() -> str:
    """A digest of the source of ``CALLED``, which each kernel's text carries: numba's cache of a function
    holds the machine code of the functions it calls, and knows only its own file's changes, so a kernel
    must be a new text (a new file) when they change."""
    digest = hashlib.sha256()
    for name in CALLED:
        digest.update(Path(importlib.util.find_spec(name).origin).read_bytes())
    return digest.hexdigest()[:24]


HEADER = '''"""Generated by grammarc.backend.fusion.codegen from a region of a grammar: do not edit."""
# the functions it calls: {called}
import numpy as np
from numba import njit

from grammarc.backend.kernels.split import lay_row, plan_row, repetitions
from grammarc.backend.prt_random import child_state, next_state, value
from grammarc.backend.random import child_key1, uniform1


@njit(cache=True, nogil=True, error_model='numpy')
def put_record(xform, record_lot, row, frames, f, l, base, a0, a1, a2, z0, z1, z2, o0, o1, o2):
    """The record at ``row`` (``kernels.scope.xforms``): column j frame axis ``aj`` times ``zj``, column 3
    the origin less the lot's."""
    for r in range(3):
        xform[row, r, 0] = frames[f, a0, r] * z0
        xform[row, r, 1] = frames[f, a1, r] * z1
        xform[row, r, 2] = frames[f, a2, r] * z2
    xform[row, 0, 3] = o0 - base[l, 0]
    xform[row, 1, 3] = o1 - base[l, 1]
    xform[row, 2, 3] = o2 - base[l, 2]
    record_lot[row] = l


@njit(cache=True, nogil=True, error_model='numpy')
def put_shape(handed, row, o0, o1, o2, s0, s1, s2, f, l, key, depth):
    """The shape handed off at ``row`` of ``handed`` (``compiled.handed_columns``), but its parameters."""
    origin, size, frame, lot, keys, depths = handed[0], handed[1], handed[2], handed[3], handed[4], handed[5]
    origin[row, 0], origin[row, 1], origin[row, 2] = o0, o1, o2
    size[row, 0], size[row, 1], size[row, 2] = s0, s1, s2
    frame[row], lot[row], keys[row], depths[row] = f, l, key, depth

'''


def generate(fusible: Fusible, root: int) -> Source:
    """The source of the region rooted at symbol ``root`` (which ``fusible`` accepted)."""
    writer = _Writer(fusible)
    writer.function(root)
    text = HEADER.format(called=called_code()) + "".join(f"{line}\n" for line in [*writer.constants, *writer.lines])
    return Source(text, writer.block, tuple(writer.attrs), writer.sites, writer.handoffs, writer.params, writer.depth,
                  writer.carries)


class _Writer:
    """The walk over the region's IR that writes the kernel's lines, numbering sites and attributes as it
    meets them."""

    def __init__(self, fusible: Fusible) -> None:
        self.fusible = fusible
        self.plan = fusible.plan
        self.lines: list[str] = []
        self.hoisted: list[str] = []  # statements that the next line's expressions need first (``draw``)
        self.constants: list[str] = []  # the module's arrays of constants, before the kernel
        self.prologue: list[str] = []  # the kernel's arrays made once, before its loop over the parents
        self.attrs: list[str] = []
        self.sequential = self.plan.sequential_random
        self.carries = bool(self.plan.dynamic)
        self.names = count()
        self.sites = 0
        self.handoffs = 0
        self.params = 0
        self.depth = 0
        self.block: Block | None = None

    # ------------------------------------------------------------------------------------------ framing
    def function(self, root: int) -> None:
        self.lines += ["@njit(cache=True, nogil=True, error_model='numpy')", ""]
        body = [
            "for i in range(len(lot)):",
            "    f = frame[i]",
            "    l = lot[i]",
            "    o0, o1, o2 = origin[i, 0], origin[i, 1], origin[i, 2]",
            "    s0, s1, s2 = size[i, 0], size[i, 1], size[i, 2]",
            "    n = 0.0",
            # a state in PRT's stream, which draws move on in place: the kernel's own copy
            *(["    ks = key[i]"] if self.sequential else []),
        ]
        self.lines += ["    " + line for line in body]
        root_params = tuple(f"q{k}[i]" for k in range(len(self.plan.symbols[root].param_types)))
        root_key = "ks" if self.sequential else "key[i]"
        self.block = self.symbol(root, Scope(("o0", "o1", "o2"), ("s0", "s1", "s2"), root_params, root_key), 2, 0)
        self.lines += ["        made[i] = n", "        if n > limit:", "            bad[i] = True"]
        columns = "".join(f"q{k}, " for k in range(len(root_params))) + "".join(
            f"a{k}, " for k in range(len(self.attrs)))
        self.lines[1] = (f"def derive(origin, size, frame, lot, key, depth, frames, {columns}base, limit, writing, "
                         "sites, made, bad, xform, record_lot, record_row, handoffs, handed):")
        self.lines[2:2] = ["    " + line for line in self.prologue]

    def put(self, level: int, line: str) -> None:
        """Write ``line`` at indentation ``level``, after the statements of the draws its expressions made
        (``draw``)."""
        self.lines += ["    " * level + hoisted for hoisted in self.hoisted]
        self.hoisted.clear()
        self.lines.append("    " * level + line)

    def fresh(self, stem: str) -> str:
        return f"{stem}_{next(self.names)}"

    # ------------------------------------------------------------------------------------------ symbols
    def symbol(self, sym_id: int, scope: Scope, level: int, depth: int) -> Block:
        """The code of symbol ``sym_id``'s rules on ``scope``."""
        self.depth = max(self.depth, depth)
        block = Block(sym_id, first=self.sites, first_handoff=self.handoffs)
        rules = applied_rules(self.plan.symbols[sym_id])
        for k, rule in enumerate(rules):
            if rule.guard is None:
                if k:
                    self.put(level, "else:")
                inner = level + 1 if k else level
            else:
                self.put(level, f"{'el' if k else ''}if {self.expr(rule.guard, scope)}:")
                inner = level + 1
            self.put(inner, "pass")
            self.alternatives(rule, block, scope, inner, depth)
        block.last, block.last_handoff = self.sites, self.handoffs
        return block

    def alternatives(self, rule: ir.Rule, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``execute.apply_rule``: the body, or the alternative the shape's draw at the rule's site picks
        from the running sum of the probabilities (which fail the lot unless they sum to 1 and none is
        negative); the alternatives' sites in their order, as the interpreter runs them one after the
        other."""
        alternatives = rule.alternatives
        if len(alternatives) == 1:
            self.body(alternatives[0].body, block, scope, level, depth)
            return
        probs = [self.fresh("pr") for _ in alternatives]
        for name, alternative in zip(probs, alternatives):
            self.put(level, f"{name} = {self.expr(alternative.prob, scope)}")
        self.check(level, f"not (abs(({' + '.join(probs)}) - 1.0) > {TOL.probability!r} or "
                          f"{' or '.join(f'{name} < 0.0' for name in probs)})")
        drawn = self.fresh("u")
        self.put(level, f"{drawn} = {self.draw(scope, rule.site)}")
        pick = self.picked(level, drawn, probs)
        for k, alternative in enumerate(alternatives):
            last = k == len(alternatives) - 1
            self.put(level, "else:" if last else f"{'el' if k else ''}if {pick} == {k}:")
            self.put(level + 1, "pass")
            self.body(alternative.body, block, scope, level + 1, depth)

    def picked(self, level: int, drawn: str, shares: list[str], per: str = "") -> str:
        """The variable of the branch the draw ``drawn`` picks: how many of the running sums of ``shares``
        (each divided as ``per`` says) it reaches, as ``execute.apply_rule`` and ``control.branch`` count."""
        running, pick = self.fresh("cu"), self.fresh("pk")
        self.put(level, f"{running} = 0.0")
        self.put(level, f"{pick} = 0")
        for name in shares:
            self.put(level, f"{running} += {name}")
            self.put(level, f"if {drawn} >= {running}{per}:")
            self.put(level + 1, f"{pick} += 1")
        return pick

    def draw(self, scope: Scope, site: int) -> str:
        """``streams.draw``: the shape's draw at ``site`` (``random.uniform``); in PRT's stream, the next
        number of the shape's state, which moves on in place before the line that reads the draw, in the
        order the interpreter evaluates the line's expressions (operands and arguments first)."""
        if not self.sequential:
            return f"uniform1({scope.key}, {site})"
        drawn = self.fresh("u")
        self.hoisted += [f"{scope.key} = next_state({scope.key})", f"{drawn} = np.float64(value({scope.key}))"]
        return drawn

    def body(self, body: ir.Body, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``execute.run``: the operations in order on one scope; ``[`` keeps it, ``]`` takes it back; an
        operation that makes shapes or records leaves it as it was (but for its state in PRT's stream). In
        CityEngine's dialect a body that hands its shape to nothing ends in a leaf of its rule's symbol."""
        stack = []
        for op in body:
            if isinstance(op, ir.Push):
                if self.sequential:  # ``streams.bracket``: the copy a child, the shape waiting moved on
                    stack.append(scope._replace(key=self.moved(scope, level)))
                    scope = scope._replace(key=self.made_state(scope, level))
                else:
                    stack.append(scope)
            elif isinstance(op, ir.Pop):
                scope = stack.pop() if stack else scope
            elif isinstance(op, ir.Scale):
                scope = scope._replace(size=self.scale(op, scope, level))
            elif isinstance(op, ir.Translate):
                scope = scope._replace(origin=self.translate(op, scope, level))
            elif isinstance(op, ir.Split):
                self.split(op, block, scope, level, depth)
            elif isinstance(op, ir.Repeat):
                self.repeat(op, block, scope, level, depth)
            elif type(op) is ir.GroupSplit:  # not ``splitArea`` (``regions``)
                self.group_split(op, block, scope, level, depth)
            elif isinstance(op, ir.Insert):
                self.emit(block, self.plan.grammar.asset_ids[op.asset], block.symbol, scope, level)
            elif isinstance(op, ir.UseAsset):  # ``inserts.placed``: ``builtin:cube`` is the scope's box
                scope = scope._replace(asset=self.plan.grammar.asset_ids[op.asset] or -1, inserted=True)
            elif isinstance(op, ir.Symbol):
                scope = self.successor(op, block, scope, level, depth)
            elif isinstance(op, ir.Case):
                self.case(op, block, scope, level, depth)
            elif isinstance(op, ir.Stochastic):
                self.stochastic(op, block, scope, level, depth)
            elif isinstance(op, ir.Empty) and self.sequential:  # ``NIL`` moves the stream on (``streams.skip``)
                scope = scope._replace(key=self.moved(scope, level))
        if self.plan.leaf_bodies and not any(isinstance(op, ENDING) for op in body):
            self.leaf(block, block.symbol, scope, level)

    def successor(self, op: ir.Symbol, block: Block, scope: Scope, level: int, depth: int) -> Scope:
        """``operations.successors``: a leaf's records, the symbol's rules inlined, or a hand-off; the
        scope after it (its state in PRT's stream moved on)."""
        self.made(level)
        args = []
        for arg in op.args:  # evaluated on the caller's scope (a leaf has none)
            args.append(self.fresh("p"))
            self.put(level, f"{args[-1]} = {self.expr(arg, scope)}")
        if self.sequential:  # ``streams.successor_keys``
            key, scope = self.made_state(scope, level), scope._replace(key=self.moved(scope, level))
        else:
            key = f"child_key1({scope.key}, {op.site}, 0)"
        target = self.plan.symbol_ids[op.name]
        if self.plan.makes_leaves(op):
            self.leaf(block, target, scope, level)
            return scope
        made = scope._replace(params=tuple(args), key=key)
        if self.fusible.inlined(op.name):
            block.events.append(self.symbol(target, made, level, depth + 1))
        else:
            self.handoff(block, target, made, level, depth + 1)
        return scope

    def case(self, op: ir.Case, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``control.branch``: the first branch whose condition holds, else the default, each a body of its
        own (``execute.run_parts``); the branches' sites in their order, as the interpreter runs them. A
        condition is evaluated only where the ones before it did not hold (``control._taken_in_order``: its
        draws are made there only)."""
        for condition, body in op.branches:
            self.put(level, f"if {self.expr(condition, scope)}:")
            self.put(level + 1, "pass")
            self.body(body, block, scope, level + 1, depth)
            self.put(level, "else:")
            level += 1
        self.put(level, "pass")
        self.body(op.default, block, scope, level, depth)

    def stochastic(self, op: ir.Stochastic, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``control.branch``: the percentages, then one draw; the branch is the number of running sums
        (divided by 100) the draw reaches, the default past the last."""
        percent = [self.fresh("pc") for _ in op.branches]
        for name, (value, _) in zip(percent, op.branches):
            self.put(level, f"{name} = {self.expr(value, scope)}")
        taken = self.picked(level, self.draw(scope, op.site), percent, " / 100.0")
        for k, body in enumerate([*(body for _, body in op.branches), op.default]):
            self.put(level, f"{'el' if k else ''}if {taken} == {k}:")
            self.put(level + 1, "pass")
            self.body(body, block, scope, level + 1, depth)

    def made_state(self, scope: Scope, level: int) -> str:
        """The variable of the state a shape made from ``scope``'s starts with (``prt_random.child``)."""
        name = self.fresh("k")
        self.put(level, f"{name} = child_state({scope.key})")
        return name

    def moved(self, scope: Scope, level: int) -> str:
        """The variable of ``scope``'s state moved one draw on."""
        name = self.fresh("k")
        self.put(level, f"{name} = next_state({scope.key})")
        return name

    # ------------------------------------------------------------------------------------------ operations
    def scale(self, op: ir.Scale, scope: Scope, level: int) -> tuple:
        """``operations.scope.scale``: each axis' value, times the size where relative; the paper's ``S``
        fails a negative or NaN size."""
        new = []
        for axis, s in enumerate(op.sizes):
            name = self.fresh("s")
            value = self.expr(s.value, scope)
            self.put(level, f"{name} = ({value}) * {scope.size[axis]}" if s.kind is ir.SizeKind.RELATIVE
                     else f"{name} = {value}")
            new.append(name)
        self.check(level, " and ".join(f"{name} >= 0.0 and {name} <= {TOL.far!r}" for name in new))
        return tuple(new)

    def translate(self, op: ir.Translate, scope: Scope, level: int) -> tuple:
        """``operations.scope.translate``: the vector along the scope axes, summed axis by axis from zero
        (as ``kernels.scope.leaf_xforms`` and the interpreter's product sum it), added to the origin."""
        local = []
        for e in op.vector:
            local.append(self.fresh("t"))
            self.put(level, f"{local[-1]} = {self.expr(e, scope)}")
        new = []
        for j in range(3):
            delta = self.fresh("d")
            self.put(level, f"{delta} = 0.0")
            for i in range(3):
                self.put(level, f"{delta} += {local[i]} * frames[f, {i}, {j}]")
            new.append(self.fresh("o"))
            self.put(level, f"{new[-1]} = {scope.origin[j]} + {delta}")
        self.within_coordinates(level, new)
        return tuple(new)

    def split(self, op: ir.Split, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``kernels.split.subdiv`` for one parent: relative sizes share what the absolute ones leave, parts
        laid end to end, cut at the scope's end, those of length ``TOL.zero`` or less dropped."""
        axis, extent = op.axes[0], scope.size[op.axes[0]]
        values = [self.fresh("v") for _ in op.sizes]
        for name, s in zip(values, op.sizes):
            self.put(level, f"{name} = {self.expr(s.value, scope)}")
        self.check(level, " and ".join(f"{name} >= 0.0" for name in values))
        absolute, relative, free, at = (self.fresh(stem) for stem in ("ab", "rl", "fr", "at"))
        self.put(level, f"{absolute} = 0.0")
        self.put(level, f"{relative} = 0.0")
        for name, s in zip(values, op.sizes):
            total = relative if s.kind is ir.SizeKind.RELATIVE else absolute
            self.put(level, f"{total} += {name}")
        self.put(level, f"{free} = {extent} - {absolute}")
        self.put(level, f"{free} = max({free}, 0.0)")
        self.put(level, f"{at} = 0.0")
        for k, (name, s, part) in enumerate(zip(values, op.sizes, op.parts)):
            step, end, length = (self.fresh(stem) for stem in ("sz", "en", "ln"))
            if s.kind is ir.SizeKind.RELATIVE:
                self.put(level, f"{step} = {name} * {free} / {relative} if {relative} > 0.0 else 0.0")
            else:
                self.put(level, f"{step} = {name}")
            self.put(level, f"{end} = {at} + {step}")
            self.put(level, f"{end} = min({end}, {extent})")
            self.put(level, f"if {end} - {at} > {TOL.zero!r}:")
            self.put(level + 1, f"{length} = {end} - {at}")
            self.child(part, block, scope, axis, at, length, level + 1, depth, f"child_key1({scope.key}, {op.site}, {k})")
            self.put(level, f"{at} = {at} + {step}")

    def repeat(self, op: ir.Repeat, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``kernels.split.repeat_counts`` and ``repeat`` for one parent: ceil(extent / size) equal
        elements (at least one on a scope longer than ``TOL.zero``), element j in part j mod parts."""
        axis, extent = op.axes[0], scope.size[op.axes[0]]
        value, times, ceiling, step, j, pos = (self.fresh(s) for s in ("rv", "c", "x", "st", "j", "ps"))
        self.put(level, f"{value} = {self.expr(op.sizes[0], scope)}")
        self.check(level, f"{value} > 0.0")
        self.put(level, f"{times} = 0")
        self.put(level, f"if {value} > 0.0 and {extent} > {TOL.zero!r}:")
        self.put(level + 1, f"{ceiling} = np.ceil({extent} / {value} - 1e-9)")
        self.put(level + 1, f"{times} = max(int({ceiling}) if {ceiling} < {MAX_COUNT} else {MAX_COUNT}, 1)")
        self.put(level, f"if {times} > limit:")  # beyond --max-shapes: the interpreter fails the lot
        self.put(level + 1, "bad[i] = True")
        self.put(level + 1, f"{times} = 0")
        self.put(level, f"{step} = {extent} / {times} if {times} > 0 else 0.0")
        self.put(level, f"for {j} in range({times}):")
        self.put(level + 1, "if n > limit:")
        self.put(level + 2, "break")
        self.put(level + 1, f"{pos} = {j} * {step}")
        parts = len(op.parts)
        for k, part in enumerate(op.parts):
            inner = level + 1
            if parts > 1:
                self.put(level + 1, f"{'if' if k == 0 else 'elif'} {j} % {parts} == {k}:")
                inner = level + 2
            self.child(part, block, scope, axis, pos, step, inner, depth, f"child_key1({scope.key}, {op.site}, {j})")

    def group_split(self, op: ir.GroupSplit, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``splits.group_split`` for one parent: CityEngine's layout by the interpreter's own kernels
        (``kernels.split.plan_row`` and ``lay_row``, on arrays of one row made once per batch, the
        children's grown as a parent needs), negative sizes taken as 0 and a NaN one refused, parts of
        ``TOL.merge`` or less not made; then the children in order, each in its part's body."""
        kind, groups, n_groups = group_arrays(op)
        if not n_groups:
            self.ungrouped_split(op, kind.tolist(), block, scope, level, depth)
            return
        if op.repeat and all(k == 2 for k in kind.tolist()):
            self.floating_repeat(op, block, scope, level, depth)
            return
        slots, parts = n_groups, len(op.sizes)  # the splits without groups are written out above
        tables = self.fresh("kind"), self.fresh("group")
        for name, table in zip(tables, (kind, groups)):
            self.constants.append(f"{name} = np.array({table.tolist()!r}, dtype=np.int64)")
        values, reps, gap, scale, total, sums, room = (self.fresh(stem) for stem in ("gv", "gr", "gg", "gs", "gt",
                                                                                       "gn", "cap"))
        made = [self.fresh(stem) for stem in ("cp", "cj", "cpos", "cln", "cix")]
        self.prologue += [f"{values} = np.empty((1, {parts}))", f"{reps} = np.zeros((1, {slots}), np.int64)",
                          f"{gap} = np.zeros((1, {slots}))", f"{scale} = np.ones(1)", f"{total} = np.zeros(1)",
                          *(f"{sums}{k} = np.zeros({slots})" for k in range(3)), f"{room} = 0",
                          *(f"{name} = np.empty(0{dtype})" for name, dtype in zip(made, self._CHILD_TYPES))]
        sizes = self.sizes(op, scope, level)
        self.put(level, "else:")
        for j, size in enumerate(sizes):
            self.put(level + 1, f"{values}[0, {j}] = {size}")
        extent = scope.size[op.axis]
        self.put(level + 1, f"plan_row(0, {extent}, {values}, 0, {tables[0]}, {tables[1]}, {n_groups}, {TOL.zero!r}, "
                            f"{reps}, {gap}, {scale}, {total}, {sums}0, {sums}1, {sums}2)")
        self.put(level + 1, f"if not ({total}[0] <= limit):")  # beyond --max-shapes: the interpreter fails it
        self.put(level + 2, "bad[i] = True")
        self.put(level + 1, "else:")
        inner = level + 2
        self.put(inner, f"if int({total}[0]) > {room}:")
        self.put(inner + 1, f"{room} = int({total}[0])")
        for name, dtype in zip(made, self._CHILD_TYPES):
            self.put(inner + 1, f"{name} = np.empty({room}{dtype})")
        laid, c = self.fresh("m"), self.fresh("c")
        self.put(inner, f"{laid} = lay_row(0, {extent}, {values}, 0, {tables[0]}, {tables[1]}, {reps}, {gap}, "
                        f"{scale}, {TOL.merge!r}, {', '.join(made)}, 0)")
        stream = self.fresh("ks")
        self.put(inner, f"{stream} = {scope.key}")
        self.put(inner, f"for {c} in range({laid}):")
        self.put(inner + 1, "if n > limit:")
        self.put(inner + 2, "break")
        key = self.piece(stream, inner + 1)
        for k, part in enumerate(op.parts):
            self.put(inner + 1, f"{'if' if k == 0 else 'elif'} {made[1]}[{c}] == {k}:")
            self.child(part, block, scope, op.axis, f"{made[2]}[{c}]", f"{made[3]}[{c}]", inner + 2, depth, key)

    def ungrouped_split(self, op: ir.GroupSplit, kind: list[int], block: Block, scope: Scope, level: int,
                        depth: int) -> None:
        """``group_split`` of a split without repeat groups, ``plan_row`` and ``lay_row`` written out (their
        arithmetic in their order, no call and no array per parent): the fixed (and relative) sizes and
        the floating ones summed apart, the floating ones scaled to fill what the others leave, the parts
        laid end to end, each in place."""
        extent, values = scope.size[op.axis], self.sizes(op, scope, level)
        self.put(level, f"elif not ({float(len(values))!r} <= limit):")  # beyond --max-shapes
        self.put(level + 1, "bad[i] = True")
        self.put(level, "else:")
        level += 1
        fixed, floating, scale, at, stream = (self.fresh(stem) for stem in ("fx", "fl", "sc", "at", "ks"))
        self.put(level, f"{fixed} = 0.0")
        self.put(level, f"{floating} = 0.0")
        for value, k in zip(values, kind):
            self.put(level, f"{floating if k == 2 else fixed} += {f'{value} * {extent}' if k == 1 else value}")
        self.put(level, f"{scale} = max({extent} - {fixed}, 0.0) / {floating} if {floating} > 0.0 else 1.0")
        self.put(level, f"{at} = 0.0")
        self.put(level, f"{stream} = {scope.key}")
        self.lay(op, values, kind, scale, at, stream, block, scope, level, depth)

    def floating_repeat(self, op: ir.GroupSplit, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``group_split`` of a split repeated as a whole whose sizes all float (``{ ~a: A | ~b: B }*``),
        ``plan_row`` and ``lay_row`` written out for its one group (their arithmetic in their order, the
        sums of no fixed part as the 0.0 they are there): as many repetitions as bring the floating sizes
        nearest their written ones (``repetitions``), the sizes scaled to fill the extent."""
        extent, values = scope.size[op.axis], self.sizes(op, scope, level)
        self.put(level, "else:")
        level += 1
        nominal, left, reps, scale, total, share, laid = (self.fresh(stem) for stem in ("nm", "lf", "rp", "sc", "tt",
                                                                                         "sh", "fl"))
        self.put(level, f"{nominal} = 0.0")
        for value in values:
            self.put(level, f"{nominal} += {value}")
        self.put(level, f"{left} = max({extent} - 0.0 - 0.0, 0.0)")
        self.put(level, f"{reps} = 0")
        self.put(level, f"{scale} = 1.0")
        self.put(level, f"{total} = 0.0")
        self.put(level, f"if {nominal} <= {TOL.zero!r}:")  # a repetition too small to lay counts what it would make
        self.put(level + 1, f"if {nominal} > 0.0 and {left} > {TOL.zero!r}:")
        self.put(level + 2, f"{total} += {left} / {nominal}")
        self.put(level, "else:")
        self.put(level + 1, f"{share} = {left} * {nominal} / {nominal}")
        self.put(level + 1, f"if {share} == np.inf:")
        self.put(level + 2, f"{share} = {left} * ({nominal} / {nominal})")
        self.put(level + 1, f"{reps} = repetitions({share}, {nominal}, 0.0, {nominal}, 0.0, 0.0, {TOL.zero!r})")
        self.put(level + 1, f"{laid} = 0.0 + {reps} * {nominal}")
        self.put(level + 1, f"if {laid} > 0.0:")
        self.put(level + 2, f"{scale} = max({extent} - (0.0 + ({reps} * 0.0 + 0.0)), 0.0) / {laid}")
        for _ in values:
            self.put(level, f"{total} += float({reps})")
        self.put(level, f"if not ({total} <= limit):")  # beyond --max-shapes: the interpreter fails it
        self.put(level + 1, "bad[i] = True")
        self.put(level, "else:")
        level += 1
        at, stream = self.fresh("at"), self.fresh("ks")
        self.put(level, f"{at} = 0.0")
        self.put(level, f"{stream} = {scope.key}")
        self.put(level, f"for _ in range({reps}):")
        self.put(level + 1, "if n > limit:")
        self.put(level + 2, "break")
        self.lay(op, values, [2] * len(values), scale, at, stream, block, scope, level + 1, depth)

    def sizes(self, op: ir.GroupSplit, scope: Scope, level: int) -> list[str]:
        """The variables of a split's sizes, a negative one taken as 0; the parent flagged where one is NaN
        (an ``if`` the caller's ``else`` follows)."""
        values = []
        for s in op.sizes:
            values.append(self.fresh("v"))
            self.put(level, f"{values[-1]} = {self.expr(s.value, scope)}")
            self.put(level, f"{values[-1]} = 0.0 if {values[-1]} < 0.0 else {values[-1]}")
        self.check(level, " and ".join(f"{value} >= 0.0" for value in values))
        return values

    def lay(self, op: ir.GroupSplit, values: list[str], kind: list[int], scale: str, at: str, stream: str,
            block: Block, scope: Scope, level: int, depth: int) -> None:
        """``lay_row``'s parts, each in place: its size (relative, floating times ``scale``, or absolute), cut at
        the extent, made if longer than ``TOL.merge``, its piece of PRT's stream, its body; then the next."""
        extent = scope.size[op.axis]
        for value, k, part in zip(values, kind, op.parts):
            size, stop, length = (self.fresh(stem) for stem in ("sz", "st", "ln"))
            self.put(level, f"{size} = {f'{value} * {extent}' if k == 1 else f'{value} * {scale}' if k == 2 else value}")
            self.put(level, f"{stop} = min({at} + {size}, {extent})")
            self.put(level, f"if {stop} - {at} > {TOL.merge!r}:")
            self.put(level + 1, f"{length} = {stop} - {at}")
            self.child(part, block, scope, op.axis, at, length, level + 1, depth, self.piece(stream, level + 1))
            self.put(level, f"{at} += {size}")

    def piece(self, stream: str, level: int) -> str:
        """The state of a split's next piece (``prt_random.pieces``: where its parent's stream, ``stream``,
        stands after the pieces before it, then one draw), and the stream moved on: CityEngine's ``split``
        draws from PRT's stream, as its dialect does."""
        key = self.fresh("k")
        self.put(level, f"{key} = next_state(child_state({stream}))")
        self.put(level, f"{stream} = next_state({stream})")
        return key

    #: The dtypes of ``lay_row``'s columns of children: parent, part, position, length, index.
    _CHILD_TYPES = (", np.int64", ", np.int64", "", "", ", np.int64")

    def child(self, part: ir.Body, block: Block, scope: Scope, axis: int, pos: str, length: str, level: int,
              depth: int, key: str) -> None:
        """A split child (``kernels.scope.place_children``: the origin moved by ``pos`` along the split
        axis, the size cut to ``length``) with random key ``key``, and its part's body."""
        moved = []
        for j in range(3):
            moved.append(self.fresh("o"))
            self.put(level, f"{moved[-1]} = {scope.origin[j]} + {pos} * frames[f, {axis}, {j}]")
        self.within_coordinates(level, moved)
        cut = tuple(length if k == axis else scope.size[k] for k in range(3))
        self.made(level)
        self.put(level, "pass")
        self.body(part, block, scope._replace(origin=tuple(moved), size=cut, key=key), level, depth)

    def emit(self, block: Block, asset: int, symbol: int, scope: Scope, level: int) -> None:
        """An emission site of ``asset`` and its record of the scope."""
        self.record(self.site(block, asset, symbol), scope, level)

    def site(self, block: Block, asset: int, symbol: int, leaf: bool = False, inserted: bool = False) -> int:
        """A new emission site, due in ``block``'s order where it is met."""
        site = self.sites
        self.sites += 1
        block.events.append(Emit(site, asset, symbol, leaf, inserted))
        return site

    def record(self, site: int, scope: Scope, level: int) -> None:
        """Counted, or a record of the scope at ``site``'s next row (``put_record``)."""
        self.put(level, "if writing:")
        self.put(level + 1, f"put_record(xform, record_lot, sites[{site}], frames, f, l, base, 0, 1, 2, "
                            f"{', '.join(scope.size)}, {', '.join(scope.origin)})")
        self.rooted(level + 1, f"record_row[sites[{site}]]")
        self.put(level, f"sites[{site}] += 1")

    def rooted(self, level: int, target: str) -> None:
        """Where the region ``carries`` per-shape columns: the row of the root that a record or a shape
        handed off comes from, into ``target``."""
        if self.carries:
            self.put(level, f"{target} = i")

    def leaf(self, block: Block, symbol: int, scope: Scope, level: int) -> None:
        """A leaf of ``symbol`` as ``terminals.emit_leaves`` makes it, which emits a batch's cubes, then its
        quads (two sites): a cube where no axis is flat (``TOL.zero`` or less); a quad where one is, its
        columns the two others in turn and the flat one times zero (the first flat axis where two are);
        nothing where more are, which has no surface. A shape whose geometry is an asset (an ``i``) is an
        instance of it on its scope."""
        if scope.asset >= 0:
            self.emit(block, scope.asset, symbol, scope, level)
            return
        assets = self.plan.grammar.module.assets
        cube = self.site(block, assets.index(LEAF_CUBE), symbol, True, scope.inserted)
        quad = self.site(block, assets.index(LEAF_QUAD), symbol, True)
        flat = [f"{size} <= {TOL.zero!r}" for size in scope.size]
        count, a, b, k, za, zb = (self.fresh(stem) for stem in ("z", "qa", "qb", "qk", "za", "zb"))
        self.put(level, f"{count} = ({flat[0]}) + ({flat[1]}) + ({flat[2]})")
        self.put(level, f"if {count} == 0:")
        self.record(cube, scope, level + 1)
        self.put(level, f"elif {count} == 1:")
        for axis, test in enumerate((f"if {flat[0]}:", f"elif {flat[1]}:", "else:")):
            first, second = (axis + 1) % 3, (axis + 2) % 3
            self.put(level + 1, test)
            self.put(level + 2, f"{a}, {b}, {k}, {za}, {zb} = {first}, {second}, {axis}, {scope.size[first]}, "
                                f"{scope.size[second]}")
        self.put(level + 1, "if writing:")
        self.put(level + 2, f"put_record(xform, record_lot, sites[{quad}], frames, f, l, base, {a}, {b}, {k}, "
                            f"{za}, {zb}, 0.0, {', '.join(scope.origin)})")
        self.rooted(level + 2, f"record_row[sites[{quad}]]")
        self.put(level + 1, f"sites[{quad}] += 1")

    def handoff(self, block: Block, symbol: int, scope: Scope, level: int, depth: int) -> None:
        """A hand-off site: counted, or the shape written at the site's next row of ``handed``
        (``put_shape``), as ``operations.successors`` makes it."""
        site = self.handoffs
        self.handoffs += 1
        self.params = max(self.params, len(scope.params))
        block.events.append(Handoff(site, symbol, int(asset_geom(scope.asset)) if scope.asset >= 0 else -1,
                                    scope.inserted))
        self.put(level, "if writing:")
        row = self.fresh("h")
        self.put(level + 1, f"{row} = handoffs[{site}]")
        self.put(level + 1, f"put_shape(handed, {row}, {', '.join(scope.origin)}, {', '.join(scope.size)}, f, l, "
                            f"{scope.key}, depth[i] + {depth})")
        for k, value in enumerate(scope.params):
            self.put(level + 1, f"handed[6][{k}, {row}] = {value}")
        self.rooted(level + 1, f"handed[7][{row}]")
        self.put(level, f"handoffs[{site}] += 1")

    def made(self, level: int) -> None:
        """One more shape of the parent (a split child, a successor), as ``Context.count`` counts them."""
        self.put(level, "n += 1.0")

    def check(self, level: int, holds: str) -> None:
        """Flag the parent where ``holds`` does not: the interpreter fails its lot (and derives the batch)."""
        self.put(level, f"if not ({holds}):")
        self.put(level + 1, "bad[i] = True")

    def within_coordinates(self, level: int, origin: list[str]) -> None:
        """Flag the parent where an origin moves beyond any coordinate: the interpreter fails its lot there
        (``Context.refuse_far``; a scale's sizes are checked with its other conditions)."""
        self.check(level, " and ".join(f"abs({o}) <= {TOL.far!r}" for o in origin))

    # ------------------------------------------------------------------------------------------ expressions
    def expr(self, expr: ir.Expr, scope: Scope) -> str:
        """``expr`` as numba source: numbers as float64 literals, attributes read by lot (those the shapes
        carry by root), parameters and ``scope.s*`` from the scope's variables, operators and functions as
        ``backend.evaluate`` applies them (float64, IEEE division, NaN-propagating ``min`` and ``max``,
        ``rand``'s scaled draw, ``p``'s draw below its probability)."""
        if isinstance(expr, ir.Bool):
            return repr(bool(expr.value))
        if isinstance(expr, ir.Num):
            value = float(expr.value)
            return repr(value) if math.isfinite(value) else f"np.float64({str(value)!r})"
        if isinstance(expr, ir.AttrRef):  # a per-shape column is the root's: no fused operation writes one
            if expr.name not in self.attrs:
                self.attrs.append(expr.name)
            return f"a{self.attrs.index(expr.name)}[{'i' if expr.name in self.plan.dynamic else 'l'}]"
        if isinstance(expr, ir.Param):
            return scope.params[expr.index]
        if isinstance(expr, ir.ScopeRef):
            return scope.size[SIZES[expr.field]]
        if isinstance(expr, ir.Unary):
            return f"({'not ' if expr.op == '!' else '-'}{self.expr(expr.operand, scope)})"
        if isinstance(expr, ir.Call):  # ``functions.math``
            args = [self.expr(arg, scope) for arg in expr.args]
            if expr.func in ("min", "max"):
                return f"np.{'minimum' if expr.func == 'min' else 'maximum'}({args[0]}, {args[1]})"
            drawn = self.draw(scope, expr.site)
            if expr.func == "p":
                return f"({drawn} < {args[0]})"
            if not args:
                return f"({drawn})"
            low, high = ("0.0", args[0]) if len(args) == 1 else args
            return f"({low} + ({high} - {low}) * {drawn})"
        operator = {"&&": "and", "||": "or"}.get(expr.op, expr.op)
        return f"({self.expr(expr.left, scope)} {operator} {self.expr(expr.right, scope)})"
