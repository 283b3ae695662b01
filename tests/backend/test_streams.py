"""backend/streams.py: CityEngine grammars derived by grammarc draw what PRT drew for the same seeds.

The expected values are the ones PRT printed (``test_prt_random``'s tables): the lots carry PRT's ``seed``
as a property, and each rule here is shaped like the rule PRT ran for its table.
"""

from __future__ import annotations

import numpy as np
import pytest
from operations.derivations import paper, per_lot, rect, run, same_records
from test_prt_random import BRACKET, COMP, EXTRUSION, RAND_01_07, SPLIT3

from grammarc.backend import prt_random as pr
from grammarc.backend import random, streams


def _reports(write, text, seeds, **options):
    """Per lot (in ``seeds`` order), its reports' sums: {key: value}."""
    r = run(write, text, [rect(10, 6)] * len(seeds), lot_attrs={"seed": np.array(seeds, dtype=float)}, **options)
    lots = per_lot(r)
    return [{k[:-4]: v for k, v in lots[i].items() if k.endswith("_sum")} for i in range(len(seeds))]


def test_the_start_shape_draws_from_its_lots_seed(write):
    got = _reports(write, 'Lot --> report("A", rand(0.1, 0.7))\n', list(RAND_01_07))
    assert [g["A"] for g in got] == list(RAND_01_07.values())


def test_a_successor_draws_as_extrusion_rules_building_does(write):
    got = _reports(write, 'Lot --> Building\nBuilding --> report("h", rand(0, 1))\n', list(EXTRUSION))
    # the table's values are the reports of volume / area, rounded to the draws' float32 here
    assert [g["h"] for g in got] == np.float32(list(EXTRUSION.values())).astype(float).tolist()


def test_brackets_make_a_child_and_move_the_shape_on(write):
    text = ('Lot --> [ report("P", rand) A ] report("Q", rand) B\n'
            'A --> report("A", rand)\nB --> report("B", rand)\n')
    assert _reports(write, text, list(BRACKET)) == list(BRACKET.values())


def test_split_pieces_draw_in_split_order(write):
    text = 'Lot --> split(x) { ~1: Q(0) | ~1: Q(1) | ~1: Q(2) }\nQ(i) --> report("v" + i, rand)\n'
    got = _reports(write, text, list(SPLIT3))
    assert [[g[f"v{i}"] for i in range(3)] for g in got] == list(SPLIT3.values())


def test_component_faces_draw_in_face_order_selected_ones_only(write):
    text = 'Lot --> extrude(1) comp(f) { front: G("front") | side: G("side") | top: G("top") }\nG(k) --> report(k, rand)\n'
    got = _reports(write, text, list(COMP))
    for g, (front, sides, top) in zip(got, COMP.values()):
        assert g["front"] == front[0] and g["top"] == top[0]
        assert g["side"] == pytest.approx(sum(sides), abs=1e-15)


def test_case_conditions_draw_in_order_on_the_shapes_left(write):
    """``case p(.5): ... case p(.5): ...``: the second condition draws only where the first did not hold,
    so a shape of the first branch draws its second number there."""
    seeds = list(range(40))
    text = ('Lot --> case p(0.5): report("a", rand)\n    case p(0.5): report("b", rand)\n'
            '    else: report("c", rand)\n')
    state = pr.start_states(np.array(seeds))
    state, first = pr.draw(state)
    after_one, second = pr.draw(state)
    _, third = pr.draw(after_one)
    for g, u1, u2, u3 in zip(_reports(write, text, seeds), first, second, third):
        want = {"a": u2} if u1 < 0.5 else {"b": u3} if u2 < 0.5 else {"c": u3}
        assert g == want


def test_nil_moves_the_stream_on(write):
    got = _reports(write, 'Lot --> NIL report("x", rand)\n', [0, 1])
    _, u = pr.draw(pr.advance(pr.start_states(np.array([0, 1])), 1))
    assert [g["x"] for g in got] == u.tolist()


def test_an_attribute_default_draws_from_a_stream_of_its_own(write):
    """The lot's own stream is the same with and without attributes that draw."""
    plain = _reports(write, 'Lot --> report("x", rand)\n', [3, 4])
    with_attrs = _reports(write, 'attr a = rand\nattr b = 50% : 1 else : rand(2, 3)\n'
                                 'Lot --> report("x", rand) report("a", a) report("b", b)\n', [3, 4])
    assert [g["x"] for g in with_attrs] == [g["x"] for g in plain]
    assert with_attrs[0]["a"] != with_attrs[0]["x"]


def test_lots_without_a_seed_draw_apart(write):
    """Lots without a ``seed`` take seeds spread from ``--seed``: neighbours do not draw the same numbers,
    as consecutive seeds of PRT's generator almost do."""
    r = run(write, 'Lot --> report("x", rand)\n', [rect(10, 6)] * 200, seed=3)
    x = np.array([lot["x_sum"] for lot in per_lot(r).values()])
    assert np.abs(np.diff(x)).mean() > 0.2
    assert not np.array_equal(x, [lot["x_sum"] for lot in per_lot(
        run(write, 'Lot --> report("x", rand)\n', [rect(10, 6)] * 200, seed=4)).values()])


def test_records_do_not_depend_on_chunking(write):
    text = ('Lot --> [ t(0, 0, rand) A ] split(x) { ~rand(1, 2): B | ~1: [ s(rand, 1, 1) C ] NIL C }*\n'
            'B --> case p(0.3): extrude(rand(1, 5)) D else: E\n')
    lots = [rect(10, 6), rect(7, 3)] * 15
    whole = run(write, text, lots, seed=5)
    same_records(whole, run(write, text, lots, seed=5, chunk_size=1))
    same_records(whole, run(write, text, lots, seed=5, chunk_size=4))


def test_the_paper_draws_from_counter_based_keys(write):
    """The paper's dialect keeps grammarc's own streams, which no ``seed`` property changes."""
    text = 'lot ~> S(1r, rand(1, 3), 1r) I("cube")\n'
    lots = [rect(10, 6)] * 3
    r = paper(write, text, lots)
    same_records(r, paper(write, text, lots, lot_attrs={"seed": np.array([1.0, 2.0, 3.0])}))
    assert np.array_equal(streams.lot_keys(False, 0, np.arange(3), None), random.lot_keys(0, np.arange(3)))
