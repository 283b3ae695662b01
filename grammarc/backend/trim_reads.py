"""Where a grammar reads the trim planes its ``comp(f)`` splits make: the sites whose planes nothing reads.

A CityEngine ``comp(f)`` gives each face the planes where it meets its neighbours (``geometry.trim``), and
a grammar that inserts anything gets them for every face of every ``comp(f)`` (``Plan.trim_slot``). They
are read in three places only: the leaf of a shape whose geometry was inserted (an ``i()`` asset, a
``primitive*``, or a box cut out of one: ``terminals.emit_leaves`` cuts it as it is placed), the paper's
``I()`` (cut as it is placed) and ``trim()``. Many faces never get there: candler's window reveals are an
``extrude`` then a ``comp(f)`` whose faces end as textured walls of their own geometry, and finding their
planes is a kernel over every face of the split (a face's planes need its neighbours).

So this follows the grammar as ``execute.run`` follows a body, with what can be known of a shape without
its numbers: whether its geometry may be inserted (``i()`` and ``primitive*`` make it so; ``extrude`` and
``resetGeometry`` make it the shape's own: ``slots.TRIM_INSERTED``) and whether it still carries the
planes in question (``resetGeometry`` clears them); ``[`` keeps both and ``]`` gives them back. A site's
planes are read where a shape it makes, or one made from it (parts of splits and of ``comp(e|v)``, case and
stochastic branches, successors handed on through any number of rules, recursion included), reaches a
reader before another ``comp(f)`` gives it planes of its own (a nested site whose planes nothing reads is
no reader of these either: what reaches its parts reads nothing). Each symbol's rules are summed up once
per state its shapes may arrive in (whether they may read the planes they carry), to the least fixed point
over the rule graph; then the states in which each symbol's shapes do arrive are followed from the start
symbol, whose shapes are the lots' (not inserted), and each ``comp(f)`` met is judged in the states it is
met in.

A body's end is a leaf where no operation of it hands its shape on (``execute.run``; ``HANDS_ON`` names
them as the operation table declares them, which is above the plan), and so is a shape that no rule of its
symbol applies to (every rule has a guard). Where unsure, planes are read: a site the start symbol does not
reach, or whose number another site shares and reads, keeps its planes. No expression reads the planes'
id, nor does ``set`` write it: it is named as no attribute can be (``slots.TRIM_PLANES``), and ``set`` takes
attributes and the switches ``trim.vertical`` and ``trim.horizontal``, which the readers look at.
"""

from __future__ import annotations

from collections import defaultdict

from grammarc.ir import nodes as ir
from grammarc.ir.traverse import sub_bodies

#: Operations that read the shape's trim planes where they run: the paper's instance, and ``trim()``.
READERS = (ir.Insert, ir.Trim)
#: Operations that hand their shape on (to successors, parts, an instance or nothing): a body that holds one
#: leaves no leaf at its end. The operations registered with ``consumes`` (``operations.table``).
HANDS_ON = frozenset((ir.Symbol, ir.Empty, ir.Insert, ir.Split, ir.Repeat, ir.GroupSplit, ir.SplitArea, ir.Comp,
                      ir.CompFaces, ir.Cut, ir.Setback, ir.SetbackToArea, ir.InnerRectangle, ir.Case, ir.Stochastic))
#: Operations after which the shape's geometry is inserted (True) or its own (False).
MARKS = {ir.UseAsset: True, ir.Primitive: True, ir.Extrude: False, ir.ResetGeometry: False}


def unread_plane_sites(module: ir.Module, start: str) -> frozenset[int]:
    """The sites of ``module``'s ``comp(f)`` splits (without ``offset``) whose faces' trim planes no
    derivation from ``start`` reads: they need not be found."""
    return _Derivation(module).unread(start)


def makes_planes(op: ir.Op) -> bool:
    """Whether ``op`` gives its components trim planes: a ``comp(f)``, but the one of an ``offset``'s faces
    (``operations.offsets.offset_faces``), whose components keep their shape's."""
    return isinstance(op, ir.CompFaces) and op.kind == "f" and op.offset is None


class _Derivation:
    """The abstract derivation of one module: ``reads[symbol, inserted]``, whether a shape arriving at a
    symbol with planes, its geometry inserted or not, may have them read; then ``unread``."""

    def __init__(self, module: ir.Module) -> None:
        self.rules: dict[str, list[ir.Rule]] = defaultdict(list)
        for rule in module.rules:
            self.rules[rule.symbol].append(rule)
        self.reads: dict[tuple[str, bool], bool] = {}
        self.arrivals: set[tuple[str, bool]] = set()
        self.waiting: list[tuple[str, bool]] = []
        self.read_sites: dict[int, bool] = defaultdict(bool)
        changed = True
        while changed:  # the least fixed point (from none read): read where a finite derivation reads
            changed = False
            for key in [(name, inserted) for name in self.rules for inserted in (False, True)]:
                read = self._applies(*key, False)
                changed |= read != self.reads.get(key, False)
                self.reads[key] = read

    def unread(self, start: str) -> frozenset[int]:
        """The sites met on the way from ``start`` whose planes are read in none of the states they are met
        in."""
        self._arrive(start, False)
        while self.waiting:
            self._applies(*self.waiting.pop(), True)
        return frozenset(site for site, read in self.read_sites.items() if not read)

    def _arrive(self, name: str, inserted: bool) -> None:
        if (name, inserted) not in self.arrivals:
            self.arrivals.add((name, inserted))
            self.waiting.append((name, inserted))

    def _applies(self, name: str, inserted: bool, met: bool) -> bool:
        """Whether shapes arriving at ``name`` with planes may have them read: by its rules' bodies, or as
        leaves where no rule applies (a terminal, or every rule guarded). ``met``: the shapes do arrive so
        (not a summary): the sites and successors on their way are recorded."""
        rules = self.rules.get(name, ())
        read = inserted and all(rule.guard is not None for rule in rules)
        for rule in rules:
            for alternative in rule.alternatives:
                read |= self._body(alternative.body, True, inserted, met)
        return read

    def _body(self, body: ir.Body, carried: bool, inserted: bool, met: bool) -> bool:
        """Whether shapes running ``body`` may read the planes they arrive with (``carried``: they still
        have them), their geometry ``inserted`` or not."""
        read = False
        stack = []
        for op in body:
            kind = type(op)
            if kind is ir.Push:
                stack.append((carried, inserted))
            elif kind is ir.Pop:
                if stack:
                    carried, inserted = stack.pop()
            elif kind in READERS:
                read |= carried
            elif kind in MARKS:
                inserted = MARKS[kind]
                carried &= kind is not ir.ResetGeometry
            elif kind is ir.Symbol:
                read |= self._successor(op, inserted, met) and carried
            elif makes_planes(op):
                if met:  # its own planes: read where its parts read them; these go no further
                    parts = [self._body(part, True, inserted, met) for part in op.parts]
                    self.read_sites[op.site] |= any(parts)
            else:
                for part in sub_bodies(op):
                    read |= self._body(part, carried, inserted, met)
        leaf = not any(type(op) in HANDS_ON for op in body)
        return read | (leaf and carried and inserted)

    def _successor(self, op: ir.Symbol, inserted: bool, met: bool) -> bool:
        """Whether a successor's shapes may read the planes they are handed with: as leaves at once (a
        symbol without rules, ``X.``), else by its rules."""
        if op.leaf or not self.rules.get(op.name):
            return inserted
        if met:
            self._arrive(op.name, inserted)
        return self.reads.get((op.name, inserted), False)
