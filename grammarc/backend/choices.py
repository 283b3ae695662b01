"""Which consequent a shape takes where a rule has a set of them: a search state's fixed choice, or a draw.

GRAMATICA's operators have sets of consequents: ``choose(a, b, c)`` in an expression, and the ``?``
alternatives of a rule. A build draws one from the shape's stream at the choice's site, all equally likely
(``consequent``). A search (``grammarc.search``) derives each of its states as a lot of a chunk whose
``Choices`` fix them: the k-th choice a lot's derivation meets (in the schedule's order, the shapes of one
batch in their order) takes the k-th entry of the lot's path. The first choice beyond the path stops the
lot: it is a state with consequents, the path extended by each option, and its shapes are derived no
further (``execute.apply`` drops them). A lot that meets no choice beyond its path is complete.

Because the schedule is the same for every lot and a choice only reads its own lot's counters, a state's
derivation does not depend on the states beside it in the chunk.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from grammarc.backend.kernels.order import rank_in_group
from grammarc.backend.streams import draw
from grammarc.ir import nodes as ir


@dataclass(eq=False)
class Choices:
    """The fixed choices of the L lots (states) of a chunk, and what their derivations found.

    ``path`` (L, D) int32 holds each lot's choices, the first ``length`` (L,) of its row; ``aggregates``
    are the design values the search statements read (``backend.aggregates`` sums them as shapes are
    made). The rest is filled by the derivation: ``options`` (L,) the number of consequents of the
    choice a lot stopped at (0: complete) and ``site`` (L,) that choice's site, ``cost`` (L,) the costs of its rule applications, and after
    it ``goal``, ``prune`` (bool) and ``heuristic`` (L,) where the grammar states them.
    """

    path: np.ndarray
    length: np.ndarray
    aggregates: tuple[ir.Aggregate, ...] = ()
    #: Whether the states' leaves are written as records (a solution's), or only read (a search's).
    records: bool = False
    #: The number of the first state in the records' ``lot`` column (the states are numbered from it).
    first: int = 0
    taken: np.ndarray = field(init=False)
    options: np.ndarray = field(init=False)
    site: np.ndarray = field(init=False)
    cost: np.ndarray = field(init=False)
    #: Per aggregate (A, L): the sum (or count), the number of shapes, the least and the greatest value.
    total: np.ndarray = field(init=False)
    counted: np.ndarray = field(init=False)
    low: np.ndarray = field(init=False)
    high: np.ndarray = field(init=False)
    goal: np.ndarray | None = None
    prune: np.ndarray | None = None
    heuristic: np.ndarray | None = None

    def __post_init__(self) -> None:
        n, a = len(self.length), len(self.aggregates)
        self.taken = np.zeros(n, dtype=np.int64)
        self.options = np.zeros(n, dtype=np.int64)
        self.site = np.full(n, -1, dtype=np.int64)
        self.cost = np.zeros(n)
        self.total = np.zeros((a, n))
        self.counted = np.zeros((a, n))
        self.low = np.full((a, n), np.inf)
        self.high = np.full((a, n), -np.inf)

    @property
    def stopped(self) -> np.ndarray:
        """(L,) bool: the lots that met a choice beyond their path."""
        return self.options > 0

    def pick(self, lot: np.ndarray, count: int, site: int) -> np.ndarray:
        """The option (n,) int64 that shapes of ``lot`` (n,) take at a choice of ``count`` options at
        ``site``; a lot whose path ends before this choice stops here (its shapes take option 0, and are
        dropped)."""
        position = self.taken[lot] + rank_in_group(lot, len(self.taken))
        fixed = position < self.length[lot]
        picked = np.zeros(len(lot), dtype=np.int64)
        picked[fixed] = self.path[lot[fixed], position[fixed]]
        beyond = lot[~fixed & ~self.stopped[lot]]
        self.options[beyond] = count
        self.site[beyond] = site
        self.taken += np.bincount(lot, minlength=len(self.taken))
        return picked

    def charge(self, lot: np.ndarray, cost: np.ndarray) -> None:
        """Add the costs (n,) of rule applications to shapes of ``lot`` (n,) to their states'."""
        self.cost += np.bincount(lot, weights=cost, minlength=len(self.cost))

    def value(self, index: int) -> np.ndarray:
        """(L,) the value of aggregate ``index`` per lot: NaN for the ``min``, ``max`` or ``mean`` of no
        shapes (a comparison with it is false)."""
        func, counted = self.aggregates[index].func, self.counted[index]
        with np.errstate(invalid="ignore", divide="ignore"):
            if func == "mean":
                return self.total[index] / counted
            if func in ("min", "max"):
                return np.where(counted > 0, (self.low if func == "min" else self.high)[index], np.nan)
        return self.total[index]


def consequent(choices: Choices | None, sequential: bool, lot: np.ndarray, key: np.ndarray, site: int,
               count: int) -> np.ndarray:
    """The option (n,) int64 each shape takes at a choice of ``count`` options at ``site``: its state's
    (``choices``), else one drawn from its stream, all equally likely."""
    if choices is not None:
        return choices.pick(lot, count, site)
    return np.minimum((draw(sequential, key, site) * count).astype(np.int64), count - 1)
