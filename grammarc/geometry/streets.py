"""Streets of lots: CityEngine's ``street.front|back|left|right|side`` selectors and the older
``streetSide`` / ``noStreetSide``.

A lot's street edges come from its ``streetWidth`` attribute (``io.lot_builder``). CityEngine selects the edges
(and the faces built on them) that lie along a street as ``street.front``, the rear ones as
``street.back`` and those in between as ``street.left`` / ``street.right``. grammarc reads that with a
*street frame* per lot: z the mean outward normal of its street edges (weighted by length), y up, x = y
cross z; an edge or face is ``street.front`` when it lies along one of the lot's street edges (within
``ALONG``) and faces out the same way, and otherwise is classified by its normal in the street frame as
``object.`` selectors are in the lot's frame (a face turned towards the street but set back from it is
front, one turned away is back). A lot without street edges falls back to its own frame (CityEngine:
"the selection falls back to the object.xxx selectors").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grammarc.ragged import next_in_segment, offsets_from_counts, ragged_take, segment_of

#: How far (metres) an edge may lie from a street edge and still lie along it.
ALONG = 0.01


@dataclass(frozen=True)
class Streets:
    """The street edges of a chunk's lots: ``start``, ``end`` (S, 3) world points, grouped by lot with
    ``lot_offsets`` (L+1,); ``axes`` (L, 3, 3) each lot's street frame (rows x, y, z), its own frame
    where it has no street edge; ``front`` (L, 2, 3) each lot's first edge (its front)."""

    start: np.ndarray
    end: np.ndarray
    lot_offsets: np.ndarray
    axes: np.ndarray
    front: np.ndarray

    def of_lots(self, lot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The street edges of the lots ``lot`` (n,), their front edge where they have none: the edges'
        ``start``, ``end`` (k, 3) and the row of ``lot`` each belongs to (k,)."""
        edge, offsets = ragged_take(self.lot_offsets, lot)
        row = np.repeat(np.arange(len(lot)), np.diff(offsets))
        bare = np.flatnonzero(np.diff(offsets) == 0)
        return (np.concatenate([self.start[edge], self.front[lot[bare], 0]]),
                np.concatenate([self.end[edge], self.front[lot[bare], 1]]), np.concatenate([row, bare]))


def lot_streets(vertices: np.ndarray, ring_offsets: np.ndarray, lot_offsets: np.ndarray, street: np.ndarray,
                lot_axes: np.ndarray) -> Streets:
    """The street edges and frames of lots given as ``model.lots.Lots`` arrays (exterior rings wind
    counter-clockwise seen from above, so an edge's outward normal is its direction turned clockwise)."""
    ring = segment_of(ring_offsets)
    nxt = next_in_segment(ring_offsets)
    edge = np.flatnonzero(street)
    lot = segment_of(lot_offsets)[ring[edge]]
    start, end = vertices[edge], vertices[nxt[edge]]
    step = end - start
    outward = np.stack([-step[:, 2], np.zeros(len(edge)), step[:, 0]], axis=1)  # length-weighted
    facing = np.zeros((len(lot_offsets) - 1, 3))
    np.add.at(facing, lot, outward)
    norm = np.linalg.norm(facing, axis=1)
    axes = lot_axes.copy()
    has = norm > 1e-9
    z = facing[has] / norm[has, None]
    y = np.tile([0.0, 1.0, 0.0], (int(has.sum()), 1))
    axes[has] = np.stack([np.cross(y, z), y, z], axis=1)
    first = ring_offsets[lot_offsets[:-1]]
    front = np.stack([vertices[first], vertices[nxt[first]]], axis=1)
    return Streets(start, end, offsets_from_counts(np.bincount(lot, minlength=len(norm))), axes, front)


def along_street(streets: Streets, lot: np.ndarray, start: np.ndarray, end: np.ndarray,
                 normal: np.ndarray) -> np.ndarray:
    """Which edges (m,) lie along a street edge of their lot: ``start``, ``end`` (m, 3) world points and
    ``normal`` (m, 3) the outward world normal; both ends within ``ALONG`` of the street edge's segment
    and facing out on its side."""
    pair_street, counts = ragged_take(streets.lot_offsets, lot)
    pair = np.repeat(np.arange(len(lot)), np.diff(counts))
    a, b = streets.start[pair_street], streets.end[pair_street]
    ab = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    out = np.stack([-ab[:, 2], np.zeros(len(ab)), ab[:, 0]], axis=1)

    def near(p):
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / length2, 0.0, 1.0)
        return np.linalg.norm(p - a - t[:, None] * ab, axis=1) <= ALONG

    facing = np.einsum("ij,ij->i", normal[pair], out) > 0
    hit = near(start[pair]) & near(end[pair]) & facing
    return np.bincount(pair[hit], minlength=len(lot)) > 0
