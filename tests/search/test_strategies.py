"""search/strategies.py: BFS, DFS and A* on the gramatica examples, against the solutions enumerated by hand.

The enumerations below follow each grammar's rules in plain Python, choice by choice in the order the
derivation meets them (a round visits the symbols in the order of their first rule: a house divides, then
its bay becomes a room or the stairs, then the next house divides), and compute each design's cost and
whether it meets the goal: the search must find exactly those paths, in its strategy's order, whatever the
batch size.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.io.lots import read_lots
from grammarc.search import Deriving, SearchOptions, run_search

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "gramatica"


def _deriving(name: str, grammar: Path | None = None) -> Deriving:
    return Deriving(make_plan(compile_grammar(grammar or EXAMPLES / f"{name}.cga")),
                    read_lots(EXAMPLES / f"{name}.geojson"))


def _found(deriving: Deriving, **options) -> list[tuple[str, tuple[int, ...], float]]:
    result = run_search(deriving, SearchOptions(**options))
    return [(s["lot"], tuple(s["path"]), s["cost"]) for s in result.summary(deriving, SearchOptions())["solutions"]]


# ------------------------------------------------------------------------------------------- figure 1
def _strips(height: int):
    """(path, strip heights, cost) of every division of a rectangle ``height`` high into strips."""
    if height == 0:
        yield (), (), 0.0
        return
    options = (1, 2, 3) if height >= 3 else (1, 2) if height >= 2 else (1,)
    for i, strip in enumerate(options):
        for path, strips, cost in _strips(height - strip):
            yield ((i,) if len(options) > 1 else ()) + path, (strip, *strips), height + cost


def _figure1_solutions(least: float = 2):
    return [(path, cost) for path, strips, cost in _strips(6) if min(strips) >= least]


def test_figure1_has_the_solutions_counted_by_hand():
    assert len(list(_strips(6))) == 24  # the compositions of 6 into 1, 2 and 3
    assert sorted(s for _, s in [(p, tuple(st)) for p, st, _ in _strips(6)] if min(s) >= 2) == [(2, 2, 2), (3, 3)]


@pytest.mark.parametrize("batch", [1, 2, 4096])
def test_figure1_bfs_finds_all_solutions_fewest_choices_first(batch):
    expected = sorted(_figure1_solutions(), key=lambda s: (len(s[0]), s[0]))
    assert [(p, c) for _, p, c in _found(_deriving("figure1"), strategy="bfs", batch=batch)] == expected


@pytest.mark.parametrize("batch", [1, 3, 4096])
def test_figure1_dfs_finds_the_first_in_written_order(batch):
    found = _found(_deriving("figure1"), strategy="dfs", batch=batch, solutions=1)
    assert [(p, c) for _, p, c in found] == [min(_figure1_solutions())]
    assert found[0][1] == (1, 1, 1)  # 2, 2, 2: the second height of each choice before the third


@pytest.mark.parametrize("batch", [1, 4096])
def test_figure1_astar_finds_a_cheapest_first(batch):
    found = _found(_deriving("figure1"), strategy="astar", batch=batch)
    assert [(p, c) for _, p, c in found] == sorted(_figure1_solutions(), key=lambda s: (s[1], s[0]))
    assert found[0][1:] == ((2, 2), 9.0)  # 3, 3: divisions of heights 6 and 3


# ------------------------------------------------------------------------------------------- Malagueira
def _bays(width: int):
    """(choices, bays as (width, kind), waste) of every division of a house ``width`` wide: per bay, the
    width's choice (where there is one) and then the bay's kind (0 room, 1 stairs)."""
    if width < 2:
        yield (), (), width > 0
        return
    options = (2, 3, 4) if width >= 4 else (2, 3) if width >= 3 else (2,)
    for i, bay in enumerate(options):
        for kind in (0, 1):
            for path, bays, waste in _bays(width - bay):
                yield ((i,) if len(options) > 1 else ()) + (kind,) + path, ((bay, kind), *bays), waste


def _malagueira_solutions(rooms: int, room_area: float, patio_area: float):
    """(path, cost) of the designs of an 8 x 12 lot that meet the brief, in no order."""
    found = []
    for i, patio in enumerate((4, 5, 6)):
        depth = 12 - patio
        for path, bays, waste in _bays(8):
            stairs = [w for w, kind in bays if kind == 1]
            room = [w * depth for w, kind in bays if kind == 0]
            if stairs == [2] and len(room) == rooms and min(room) >= room_area and patio * 8 >= patio_area \
                    and not waste:
                # the lot's rule costs its depth, each house division and each bay's the house's depth
                found.append(((i, *path), 12.0 + depth * 2 * len(bays)))
    return found


BRIEFS = {"T2": (2, 12, 24), "T3": (3, 14, 32)}


def _per_lot(found, lot):
    return [(p, c) for name, p, c in found if name == lot]


@pytest.mark.parametrize("batch", [1, 7, 4096])
def test_malagueira_bfs_enumerates_every_valid_division(batch):
    found = _found(_deriving("malagueira"), strategy="bfs", batch=batch)
    for lot, brief in BRIEFS.items():
        expected = _malagueira_solutions(*brief)
        assert _per_lot(found, lot) == sorted(expected, key=lambda s: (len(s[0]), s[0]))
    assert len(_per_lot(found, "T2")) == 27 and len(_per_lot(found, "T3")) == 8


@pytest.mark.parametrize("batch", [1, 5, 4096])
def test_malagueira_dfs_gives_the_solutions_in_written_order(batch):
    found = _found(_deriving("malagueira"), strategy="dfs", batch=batch)
    for lot, brief in BRIEFS.items():
        assert _per_lot(found, lot) == sorted(_malagueira_solutions(*brief))


@pytest.mark.parametrize("batch", [1, 6, 4096])
def test_malagueira_astar_gives_the_cheapest_first(batch):
    found = _found(_deriving("malagueira"), strategy="astar", batch=batch)
    for lot, brief in BRIEFS.items():
        expected = sorted(_malagueira_solutions(*brief), key=lambda s: (s[1], s[0]))
        assert _per_lot(found, lot) == expected
        assert _per_lot(found, lot)[0][1] == min(c for _, c in expected)


def test_solutions_stops_each_lots_search():
    found = _found(_deriving("malagueira"), strategy="bfs", solutions=2)
    assert [lot for lot, _, _ in found] == ["T2", "T2", "T3", "T3"]


def test_prune_cuts_branches_and_keeps_the_solutions(tmp_path):
    text = (EXAMPLES / "malagueira.cga").read_text(encoding="utf-8")
    unpruned = tmp_path / "malagueira.cga"
    unpruned.write_text("\n".join(line for line in text.splitlines() if not line.startswith("prune:")),
                        encoding="utf-8")
    pruned, plain = _deriving("malagueira"), _deriving("malagueira", unpruned)
    assert _found(pruned, strategy="bfs") == _found(plain, strategy="bfs")
    assert run_search(pruned, SearchOptions()).states < run_search(plain, SearchOptions()).states


@pytest.mark.parametrize("strategy", ["bfs", "dfs", "astar"])
def test_max_states_stops_a_search_with_the_count_reached(strategy):
    result = run_search(_deriving("malagueira"), SearchOptions(strategy=strategy, max_states=40))
    assert [r.states for r in result.lots] == [40, 40]
    assert all(r.limited for r in result.lots)


def test_a_search_that_ends_is_not_limited():
    result = run_search(_deriving("figure1"), SearchOptions(max_states=10_000))
    assert not any(r.limited for r in result.lots)
    # by hand: the lot, its 3 consequents; of those, strip 1 is pruned, strips 2 and 3 have 3 consequents
    # each; of those 2-1 and 3-1 are pruned and 2-2 has 2 more: 1 + 3 + 6 + 2
    assert result.states == 12


def test_unbounded_recursion_is_stopped_by_max_states(tmp_path):
    grammar = tmp_path / "grow.cga"
    grammar.write_text('grow ~> T(1, 0, 0) grow ?\n     ~> B ?\ngoal: count("C") > 0\n',
                       encoding="utf-8")
    deriving = Deriving(make_plan(compile_grammar(grammar)), read_lots(EXAMPLES / "figure1.geojson"))
    for strategy in ("bfs", "dfs", "astar"):
        result = run_search(deriving, SearchOptions(strategy=strategy, max_states=100, batch=16))
        assert result.lots[0].states == 100 and result.lots[0].limited and not result.lots[0].found


def test_ice_ray_lattices_are_found_depth_first():
    deriving = Deriving(make_plan(compile_grammar(EXAMPLES / "iceray.cga")), read_lots(EXAMPLES / "figure1.geojson"))
    result = run_search(deriving, SearchOptions(strategy="dfs", solutions=2))
    found = result.summary(deriving, SearchOptions())["solutions"]
    assert len(found) == 2 and found[0]["path"] < found[1]["path"]
    _, (records,) = deriving.derive(result.solutions, records=True)
    corners = np.diff(records.mesh.ring_offsets)
    assert set(corners.tolist()) <= {3, 4, 5}
    assert np.bincount(records.mesh.lot).min() >= 4  # a lattice of cells of 2.5 to 6 m2 on 24 m2
