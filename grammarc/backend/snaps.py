"""Snap shapes (paper section 3.3): construction planes of a lot, and where they cross a split's scope.

``Snap`` and ``SnapLines`` add planes (a point and a unit normal in world coordinates, the lot, a label);
a snapped split (``Subdiv("XS", ...)``, ``Repeat("YS", ...)``) asks for the planes of its shape's lot that
stand across its axis (normal along it) and cut its scope: their positions along the axis, sorted, each
once. Only the shape's own lot is searched, so a lot's snaps never depend on which lots share its chunk;
the planes a split sees are those its lot made in earlier rules (the derivation's order, which is the same
for every lot).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from grammarc.ragged import offsets_from_counts, ragged_take

#: How parallel (cosine) a plane's normal must be to a split axis to stand across it.
_ACROSS = 1 - 1e-9
#: Snap positions closer than this (metres) are one.
_SAME = 1e-6


@dataclass
class SnapStore:
    """The snap planes of a chunk, appended batch by batch."""

    lot: list[np.ndarray] = field(default_factory=list)
    point: list[np.ndarray] = field(default_factory=list)
    normal: list[np.ndarray] = field(default_factory=list)
    label: list[np.ndarray] = field(default_factory=list)
    #: Label -> its number in ``label`` (an unlabelled plane has -1).
    labels: dict[str, int] = field(default_factory=dict)

    def add(self, lot: np.ndarray, point: np.ndarray, normal: np.ndarray, label: str | None) -> None:
        """Planes through ``point`` (k, 3) across unit ``normal`` (k, 3) of the lots ``lot`` (k,)."""
        number = -1 if label is None else self.labels.setdefault(label, len(self.labels))
        self.lot.append(lot.astype(np.int64))
        self.point.append(point)
        self.normal.append(normal)
        self.label.append(np.full(len(lot), number, dtype=np.int64))

    def across(self, lot: np.ndarray, origin: np.ndarray, axis: np.ndarray, extent: np.ndarray,
               label: str | None, tol: float) -> tuple[np.ndarray, np.ndarray]:
        """Where the planes of each scope's lot cross it: scopes from ``origin`` (n, 3) along the unit
        ``axis`` (n, 3) over ``extent`` (n,), planes with ``label`` (None: any). Returns offsets (n+1,)
        and the positions (k,) along the axis, strictly inside (tol, extent - tol), sorted per scope."""
        n = len(lot)
        if not self.lot or (label is not None and label not in self.labels):
            return np.zeros(n + 1, dtype=np.int64), np.zeros(0)
        plane_lot, point, normal, plane_label = (np.concatenate(c) for c in (self.lot, self.point, self.normal,
                                                                           self.label))
        if label is not None:
            keep = plane_label == self.labels[label]
            plane_lot, point, normal = plane_lot[keep], point[keep], normal[keep]
        order = np.argsort(plane_lot, kind="stable")
        plane_lot, point, normal = plane_lot[order], point[order], normal[order]
        by_lot = offsets_from_counts(np.bincount(plane_lot, minlength=int(lot.max(initial=-1)) + 1))
        plane, pair_offsets = ragged_take(by_lot, lot)
        scope = np.repeat(np.arange(n), np.diff(pair_offsets))
        facing = np.einsum("ij,ij->i", normal[plane], axis[scope])
        at = np.einsum("ij,ij->i", point[plane] - origin[scope], axis[scope])
        hit = (np.abs(facing) >= _ACROSS) & (at > tol) & (at < extent[scope] - tol)
        scope, at = scope[hit], at[hit]
        order = np.lexsort((at, scope))
        scope, at = scope[order], at[order]
        distinct = np.r_[True, (np.diff(scope) != 0) | (np.diff(at) > _SAME)] if len(at) else np.zeros(0, bool)
        scope, at = scope[distinct], at[distinct]
        return offsets_from_counts(np.bincount(scope, minlength=n)), at
