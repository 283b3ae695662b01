"""CityEngine's random stream as Esri's Procedural Runtime (PRT) draws it, measured against PRT.

Every shape owns a linear congruential generator, the one of Numerical Recipes' table of quick
generators: ``x <- (4096 x + 150889) mod 714025``. A draw advances the state and returns
``float32(x) / float32(714024)`` (a float32, so 1.0 is possible); ``rand(lo, hi)`` is
``lo + (hi - lo) * u`` in float64 and ``p(q)`` is ``u < q``; a two-way stochastic case ``20%: A else: B``
is compiled to ``p(0.2)`` (how CityEngine's compiler turns three or more percentages into draws is not
known: compiled rules with them were not at hand). Which shape draws what, in PRT's order:

- a start shape's state is its ``seed`` taken as an unsigned 32-bit integer (seed -1 is 2**32 - 1);
- each ``rand``, ``p`` or stochastic case evaluated on a shape is one draw of that shape, in the order the
  rule evaluates them;
- a shape made by the rule (a successor, or the copy that ``[`` pushes) starts from
  ``(4096 x + 339068) mod 714025`` of its parent's state ``x``, and the parent's state advances by one
  draw: the child starts where the parent's draw lands, plus 188179 (``NIL`` moves the parent on too);
- the pieces of a split, a component split or a setback are made the same way, one after the other in the
  order PRT makes them (split order; for ``comp`` the order of the faces; for ``setback`` the edge pieces
  before the remainder, pieces that come out empty make none), and each piece spends one draw before its
  operations run;
- an attribute's default expression draws from its own stream, started at
  ``(seed mod 714025 + h(name)) mod 714025`` (the seed again as an unsigned 32-bit integer), where ``h``
  is a hash of the attribute's name as the compiled rule spells it (``Default$floorHeight``: 673492,
  ``Default$nFloor``: 207149) that is not identified. It is none of Java's ``String.hashCode``, FNV-1 and
  FNV-1a (32 and 64 bits), djb2, sdbm, CRC-32, Adler-32, libstdc++'s ``std::hash`` (murmur2) or boost's
  ``hash_range``, on UTF-8 or UTF-16, reduced modulo 714025 or 2**32 first, signed or not: the last
  character moves it by about 64 per code point with jumps (an exclusive or), the one before by about 64
  times as much, and no polynomial hash of base 1 to 93 gives it.

Operations that make no shape (``extrude``, ``t``, ``s``, ``i``, ``color``, ``texture``, ``set``...) draw
nothing; ``listRandom`` (and ``fileRandom`` over ``fileSearch``) is one draw, item ``floor(u (n - 1e-7))``.
Everything here is closed form over batches: ``k`` draws at once are ``x -> A_k x + C_k``. The kernels at
the end work on a derivation's key columns (uint64 states) in one pass each (``backend.streams``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

MODULUS = 714025
MULTIPLIER = 4096
INCREMENT = 150889
CHILD_INCREMENT = 339068  # INCREMENT + 188179: a child starts 188179 after its parent's draw


def start_states(seed: np.ndarray) -> np.ndarray:
    """The states (n,) int64 of start shapes whose ``seed`` attributes are ``seed`` (n,) integers."""
    return (np.asarray(seed, dtype=np.int64) & 0xFFFFFFFF) % MODULUS


def jump(k: int) -> tuple[int, int]:
    """``(A_k, C_k)``: ``k`` draws take a state ``x`` to ``(A_k x + C_k) mod 714025``."""
    return pow(MULTIPLIER, k, MODULUS), INCREMENT * _geometric(k) % MODULUS


def _geometric(k: int) -> int:
    """``1 + 4096 + ... + 4096**(k-1)`` mod 714025, by halving (no inverse: 4095 and 714025 share 5)."""
    if k == 0:
        return 0
    if k % 2:
        return (1 + MULTIPLIER * _geometric(k - 1)) % MODULUS
    half = _geometric(k // 2)
    return half * (1 + pow(MULTIPLIER, k // 2, MODULUS)) % MODULUS


def advance(state: np.ndarray, k: np.ndarray | int) -> np.ndarray:
    """The states (n,) int64 after ``k`` draws (scalar or (n,) non-negative integers) from ``state`` (n,)."""
    state = np.asarray(state, dtype=np.int64)
    if np.ndim(k) == 0:
        mul, add = jump(int(k))
        return (mul * state + add) % MODULUS
    return _advanced(state.astype(np.uint64), np.asarray(k, dtype=np.int64)).astype(np.int64)


def uniform(state: np.ndarray) -> np.ndarray:
    """The value (n,) float64 of a draw that landed on ``state`` (n,): float32(x) / float32(714024)."""
    return (np.asarray(state).astype(np.float32) / np.float32(MODULUS - 1)).astype(np.float64)


def draw(state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One draw per shape: the advanced states (n,) int64 and the values (n,) float64 in [0, 1]."""
    state = advance(state, 1)
    return state, uniform(state)


def child(state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A shape made by the rule from parents in ``state`` (n,): the child's states and the parents'."""
    state = np.asarray(state, dtype=np.int64)
    return (MULTIPLIER * state + CHILD_INCREMENT) % MODULUS, advance(state, 1)


def pieces(state: np.ndarray, index: np.ndarray | int) -> np.ndarray:
    """The states (m,) int64 of pieces of a split, a component split or a setback when their operations
    start: ``state`` (m,) each piece's parent's state before the operation, ``index`` (scalar or (m,)) its
    number among the parent's pieces. Piece ``i`` starts where the parent's stream stands after the ``i``
    pieces before it, and spends one draw. A split ends its shape's operations, so the parent's own state
    after it is never read again."""
    state = np.asarray(state, dtype=np.int64)
    index = np.broadcast_to(np.asarray(index, dtype=np.int64), state.shape)
    return piece_states(state.astype(np.uint64), np.ascontiguousarray(index)).astype(np.int64)


def rand(u: np.ndarray, lo, hi) -> np.ndarray:
    """``rand(lo, hi)`` from draws ``u`` (n,) float64: ``lo + (hi - lo) * u`` as PRT computes it."""
    lo = np.asarray(lo, dtype=np.float64)
    return lo + (np.asarray(hi, dtype=np.float64) - lo) * u


# ------------------------------------------------------------------------------------- kernels on key columns


@njit(cache=True, nogil=True)
def _jumps(k_max):
    """``(A_k, C_k)`` (k_max + 1,) uint64 each, for k = 0 .. k_max."""
    mul = np.empty(k_max + 1, np.uint64)
    add = np.empty(k_max + 1, np.uint64)
    mul[0], add[0] = 1, 0
    for k in range(k_max):
        mul[k + 1] = mul[k] * np.uint64(MULTIPLIER) % np.uint64(MODULUS)
        add[k + 1] = (add[k] * np.uint64(MULTIPLIER) + np.uint64(INCREMENT)) % np.uint64(MODULUS)
    return mul, add


@njit(cache=True, nogil=True)
def _advanced(state, k):
    """The states (n,) uint64 after ``k`` (n,) int64 draws from ``state`` (n,) uint64."""
    mul, add = _jumps(k.max() if len(k) else 0)
    out = np.empty_like(state)
    for i in range(len(state)):
        out[i] = (mul[k[i]] * state[i] + add[k[i]]) % np.uint64(MODULUS)
    return out


@njit(cache=True, nogil=True, inline="always")
def next_state(x):
    """The state after one draw from state ``x`` (uint64): where the draw lands."""
    return (np.uint64(MULTIPLIER) * x + np.uint64(INCREMENT)) % np.uint64(MODULUS)


@njit(cache=True, nogil=True, inline="always")
def child_state(x):
    """The state of a shape made by the rule from a parent in state ``x`` (uint64), before its own draw."""
    return (np.uint64(MULTIPLIER) * x + np.uint64(CHILD_INCREMENT)) % np.uint64(MODULUS)


@njit(cache=True, nogil=True, inline="always")
def value(x):
    """The value of a draw that landed on state ``x``, as ``uniform`` gives it (float32 division)."""
    return np.float32(x) / np.float32(MODULUS - 1)


@njit(cache=True, nogil=True)
def piece_states(state, index):
    """``pieces`` on uint64 states (m,) and int64 numbers (m,): the pieces' states (m,) uint64."""
    mul, add = _jumps(index.max() if len(index) else 0)
    out = np.empty_like(state)
    for i in range(len(state)):
        out[i] = next_state(child_state((mul[index[i]] * state[i] + add[index[i]]) % np.uint64(MODULUS)))
    return out


@njit(cache=True, nogil=True)
def draw_in_place(state):
    """One draw per shape from the states ``state`` (n,) uint64, which it advances in place: the values (n,)
    float64, as ``draw`` gives them."""
    out = np.empty(len(state))
    for i in range(len(state)):
        state[i] = next_state(state[i])
        out[i] = value(state[i])
    return out


@njit(cache=True, nogil=True)
def child_in_place(state):
    """``child`` of the states ``state`` (n,) uint64: the children's states (n,) uint64; the parents' move
    on in place."""
    made = np.empty_like(state)
    for i in range(len(state)):
        made[i] = child_state(state[i])
        state[i] = next_state(state[i])
    return made
