"""Search states as columns, and a batch of them derived at once.

A state is a lot with a path: the options taken at the choices its derivation meets, in order
(``backend.choices``). A batch of states is derived as one chunk whose lots are the states' lots repeated,
each fixed by its own path; nothing is done per state in Python. What a state's derivation found is its
``Outcome``: the number of consequents of the choice it stopped at, or complete; its cost so far, and the
search statements' values.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from grammarc.backend.choices import Choices
from grammarc.backend.derive import derive_chunk
from grammarc.backend.plan import Plan
from grammarc.constants import LIMITS, Limits
from grammarc.errors import ChunkTooLarge, LotFailure
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_exprs
from grammarc.model.lots import Lots
from grammarc.model.records import TerminalChunk


@dataclass(frozen=True, eq=False)
class States:
    """n states: ``lot`` (n,) their lots (rows of the searched ``Lots``), ``path`` (n, D) int32 their
    options (the first ``length`` (n,) of each row; -1 beyond), ``parent`` (n,) the id of the state they
    are a consequent of (-1: a lot's initial state); once derived, ``id`` (n,) their numbers in the order
    derived (-1 before), ``cost`` their costs, ``score`` what A* ranks them by, ``goal`` whether they are
    solutions (complete and the goal holds)."""

    lot: np.ndarray
    path: np.ndarray
    length: np.ndarray
    parent: np.ndarray
    id: np.ndarray
    cost: np.ndarray
    score: np.ndarray
    goal: np.ndarray

    def __len__(self) -> int:
        return len(self.lot)

    @staticmethod
    def initial(lot: int) -> States:
        """The initial state of lot ``lot``: no choice taken."""
        return States(np.array([lot]), np.zeros((1, 0), np.int32), np.zeros(1, np.int64), np.full(1, -1),
                      np.full(1, -1), np.zeros(1), np.zeros(1), np.zeros(1, bool))

    def take(self, index) -> States:
        return States(*(getattr(self, f.name)[index] for f in fields(self)))

    def with_outcome(self, ids: np.ndarray, outcome: Outcome) -> States:
        """These states derived: numbered ``ids``, with their costs, scores and whether they are solutions."""
        score = outcome.cost + (np.nan_to_num(outcome.heuristic, nan=np.inf) if outcome.heuristic is not None else 0)
        return States(self.lot, self.path, self.length, self.parent, ids, outcome.cost, score, outcome.solution)

    @staticmethod
    def concat(parts: list[States]) -> States:
        """The states of ``parts`` in order, their paths padded to the longest."""
        width = max((p.path.shape[1] for p in parts), default=0)
        padded = [p if p.path.shape[1] == width else States(
            p.lot, np.pad(p.path, ((0, 0), (0, width - p.path.shape[1])), constant_values=-1),
            *(getattr(p, f.name) for f in fields(p)[2:])) for p in parts]
        if len(padded) == 1:
            return padded[0]
        return States(*(np.concatenate([getattr(p, f.name) for p in padded]) for f in fields(States)))

    def consequents(self, options: np.ndarray, reverse: bool = False) -> States:
        """The consequents of these (derived) states: each state's path extended by each of its
        ``options`` (n,) (0 for none), in order (``reverse``: last option first), undrived."""
        rows = np.repeat(np.arange(len(self)), options)
        starts = np.repeat(np.cumsum(options) - options, options)
        rank = np.arange(len(rows)) - starts
        value = np.repeat(options, options) - 1 - rank if reverse else rank
        length = self.length[rows]
        width = max(self.path.shape[1], int(length.max(initial=-1)) + 1)
        path = np.full((len(rows), width), -1, dtype=np.int32)
        path[:, :self.path.shape[1]] = self.path[rows]
        path[np.arange(len(rows)), length] = value
        n = len(rows)
        return States(self.lot[rows], path, length + 1, self.id[rows], np.full(n, -1), np.zeros(n),
                      np.zeros(n), np.zeros(n, bool))


@dataclass(frozen=True, eq=False)
class Outcome:
    """What deriving n states found: ``options`` (n,) consequents of the choice each stopped at (0:
    complete) and ``site`` (n,) that choice's, ``cost`` (n,), ``goal``/``prune`` (n,) bool and
    ``heuristic`` (n,) (None where the grammar states none), ``failed`` (n,) bool with ``reasons``
    (state row -> why its derivation failed: a limit, a bad value)."""

    options: np.ndarray
    site: np.ndarray
    cost: np.ndarray
    goal: np.ndarray | None
    prune: np.ndarray | None
    heuristic: np.ndarray | None
    failed: np.ndarray
    reasons: dict[int, str]

    @staticmethod
    def concat(parts: list[Outcome]) -> Outcome:
        """The outcomes of consecutive pieces of states, as one."""
        if len(parts) == 1:
            return parts[0]
        starts = np.cumsum([0, *(len(p.options) for p in parts)])
        columns = {f.name: None if getattr(parts[0], f.name) is None else
                   np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Outcome)[:-1]}
        reasons = {int(start) + row: why for start, p in zip(starts, parts) for row, why in p.reasons.items()}
        return Outcome(**columns, reasons=reasons)

    @property
    def complete(self) -> np.ndarray:
        return (self.options == 0) & ~self.failed

    @property
    def solution(self) -> np.ndarray:
        """Complete states whose goal holds (every complete state, where the grammar has no goal)."""
        return self.complete & (self.goal if self.goal is not None else True)

    @property
    def pruned(self) -> np.ndarray:
        return (self.options > 0) & ~self.failed & (self.prune if self.prune is not None else False)

    @property
    def expanded(self) -> np.ndarray:
        """(n,) the number of consequents to search of each state: none for complete, pruned or failed."""
        return np.where((self.options > 0) & ~self.failed & ~self.pruned, self.options, 0)


@dataclass(frozen=True)
class Deriving:
    """How states are derived: the grammar's plan, the searched lots, the build's settings."""

    plan: Plan
    lots: Lots
    seed: int = 0
    limits: Limits = LIMITS
    overrides: tuple[tuple[str, object], ...] = ()
    #: Shapes a chunk of states may make before it is halved (``ChunkTooLarge``), as a build's chunk.
    chunk_budget: int = 20_000_000

    @property
    def aggregates(self) -> tuple[ir.Aggregate, ...]:
        module = self.plan.grammar.module
        return tuple(dict.fromkeys(e for o in module.objectives for e in iter_exprs(o.expr)
                                   if isinstance(e, ir.Aggregate)))

    def derive(self, states: States, records: bool = False, first: int = 0) -> tuple[Outcome, list[TerminalChunk]]:
        """Derive ``states`` as one chunk (halves of it, where it makes more shapes than ``chunk_budget``):
        their outcome, and with ``records`` their records (chunks in order, whose ``lot`` numbers the
        states from ``first``). A state whose derivation fails is ``failed``; the others are derived again
        without it. Records are asked of states derived before (solutions), which derive again as they
        did: a failure there is raised."""
        try:
            return self._derive(states, records, first)
        except ChunkTooLarge:
            half = len(states) // 2
            (a, made_a), (b, made_b) = (self.derive(states.take(slice(0, half)), records, first),
                                        self.derive(states.take(slice(half, None)), records, first + half))
            return Outcome.concat([a, b]), made_a + made_b

    def _derive(self, states: States, records: bool, first: int) -> tuple[Outcome, list[TerminalChunk]]:
        n = len(states)
        keep = np.arange(n)
        failed = np.zeros(n, dtype=bool)
        reasons: dict[int, str] = {}
        while True:
            choices = Choices(states.path[keep], states.length[keep], self.aggregates, records, first)
            try:
                made, _ = derive_chunk(self.plan, self.lots, seed=self.seed, limits=self.limits,
                                       overrides=dict(self.overrides), chunk_budget=self.chunk_budget,
                                       choices=choices, records=records, rows=states.lot[keep])
                break
            except LotFailure as failure:
                if records:
                    raise
                for k, local in enumerate(np.atleast_1d(failure.lots)):
                    reasons[int(keep[local])] = failure.reason(k)
                failed[keep[failure.lots]] = True
                keep = np.delete(keep, failure.lots)
        outcome = Outcome(
            _spread(choices.options, keep, n, 0), _spread(choices.site, keep, n, -1), _spread(choices.cost, keep, n, 0.0),
            *(None if v is None else _spread(v, keep, n, v.dtype.type(0)) for v in
              (choices.goal, choices.prune, choices.heuristic)), failed, reasons)
        return outcome, [made] if made is not None else []


def _spread(values: np.ndarray, rows: np.ndarray, n: int, fill) -> np.ndarray:
    """``values`` of ``rows`` into an (n,) array of ``fill``."""
    out = np.full(n, fill, dtype=values.dtype)
    out[rows] = values
    return out
