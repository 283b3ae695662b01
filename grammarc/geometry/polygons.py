"""The ragged polygon store: the geometry of shapes that are not simply their scope.

A polygon (with holes) is stored in its shape's scope, normalized: a vertex is (u, v) in [0, 1]^2, the
fractions of the scope size along the two axes of the polygon's plane. Because coordinates are relative to
the scope, ``T``, ``R`` and ``S`` never touch the store; only operations that make new geometry append
to it. ``plane`` is the scope axis normal to the polygon: 1 (y) for footprints, whose (u, v) run along
scope (x, z); 2 (z) for faces, along (x, y); 0 (x) along (y, z). Exterior rings wind counter-clockwise
around the +normal axis, holes clockwise.

Layout (Arrow-style offsets, each starting at 0):

- ``coords`` (V, 2) float64, ``ring_offsets`` (R+1,) int64 into coords,
- ``poly_offsets`` (G+1,) int64 into rings (exterior ring first), ``plane`` (G,) int8,
- ``turn`` (V,) int8: where the ring of a prism's side face over the edge from each vertex starts, and so
  which way its scope's x runs (``geometry.components.ALONG``, ``UP``, ``DOWN``): ``ALONG`` (0) but on
  the faces a split cuts through a hole (``geometry.clip.cap_turns``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.constants import STRICT
from grammarc.ragged import ragged_take

#: Scope axes spanned by (u, v) for each normal axis.
PLANE_AXES = {0: (1, 2), 1: (0, 2), 2: (0, 1)}
#: The scope axis of u (``PLANE_U``) and of v (``PLANE_V``), indexed by the normal axis.
PLANE_U = np.array([PLANE_AXES[p][0] for p in range(3)])
PLANE_V = np.array([PLANE_AXES[p][1] for p in range(3)])


def plane_to_scope(uv: np.ndarray, plane: np.ndarray, height: np.ndarray | None = None) -> np.ndarray:
    """Points (k, 3) in scope axes from in-plane coordinates ``uv`` (k, 2) of the planes ``plane`` (k,)
    and, if given, their ``height`` (k,) along each plane's normal axis (0 otherwise)."""
    out = np.zeros((len(uv), 3))
    at = np.arange(len(uv))
    out[at, PLANE_U[plane]] = uv[:, 0]
    out[at, PLANE_V[plane]] = uv[:, 1]
    if height is not None:
        out[at, plane] = height
    return out


class PolygonStore:
    """Append-only ragged storage of normalized polygons for one chunk of lots."""

    def __init__(self) -> None:
        self.coords = np.empty((0, 2))
        self.ring_offsets = np.zeros(1, dtype=np.int64)
        self.poly_offsets = np.zeros(1, dtype=np.int64)
        self.plane = np.empty(0, dtype=np.int8)
        self.turn = np.empty(0, dtype=np.int8)

    def __len__(self) -> int:
        return len(self.plane)

    def add(self, coords: np.ndarray, ring_offsets: np.ndarray, poly_offsets: np.ndarray,
            plane: np.ndarray, turn: np.ndarray | None = None) -> np.ndarray:
        """Append polygons given as ragged arrays (offsets from 0), with their side faces' ``turn`` (V,)
        (None: all 0); returns their ids (k,) int32."""
        if STRICT:
            assert ring_offsets[0] == 0 and poly_offsets[0] == 0, "offsets must start at 0"
            assert (np.diff(ring_offsets) >= 3).all(), "a ring has fewer than 3 vertices"
            assert (np.diff(poly_offsets) >= 1).all(), "a polygon has no ring"
            assert ring_offsets[-1] == len(coords) and poly_offsets[-1] == len(ring_offsets) - 1
        first = len(self.plane)
        self.ring_offsets = np.concatenate([self.ring_offsets, ring_offsets[1:] + len(self.coords)])
        self.poly_offsets = np.concatenate(
            [self.poly_offsets, poly_offsets[1:] + (len(self.ring_offsets) - len(ring_offsets))]
        )
        self.coords = np.concatenate([self.coords, coords])
        self.turn = np.concatenate([self.turn, np.zeros(len(coords), np.int8) if turn is None
                                    else np.asarray(turn, dtype=np.int8)])
        self.plane = np.concatenate([self.plane, np.asarray(plane, dtype=np.int8)])
        return np.arange(first, len(self.plane), dtype=np.int32)

    def gather(self, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Polygons ``ids`` as new ragged arrays: (coords, ring_offsets, poly_offsets)."""
        return _gather(self.coords, self.ring_offsets, self.poly_offsets, np.asarray(ids, np.int64))

    def turns(self, ids: np.ndarray) -> np.ndarray:
        """The ``turn`` of polygons ``ids``' vertices (V',) int8, in ``gather``'s order."""
        rings, _ = ragged_take(self.poly_offsets, np.asarray(ids, np.int64))
        vertices, _ = ragged_take(self.ring_offsets, rings)
        return self.turn[vertices]


@njit(cache=True, nogil=True)
def _gather(coords, ring_offsets, poly_offsets, ids):
    """Copy polygons ``ids`` out of a ragged store.

    coords : (V, 2) float64; ring_offsets : (R+1,) int64; poly_offsets : (G+1,) int64; ids : (k,) int64.
    Returns coords (V', 2), ring_offsets (R'+1,), poly_offsets (k+1,), all allocated here.
    """
    k = len(ids)
    out_poly = np.zeros(k + 1, np.int64)
    n_rings = 0
    n_verts = 0
    for i in range(k):
        g = ids[i]
        r0, r1 = poly_offsets[g], poly_offsets[g + 1]
        n_rings += r1 - r0
        n_verts += ring_offsets[r1] - ring_offsets[r0]
        out_poly[i + 1] = n_rings
    out_ring = np.zeros(n_rings + 1, np.int64)
    out_coords = np.empty((n_verts, 2))
    r = 0
    v = 0
    for i in range(k):
        g = ids[i]
        for ring in range(poly_offsets[g], poly_offsets[g + 1]):
            for j in range(ring_offsets[ring], ring_offsets[ring + 1]):
                out_coords[v, 0] = coords[j, 0]
                out_coords[v, 1] = coords[j, 1]
                v += 1
            r += 1
            out_ring[r] = v
    return out_coords, out_ring, out_poly
