"""backend/kernels/split.py ``group_counts`` and ``group_split``: CityEngine's split with ``'``, ``~`` sizes and repeat groups.

Layouts are computed by hand from the kernel's rule (its docstring): fixed parts and floating parts outside
groups keep their written sizes while the groups share what is left: two or more floating groups take
repetitions in turns (PRT's counts on candler's wide floor), otherwise in proportion to one repetition's
size, in order, each from what the earlier ones left; a group with floating parts repeats as often as
brings the floating parts' stretch nearest 1 (those outside the groups, the earlier groups' repetitions and
its own; at least once when room is left and no floating part is laid before it), a group of fixed sizes floor(share / repetition) times with the rest of its share left empty; then
one factor scales every floating size so that the parts fill the extent. A plain Python reference of the
same rule checks random batches.
"""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend.kernels.split import MAX_COUNT, group_counts, group_split

ABS, REL, FLT = 0, 1, 2
TOL = 1e-9


def split_parts(extent, values, kind, group, n_groups, tol):
    """The parts as the operation makes them: counted (``group_counts``), then laid (``group_split``)."""
    return group_split(extent, values, kind, group, *group_counts(extent, values, kind, group, n_groups, tol), tol)


def layout(extent, sizes, groups=None, kinds=None, rows=None):
    """Run the kernel on one shape of ``extent``: [(part, position, length, index), ...].

    ``sizes`` are written as CityEngine does: a number is absolute, ``"'0.5"`` relative, ``"~3"``
    floating; ``groups`` gives each part's repeat group (-1 or None: none).
    """
    values, kind = _parse(sizes)
    if kinds is not None:
        kind = np.array(kinds, np.int64)
    group = np.array([-1 if g is None else g for g in (groups or [-1] * len(sizes))], np.int64)
    n_groups = int(group.max()) + 1 if len(group) else 0
    parent, part, pos, length, index = split_parts(np.array([extent], float), values[None, :], kind,
                                                   group, n_groups, TOL)
    assert (parent == 0).all()
    return list(zip(part.tolist(), pos.tolist(), length.tolist(), index.tolist()))


def _parse(sizes):
    values, kind = [], []
    for s in sizes:
        if isinstance(s, str) and s[0] in "'~":
            values.append(float(s[1:]))
            kind.append(REL if s[0] == "'" else FLT)
        else:
            values.append(float(s))
            kind.append(ABS)
    return np.array(values, float), np.array(kind, np.int64)


def assert_layout(got, want):
    """``want``: [(part, length), ...] laid end to end from 0, or (part, position, length) triples."""
    assert [g[0] for g in got] == [w[0] for w in want], got
    assert [g[3] for g in got] == list(range(len(want)))
    at = 0.0
    for g, w in zip(got, want):
        pos, length = (w[1], w[2]) if len(w) == 3 else (at, w[1])
        assert g[1] == pytest.approx(pos, abs=1e-9), got
        assert g[2] == pytest.approx(length, abs=1e-9), got
        at = pos + length


# --------------------------------------------------------------------------------------- absolute and '


def test_absolute_sizes_end_to_end():
    assert_layout(layout(12, [3, 4, 5]), [(0, 3), (1, 4), (2, 5)])


def test_absolute_sizes_beyond_the_extent_are_cut_then_dropped():
    # 3 | 4 | 5 | 2 on 10: the third part is cut at 10, the fourth starts beyond the extent
    assert_layout(layout(10, [3, 4, 5, 2]), [(0, 3), (1, 4), (2, 3)])
    # a first part longer than the extent is cut, the rest dropped
    assert_layout(layout(2.5, [3, 4]), [(0, 2.5)])


def test_absolute_sizes_short_of_the_extent_leave_the_rest_empty():
    assert_layout(layout(10, [2, 3]), [(0, 2), (1, 3)])


def test_relative_sizes_are_fractions_of_the_extent():
    # '0.25 | 2 | '0.5 on 12: 3, 2, 6 (one metre left empty)
    assert_layout(layout(12, ["'0.25", 2, "'0.5"]), [(0, 3), (1, 2), (2, 6)])


def test_parts_of_zero_length_are_dropped_and_not_numbered():
    got = layout(10, [5, 0, 5])
    assert_layout(got, [(0, 0, 5), (2, 5, 5)])


# ------------------------------------------------------------------------------------------------ ~ sizes


def test_floating_sizes_share_the_rest_in_proportion():
    # 2 | ~1 | ~3 on 10: the floating parts take the 8 left, 1:3
    assert_layout(layout(10, [2, "~1", "~3"]), [(0, 2), (1, 2), (2, 6)])


def test_floating_sizes_shrink_to_fill_the_extent():
    # ~6 | ~6 | 2 on 8: the two floating parts shrink to 3 each
    assert_layout(layout(8, ["~6", "~6", 2]), [(0, 3), (1, 3), (2, 2)])


def test_floating_sizes_vanish_when_the_fixed_parts_fill_the_extent():
    # 8 | ~1 | 8 on 10: nothing left for the floating part; the last fixed part is cut
    assert_layout(layout(10, [8, "~1", 8]), [(0, 0, 8), (2, 8, 2)])


# ------------------------------------------------------------------------------------------ repeat groups


@pytest.mark.parametrize("extent, reps", [(10, 3), (11, 4), (9, 3), (3.9, 1), (4.1, 2), (7.1, 2), (7.3, 3),
                                          (1, 1)])
def test_floating_repeat_group_rounds_and_fills(extent, reps):
    """{ ~3 : A }*: the count whose stretch is nearest 1 (at least one), stretched to fill the extent, as
    PRT counts: 4.1 m is 1.37 repetitions, 2 stretched by 0.68 (0.32 from 1) rather than 1 by 1.37 (0.37
    from 1); from r to r + 1 at 2r(r + 1) / (2r + 1) repetitions: 4/3, 12/5 (7.2 m)."""
    got = layout(extent, ["~3"], groups=[0])
    assert_layout(got, [(0, extent / reps)] * reps)


def test_floating_repeat_group_without_room_makes_nothing():
    # 8 | { ~3 }* on 8: no room for a repetition
    assert_layout(layout(8, [8, "~3"], groups=[-1, 0]), [(0, 8)])
    # on 8.5 there is room for one, shrunk to 0.5
    assert_layout(layout(8.5, [8, "~3"], groups=[-1, 0]), [(0, 8), (1, 0.5)])


def test_floating_repeat_group_may_vanish_beside_a_floating_part():
    # candler's Windows(1): { ~w : Window | 0.25 : Wall }* | ~w : Window on an extent of w is one window
    # (PRT), the floating part outside the group taking the room
    assert_layout(layout(1.2, ["~1.2", 0.25, "~1.2"], groups=[0, 0, -1]), [(2, 0, 1.2)])
    # with room for it, the group repeats: two windows and the divider
    assert_layout(layout(2.15, ["~1.075", 0.25, "~1.075"], groups=[0, 0, -1]),
                  [(0, 0, 0.95), (1, 0.95, 0.25), (2, 1.2, 0.95)])


def test_floating_repeat_groups_take_their_shares_in_order():
    # candler's wide floor, 1 | 3.55 | {~3.55}* | 3.55 | {~3.55}* | 3.55 | 1, as PRT lays it: on 15 m
    # one repetition, in the first group (six windows a floor on the triangle's front); on 20 m one in
    # each; on 25 m two in each; on 30 m three (2.44 repetitions' share), then two from the 6.7 m the
    # first left (PRT's centre tile from 14.96 to 18.51 m)
    parts, groups = [1, 3.55, "~3.55", 3.55, "~3.55", 3.55, 1], [-1, -1, 0, -1, 1, -1, -1]
    assert [p for p, *_ in layout(15, parts, groups=groups)] == [0, 1, 2, 3, 5, 6]
    assert [p for p, *_ in layout(20, parts, groups=groups)] == [0, 1, 2, 3, 4, 5, 6]
    assert [p for p, *_ in layout(25, parts, groups=groups)] == [0, 1, 2, 2, 3, 4, 4, 5, 6]
    thirty = layout(30, parts, groups=groups)
    assert [p for p, *_ in thirty] == [0, 1, 2, 2, 2, 3, 4, 4, 5, 6]
    assert thirty[5][1] == pytest.approx(14.96)


def test_floating_repeat_group_after_one_that_rounded_up_stretches_its_floating_parts_too():
    """candler's wide floor on a 17.21 m facade (the conformance case candler.convex.3084: corner walls of
    1.811 m, tiles of 3.293 m) leaves 3.709 m, 1.13 repetitions, to the two groups. The first takes its
    1.85 m share as one tile; the second would stretch that tile and its own to 0.56 of their size with a
    repetition, to 1.13 without: PRT lays four tiles, not five."""
    parts = [1.811, 3.293, "~3.293", 3.293, "~3.293", 3.293, 1.811]
    got = layout(17.2103, parts, groups=[-1, -1, 0, -1, 1, -1, -1])
    assert [p for p, *_ in got] == [0, 1, 2, 3, 5, 6]
    assert got[2][2] == pytest.approx(17.2103 - 2 * 1.811 - 3 * 3.293)


def test_floating_repeat_group_after_one_that_rounded_up_keeps_its_own_count():
    """candler.L.7086's 27.66 m rear facade (corner walls of 1.582 m, tiles of 3.815 m) leaves 3.42
    repetitions: the first group rounds its 1.71 up to 2, the second its 1.42 up to 2 as well (PRT lays
    seven tiles), though the four repetitions stretch all tiles further from their size than three."""
    parts = [1.582, 3.815, "~3.815", 3.815, "~3.815", 3.815, 1.582]
    got = layout(27.66, parts, groups=[-1, -1, 0, -1, 1, -1, -1])
    assert [p for p, *_ in got] == [0, 1, 2, 2, 3, 4, 4, 5, 6]


@pytest.mark.parametrize("corner, thresholds", [
    # PRT's counts on candler's wide floor swept finely (tiles of 3.55 m, 5 m; corner walls of 1 m, 2.5 m:
    # the same rooms in repetitions), each threshold the room where the next repetition comes
    (1.0, [(0.1667, (1, 1), (1, 0)), (23 / 18, (1, 0), (1, 1)), (86 / 35, (1, 1), (2, 1)),
           (164 / 49, (2, 1), (2, 2)), (284 / 63, (2, 2), (3, 2)), (414 / 77, (3, 2), (3, 3)),
           (594 / 91, (3, 3), (4, 3)), (776 / 105, (4, 3), (4, 4)), (1250 / 133, (5, 4), (5, 5))]),
    # without corner walls the split has five parts of positive size, not seven
    (0.0, [(5 / 4, (1, 0), (1, 1)), (62 / 25, (1, 1), (2, 1)), (116 / 35, (2, 1), (2, 2)),
           (68 / 15, (2, 2), (3, 2))]),
])
def test_floating_repeat_groups_take_repetitions_in_turns(corner, thresholds):
    """Two floating groups in one split, ``c | t | {~t}* | t | {~t}* | t | c``: the groups take the
    repetitions in turns, the first group first, as PRT lays them (the fixed tiles and corner walls do not
    change where, only the room R left to the groups in repetitions of t and the number of parts)."""
    tile = 3.55
    parts, groups = [corner, tile, f"~{tile}", tile, f"~{tile}", tile, corner], [-1, -1, 0, -1, 1, -1, -1]

    def counts(room):
        got = [p for p, *_ in layout(2 * corner + 3 * tile + room * tile, parts, groups=groups)]
        return got.count(2), got.count(4)

    for room, below, above in thresholds:
        assert counts(room - 1e-4) == below, room
        assert counts(room + 1e-4) == above, room
    assert counts(40.6) == (21, 20)  # PRT: the 41st repetition at R = 40.5644


def test_floating_repeat_group_on_a_tie_takes_the_more_repetitions():
    """The kit's rotated 25 x 15 lot with tiles of 3 m: the 15 m side leaves 4 m, 4/3 repetitions; the
    second group stretches by 4/3 without a repetition and by 2/3 with one, and PRT lays one in each."""
    parts, groups = [1, 3, "~3", 3, "~3", 3, 1], [-1, -1, 0, -1, 1, -1, -1]
    assert [p for p, *_ in layout(15, parts, groups=groups)] == [0, 1, 2, 3, 4, 5, 6]


def test_floating_repeat_group_beside_a_floating_part_takes_the_count_nearest_its_size():
    """complexpatterns' facade, ~g | {~f}*: none or one repetition, whichever stretches every floating
    part nearer 1; PRT's threshold is where E / g - 1 = 1 - E / (g + f), 4 m for g = f = 3."""
    assert [p for p, *_ in layout(3.95, ["~3", "~3"], groups=[-1, 0])] == [0]
    assert_layout(layout(4.05, ["~3", "~3"], groups=[-1, 0]), [(0, 2.025), (1, 2.025)])
    # the conformance case: 5.759 m, g = 4.182, f = 4.358 gives two floors (one would stretch by 1.377)
    assert [p for p, *_ in layout(5.759, ["~4.182", "~4.358"], groups=[-1, 0])] == [0, 1]


def test_absolute_repeat_group_floors_and_leaves_the_rest_empty():
    # { 3 }* on 10: three parts, one metre empty at the end
    assert_layout(layout(10, [3], groups=[0]), [(0, 3)] * 3)
    # 1 | { 3 }* | 1 on 10: two repetitions; the group's rest (2) stays empty before the last part
    assert_layout(layout(10, [1, 3, 1], groups=[-1, 0, -1]),
                  [(0, 0, 1), (1, 1, 3), (1, 4, 3), (2, 9, 1)])


def test_absolute_repeat_group_too_long_for_the_extent_makes_nothing():
    assert_layout(layout(2, [3], groups=[0]), [])


def test_mixed_repeat_group_scales_only_its_floating_sizes():
    """{ ~1 : A | 0.2 : B }* on 10: round(10 / 1.2) = 8 repetitions; A takes (10 - 8 * 0.2) / 8."""
    a = (10 - 8 * 0.2) / 8
    assert_layout(layout(10, ["~1", 0.2], groups=[0, 0]), [(0, a), (1, 0.2)] * 8)


def test_floating_parts_outside_a_group_keep_their_written_size_for_the_count():
    """~2 | { ~3 }* on 21: the group gets 19, round(19 / 3) = 6; one factor 21 / 20 for all ~ sizes."""
    f = 21 / 20
    assert_layout(layout(21, ["~2", "~3"], groups=[-1, 0]), [(0, 2 * f)] + [(1, 3 * f)] * 6)


def test_relative_sizes_inside_a_group_are_fixed():
    # { '0.1 }* on 10: ten parts of 1
    assert_layout(layout(10, ["'0.1"], groups=[0]), [(0, 1)] * 10)


def test_whole_split_repeat_is_one_group():
    """split(x){ 2 : A | ~1 : B }* on 10 is one group around all parts: round(10 / 3) = 3 repetitions."""
    b = (10 - 3 * 2) / 3
    assert_layout(layout(10, [2, "~1"], groups=[0, 0]), [(0, 2), (1, b)] * 3)


# ------------------------------------------------------------------------------------------- batches


def test_no_shapes():
    out = split_parts(np.zeros(0), np.ones((1, 2)), np.array([ABS, FLT], np.int64),
                      np.array([-1, 0], np.int64), 1, TOL)
    assert [len(a) for a in out] == [0] * 5
    assert out[0].dtype == np.int64 and out[2].dtype == np.float64 and out[4].dtype == np.int64


def test_one_shape_and_no_parts():
    out = split_parts(np.array([10.0]), np.zeros((1, 0)), np.zeros(0, np.int64), np.zeros(0, np.int64), 0,
                      TOL)
    assert [len(a) for a in out] == [0] * 5


def test_one_row_of_values_serves_every_shape_like_one_row_each():
    extent = np.array([10.0, 11.0, 4.4, 0.0, 30.0])
    kind = np.array([ABS, FLT, ABS], np.int64)
    group = np.array([-1, 0, -1], np.int64)
    shared = split_parts(extent, np.array([[1.0, 3.0, 1.0]]), kind, group, 1, TOL)
    per_shape = split_parts(extent, np.tile([1.0, 3.0, 1.0], (5, 1)), kind, group, 1, TOL)
    for a, b in zip(shared, per_shape):
        np.testing.assert_array_equal(a, b)
    # the shape of zero extent makes nothing; the others are in parent order
    assert 3 not in shared[0] and (np.diff(shared[0]) >= 0).all()


def test_values_per_shape_are_read_per_row():
    extent = np.array([10.0, 10.0])
    values = np.array([[2.0, 1.0], [5.0, 1.0]])
    parent, _, pos, length, index = split_parts(extent, values, np.array([ABS, FLT], np.int64),
                                                np.array([-1, -1], np.int64), 0, TOL)
    np.testing.assert_array_equal(parent, [0, 0, 1, 1])
    np.testing.assert_allclose(length, [2, 8, 5, 5])
    np.testing.assert_allclose(pos, [0, 2, 0, 5])
    np.testing.assert_array_equal(index, [0, 1, 0, 1])


def stretch_nearest_one(share, nominal, g_fixed, g_float, loose, laid, tol):
    """The repetition count whose floating parts' stretch is nearest 1, by search over every count (none
    only beside floating parts laid before; below one repetition's room those count with theirs)."""
    if share <= tol:
        return 0
    if share < nominal:
        loose = laid

    def off(n):
        return abs((share + loose - n * g_fixed) / (loose + n * g_float) - 1)

    return min(reversed(range(0 if loose > 0 else 1, int(share / nominal) + 3)), key=off)


def turns(room, loose, nominal, g_fixed, g_float, parts, tol):
    """Repetitions of two or more floating groups: the chain (1, 0, ..), (1, 1, ..), (2, 1, ..) .. (from
    (0, 0, ..) beside floating parts outside the groups) walked while the stretch's distance from 1, plus
    the uneven counts' share of the first group's repetition, does not grow."""
    if room <= tol:
        return [0] * len(nominal)

    def off(reps):
        laid = loose + sum(r * f for r, f in zip(reps, g_float))
        if laid <= 0:
            return np.inf
        uneven = 0.0 if min(reps) == max(reps) else nominal[0] / (2 * (parts - 1) if min(reps) == 0 else parts)
        return abs((room + loose - sum(r * f for r, f in zip(reps, g_fixed))) / laid - 1) + uneven / laid

    reps, turn = [0] * len(nominal), 0
    if loose <= 0:
        reps[0], turn = 1, 1 % len(nominal)
    while True:
        more = list(reps)
        more[turn] += 1
        if off(more) > off(reps) + 1e-9:
            return reps
        reps, turn = more, (turn + 1) % len(nominal)


def reference(extent, values, kind, group, n_groups, tol):
    """The docstring's rule in plain Python, one shape at a time."""
    out = []
    for i, e in enumerate(extent):
        row = values[0 if len(values) == 1 else i]
        size = [v * e if k == REL else v for v, k in zip(row, kind)]
        fixed = sum(s for s, k, g in zip(size, kind, group) if g < 0 and k != FLT)
        floating = sum(s for s, k, g in zip(size, kind, group) if g < 0 and k == FLT)
        nominal = [sum(s for s, g in zip(size, group) if g == gi) for gi in range(n_groups)]
        room = e - fixed
        avail = max(room - floating, 0.0)
        loose = floating
        reps, gaps = [0] * n_groups, [0.0] * n_groups
        fixed_of = [sum(s for s, k, g in zip(size, kind, group) if g == gi and k != FLT) for gi in range(n_groups)]
        float_of = [n - f for n, f in zip(nominal, fixed_of)]
        in_turns = n_groups >= 2 and all(f > 0 for f in float_of) and all(n > tol for n in nominal)
        if in_turns:
            reps = turns(avail, loose, nominal, fixed_of, float_of, sum(s > tol for s in size), tol)
            fixed += sum(r * f for r, f in zip(reps, fixed_of))
            floating += sum(r * f for r, f in zip(reps, float_of))
        for gi in range(0 if in_turns else n_groups):
            if nominal[gi] <= tol:
                continue
            share = avail * nominal[gi] / sum(nominal[gi:])
            members = [(s, k) for s, k, g in zip(size, kind, group) if g == gi]
            g_float = sum(s for s, k in members if k == FLT)
            if g_float > 0:
                reps[gi] = stretch_nearest_one(share, nominal[gi], nominal[gi] - g_float, g_float, loose,
                                               floating, tol)
                avail = max(avail - reps[gi] * nominal[gi], 0.0)
            else:
                reps[gi] = int(np.floor(share / nominal[gi] + 1e-9))
                gaps[gi] = share - reps[gi] * nominal[gi]
                avail -= share
            fixed += reps[gi] * sum(s for s, k in members if k != FLT) + gaps[gi]
            floating += reps[gi] * sum(s for s, k in members if k == FLT)
        scale = max(e - fixed, 0.0) / floating if floating > 0 else 1.0
        sequence = []
        j = 0
        while j < len(size):
            if group[j] < 0:
                sequence.append((j, size[j] * (scale if kind[j] == FLT else 1.0)))
                j += 1
                continue
            end = j
            while end < len(size) and group[end] == group[j]:
                end += 1
            for _ in range(reps[group[j]]):
                sequence.extend((k, size[k] * (scale if kind[k] == FLT else 1.0)) for k in range(j, end))
            sequence.append((None, gaps[group[j]]))
            j = end
        at, child = 0.0, 0
        for part, length in sequence:
            end = min(at + length, e)
            if part is not None and end - at > tol:
                out.append((i, part, at, end - at, child))
                child += 1
            at += length
    return out


@pytest.mark.parametrize("seed", [*range(5), 12, 40, 50, 55, 57])  # the last: floating groups in turns
def test_random_batches_match_the_reference(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 40))
    count = int(rng.integers(1, 7))
    kind = rng.integers(0, 3, count).astype(np.int64)
    # groups are contiguous runs: [-1, 0, 0, -1, 1, ...]
    group = np.full(count, -1, np.int64)
    at, g = 0, 0
    while at < count:
        run = int(rng.integers(1, 3))
        if rng.random() < 0.5:
            group[at:at + run] = g
            g += 1
        at += run
    values = np.where(kind == REL, rng.uniform(0.05, 0.4, (n, count)), rng.uniform(0.2, 5, (n, count)))
    if rng.random() < 0.5:
        values = values[:1]
    extent = rng.uniform(0, 30, n)
    extent[0] = 0.0
    got = split_parts(extent, values, kind, group, g, TOL)
    want = reference(extent, values, kind, group, g, TOL)
    assert len(got[0]) == len(want)
    for column, expected in zip(got, zip(*want)):
        np.testing.assert_allclose(column, expected, atol=1e-9)


def test_counts_come_first_and_saturate_where_int64_overflows():
    """``group_counts`` says how many parts each shape lays before any is made (the operation checks them
    against --max-shapes in between): a repetition too small to lay (which made nothing and said nothing)
    counts the parts it would make, and one whose count int64 cannot hold is ``MAX_COUNT``, never a
    wrapped-around number of none or one."""
    kind = np.array([ABS, FLT, ABS], np.int64)
    group = np.array([-1, 0, -1], np.int64)
    *_, count = group_counts(np.array([10.0, 11.0, 0.0]), np.array([[1.0, 3.0, 1.0]]), kind, group, 1, TOL)
    np.testing.assert_array_equal(count, [5, 5, 2])
    assert (count >= [len(split_parts(np.array([e]), np.array([[1.0, 3.0, 1.0]]), kind, group, 1, TOL)[0])
                      for e in (10.0, 11.0, 0.0)]).all()
    for sizes, least in (([1e-18], 3e19), (["~1e-18"], 3e19), ([1e-9, "~1e-9"], 1.5e10), ([5e-10], 6e10)):
        values, kinds = _parse(sizes)
        *_, count = group_counts(np.array([30.0]), values[None, :], kinds, np.zeros(len(sizes), np.int64), 1, TOL)
        assert count[0] >= least * 0.999, sizes
    reps, _, _, count = group_counts(np.array([1e12]), np.array([[1e-8]]), np.array([ABS], np.int64),
                                     np.zeros(1, np.int64), 1, TOL)
    assert reps[0, 0] == MAX_COUNT and count[0] == float(MAX_COUNT)
