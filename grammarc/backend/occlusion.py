"""CityEngine's occlusion queries on the shape columns: occluders, who sees which, and the answers.

Occluders are closed solids (CityEngine tests only closed geometry): a shape that a component split takes
apart (the mass a facade comes from), a leaf solid (a box, a prism, ``primitiveCube``) and a shape given a
``label``. Each is stored as a prism (``geometry.occlusion.Prisms``) with its lot, an id (the lot's number
times 2^24 plus its count in the lot: the same whatever the chunking) and its label. Roofs and other
meshes do not occlude yet.

``minimumDistance`` and ``contextCount`` look at labelled shapes (``label``), solid or not: the distance
from the shape's scope to their scopes, their number (``_context``).

A query (``inside``, ``overlaps``, ``touches``) of a shape tests its scope box (a solid's) or rectangle
(a face's) against:

- ``intra``: the occluders of its own lot that are not its ancestors. A shape carries the ids of its
  nearest ``ANCESTORS`` occluding ancestors; descendants do not exist yet when a query runs.
- ``inter``: the occluders of the other lots, from the first pass of a two-pass build
  (``build.derive_all``): every lot is derived up to its first query, its occluders are kept, then the
  city is derived again with them. So a lot's answers do not depend on its chunk.

Rules that query wait (``derive.derive_chunk``) until nothing else of their stage is pending, so the
occluders of every other branch exist when they run.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import shapely

from grammarc.backend.shapes import asset_geom, face_axes
from grammarc.backend.slots import ANCESTORS
from grammarc.constants import TOL
from grammarc.geometry.box_distance import box_distances
from grammarc.geometry.clip import scope_polygons
from grammarc.geometry.meshes import is_polygon
from grammarc.geometry.occlusion import (
    BOX_CORNERS,
    BOX_EDGES,
    QUAD_CORNERS,
    QUAD_EDGES,
    Prisms,
    prisms,
    relations,
)
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.ir.nodes import CONTEXT_KINDS

#: Occluders per lot are numbered below this.
_PER_LOT = 2 ** 24
#: A sightline: one edge between its two ends.
_SEGMENT = np.array([[0, 1]])
#: How far (metres) apart boxes may be and still be paired for the exact test.
_PAD = 1e-3
#: The ``geom`` of a ``primitiveCube`` (the built-in cube, asset 0, not mirrored): a box.
_CUBE = int(asset_geom(np.array([0]))[0])


@dataclass(frozen=True)
class Occluders:
    """A table of occluders: ``lot`` (k,) global lot numbers, ``ident`` (k,) float64 ids, ``label`` (k,)
    object (str or None), ``active`` (k,) bool (a leaf, not a shape taken apart), ``size`` (k, 3) their
    scopes' sizes (the prisms hold the scopes' origins and axes), ``solid`` (k,) bool, and their ``prisms``.

    A labelled shape that is not a closed solid (a face, a roof) is a row too, not ``solid``: the occlusion
    queries do not see it (``solids``), the context queries (``_context``) do."""

    lot: np.ndarray
    ident: np.ndarray
    label: np.ndarray
    active: np.ndarray
    size: np.ndarray
    solid: np.ndarray
    prisms: Prisms

    @staticmethod
    def concat(tables: list[Occluders]) -> Occluders:
        tables = [t for t in tables if len(t.lot)] or [_EMPTY]
        if len(tables) == 1:
            return tables[0]
        return Occluders(*(np.concatenate([getattr(t, f) for t in tables]) for f in _COLUMNS),
                         Prisms.concat([t.prisms for t in tables]))

    def take(self, rows: np.ndarray) -> Occluders:
        return Occluders(*(getattr(self, f)[rows] for f in _COLUMNS), self.prisms.take(rows))

    @cached_property
    def solids(self) -> Occluders:
        """The rows that occlude (closed solids), for ``inside``, ``overlaps``, ``touches``."""
        return self if self.solid.all() else self.take(np.flatnonzero(self.solid))

    @cached_property
    def index(self):
        """The occluders' world boxes (low, high (k, 3)) and a GEOS STRtree of their ground rectangles."""
        p = self.prisms
        k = np.arange(len(p.plane))
        bounds = shapely.bounds(p.polygon)
        low = np.zeros((len(k), 3))
        size = np.zeros((len(k), 3))
        low[k, PLANE_U[p.plane]], low[k, PLANE_V[p.plane]] = bounds[:, 0], bounds[:, 1]
        size[k, PLANE_U[p.plane]] = bounds[:, 2] - bounds[:, 0]
        size[k, PLANE_V[p.plane]] = bounds[:, 3] - bounds[:, 1]
        size[k, p.plane] = p.height
        o_low, o_high = _world_boxes(p.origin + np.einsum("pi,pij->pj", low, p.axes), p.axes, size)
        pad = _PAD
        tree = shapely.STRtree(shapely.box(o_low[:, 0] - pad, o_low[:, 2] - pad, o_high[:, 0] + pad,
                                           o_high[:, 2] + pad))
        return o_low, o_high, tree


_COLUMNS = ("lot", "ident", "label", "active", "size", "solid")
_EMPTY = Occluders(np.zeros(0, np.int64), np.zeros(0), np.zeros(0, dtype=object), np.zeros(0, dtype=bool),
                   np.zeros((0, 3)), np.zeros(0, dtype=bool),
                   prisms(np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros(0, np.int64), np.zeros(0),
                          np.zeros(0, dtype=object)))


@dataclass
class OccluderStore:
    """The occluders a chunk has made so far, and how many per lot (for their ids)."""

    tables: list[Occluders] = field(default_factory=list)
    count: np.ndarray | None = None

    def table(self) -> Occluders:
        return Occluders.concat(self.tables)


def add_occluders(chunk, shapes, label: str | np.ndarray | None = None, active: bool = True,
                  scopes: bool = False) -> np.ndarray:
    """Store the closed solids among ``shapes`` (scope boxes and polygon prisms) as occluders of their
    lots (``active``: leaves, not shapes being taken apart), labelled ``label`` (one, or (n,) texts, one
    a shape); returns each shape's new id (NaN for a shape that is not a solid). With ``scopes`` (``label()``),
    the other shapes are stored too, as scopes that do not occlude (``Occluders.solid``), for the
    context queries."""
    ident = np.full(len(shapes), np.nan)
    flat = (shapes.size <= 1e-9).any(axis=1)
    polygon = is_polygon(shapes.geom)
    solid = ~flat & ((shapes.geom == -1) | (shapes.geom == _CUBE) | polygon)
    if scopes:
        _add_scopes(chunk, shapes.take(np.flatnonzero(~solid)), label[~solid] if isinstance(label, np.ndarray)
                    else label)
    rows = np.flatnonzero(solid)
    if not len(rows):
        return ident
    store = chunk.occluders
    if store.count is None:
        store.count = np.zeros(len(chunk.lot_index), dtype=np.int64)
    lot = shapes.lot[rows]
    # numbered per lot in row order: the same rows in any chunk
    order = np.argsort(lot, kind="stable")
    first = np.searchsorted(lot[order], lot[order])
    number = np.empty(len(rows), dtype=np.int64)
    number[order] = store.count[lot[order]] + (np.arange(len(rows)) - first)
    np.add.at(store.count, lot, 1)
    ident[rows] = chunk.lot_index[lot].astype(np.float64) * _PER_LOT + number
    sub = shapes.take(rows)
    plane = np.ones(len(rows), dtype=np.int64)
    is_poly = polygon[rows]
    plane[is_poly] = chunk.polygons.plane[sub.geom[is_poly]]
    polygons = np.empty(len(rows), dtype=object)
    k = np.arange(len(rows))
    polygons[~is_poly] = shapely.box(0, 0, sub.size[k, PLANE_U[plane]][~is_poly], sub.size[k, PLANE_V[plane]][~is_poly])
    if is_poly.any():
        polygons[is_poly] = scope_polygons(chunk.polygons, sub.geom[is_poly], sub.size[is_poly])
    labels = label[rows] if isinstance(label, np.ndarray) else np.full(len(rows), label, dtype=object)
    store.tables.append(Occluders(chunk.lot_index[lot], ident[rows], labels, np.full(len(rows), active),
                                  sub.size.copy(), np.ones(len(rows), dtype=bool),
                                  prisms(sub.origin.copy(), chunk.frames[sub.frame], plane, sub.size[k, plane], polygons)))
    return ident


def _add_scopes(chunk, shapes, label: str | np.ndarray) -> None:
    """Store labelled ``shapes`` that are not closed solids as scopes (their boxes as prisms, never tested
    by an occlusion query) without ids: they are nobody's occluding ancestor."""
    n = len(shapes)
    if not n:
        return
    size = shapes.size.copy()
    labels = label if isinstance(label, np.ndarray) else np.full(n, label, dtype=object)
    chunk.occluders.tables.append(Occluders(
        chunk.lot_index[shapes.lot], np.full(n, np.nan), labels, np.ones(n, dtype=bool), size,
        np.zeros(n, dtype=bool), prisms(shapes.origin.copy(), chunk.frames[shapes.frame], np.ones(n, dtype=np.int64),
                                        size[:, 1], shapely.box(0, 0, size[:, 0], size[:, 2]))))


def with_ancestor(plan, shapes, ident: np.ndarray):
    """``shapes`` with ``ident`` (n,) pushed onto their occluding ancestors (where it is not NaN)."""
    slots = [plan.dynamic[name] for name in ANCESTORS]
    dynamic = list(shapes.dynamic)
    has = ~np.isnan(ident)
    for k in range(len(slots) - 1, 0, -1):
        dynamic[slots[k]] = np.where(has, dynamic[slots[k - 1]], dynamic[slots[k]])
    dynamic[slots[0]] = np.where(has, ident, dynamic[slots[0]])
    return replace(shapes, dynamic=tuple(dynamic))


def take_apart(ctx, shapes, children, parent: np.ndarray):
    """``children`` (a component split's, of ``shapes`` rows ``parent`` (m,)) carrying their parents as
    occluding ancestors: the parents, solids taken apart, become occluders, once each
    (``Context.taken_apart``)."""
    if not ctx.plan.occluders:
        return children
    ident = ctx.taken_apart.get(shapes)
    if ident is None:
        ident = ctx.taken_apart[shapes] = add_occluders(ctx.chunk, shapes, occluder_label(ctx.plan, ctx.symbol),
                                                        active=False)
    return with_ancestor(ctx.plan, children, ident[parent])


def occluder_label(plan, symbol: int) -> str | None:
    """The label of the occluders a rule of ``symbol`` makes: the paper names a shape by its symbol
    (``Shape.occ("balcony")``); CityEngine labels with ``label()`` only."""
    return None if plan.leaf_bodies else plan.symbols[symbol].name


def interned_texts(plan, ids: np.ndarray) -> np.ndarray:
    """The texts (objects) of interned string ``ids``, as occluders keep their labels."""
    return np.array(list(plan.strings.ids), dtype=object)[ids]


def query(expr, env, distance: np.ndarray | None = None, which: np.ndarray | None = None,
          named: np.ndarray | None = None) -> np.ndarray:
    """The answer of an ``ir.Occlusion`` for every shape of ``env``: (n,) bool, or for the paper's
    ``Shape.occ`` the interned strings "none", "part", "full" (n,); ``distance`` (n,) the value of its
    ``distance`` expression, ``which`` and ``named`` (n,) interned strings those of its computed target
    and label. A computed target ``intra`` tests the shape's own lot, ``inter`` the others, any other
    text (``all``) both."""
    shapes, chunk = env.shapes, env.chunk
    n = len(shapes)
    if which is not None:
        which = np.broadcast_to(interned_texts(env.plan, which), (n,))
    if named is not None:
        named = np.broadcast_to(interned_texts(env.plan, named), (n,))
    if expr.kind == "visible":
        return _visible(shapes, chunk)
    if expr.kind in CONTEXT_KINDS:
        return _context(expr, shapes, chunk, which, named)
    occ = expr.kind == "occ"
    kinds = ("inside", "touches") if occ else (expr.kind,)
    found = {kind: np.zeros(n, dtype=bool) for kind in kinds}
    distance = np.zeros(n) if distance is None else np.broadcast_to(np.asarray(distance, np.float64), (n,))
    own = chunk.lot_index[shapes.lot]
    ancestors = np.stack([shapes.dynamic[env.plan.dynamic[name]] for name in ANCESTORS], axis=1)
    for table, intra in _sources(chunk, expr.target if which is None else "all"):
        if expr.label is not None or expr.active:
            table = table.take(np.flatnonzero((table.label == expr.label) if expr.label is not None else table.active))
        rows, occluder = _pairs(shapes, chunk, table, distance)
        keep = (table.lot[occluder] == own[rows]) == intra
        if which is not None:
            keep &= which[rows] != ("inter" if intra else "intra")
        if named is not None:
            keep &= table.label[occluder] == named[rows]
        if intra and not expr.parents:
            keep &= ~(ancestors[rows] == table.ident[occluder, None]).any(axis=1)
        rows, occluder = rows[keep], occluder[keep]
        if len(rows):
            for kind, result in zip(kinds, _relations(kinds, shapes, chunk, rows, table.take(occluder),
                                                      distance[rows])):
                np.logical_or.at(found[kind], rows, result)
    if not occ:
        return found[expr.kind]
    full, part = found["inside"], found["touches"] & ~found["inside"]
    strings = env.strings
    return np.where(full, strings["full"], np.where(part, strings["part"], strings["none"])).astype(np.int32)


#: At most this many (query, labelled scope) pairs of other lots are taken at once (``_labelled_pairs``).
_PAIRS = 1 << 20


def _context(expr, shapes, chunk, which: np.ndarray | None, named: np.ndarray | None) -> np.ndarray:
    """CityEngine's context queries over labelled shapes, (n,) float64 each:

    - ``minimumDistance(target, label)``: the least distance from the shape's scope box to the scope of a
      shape labelled ``label`` (``geometry.box_distance``), infinity where there is none;
    - ``contextCount(target, label)``: how many shapes are labelled ``label``.

    An empty label finds none, as the reference says. Every ``label()`` makes a labelled shape of its
    own, counted separately (the reference's ``contextCount`` example counts a tile's own label), so a
    shape's own label and its ancestors' count: a labelled shape is at distance 0 from what follows it.
    ``intra`` looks at the labelled shapes of the shape's lot, ``inter`` at those of the other lots (every
    other lot of the city: CityEngine's context queries look at the whole scene by default)."""
    n = len(shapes)
    count = expr.kind == "contextCount"
    found = np.zeros(n) if count else np.full(n, np.inf)
    axes = chunk.frames[shapes.frame]
    for table, rows, labelled in _labelled_pairs(expr, shapes, chunk, which, named):
        if count:
            found += np.bincount(rows, minlength=n)
        else:
            np.minimum.at(found, rows, box_distances(shapes.origin[rows], axes[rows], shapes.size[rows],
                                                     table.prisms.origin[labelled], table.prisms.axes[labelled],
                                                     table.size[labelled]))
    return found


def _labelled_pairs(expr, shapes, chunk, which, named):
    """The (table, query rows (p,), table rows (p,)) of the shapes and the labelled shapes they look at
    (``_context``): a join on the lot for ``intra``; all pairs of other lots for ``inter``, a block of
    query rows at a time (at most ``_PAIRS`` pairs)."""
    n = len(shapes)
    label = np.broadcast_to(np.asarray(expr.label if named is None else named, dtype=object), (n,))
    own = chunk.lot_index[shapes.lot]
    for table, intra in _sources(chunk, expr.target if which is None else "all", solids=False):
        asked = np.zeros(len(table.lot), dtype=bool)
        for text in ({expr.label} if named is None else set(np.unique(named))) - {""}:  # (isin sorts None)
            asked |= table.label == text
        table = table.take(np.flatnonzero(asked))
        if not len(table.lot):
            continue
        order = np.argsort(table.lot, kind="stable")
        sorted_lot = table.lot[order]
        if intra:
            first, last = np.searchsorted(sorted_lot, own, "left"), np.searchsorted(sorted_lot, own, "right")
            blocks = [np.arange(n)]
        else:
            first, last = np.zeros(n, np.int64), np.full(n, len(order))
            blocks = np.array_split(np.arange(n), max(1, n * len(order) // _PAIRS))
        for block in blocks:
            count = last[block] - first[block]
            rows = np.repeat(block, count)
            starts = np.cumsum(count) - count
            labelled = order[first[rows] + np.arange(len(rows)) - np.repeat(starts, count)]
            keep = (table.label[labelled] == label[rows]) & ((table.lot[labelled] == own[rows]) == intra)
            if which is not None:
                keep &= which[rows] != ("inter" if intra else "intra")
            if keep.any():
                yield table, rows[keep], labelled[keep]


#: A face sees street points more than this (metres) in front of its plane (``_visible``).
_AHEAD = 1e-3
#: Where a sightline ends: this far (metres) out from the lot's street edge, on the street.
_STREET_OUTSET = 1.0


def _visible(shapes, chunk) -> np.ndarray:
    """The paper's ``Shape.visible("street")``: the sightline from the centre of each shape's scope to the
    nearest point of its lot's street (its street edges, or its front edge where it has none, moved
    ``_STREET_OUTSET`` out onto the street) passes through no occluder's interior, of any lot (its own building's mass included: a facade turned away from the
    street looks through it).

    A wall (a flat scope standing up) looks only ahead: its sightline goes to the nearest street point in
    front of its plane (more than ``_AHEAD`` m), and it sees nothing when there is none. So a wall square to the
    street on the lot's boundary (a party wall, a row house's end) does not see the street, though the
    line along its surface meets no interior; set back from the boundary, it sees the street obliquely.
    """
    n = len(shapes)
    axes = chunk.frames[shapes.frame]
    centre = shapes.origin + 0.5 * np.einsum("pj,pji->pi", shapes.size, axes)
    start, end, row = chunk.streets.of_lots(shapes.lot)
    step = end - start
    # the street runs beside the lot, not on its edge: 1 m out (lots are counter-clockwise seen from +y)
    out = np.cross(step, [0.0, 1.0, 0.0])
    out *= _STREET_OUTSET / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-300)
    start, end = start + out, end + out
    t = np.clip(np.einsum("kj,kj->k", centre[row] - start, step) / np.maximum(
        np.einsum("kj,kj->k", step, step), 1e-300), 0.0, 1.0)
    # a wall (a flat scope whose normal is mostly horizontal): t limited to the part of the street edge
    # ahead of it, on the side its normal points to (empty: lo > hi); roofs and ground shapes look anywhere
    flat = shapes.size[row] <= TOL.zero
    normal = np.einsum("pk,pki->pi", flat.astype(float), axes[row])  # the flat axis: the face's normal
    normal[:, 1] = 0.0
    face = flat.any(axis=1) & (np.linalg.norm(normal, axis=1) > 0.5)
    a = np.einsum("pi,pi->p", start - centre[row], normal) - _AHEAD
    b = np.einsum("pi,pi->p", end - centre[row], normal) - _AHEAD
    with np.errstate(divide="ignore", invalid="ignore"):
        crossing = np.where(a != b, a / (a - b), 0.0)  # where a + t (b - a) = 0
    lo = np.where(face & (a <= 0) & (b > 0), crossing, 0.0)
    hi = np.where(face & (a > 0) & (b <= 0), crossing, 1.0)
    ahead = ~face | (a > 0) | (b > 0)
    t = np.clip(t, lo, hi)
    point = start + t[:, None] * step
    distance = np.where(ahead & (lo <= hi), np.linalg.norm(point - centre[row], axis=1), np.inf)
    nearest = np.full(n, np.inf)
    np.minimum.at(nearest, row, distance)
    chosen = np.flatnonzero((distance <= nearest[row]) & np.isfinite(distance))
    chosen = chosen[np.unique(row[chosen], return_index=True)[1]]  # one sightline a shape
    sight = np.stack([centre[row[chosen]], point[chosen]], axis=1)
    blocked = np.ones(n, dtype=bool)
    blocked[row[chosen]] = False  # a shape with no street ahead sees none
    own = chunk.lot_index[shapes.lot]
    for table, intra in _sources(chunk, "all"):
        q, o = _candidates(table, sight.min(axis=1), sight.max(axis=1))
        shape_row = row[chosen][q]
        keep = (table.lot[o] == own[shape_row]) == intra
        q, o, shape_row = q[keep], o[keep], shape_row[keep]
        if len(q):
            hit = relations(sight[q], _SEGMENT, table.prisms.take(o), ("overlaps",))["overlaps"]
            np.logical_or.at(blocked, shape_row, hit)
    return ~blocked


def _sources(chunk, target: str, solids: bool = True) -> list[tuple[Occluders, bool]]:
    """The occluders a query of ``target`` tests (the ``solids`` only, or every labelled scope too), each
    table with whether it is for the shape's own lot (the chunk's, as they are now) or for the other lots
    (the first pass's)."""
    sources = []
    if target in ("intra", "all"):
        sources.append((chunk.occluders.table(), True))
    if target in ("inter", "all") and chunk.foreign is not None:
        sources.append((chunk.foreign, False))
    return [(table.solids, intra) for table, intra in sources] if solids else sources


def _relations(kinds, shapes, chunk, rows: np.ndarray, occluders: Occluders, distance: np.ndarray):
    """The ``kinds`` (each (p,) bool) of the shapes ``rows`` (p,) (their scope boxes, or rectangles for
    faces, enlarged by ``distance`` (p,)) against the pairs' occluders."""
    out = [np.zeros(len(rows), dtype=bool) for _ in kinds]
    axes = chunk.frames[shapes.frame[rows]]
    size = shapes.size[rows] + 2 * distance[:, None]
    origin = shapes.origin[rows] - np.einsum("p,pij->pj", distance, axes)
    flat = size <= 1e-9
    face = flat.any(axis=1)
    for is_face, unit, edges in ((False, BOX_CORNERS, BOX_EDGES), (True, QUAD_CORNERS, QUAD_EDGES)):
        pick = np.flatnonzero(face == is_face)
        if not len(pick):
            continue
        s, frame = size[pick], axes[pick]
        if is_face:  # the face's two extents as its x and y
            frame, s = face_axes(frame, s, np.argmax(flat[pick], axis=1))
        corners = origin[pick, None] + np.einsum("cj,pj,pji->pci", unit, s, frame)
        found = relations(corners, edges, occluders.prisms.take(pick), kinds)
        for k, kind in enumerate(kinds):
            out[k][pick] = found[kind]
    return out


def _pairs(shapes, chunk, table: Occluders, distance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(query row, occluder) pairs whose world boxes meet, the scopes enlarged by ``distance``."""
    axes = chunk.frames[shapes.frame]
    low, high = _world_boxes(shapes.origin - np.einsum("p,pij->pj", distance, axes), axes,
                             shapes.size + 2 * distance[:, None])
    return _candidates(table, low, high)


def _candidates(table: Occluders, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(query, occluder) pairs whose world boxes (query boxes ``low``, ``high`` (n, 3)) meet: GEOS
    STRtree on the ground plane, then the heights."""
    if not len(table.lot):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    o_low, o_high, tree = table.index
    q, o = tree.query(shapely.box(low[:, 0], low[:, 2], high[:, 0], high[:, 2]))
    keep = (low[q, 1] <= o_high[o, 1] + _PAD) & (o_low[o, 1] <= high[q, 1] + _PAD)
    return q[keep], o[keep]


def _world_boxes(origin, axes, size):
    """World axis-aligned bounds (low, high) of scope boxes."""
    corners = origin[:, None] + np.einsum("cj,pj,pji->pci", BOX_CORNERS, size, axes)
    return corners.min(axis=1), corners.max(axis=1)
