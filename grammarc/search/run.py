"""``grammarc search``: search each lot, write the solutions as records and the derivation graph.

The solutions of all lots are numbered in the order found, lot by lot; they are derived again as one
chunk (each its lot with its path: the same design the search found) and written as a record whose
``lot`` column is the solution's number. The record's ``meta["search"]`` says which lot and path each
solution came from, its cost, and how the search went.
"""

from __future__ import annotations

import time
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path

from grammarc.io import writer_for
from grammarc.search.states import Deriving, States
from grammarc.search.strategies import LotSearch, SearchOptions, search_lot
from grammarc.search.tree import Tree
from grammarc.workers import worker_pool


@dataclass
class SearchResult:
    lots: list[LotSearch]
    seconds: float
    tree: Tree

    @property
    def states(self) -> int:
        return sum(r.states for r in self.lots)

    @property
    def solutions(self) -> States | None:
        """Every lot's solutions in the order found, None for none."""
        found = [s for r in self.lots for s in r.solutions]
        return States.concat(found) if found else None

    def summary(self, deriving: Deriving, options: SearchOptions) -> dict:
        """What the record's ``meta["search"]`` and the tree say of the search."""
        ids = deriving.lots.ids
        solutions = self.solutions
        listed = [] if solutions is None else [
            {"solution": k, "lot": str(ids[solutions.lot[k]]), "path": solutions.path[k, :solutions.length[k]].tolist(),
             "cost": float(solutions.cost[k]), "state": int(solutions.id[k])} for k in range(len(solutions))]
        return {"strategy": options.strategy, "max_states": options.max_states, "batch": options.batch,
                "wanted": options.solutions, "states": self.states,
                "limited": [str(ids[r.lot]) for r in self.lots if r.limited], "solutions": listed}


def run_search(deriving: Deriving, options: SearchOptions, *, record_tree: bool = False,
               workers: int = 1) -> SearchResult:
    """Search every lot of ``deriving.lots`` in turn, deriving states in ``workers`` processes (forked
    once, with the plan); the result does not depend on ``workers``."""
    started = time.perf_counter()
    tree = Tree(record_tree)
    with worker_pool(_outcomes(deriving), workers) as submit:
        def outcome(states: States) -> Future:
            received: Future = Future()
            submit(states).add_done_callback(lambda done: _first(done, received))
            return received

        found = [search_lot(outcome, workers, options, tree, lot) for lot in range(len(deriving.lots))]
    return SearchResult(found, time.perf_counter() - started, tree)


def _outcomes(deriving: Deriving):
    """The work of ``worker_pool`` (results as its build's are shaped: ``[(n, (arrays, per lot))]``):
    the outcome of a batch of states."""
    def work(states: States):
        outcome, _ = deriving.derive(states)
        return [(len(states), (outcome, None))], []

    return work


def _first(done: Future, received: Future) -> None:
    """``received`` gets the outcome of the pool's ``done``, or its error."""
    if not received.set_running_or_notify_cancel():
        return
    try:
        results, _ = done.result()
        received.set_result(results[0][1][0])
    except BaseException as error:  # noqa: BLE001 - handed to the strategy by received.result()
        received.set_exception(error)


def write_solutions(path: Path, deriving: Deriving, result: SearchResult, options: SearchOptions,
                    meta: dict) -> dict:
    """The solutions' designs as a record at ``path`` (any output format); returns the writer's counts."""
    grammar = deriving.plan.grammar
    writer_class = writer_for(path)
    solutions = result.solutions
    with writer_class(path, assets=grammar.assets, symbols=deriving.plan.symbol_names,
                      meta={**meta, "search": result.summary(deriving, options)}) as writer:
        # the solutions derived again a batch at a time, numbered in the order found
        for start in range(0, 0 if solutions is None else len(solutions), options.batch):
            _, chunks = deriving.derive(solutions.take(slice(start, start + options.batch)), records=True,
                                        first=start)
            for records in chunks:
                writer.write(records)
        return writer.close()
