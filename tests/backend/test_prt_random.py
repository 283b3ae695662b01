"""backend/prt_random.py: PRT's random stream against values PRT printed (PyPRT 1.x, seeds as given).

Kit packages: ``extrusion_rule.rpk`` with minBuildingHeight 0 and maxBuildingHeight 1 reports
``Building Height.0``, one rand(0, 1) of the start shape's successor (rounded to float32 here: the report is
volume / area, off by 1e-16); ``reporting.rpk``'s start rule draws ``p(greenspacePercentage / 100)``
(bisected over greenspacePercentage: the draw is the highest percentage that gave BuildUp, p(q) being
u < q, and lies below the lowest that gave Greenspace) and its attribute ``floorHeight = rand(4, 5)``.

The other tables come from rule packages written for the measurement (compiled rules of the kit's
complexpatterns package with their bodies replaced): a split of the lot into three pieces whose successors
draw once; ``Lot --> extrude(1) comp(f){ front: A | side: B | top: C }`` where A, B and C report one draw;
``Lot --> [ report("P", rand) A ] report("Q", rand) B`` with A and B reporting one draw; and
``report("A", rand(0.1, 0.7))`` on the start shape.
"""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend import prt_random as pr

EXTRUSION = {0: 0.2728087604045868, 1: 0.7694881558418274, 2: 0.2661661207675934, 3: 0.762845516204834,
             9999: 0.5630077123641968, 10000: 0.05968566983938217, -1: 0.1580997258424759,
             -2: 0.6614217162132263, 2147483647: 0.9671159386634827, 123456789: 0.223579317331314}
P_BRACKETS = {0: (0.21132202446460724, 0.21132203936576843), 1: (0.21705852448940277, 0.21705853939056396),
              2: (0.2227950394153595, 0.2227950543165207), 499: (0.07383224368095398, 0.07383225858211517)}
FLOOR_HEIGHT = {0: 4.694018661975861, 1: 4.6997551918029785, 2: 4.705491721630096, 1999: 4.161269083619118,
                65536: 4.640877604484558, 714024: 4.6882821917533875, 2147483647: 4.364109605550766,
                -1: 4.039937034249306}
FLOOR_HEIGHT_OFFSET = 673492  # h("floorHeight") measured: the attribute's stream starts at seed + 673492
# reporting's nFloor = ceil(rand(1, 15) * buildingHeightFactor) with buildingHeightFactor 1e6: the draw to 1e-6
N_FLOOR = {0: 8283932.0, 1: 8364243.0, 1999: 14825457.0, 65536: 7539957.0, 714024: 8203621.0,
           2147483647: 3665205.0, -1: 13126808.0}
N_FLOOR_OFFSET = 207149
SPLIT3 = {0: [0.30774736404418945, 0.0696377158164978, 0.773905336856842],
          1: [0.9342402815818787, 0.1811549812555313, 0.547961950302124]}
COMP = {0: ([0.30774736404418945], [0.0696377158164978, 0.4501333236694336, 0.773905336856842],
            [0.2817552387714386]),
        1: ([0.9342402815818787], [0.1811549812555313, 0.547961950302124, 0.9873225688934326],
            [0.6057443618774414])}
BRACKET = {0: {"P": 0.2728087604045868, "A": 0.30774736404418945, "Q": 0.7851388454437256, "B": 0.3185747265815735},
           1: {"P": 0.7694881558418274, "A": 0.9342402815818787, "Q": 0.28181686997413635, "B": 0.9450676441192627}}
RAND_01_07 = {0: 0.22679321467876434, 1: 0.23023511469364166, 2: 0.2336770236492157, 1999: 0.5071443080902099}


def _seeds(table):
    return np.array(list(table), dtype=np.int64)


def _first_draw_of_successor(states):
    successor, _ = pr.child(states)
    return pr.draw(successor)[1]


def test_successor_of_start_shape_draws_what_extrusion_rule_reports():
    seeds = _seeds(EXTRUSION)
    got = _first_draw_of_successor(pr.start_states(seeds))
    want = np.array(list(EXTRUSION.values()), dtype=np.float32).astype(np.float64)
    assert np.array_equal(got, want)


def test_start_shape_draws_the_p_of_reporting_first():
    seeds = _seeds(P_BRACKETS)
    _, u = pr.draw(pr.start_states(seeds))
    lo, hi = np.array(list(P_BRACKETS.values())).T
    assert np.all((lo <= u) & (u < hi))


def test_attribute_streams_start_at_seed_plus_the_name_hash():
    seeds = _seeds(FLOOR_HEIGHT)
    _, u = pr.draw((pr.start_states(seeds) + FLOOR_HEIGHT_OFFSET) % pr.MODULUS)
    assert np.array_equal(pr.rand(u, 4.0, 5.0), np.array(list(FLOOR_HEIGHT.values())))


def test_attribute_streams_take_the_seed_as_an_unsigned_32_bit_integer():
    seeds = _seeds(N_FLOOR)
    _, u = pr.draw((pr.start_states(seeds) + N_FLOOR_OFFSET) % pr.MODULUS)
    assert np.array_equal(np.ceil(pr.rand(u, 1.0, 15.0) * 1e6), np.array(list(N_FLOOR.values())))


def test_rand_is_lo_plus_range_times_the_float32_draw():
    seeds = _seeds(RAND_01_07)
    _, u = pr.draw(pr.start_states(seeds))
    assert np.array_equal(pr.rand(u, 0.1, 0.7), np.array(list(RAND_01_07.values())))


def test_split_pieces_are_seeded_in_order_and_spend_one_draw():
    seeds = _seeds(SPLIT3)
    piece = pr.pieces(np.repeat(pr.start_states(seeds), 3), np.tile(np.arange(3), 2))
    got = _first_draw_of_successor(piece).reshape(2, 3)
    assert np.array_equal(got, np.array(list(SPLIT3.values())))


def test_component_split_seeds_its_faces_like_split_pieces():
    seeds = _seeds(COMP)
    piece = pr.pieces(np.repeat(pr.start_states(seeds), 5), np.tile(np.arange(5), 2))  # front, three sides, top: the unselected bottom makes none
    got = _first_draw_of_successor(piece).reshape(2, 5)
    for row, (front, sides, top) in zip(got, COMP.values()):
        assert row[0] == front[0] and row[4] == top[0]
        assert sorted(row[1:4]) == sides  # the report gives the sides' values unordered


def test_bracket_copy_is_a_child_and_the_parent_moves_on():
    seeds = _seeds(BRACKET)
    start = pr.start_states(seeds)
    copy, lot = pr.child(start)
    copy, p = pr.draw(copy)
    lot, q = pr.draw(lot)
    a = _first_draw_of_successor(copy)
    b = _first_draw_of_successor(lot)
    for name, got in {"P": p, "A": a, "Q": q, "B": b}.items():
        assert got.tolist() == [row[name] for row in BRACKET.values()]


@pytest.mark.parametrize("k", [0, 1, 2, 7, 64, 1000])
def test_jump_equals_k_single_draws(k):
    state = np.arange(0, 714025, 9973, dtype=np.int64)
    once = state.copy()
    for _ in range(k):
        once = (4096 * once + 150889) % 714025
    assert np.array_equal(pr.advance(state, k), once)


def test_the_period_is_the_modulus():
    state = np.arange(0, 714025, 9973, dtype=np.int64)
    assert np.array_equal(pr.advance(state, 714025), state)
    assert not np.any(pr.advance(state, 714025 // 5) == state)


def test_advance_takes_a_count_per_shape():
    state = np.array([5, 5, 9], dtype=np.int64)
    each = [pr.advance(state[i:i + 1], k)[0] for i, k in enumerate([0, 2, 1])]
    assert pr.advance(state, np.array([0, 2, 1])).tolist() == each
