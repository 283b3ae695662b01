"""Breadth-first, depth-first and A* search over a grammar's states (GRAMATICA, section "search").

Each strategy keeps its frontier as ``States`` (columns) and derives it a batch at a time
(``Deriving.derive``): a BFS layer, the top of the DFS stack, A*'s best states. A state's consequents are
its path extended by each option of the choice it stopped at.

The orders are defined so that the solutions do not depend on the batch size but where a limit cuts the
search short:

- BFS takes the states a layer (a number of choices) at a time, each layer in the order of the paths
  (the consequents of a state in their written order, after those of the states before it): its
  solutions come shortest path first, then in path order.
- DFS keeps a stack whose top is the next state a one-at-a-time depth-first search would visit (a
  state's consequents above the states after it, the first option on top). It derives the top ``batch``
  states at once, but a solution found below the top waits there as found until everything above it
  is searched: solutions come in depth-first order, first written option first.
- A* ranks derived states by cost plus heuristic, ties by path. It expands the best ``batch`` states at
  once; a solution is given when it is the best of all open states, so with a heuristic that never
  overestimates, the first solution is a cheapest one.

``--max-states`` bounds the states derived per lot, and so the memory: a frontier is never kept beyond
the states that may still be derived.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from grammarc.search.states import Outcome, States
from grammarc.search.tree import Tree

STRATEGIES = ("bfs", "dfs", "astar")


@dataclass(frozen=True)
class SearchOptions:
    strategy: str = "bfs"
    #: Solutions to find per lot (None: all).
    solutions: int | None = None
    #: States to derive per lot at most.
    max_states: int = 1_000_000
    #: States derived together (a frontier's batch).
    batch: int = 16384


@dataclass
class LotSearch:
    """One lot's search: its solutions (derived ``States``) in the order found, the states derived, and
    whether ``max_states`` stopped it."""

    lot: int
    solutions: list[States] = field(default_factory=list)
    states: int = 0
    limited: bool = False

    @property
    def found(self) -> int:
        return sum(len(s) for s in self.solutions)


class _Run:
    """What a strategy asks of its lot's search: derive within the budget, give solutions.

    ``submit(states) -> Future`` derives states (``Deriving.derive``, maybe in a worker process) and
    ``workers`` says how many at once: a batch is cut into that many pieces, all submitted before the
    first is waited for."""

    def __init__(self, submit, workers: int, options: SearchOptions, tree: Tree, lot: int) -> None:
        self.submit = submit
        self.workers = workers
        self.options = options
        self.tree = tree
        self.result = LotSearch(lot)

    @property
    def wanted(self) -> float:
        wanted = self.options.solutions
        return (np.inf if wanted is None else wanted) - self.result.found

    @property
    def budget(self) -> int:
        return self.options.max_states - self.result.states

    def give(self, solutions: States) -> None:
        """Solutions found, in order; those beyond ``--solutions`` are dropped."""
        if len(solutions) and self.wanted > 0:
            taken = solutions.take(slice(0, int(min(self.wanted, len(solutions)))))
            self.tree.solved(taken.id)
            self.result.solutions.append(taken)

    def derive(self, states: States):
        """``(derived states, outcome)`` of each piece of ``states`` in order, as far as the budget goes.
        The pieces are at most a batch, and as many as the workers where a batch is not more; how the
        states are cut changes nothing of their outcomes."""
        if len(states) > self.budget:
            self.result.limited = True
            states = states.take(slice(0, max(self.budget, 0)))
        size = max(min(self.options.batch, -(-len(states) // self.workers)), 1)
        pieces = [states.take(slice(start, start + size)) for start in range(0, len(states), size)]
        futures = [self.submit(piece) for piece in pieces]
        try:
            for piece, future in zip(pieces, futures):
                outcome = future.result()
                ids = self.tree.add(piece, outcome)
                self.result.states += len(piece)
                yield piece.with_outcome(ids, outcome), outcome
        finally:  # a strategy that stops early gives up the pieces it no longer needs
            for future in futures:
                future.cancel()


def search_lot(submit, workers: int, options: SearchOptions, tree: Tree, lot: int) -> LotSearch:
    """Search lot ``lot`` from its initial state with ``options.strategy``; ``submit`` derives states."""
    run = _Run(submit, workers, options, tree, lot)
    _STRATEGY[options.strategy](run, States.initial(lot))
    return run.result


def _bfs(run: _Run, layer: States) -> None:
    dropped = False  # consequents left out of a layer: the budget could never derive them
    while len(layer) and run.wanted > 0:
        following, room = [], run.budget - len(layer)  # what the next layer may derive
        for derived, outcome in run.derive(layer):
            run.give(derived.take(outcome.solution))
            if run.wanted <= 0:
                return
            kids = derived.consequents(outcome.expanded)
            taken = max(min(len(kids), room), 0)
            dropped |= taken < len(kids)
            following.append(kids.take(slice(0, taken)))
            room -= taken
        if run.result.limited:
            return
        layer = States.concat(following)
    run.result.limited |= dropped and run.wanted > 0


def _dfs(run: _Run, stack: States) -> None:
    found = np.zeros(len(stack), dtype=bool)  # solutions waiting below the top
    while len(stack) and run.wanted > 0:
        on_top = len(found) - _last_false(found)
        if on_top:
            run.give(stack.take(np.arange(len(stack) - 1, len(stack) - 1 - on_top, -1)))  # the top first
            stack, found = stack.take(slice(0, len(stack) - on_top)), found[:len(found) - on_top]
            continue
        if run.budget <= 0:
            run.result.limited = True
            return
        k = min(run.options.batch, run.budget, len(stack))
        below, top, waiting = stack.take(slice(0, len(stack) - k)), stack.take(slice(len(stack) - k, None)), found[-k:]
        todo = np.flatnonzero(~waiting)
        pieces = [*run.derive(top.take(todo))]
        derived = States.concat([piece for piece, _ in pieces])
        outcome = Outcome.concat([piece for _, piece in pieces])
        # each entry of the top, bottom to top, becomes: itself if found, else its consequents (the first
        # option uppermost), nothing if it has none
        found_rows = np.concatenate([np.flatnonzero(waiting), todo[outcome.solution]])
        kept = States.concat([top.take(np.flatnonzero(waiting)), derived.take(outcome.solution)])
        kids = derived.consequents(outcome.expanded, reverse=True)
        owner = np.concatenate([found_rows, np.repeat(todo, outcome.expanded)])
        order = np.argsort(owner, kind="stable")
        replaced = States.concat([kept, kids]).take(order)
        stack = States.concat([below, replaced])
        found = np.concatenate([found[:len(found) - k], np.r_[np.ones(len(kept), bool), np.zeros(len(kids), bool)][order]])


def _last_false(flags: np.ndarray) -> int:
    """The length of ``flags`` without its trailing run of True."""
    false = np.flatnonzero(~flags)
    return int(false[-1]) + 1 if len(false) else 0


def _astar(run: _Run, start: States) -> None:
    open_states, open_options = _opened([*run.derive(start)])
    while len(open_states) and run.wanted > 0:
        best = _best(open_states, run.options.batch)
        leading = _leading(open_states.goal[best])
        run.give(open_states.take(best[:leading]))
        rest = best[leading:]
        expand = rest[~open_states.goal[rest]]
        if run.wanted <= 0:
            return
        if len(expand) and run.budget <= 0:  # solutions still open behind these are not the best
            run.result.limited = True
            return
        kids = open_states.take(expand).consequents(open_options[expand])
        keep = np.ones(len(open_states), dtype=bool)
        keep[best[:leading]] = False
        keep[expand] = False
        made_states, made_options = _opened([*run.derive(kids)])
        open_states = States.concat([open_states.take(keep), made_states])
        open_options = np.concatenate([open_options[keep], made_options])


def _leading(flags: np.ndarray) -> int:
    """The length of the leading run of True of ``flags``."""
    false = np.flatnonzero(~flags)
    return int(false[0]) if len(false) else len(flags)


def _opened(batches: list[tuple[States, Outcome]]) -> tuple[States, np.ndarray]:
    """The states of derived ``batches`` that stay open: solutions, and states with consequents; with
    the number of consequents of each."""
    parts = [derived.take(outcome.solution | (outcome.expanded > 0)) for derived, outcome in batches]
    options = [outcome.expanded[outcome.solution | (outcome.expanded > 0)] for _, outcome in batches]
    if not parts:
        return States.initial(0).take(slice(0, 0)), np.zeros(0, dtype=np.int64)
    return States.concat(parts), np.concatenate(options)


def _best(states: States, k: int) -> np.ndarray:
    """The rows of the ``k`` best states, best first: by score, ties by path (a path before the paths it
    begins)."""
    score = states.score
    rows = np.arange(len(states))
    if len(states) > k:
        rows = np.flatnonzero(score <= np.partition(score, k - 1)[k - 1])
    keys = [states.path[rows, j] for j in range(states.path.shape[1] - 1, -1, -1)] + [score[rows]]
    return rows[np.lexsort(keys)][:k]


_STRATEGY = {"bfs": _bfs, "dfs": _dfs, "astar": _astar}
