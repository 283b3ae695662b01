"""Which random stream a grammar draws from, and how its shapes hand it on: one place for every site.

The paper's dialect draws from grammarc's counter-based keys (``backend.random``): a draw is a pure function
of the shape's key and the call's site, and nothing advances. CityEngine's dialect draws as Esri's Procedural
Runtime does (``backend.prt_random``), so that a lot with the same ``seed`` makes the same choices as in
CityEngine: the key column holds the shape's generator state (below 714025), a draw advances it in place,
and a shape the rule makes starts from its parent's state and moves the parent on. Both keep a lot's
numbers a function of its seed and its derivation path only, so records stay independent of chunking.

Draws, successors and ``NIL`` advance ``key`` in place, so that the operations after them in the body see
the state moved on. No other batch sees the write: a batch's key column is its own (``Shapes.take`` copies
it, but for a mask that keeps every shape, which gives the batch itself), the shapes an operation makes get
new keys, and a bracket keeps the states its waiting shape takes back at ``]`` (``execute.run``).
"""

from __future__ import annotations

import zlib

import numpy as np

from grammarc.backend import prt_random as prt
from grammarc.backend import random
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_exprs

#: The functions that draw from the shape's stream (``functions.math``, ``lists``, ``files``, ``assets``,
#: ``images``).
DRAWING = frozenset({"rand", "p", "listRandom", "fileRandom", "assetBestSize", "assetApproxSize", "assetFitSize",
                     "assetBestRatio", "assetApproxRatio", "imageBestRatio", "imageApproxRatio"})


def lot_keys(sequential: bool, seed: int, lot_index: np.ndarray, lot_seed: np.ndarray | None) -> np.ndarray:
    """The keys (L,) uint64 of lots numbered ``lot_index`` (L,).

    CityEngine's: a lot's state is its ``seed`` property (``lot_seed`` (L,), the lots' property column,
    NaN or None where a lot has none), as PRT takes an initial shape's ``seed`` attribute. A lot without a
    number there takes one drawn from ``seed`` and its number (its counter-based key), as CityEngine gives
    each new shape a random seed: PRT's streams of consecutive seeds start one step apart and draw almost
    the same numbers, so numbering the lots would give neighbours the same choices.
    """
    counted = random.lot_keys(seed, lot_index)
    if not sequential:
        return counted
    seeds = (counted & np.uint64(0xFFFFFFFF)).astype(np.int64)
    if lot_seed is not None and lot_seed.dtype != object:  # a text column gives no numbers
        given = np.isfinite(lot_seed)
        seeds[given] = lot_seed[given].astype(np.int64)
    return prt.start_states(seeds).astype(np.uint64)


def draws(expr: ir.Expr) -> bool:
    """Whether evaluating ``expr`` draws from the shape's stream."""
    return any(isinstance(e, ir.Call) and e.func in DRAWING for e in iter_exprs(expr))


def draw(sequential: bool, key: np.ndarray, site: int) -> np.ndarray:
    """One draw per shape (n,) float64 in [0, 1]; a sequential draw advances ``key`` (n,) in place."""
    if not sequential:
        return random.uniform(key, site)
    return prt.draw_in_place(key)


def successor_keys(sequential: bool, key: np.ndarray, site: int) -> np.ndarray:
    """The keys (n,) uint64 of the successors the shapes ``key`` (n,) make at ``site``; a sequential
    parent moves one draw on, in place."""
    if not sequential:
        return random.child_keys(key, site)
    return prt.child_in_place(key)


def bracket(sequential: bool, key: np.ndarray) -> np.ndarray | None:
    """``[``: a sequential copy that runs inside the brackets takes a child's states in ``key`` (in place);
    returns the states (n,) the shape that waits for ``]`` takes back then, having moved one draw on.
    None for the counter-based copy, which keeps its parent's key."""
    if not sequential:
        return None
    made = prt.child_in_place(key)
    moved = key.copy()
    key[:] = made
    return moved


def skip(sequential: bool, key: np.ndarray) -> None:
    """``NIL``: a sequential shape's state moves one draw on, as PRT's does, in place."""
    if sequential:
        prt.draw_in_place(key)


def piece_keys(sequential: bool, parent_key: np.ndarray, index: np.ndarray, site: int) -> np.ndarray:
    """The keys (m,) uint64 of pieces made at ``site`` (a split's, a component split's, a setback's):
    ``parent_key`` (m,) each piece's parent's key, ``index`` (m,) its number among its parent's pieces,
    in PRT's order (split order, face order, edge pieces before the remainder). A sequential piece
    starts where its parent's stream stands after the pieces before it, and spends one draw."""
    if not sequential:
        return random.child_keys(parent_key, site, index)
    return prt.piece_states(np.ascontiguousarray(parent_key), np.ascontiguousarray(index, dtype=np.int64))


def remade_keys(sequential: bool, key: np.ndarray) -> np.ndarray:
    """The keys of shapes an operation replaces by one new shape each (an offset face made a mesh of its
    pieces): a new counter-based key; a sequential shape goes on with its state (PRT makes no shape)."""
    if not sequential:
        return random.child_keys(key, 0, np.zeros(len(key), dtype=np.int64))
    return key


def attribute_keys(key: np.ndarray, name: str) -> np.ndarray:
    """The states (L,) uint64 a sequential attribute's default draws from on the lots ``key`` (L,).

    PRT draws each attribute's default from a stream of its own, started at the lot's seed plus a hash of
    the attribute's name; that hash is not identified (``prt_random``), so grammarc's stream of a name
    starts at the seed plus the name's CRC-32: defaults draw as independently of the lot's own stream
    and of each other as PRT's do, with other values.
    """
    return ((key.astype(np.int64) + zlib.crc32(name.encode())) % prt.MODULUS).astype(np.uint64)
