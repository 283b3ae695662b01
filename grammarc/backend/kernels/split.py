"""Split and repeat fan-out along one scope axis, for a whole batch of shapes.

Both kernels return the children of n parents as flat arrays ``parent`` (m,) int64, ``part`` (m,) int64,
``position`` (m,) float64 (offset of the child along the axis from the parent's origin) and ``length``
(m,) float64 (the child's size on the axis). They count first and allocate once.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.ir import nodes as ir


@njit(cache=True, nogil=True)
def subdiv(extent, values, relative, tol):
    """Sizes of ``Subdiv`` parts (paper section 2, "Basic split rule" and "Scaling of rules").

    extent : (n,) float64 scope size on the split axis; values : (n, P) or (1, P) float64 the sizes as
    written (one row for all shapes when they do not vary);
    relative : (P,) bool, True for ``r`` sizes; tol : float, parts of this length or less are dropped.

    A relative size r_i becomes r_i * (extent - sum(absolute)) / sum(r) (zero when the absolute sizes
    already fill the scope). Parts are laid end to end; a part that starts beyond the scope is dropped and
    the last one is cut at the scope's end, as CityEngine does.
    """
    n = len(extent)
    count = values.shape[1]
    shared = values.shape[0] == 1
    keep = np.zeros((n, count), np.bool_)
    pos = np.zeros((n, count))
    length = np.zeros((n, count))
    total = 0
    for i in range(n):
        row = 0 if shared else i
        absolute = 0.0
        rel = 0.0
        for j in range(count):
            if relative[j]:
                rel += values[row, j]
            else:
                absolute += values[row, j]
        free = extent[i] - absolute
        free = max(free, 0.0)
        at = 0.0
        for j in range(count):
            if relative[j]:
                size = values[row, j] * free / rel if rel > 0.0 else 0.0
            else:
                size = values[row, j]
            end = at + size
            end = min(end, extent[i])
            if end - at > tol:
                keep[i, j] = True
                pos[i, j] = at
                length[i, j] = end - at
                total += 1
            at = at + size
    parent = np.empty(total, np.int64)
    part = np.empty(total, np.int64)
    out_pos = np.empty(total)
    out_len = np.empty(total)
    m = 0
    for i in range(n):
        for j in range(count):
            if keep[i, j]:
                parent[m] = i
                part[m] = j
                out_pos[m] = pos[i, j]
                out_len[m] = length[i, j]
                m += 1
    return parent, part, out_pos, out_len


#: The count a fan-out reports for more elements than int64 holds (or a NaN number of them): far beyond
#: any --max-shapes, so the caller's limit check fails the shape's lot before anything is allocated.
MAX_COUNT = 2**62


@njit(cache=True, nogil=True)
def _count(x):
    """floor(x) as an int64 count, ``MAX_COUNT`` for more (or NaN): casting those is undefined."""
    if x < MAX_COUNT:
        return int(x)
    return MAX_COUNT


@njit(cache=True, nogil=True)
def repeat_counts(extent, size, tol):
    """Elements of ``Repeat``: ceil(extent / size) per shape (paper section 2, "Repeat"), (n,) int64,
    ``MAX_COUNT`` where that overflows.

    A scope of zero extent has no element. ``size`` must be positive (the caller checks).
    """
    n = len(extent)
    counts = np.zeros(n, np.int64)
    for i in range(n):
        if extent[i] > tol:
            counts[i] = max(_count(np.ceil(extent[i] / size[i] - 1e-9)), 1)
    return counts


@njit(cache=True, nogil=True)
def repeat(extent, counts):
    """Children of ``Repeat``: each shape's extent cut into counts[i] equal elements.

    extent : (n,) float64; counts : (n,) int64 from ``repeat_counts``.
    Returns parent, part (the element's index), position and length, each (sum(counts),).
    """
    total = 0
    for i in range(len(counts)):
        total += counts[i]
    parent = np.empty(total, np.int64)
    part = np.empty(total, np.int64)
    pos = np.empty(total)
    length = np.empty(total)
    m = 0
    for i in range(len(counts)):
        c = counts[i]
        if c == 0:
            continue
        step = extent[i] / c
        for j in range(c):
            parent[m] = i
            part[m] = j
            pos[m] = j * step
            length[m] = step
            m += 1
    return parent, part, pos, length



@njit(cache=True, nogil=True)
def group_counts(extent, values, kind, group, n_groups, tol):
    """How CityEngine's ``split`` with absolute, relative and floating sizes and repeat groups lays its
    parts, before any child is made: the first half of ``group_split``.

    extent : (n,) float64; values : (n, P) or (1, P) float64 the sizes as written; kind : (P,) int64,
    0 absolute, 1 relative (a fraction of the extent), 2 floating (``~``); group : (P,) int64 the repeat
    group of each part, -1 for none; n_groups : int.

    The rule (grammarc's reading of CityEngine's, fitted to PRT): what the fixed parts and the floating
    parts outside groups leave at their written sizes goes to the groups. Two or more groups, each with
    floating parts, take repetitions in turns (``_turns``: PRT lays candler's
    ``1 | 3.55 | {~3.55}* | 3.55 | {~3.55}* | 3.55 | 1`` with 3 then 2 repetitions on 30 m, 2 and 2 on
    25 m, 1 and 1 on 20 m, 1 then 0 on 15 m). Otherwise the groups take it in order, each a share of what
    the earlier ones left in proportion to its repetition's size among the groups still to come. A
    group with floating parts repeats as often as brings the floating parts nearest their written sizes
    (``repetitions``) and uses that many repetitions' room (``{ ~w: A | d: B }* | ~w: A`` on an extent
    of w is one A). A group of fixed sizes repeats floor(share / repetition) times, the rest of its share
    left empty at its end. Then every floating size, in groups or not, is scaled by one factor so that
    the parts fill the extent.

    Returns reps (n, max(n_groups, 1)) int64 each group's repetitions (``MAX_COUNT`` beyond int64), gap
    (n, max(n_groups, 1)) float64 the room left at a group's end, scale (n,) float64 the floating sizes'
    factor, and count (n,) float64 the parts each shape lays, and those a repetition too small to lay
    (of at most ``tol``) would make: what the caller checks against --max-shapes before ``group_split``
    allocates them (an upper bound: parts of length <= tol are dropped).
    """
    n = len(extent)
    slots = max(n_groups, 1)
    reps = np.zeros((n, slots), np.int64)
    gap = np.zeros((n, slots))
    scale = np.ones(n)
    total = np.zeros(n)
    # each shape's sums by group, in arrays used again shape after shape
    nominal = np.zeros(slots)
    group_fixed = np.zeros(slots)
    group_float = np.zeros(slots)
    for i in range(n):
        plan_row(i, extent[i], values, 0 if values.shape[0] == 1 else i, kind, group, n_groups, tol, reps, gap,
                 scale, total, nominal, group_fixed, group_float)
    return reps, gap, scale, total


@njit(cache=True, nogil=True)
def plan_row(i, extent, values, row, kind, group, n_groups, tol, reps, gap, scale, total, nominal, group_fixed,
             group_float):
    """``group_counts`` of one shape: its row ``i`` of ``reps``, ``gap``, ``scale`` and ``total`` laid out
    for an ``extent`` and the sizes of row ``row`` of ``values``; ``nominal``, ``group_fixed`` and
    ``group_float`` (max(n_groups, 1),) are room for its sums. A fused kernel calls it on its own arrays
    of one row, made once (``fusion.codegen``)."""
    count = values.shape[1]
    for g in range(len(nominal)):  # a loop, not slices: a slice's view costs as much as this row's layout
        reps[i, g] = 0
        gap[i, g] = 0.0
        nominal[g] = 0.0
        group_fixed[g] = 0.0
        group_float[g] = 0.0
    scale[i] = 1.0
    total[i] = 0.0
    fixed = 0.0
    floating = 0.0
    for j in range(count):
        size = values[row, j] * extent if kind[j] == 1 else values[row, j]
        g = group[j]
        if g < 0:
            if kind[j] == 2:
                floating += size
            else:
                fixed += size
        else:
            nominal[g] += size
            if kind[j] == 2:
                group_float[g] += size
            else:
                group_fixed[g] += size
    avail = extent - fixed - floating
    loose = floating
    if _in_turns(nominal, group_float, n_groups, tol):
        parts = 0
        for j in range(count):
            size = values[row, j] * extent if kind[j] == 1 else values[row, j]
            parts += size > tol
        _turns(max(avail, 0.0), loose, nominal, group_fixed, group_float, n_groups, parts, tol, reps, i)
        for g in range(n_groups):
            fixed += reps[i, g] * group_fixed[g]
            floating += reps[i, g] * group_float[g]
        if floating > 0.0:
            scale[i] = max(extent - fixed, 0.0) / floating
        for j in range(count):
            g = group[j]
            total[i] += 1.0 if g < 0 else float(reps[i, g])
        return
    # the groups in order, each sharing what the earlier ones left with the later ones
    left = max(avail, 0.0)
    later = 0.0
    for g in range(n_groups):
        later += nominal[g]
    for g in range(n_groups):
        if nominal[g] <= tol:
            # a repetition too small to lay repeats nothing, but counts as the parts it would make:
            # its lot fails if they are more than --max-shapes (one of no size makes none)
            if nominal[g] > 0.0 and left > tol:
                total[i] += left / nominal[g]
            continue
        share = left * nominal[g] / later
        if share == np.inf:  # left * nominal overflowed (a size near float64's largest)
            share = left * (nominal[g] / later)
        later -= nominal[g]
        if group_float[g] > 0.0:
            r = repetitions(share, nominal[g], group_fixed[g], group_float[g], loose, floating, tol)
            left = max(left - r * nominal[g], 0.0)
        else:
            r = _count(np.floor(share / nominal[g] + 1e-9))
            gap[i, g] = share - r * nominal[g]
            left -= share
        reps[i, g] = r
        fixed += r * group_fixed[g] + gap[i, g]
        floating += r * group_float[g]
    if floating > 0.0:
        scale[i] = max(extent - fixed, 0.0) / floating
    for j in range(count):
        g = group[j]
        total[i] += 1.0 if g < 0 else float(reps[i, g])


@njit(cache=True, nogil=True)
def group_split(extent, values, kind, group, reps, gap, scale, count, tol):
    """Parts of CityEngine's ``split``, laid as ``group_counts`` planned them (its ``reps``, ``gap``,
    ``scale`` and ``count``; the other arguments as it was given). Parts are laid end to end; parts
    beyond the extent are dropped, the last one cut; parts of length <= tol are dropped.

    Returns parent, part (index into the P parts), position, length (m,) and index (m,) int64, the
    child's number within its parent.
    """
    n = len(extent)
    total = 0
    for i in range(n):
        total += int(count[i])
    parent = np.empty(total, np.int64)
    part = np.empty(total, np.int64)
    pos = np.empty(total)
    length = np.empty(total)
    index = np.empty(total, np.int64)
    m = 0
    for i in range(n):
        m = lay_row(i, extent[i], values, 0 if values.shape[0] == 1 else i, kind, group, reps, gap, scale, tol,
                    parent, part, pos, length, index, m)
    return parent[:m], part[:m], pos[:m], length[:m], index[:m]


@njit(cache=True, nogil=True)
def lay_row(i, extent, values, row, kind, group, reps, gap, scale, tol, parent, part, pos, length, index, m):
    """``group_split`` of one shape: the parts of row ``i`` of the plan (``plan_row``) on an ``extent``,
    sizes from row ``row`` of ``values``, written from ``m`` on into ``parent``...``index`` (which have
    room for the plan's ``total``); returns where the next shape's parts go."""
    parts = values.shape[1]
    at = 0.0
    child = 0
    j = 0
    while j < parts:
        # a part outside the groups once, a group's parts as often as it repeats, then the room left at its end
        g = group[j]
        end = j + 1
        while g >= 0 and end < parts and group[end] == g:
            end += 1
        for _ in range(1 if g < 0 else reps[i, g]):
            for k in range(j, end):
                # written out here, not called: a call per part (even one numba inlines) costs it several times
                value = values[row, k]
                size = value * extent if kind[k] == 1 else (value * scale[i] if kind[k] == 2 else value)
                stop = min(at + size, extent)  # cut at the extent; dropped if empty
                if stop - at > tol:
                    parent[m] = i
                    part[m] = k
                    pos[m] = at
                    length[m] = stop - at
                    index[m] = child
                    m += 1
                    child += 1
                at += size
        if g >= 0:
            at += gap[i, g]
        j = end
    return m


@njit(cache=True, nogil=True)
def _in_turns(nominal, group_float, n_groups, tol):
    """Whether a split's groups take their repetitions in turns (``_turns``): two or more groups, each
    with floating parts and a repetition longer than ``tol``."""
    if n_groups < 2:
        return False
    for g in range(n_groups):
        if group_float[g] <= 0.0 or nominal[g] <= tol:
            return False
    return True


@njit(cache=True, nogil=True)
def _turns(room, loose, nominal, fixed, floating, n_groups, parts, tol, reps, i):
    """Repetitions of two or more floating repeat groups that share ``room`` (what the parts outside the
    groups leave at their written sizes; ``loose`` the floating ones among those), written into ``reps``.

    The groups take repetitions in turns, in written order, the first group the first one (or, beside
    floating parts outside the groups, none until it is worth it); the next one is taken while it leaves
    the floating parts' stretch nearer 1 than before, measured as ``_unevenness`` says. This is PRT's
    rule as measured on candler's ``1 | t | {~t}* | t | {~t}* | t | 1`` (the counts depend only on the
    room in repetitions, R): the n-th repetition over 2m comes at R = n + (8/7) n / (2n + 1) and the one
    that evens the groups at R = n + (6n - 1) / (7 (2n + 1)), thresholds 23/18, 86/35, 164/49, 284/63,
    ...; without the corner walls the 7 becomes 5, the split's parts of positive size. Counts beyond
    int64 are ``MAX_COUNT`` (the caller fails the lot).
    """
    for g in range(n_groups):
        reps[i, g] = 0
    if room <= tol:
        return
    cycle = 0.0
    for g in range(n_groups):
        cycle += nominal[g]
    rounds = np.floor(room / cycle) - 1.0
    if rounds >= MAX_COUNT:
        for g in range(n_groups):
            reps[i, g] = MAX_COUNT
        return
    turn = 0
    if rounds >= 1.0:
        for g in range(n_groups):
            reps[i, g] = int(rounds)
    elif loose <= 0.0:
        reps[i, 0] = 1
        turn = 1
    best = _unevenness(room, loose, nominal, fixed, floating, n_groups, parts, reps, i)
    while True:
        reps[i, turn] += 1
        off = _unevenness(room, loose, nominal, fixed, floating, n_groups, parts, reps, i)
        if off > best + 1e-9:
            reps[i, turn] -= 1
            return
        best = off
        turn = (turn + 1) % n_groups


@njit(cache=True, nogil=True)
def _unevenness(room, loose, nominal, fixed, floating, n_groups, parts, reps, i):
    """How far the repetitions in row i of ``reps`` leave the floating parts from their written sizes: |stretch - 1|,
    plus, where the groups' counts differ, a share of a repetition (of the first group) per floating
    length, 1 / parts of it, or 1 / (2 (parts - 1)) where a group has none (PRT, measured on candler;
    ``parts`` the split's parts of positive size). Infinite where no floating part is laid."""
    laid = loose
    kept = 0.0
    low = reps[i, 0]
    high = reps[i, 0]
    for g in range(n_groups):
        laid += reps[i, g] * floating[g]
        kept += reps[i, g] * fixed[g]
        low = min(low, reps[i, g])
        high = max(high, reps[i, g])
    if laid <= 0.0:
        return np.inf
    off = abs((room + loose - kept) / laid - 1.0)
    if high > low:
        off += nominal[0] / (2.0 * (parts - 1) if low == 0 else float(parts)) / laid
    return off


@njit(cache=True, nogil=True)
def repetitions(share, nominal, fixed, floating, loose, laid, tol):
    """How often a group with floating parts repeats in ``share``: the count that brings the floating
    parts nearest their written sizes, as the reference has a floating repeat come "closest" to them.
    With r repetitions every floating part, in the group (``floating`` of its ``nominal`` size, ``fixed``
    the rest) or outside the groups (``loose``, their written size), stretches by
    (share + loose - r fixed) / (loose + r floating), which is 1 at r = share / nominal; of the counts
    either side, the one whose stretch is nearer 1 (the difference, not the ratio) wins, the more on a
    tie. PRT's thresholds: ``{~f}*`` goes from r to r + 1 repetitions at 2r(r + 1) / (2r + 1)
    repetitions' room (4/3, 12/5, 24/7), complexpatterns' ``~g | {~f}*`` from none to one where
    E / g - 1 = 1 - E / (g + f). A share of less than one repetition gives one where no floating part was
    laid before the group; where some were (``laid``: those outside the groups and the earlier groups'
    repetitions), one only if that stretches them and the group's own nearer 1 than none."""
    if share <= tol:
        return 0
    r = _count(np.floor(share / nominal))
    if r == MAX_COUNT:
        return r
    if r == 0:
        if laid <= 0.0:
            return 1
        loose = laid
    room = share + loose
    below = abs((room - r * fixed) / (loose + r * floating) - 1.0)
    above = abs((room - (r + 1) * fixed) / (loose + (r + 1) * floating) - 1.0)
    return r + 1 if above < below + 1e-9 else r


@njit(cache=True, nogil=True)
def snap_subdiv(parent, pos, length, offsets, snaps):
    """Subdiv children moved to snap planes (paper section 3.3, Fig. 9 right): each snap position of a
    parent moves the line between two of its consecutive children nearest to it there, if both keep a
    positive length; a line two snaps would move goes to the nearer. ``parent``, ``pos``, ``length``
    (m,) the children, grouped by parent in order; ``offsets`` (n+1,) and ``snaps`` (k,) each parent's
    sorted positions. Changes pos and length in place."""
    m = len(parent)
    best = np.full(m, np.inf)  # per line (after child c): distance and position of its nearest snap
    target = np.zeros(m)
    c = 0
    while c < m:
        p = parent[c]
        end = c
        while end < m and parent[end] == p:
            end += 1
        for s in range(offsets[p], offsets[p + 1]):
            t = snaps[s]
            line = -1
            for k in range(c, end - 1):  # the line between child k and k + 1
                d = abs(pos[k] + length[k] - t)
                if line < 0 or d < abs(pos[line] + length[line] - t):
                    line = k
            if line >= 0 and pos[line] < t < pos[line + 1] + length[line + 1]:
                d = abs(pos[line] + length[line] - t)
                if d < best[line]:
                    best[line] = d
                    target[line] = t
        for k in range(c, end - 1):
            if best[k] < np.inf:
                right = pos[k + 1] + length[k + 1]
                length[k] = target[k] - pos[k]
                pos[k + 1] = target[k]
                length[k + 1] = right - target[k]
        c = end


#: ``group_counts``' codes of a CityEngine split's size kinds.
SIZE_KINDS = {ir.SizeKind.ABSOLUTE: 0, ir.SizeKind.RELATIVE: 1, ir.SizeKind.FLOATING: 2}


def group_arrays(op: ir.GroupSplit) -> tuple[np.ndarray, np.ndarray, int]:
    """What ``group_counts`` (and ``plan_row``) take of ``op``: the kind of each part's size (P,) int64
    (``SIZE_KINDS``), its repeat group (P,) int64 (-1 outside any; all one group where the whole split
    repeats) and the number of groups."""
    groups = np.array(op.groups, dtype=np.int64)
    if op.repeat:
        groups = np.zeros_like(groups)
    return (np.array([SIZE_KINDS[s.kind] for s in op.sizes], dtype=np.int64), groups,
            int(groups.max()) + 1 if len(groups) else 0)
