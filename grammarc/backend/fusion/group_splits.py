"""The code of CityEngine's ``split`` of the scope (``ir.GroupSplit``) in a region's kernel.

Its layout (repeat groups, floating sizes, PRT's rounding of repetitions) is the interpreter's own code,
not a copy: ``kernels.split.plan_row`` and ``lay_row``, which the interpreter's batch kernels call row by
row, called here for one parent on arrays made once per batch. A kernel lays each split twice (its count
pass and its write pass), where the interpreter lays it once per batch, so the commonest forms are written
out with the same arithmetic in the same order, no call and no array: a split without repeat groups, and
a split with one (a window row ``{ ~w: Window | d: Wall }* | ~w: Window``; a split repeated as a whole is
one group). A split's pieces take their states in PRT's stream where their parent's stands after the pieces
before them.

``SplitWriter`` is a part of ``codegen._Writer``, whose ``put``, ``fresh``, ``check``, ``expr`` and ``child``
it writes with.
"""

from __future__ import annotations

from grammarc.backend.fusion.sites import Block, Scope
from grammarc.backend.kernels.split import MAX_COUNT, group_arrays
from grammarc.constants import TOL
from grammarc.ir import nodes as ir


class SplitWriter:
    """The writer's methods for CityEngine's ``split`` (mixed into ``codegen._Writer``)."""

    #: The dtypes of ``lay_row``'s columns of children: parent, part, position, length, index.
    _CHILD_TYPES = (", np.int64", ", np.int64", "", "", ", np.int64")

    def group_split(self, op: ir.GroupSplit, block: Block, scope: Scope, level: int, depth: int) -> None:
        """``splits.group_split`` for one parent: CityEngine's layout by the interpreter's own kernels
        (``kernels.split.plan_row`` and ``lay_row``, on arrays of one row made once per batch, the
        children's grown as a parent needs), negative sizes taken as 0 and a NaN one refused, parts of
        ``TOL.merge`` or less not made; then the children in order, each in its part's body."""
        kind, groups, n_groups = group_arrays(op)
        if n_groups <= 1:  # a group's parts are one run: it is written between braces
            self.written_out(op, kind.tolist(), groups.tolist(), block, scope, level, depth)
            return
        slots, parts = n_groups, len(op.sizes)  # the splits of fewer groups are written out above
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
            self.child(part, block, self.placed(scope, op.axis, f"{made[2]}[{c}]", f"{made[3]}[{c}]", inner + 2, key),
                       inner + 2, depth)

    def written_out(self, op: ir.GroupSplit, kind: list[int], groups: list[int], block: Block, scope: Scope,
                    level: int, depth: int) -> None:
        """``group_split`` of a split of no repeat group or one (``{ ~a: A | b: B }* | ~c: C``, or a split
        repeated as a whole), ``plan_row`` and ``lay_row`` written out (their arithmetic in their order, no
        call and no array per parent): the sizes outside the group and the group's own summed apart, fixed
        and floating; the group repeated (``repeated``); the floating sizes scaled to fill the extent; the
        parts laid end to end, each in place, the group's as often as it repeats."""
        extent, values = scope.size[op.axis], self.sizes(op, scope, level)
        self.put(level, "else:")
        level += 1
        inside = [j for j, g in enumerate(groups) if g >= 0]
        fixed, floating, scale, total = (self.fresh(stem) for stem in ("fx", "fl", "sc", "tt"))
        sums = [fixed, floating]
        if inside:
            nominal, group_fixed, group_float = (self.fresh(stem) for stem in ("nm", "gx", "gf"))
            sums += [nominal, group_fixed, group_float]
        for name in sums:
            self.put(level, f"{name} = 0.0")
        for value, k, g in zip(values, kind, groups):
            size = value
            if k == 1:  # relative: of the extent
                size = self.fresh("sz")
                self.put(level, f"{size} = {value} * {extent}")
            if g < 0:
                self.put(level, f"{floating if k == 2 else fixed} += {size}")
            else:
                self.put(level, f"{nominal} += {size}")
                self.put(level, f"{group_float if k == 2 else group_fixed} += {size}")
        self.put(level, f"{scale} = 1.0")
        self.put(level, f"{total} = 0.0")
        if inside:
            reps, gap = self.repeated(extent, fixed, floating, nominal, group_fixed, group_float, total, level)
        self.put(level, f"if {floating} > 0.0:")
        self.put(level + 1, f"{scale} = max({extent} - {fixed}, 0.0) / {floating}")
        for g in groups:
            self.put(level, f"{total} += {'1.0' if g < 0 else f'float({reps})'}")
        self.put(level, f"if not ({total} <= limit):")  # beyond --max-shapes: the interpreter fails it
        self.put(level + 1, "bad[i] = True")
        self.put(level, "else:")
        level += 1
        at, stream = self.fresh("at"), self.fresh("ks")
        self.put(level, f"{at} = 0.0")
        self.put(level, f"{stream} = {scope.key}")
        if not inside:
            self.lay(op, values, kind, range(len(values)), scale, at, stream, block, scope, level, depth)
            return
        self.lay(op, values, kind, range(inside[0]), scale, at, stream, block, scope, level, depth)
        self.put(level, f"for _ in range({reps}):")
        self.put(level + 1, "if n > limit:")
        self.put(level + 2, "break")
        self.lay(op, values, kind, inside, scale, at, stream, block, scope, level + 1, depth)
        self.put(level, f"{at} += {gap}")
        self.lay(op, values, kind, range(inside[-1] + 1, len(values)), scale, at, stream, block, scope, level, depth)

    def repeated(self, extent: str, fixed: str, floating: str, nominal: str, group_fixed: str, group_float: str,
                 total: str, level: int) -> tuple[str, str]:
        """``plan_row``'s repetitions of a split's one group, of ``nominal`` size (``group_fixed`` of it fixed,
        ``group_float`` floating) in what the sizes outside it leave (``fixed`` and ``floating``, which take
        its repetitions' share): as many as bring its floating parts nearest their written sizes
        (``repetitions``, PRT's rounding), or, all its sizes fixed, as many as fit, what is left a gap after
        them; one too small to lay counts into ``total`` what it would make. The variables of the count and
        the gap."""
        left, reps, gap, share, times = (self.fresh(stem) for stem in ("lf", "rp", "gp", "sh", "x"))
        self.put(level, f"{left} = max({extent} - {fixed} - {floating}, 0.0)")
        self.put(level, f"{reps} = 0")
        self.put(level, f"{gap} = 0.0")
        self.put(level, f"if {nominal} <= {TOL.zero!r}:")
        self.put(level + 1, f"if {nominal} > 0.0 and {left} > {TOL.zero!r}:")
        self.put(level + 2, f"{total} += {left} / {nominal}")
        self.put(level, "else:")
        self.put(level + 1, f"{share} = {left} * {nominal} / {nominal}")
        self.put(level + 1, f"if {share} == np.inf:")
        self.put(level + 2, f"{share} = {left} * ({nominal} / {nominal})")
        self.put(level + 1, f"if {group_float} > 0.0:")  # the floating ones outside are both loose and laid
        self.put(level + 2, f"{reps} = repetitions({share}, {nominal}, {group_fixed}, {group_float}, {floating}, "
                            f"{floating}, {TOL.zero!r})")
        self.put(level + 1, "else:")
        self.put(level + 2, f"{times} = np.floor({share} / {nominal} + 1e-9)")
        self.put(level + 2, f"{reps} = int({times}) if {times} < {MAX_COUNT} else {MAX_COUNT}")
        self.put(level + 2, f"{gap} = {share} - {reps} * {nominal}")
        self.put(level + 1, f"{fixed} += {reps} * {group_fixed} + {gap}")
        self.put(level + 1, f"{floating} += {reps} * {group_float}")
        return reps, gap

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

    def lay(self, op: ir.GroupSplit, values: list[str], kind: list[int], parts, scale: str, at: str, stream: str,
            block: Block, scope: Scope, level: int, depth: int) -> None:
        """``lay_row``'s parts ``parts`` (their numbers), each in place: its size (relative, floating times
        ``scale``, or absolute), cut at the extent, made if longer than ``TOL.merge``, its piece of PRT's
        stream, its body; then the next."""
        extent = scope.size[op.axis]
        for k in parts:
            value, part = values[k], op.parts[k]
            size, stop, length = (self.fresh(stem) for stem in ("sz", "st", "ln"))
            self.put(level, f"{size} = {f'{value} * {extent}' if kind[k] == 1 else f'{value} * {scale}' if kind[k] == 2 else value}")
            self.put(level, f"{stop} = min({at} + {size}, {extent})")
            self.put(level, f"if {stop} - {at} > {TOL.merge!r}:")
            self.put(level + 1, f"{length} = {stop} - {at}")
            self.child(part, block, self.placed(scope, op.axis, at, length, level + 1, self.piece(stream, level + 1)),
                       level + 1, depth)
            self.put(level, f"{at} += {size}")

    def piece(self, stream: str, level: int) -> str:
        """The state of a split's next piece (``prt_random.pieces``: where its parent's stream, ``stream``,
        stands after the pieces before it, then one draw), and the stream moved on: CityEngine's ``split``
        draws from PRT's stream, as its dialect does."""
        key = self.fresh("k")
        self.put(level, f"{key} = next_state(child_state({stream}))")
        self.put(level, f"{stream} = next_state({stream})")
        return key
