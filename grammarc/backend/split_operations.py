"""The splits of ``Executor``: ``split``/``repeat`` (the paper's Subdiv and Repeat), CityEngine's
``split`` with repeat groups, the children they fan out to (scopes, keys, context), and the pieces of
polygons and meshes cut to their slabs.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend import mesh_shapes
from grammarc.backend.evaluate import evaluate, evaluate_array
from grammarc.backend.kernels import scope as scope_kernels
from grammarc.backend.kernels import split as split_kernels
from grammarc.backend.kernels.order import group_by
from grammarc.backend.leaf_parts import LeafRecords
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.errors import LimitError
from grammarc.geometry.clip import clip_to_slabs
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.ir import nodes as ir
from grammarc.ragged import offsets_from_counts, ragged_take, rank_within


class SplitOperations:
    """The split operations of ``Executor`` (which provides ``plan``, ``chunk``, ``env``, ``fail``, ``count``
    and the others' methods)."""

    def split_sizes(self, op: ir.Split | ir.GroupSplit, cursor: Shapes, symbol: int, what: str) -> np.ndarray:
        """The parts' sizes, (n, P) or (1, P) when the same for all shapes; a negative or NaN one fails."""
        env = self.env(cursor)
        values = _size_matrix([evaluate(s.value, env) for s in op.sizes], len(cursor))
        self.fail_negative(cursor, values, f"`{what}` has a negative or NaN size", symbol, op.span)
        return values

    def split(self, op: ir.Split, cursor: Shapes, symbol: int) -> None:
        values = self.split_sizes(op, cursor, symbol, "Subdiv")
        relative = np.array([s.kind is ir.SizeKind.RELATIVE for s in op.sizes])

        def cut(shapes: Shapes, level: int, axis: int):
            nonlocal values
            parent, part, pos, length = split_kernels.subdiv(
                np.ascontiguousarray(shapes.size[:, axis]), values, relative, TOL.zero
            )
            if op.snap:
                split_kernels.snap_subdiv(parent, pos, length, *self.snaps_across(shapes, axis, op.snap_label))
            if values.shape[0] > 1:
                values = values[parent]  # the next axis' sizes follow the children
            return parent, part * len(op.sizes) ** level, pos, length

        self.fan_out(op, cursor, symbol, cut)

    def repeat(self, op: ir.Repeat, cursor: Shapes, symbol: int) -> None:
        env = self.env(cursor)
        sizes = [evaluate_array(e, env) for e in op.sizes]
        stride = np.ones(len(cursor), dtype=np.int64)

        def cut(shapes: Shapes, level: int, axis: int):
            nonlocal sizes, stride
            size = sizes[level]
            bad = ~(size > 0)
            if bad.any():
                self.fail(shapes, bad, f"`Repeat` needs a positive size, got {size[bad][0]:g}", symbol,
                          op.span)
            extent = np.ascontiguousarray(shapes.size[:, axis])
            counts = split_kernels.repeat_counts(extent, size, TOL.zero)
            if op.snap:  # each snap plane adds one element at most
                offsets, snaps = self.snaps_across(shapes, axis, op.snap_label)
                self.check_fan_out(shapes, counts + np.diff(offsets), symbol, op.span)
                # the snap planes cut the scope first and each piece repeats on its own (Fig. 9)
                piece_parent, start, piece = _pieces(extent, offsets, snaps)
                piece_counts = split_kernels.repeat_counts(piece, size[piece_parent], TOL.zero)
                child, _, pos, length = split_kernels.repeat(piece, piece_counts)
                parent = piece_parent[child]
                pos += start[child]
                part = rank_within(parent)
                counts = np.bincount(parent, minlength=len(shapes))
            else:
                self.check_fan_out(shapes, counts, symbol, op.span)
                parent, part, pos, length = split_kernels.repeat(extent, counts)
            step = part * stride[parent]
            stride = stride[parent] * counts[parent]
            sizes = [s[parent] for s in sizes]  # the next axes' sizes follow the children
            return parent, step, pos, length

        self.fan_out(op, cursor, symbol, cut)

    def snaps_across(self, shapes: Shapes, axis: int, label: str | None) -> tuple[np.ndarray, np.ndarray]:
        """Where the snap planes of each shape's lot cross its scope along ``axis`` (``SnapStore.across``)."""
        axes = self.chunk.frames[shapes.frame]
        return self.chunk.snaps.across(shapes.lot, shapes.origin, np.ascontiguousarray(axes[:, axis]),
                                       np.ascontiguousarray(shapes.size[:, axis]), label, TOL.zero)

    def snap(self, op: ir.Snap, cursor: Shapes, symbol: int) -> None:
        """``Snap`` / ``SnapLines``: the lot's construction planes across the scope axis ``op.normal``,
        through the scope's origin (and, for lines, its far end too)."""
        axes = self.chunk.frames[cursor.frame]
        normal = np.ascontiguousarray(axes[:, op.normal])
        self.chunk.snaps.add(cursor.lot, cursor.origin.copy(), normal, op.label)
        if op.lines:
            far = cursor.origin + normal * cursor.size[:, op.normal, None]
            self.chunk.snaps.add(cursor.lot, far, normal, op.label)

    def fan_out(self, op: ir.Split | ir.Repeat, cursor: Shapes, symbol: int, cut) -> None:
        """Split ``cursor`` along each of ``op.axes`` in turn and run the parts on the cells.

        ``cut(shapes, level, axis)`` returns the children of one axis as (parent, cell step, position,
        length); a cell's number adds up the steps, the first axis varying fastest.
        """
        shapes = cursor
        cell = np.zeros(len(cursor), dtype=np.int64)
        for level, axis in enumerate(op.axes):
            parent, step, pos, length = cut(shapes, level, axis)
            parent, step, pos, length, _, geometry = self.clip(shapes, axis, parent, step, pos, length,
                                                               np.zeros(len(parent), dtype=np.int64), symbol,
                                                               op.span)
            cell = cell[parent] + step
            if level == len(op.axes) - 1:
                leaves = self.leaf_parts(op.parts, shapes, geometry)
                if leaves is not None:
                    self.fan_out_leaves(op, shapes, axis, parent, cell, pos, length, leaves, symbol)
                    return
                shapes, offsets = self.grouped_children(shapes, axis, parent, cell, pos, length, op.site,
                                                        len(op.parts), geometry)
            else:
                shapes = self.children(shapes, axis, parent, cell, pos, length, op.site,
                                       geometry=geometry)
        self.count(shapes, symbol, op.span)
        self.run_parts(op.parts, shapes, offsets, symbol)

    def leaf_parts(self, parts: tuple[ir.Body, ...], shapes: Shapes, geometry) -> list | None:
        """Per body part, the ``LeafInsert`` of the symbol it names if its records can be written straight
        from the parent's scope (``backend.leaf_parts``), else None; None if no part can."""
        inserts = self.plan.leaf_inserts
        if not inserts or geometry is not None or "split.total" in self.plan.dynamic:
            return None
        leaves = [inserts.get(self.plan.symbol_ids[body[0].name])
                  if len(body) == 1 and isinstance(body[0], ir.Symbol) and not body[0].args and not body[0].leaf
                  else None for body in parts]
        # the successor would be one rule application deeper: where that reaches --max-depth, the
        # general path reports it
        if not any(leaves) or int(shapes.depth.max()) + 1 >= self.limits.max_depth:
            return None
        return leaves

    def fan_out_leaves(self, op, shapes: Shapes, axis: int, parent, cell, pos, length, leaves: list,
                       symbol: int) -> None:
        """The last axis of ``fan_out`` when some parts only place an asset: their records are computed
        from ``shapes`` and the cuts and queued for their symbol (``LeafRecords``); the other parts' children
        are made and run as usual. Shape counts are kept as the general path keeps them."""
        n_parts = len(op.parts)
        order, offsets = _by_part(cell, n_parts)
        # the children, as `fan_out` counts them: per parent, then per lot (fewer rows to gather)
        n_lots = len(self.chunk.shape_count)
        per_parent = np.bincount(parent, minlength=len(shapes))
        self.add_counts(np.bincount(shapes.lot, weights=per_parent, minlength=n_lots).astype(np.int64), symbol,
                        op.span)
        general = [i for i, leaf in enumerate(leaves) if leaf is None]
        rows = [order[offsets[i]:offsets[i + 1]] for i in range(n_parts)]
        if general:
            kept = np.concatenate([rows[i] for i in general])
            children = self.children(shapes, axis, parent, cell, pos, length, op.site, kept)
            starts = dict(zip(general, np.cumsum([0] + [len(rows[i]) for i in general]).tolist()))
        frames = self.chunk.frames.data
        for i, body in enumerate(op.parts):
            if not len(rows[i]):
                continue
            leaf = leaves[i]
            if leaf is None:
                part = children.take(slice(starts[i], starts[i] + len(rows[i])))
                self.run(body, part, symbol, leaf_at_end=True)
                continue
            lot = shapes.lot[parent[rows[i]]]
            self.add_counts(np.bincount(lot, minlength=n_lots), symbol, body[0].span)  # the successors
            xform = scope_kernels.leaf_xforms(
                shapes.origin, shapes.size, shapes.frame, frames, axis, rows[i], parent, pos, length, leaf.size,
                leaf.relative, leaf.offset if leaf.offset is not None else np.zeros(0))
            self.pending[leaf.symbol].append(LeafRecords(xform, lot))

    def check_fan_out(self, shapes: Shapes, counts: np.ndarray, symbol: int, span) -> None:
        """Refuse a repeat that would exceed --max-shapes before allocating its children."""
        per_lot = np.bincount(shapes.lot, weights=counts, minlength=len(self.chunk.shape_count))
        self.check_shape_limit(per_lot + self.chunk.shape_count, symbol, span)

    def check_shape_limit(self, counts: np.ndarray, symbol: int, span) -> None:
        """LimitError naming the rule if a lot's shape count (made or about to be) exceeds --max-shapes."""
        worst = int(np.argmax(counts))
        if counts[worst] > self.limits.max_shapes:
            rule = self.plan.symbols[symbol].name
            raise LimitError(
                f"lot {self.chunk.lot_ids[worst]} makes more than {self.limits.max_shapes:,} shapes "
                f"({int(counts[worst]):,}) in rule `{rule}` at {span}: a runaway grammar? "
                "Raise the limit with --max-shapes N."
            )

    def clip(self, shapes: Shapes, axis: int, parent, step, pos, length, index, symbol: int, span):
        """Children of polygons split across their plane become the pieces of the polygon in their slabs
        (``geometry.clip``): empty ones go, a slab that cuts the polygon apart gives one child a piece.
        Children of meshes (roofs, envelopes) become the mesh cut to their slab and closed
        (``mesh_shapes.clip_meshes``).

        Takes and returns the split's children as (parent, step, pos, length, index) arrays, and the
        pieces' geometry for ``children`` (None when no child is a polygon split across its plane).
        """
        if len(self.chunk.meshes) and is_mesh(shapes.geom[parent]).any():
            parent, step, pos, length, index, meshes = self.clip_meshes(shapes, axis, parent, step, pos, length,
                                                                        index, symbol, span)
        else:
            meshes = None
        store = self.chunk.polygons
        geom = shapes.geom[parent]
        poly = np.flatnonzero(is_polygon(geom))
        poly = poly[store.plane[geom[poly]] != axis]
        if not len(poly):
            return parent, step, pos, length, index, meshes
        clipped = clip_to_slabs(store, geom[poly], shapes.size[parent[poly]], axis, pos[poly], length[poly])
        whole = np.ones(len(parent), dtype=bool)
        whole[poly] = False
        rows = np.concatenate([np.flatnonzero(whole), poly[clipped.source]])
        piece = np.concatenate([np.full(int(whole.sum()), -1), np.arange(len(clipped.source))])
        order = np.lexsort((piece, rows))  # pieces take their child's place, in GEOS's order
        rows, piece = rows[order], piece[order]
        new_geom = np.full(len(clipped.source), -1, dtype=np.int32)
        shaped = np.flatnonzero(~clipped.is_rect)
        if len(shaped):
            rings, poly_offsets = ragged_take(clipped.poly_offsets, shaped)
            vertices, ring_offsets = ragged_take(clipped.ring_offsets, rings)
            new_geom[shaped] = store.add(clipped.coords[vertices], ring_offsets, poly_offsets,
                                         clipped.plane[shaped])
        is_piece = piece >= 0
        pos, length = pos[rows].copy(), length[rows].copy()
        pos[is_piece] = clipped.low[piece[is_piece], axis]
        length[is_piece] = clipped.extent[piece[is_piece], axis]
        geometry = (is_piece, new_geom[piece], clipped.low[piece], clipped.extent[piece])
        if meshes is not None:  # the mesh children keep their cut meshes
            from_mesh = ~is_piece & meshes[0][rows]
            for mine, theirs in zip(geometry, meshes):
                mine[from_mesh] = theirs[rows][from_mesh]
        return parent[rows], step[rows], pos, length, index[rows], geometry

    def clip_meshes(self, shapes: Shapes, axis: int, parent, step, pos, length, index, symbol: int, span):
        """``clip`` for the children of mesh shapes: each gets its parent's mesh cut to its slab, a child
        whose slab misses the mesh goes. Returns the children and their geometry (as ``clip``'s)."""
        mesh_rows = np.flatnonzero(is_mesh(shapes.geom[parent]))
        geom, low, extent, keep = mesh_shapes.clip_meshes(self.chunk, shapes, parent[mesh_rows], axis,
                                                          pos[mesh_rows], length[mesh_rows])
        n = len(parent)
        kept = np.ones(n, dtype=bool)
        kept[mesh_rows[~keep]] = False
        is_piece = np.zeros(n, dtype=bool)
        piece_geom = np.full(n, -1, dtype=np.int32)
        piece_low = np.zeros((n, 3))
        piece_extent = np.zeros((n, 3))
        is_piece[mesh_rows] = True
        piece_geom[mesh_rows], piece_low[mesh_rows], piece_extent[mesh_rows] = geom, low, extent
        pos, length = pos.copy(), length.copy()
        pos[mesh_rows], length[mesh_rows] = low[:, axis], extent[:, axis]
        geometry = tuple(a[kept] for a in (is_piece, piece_geom, piece_low, piece_extent))
        return parent[kept], step[kept], pos[kept], length[kept], index[kept], geometry

    def children(self, shapes: Shapes, axis: int, parent, index, pos, length, site: int,
                 order=None, geometry=None) -> Shapes:
        """Children of a split along ``axis``: the parent's scope moved by ``pos`` and cut to ``length``.

        ``order`` (default: as given) picks and orders the children; ``geometry`` (from ``clip``) gives
        the clipped pieces their own boxes and polygons.
        """
        if order is None:
            order = np.arange(len(parent))
        origin, size, key, frame, geom, lot, depth, parents = scope_kernels.place_children(
            shapes.origin, shapes.size, shapes.key, shapes.frame, shapes.geom, shapes.lot, shapes.depth,
            self.chunk.frames.data, axis, order, parent, pos, length, site, index,
        )
        if geometry is not None:
            is_piece, piece_geom, low, extent = (g[order] for g in geometry)
            rows = np.flatnonzero(is_piece)
            axes = self.chunk.frames[frame[rows]]
            origin[rows] = shapes.origin[parents[rows]] + np.einsum("ni,nij->nj", low[rows], axes)
            size[rows] = extent[rows]
            geom[rows] = piece_geom[rows]
        children = Shapes(origin, size, frame, geom, lot, key, depth,
                          tuple(p[parents] for p in shapes.params), tuple(d[parents] for d in shapes.dynamic))
        return self.with_context(children, "split", index[order], parents, len(shapes))

    def with_context(self, shapes: Shapes, kind: str, index, parents, n_parents: int,
                     selector=None) -> Shapes:
        """Set ``split.index``/``split.total`` (or ``comp.*``) of new children, where the grammar reads
        them: the child's number and its parent's number of children."""
        dynamic = list(shapes.dynamic)
        slots = self.plan.dynamic
        if f"{kind}.index" in slots:
            dynamic[slots[f"{kind}.index"]] = index.astype(np.float64)
        if f"{kind}.total" in slots:
            dynamic[slots[f"{kind}.total"]] = np.bincount(parents, minlength=n_parents)[parents].astype(
                np.float64)
        if selector is not None and "comp.sel" in slots:
            dynamic[slots["comp.sel"]] = selector
        return replace(shapes, dynamic=tuple(dynamic))

    def grouped_children(self, shapes, axis, parent, cell, pos, length, site, n_parts, geometry=None):
        """``children`` ordered by body part (cell mod parts): each part's batch is then a slice."""
        order, offsets = _by_part(cell, n_parts)
        return self.children(shapes, axis, parent, cell, pos, length, site, order, geometry), offsets

    def run_parts(self, parts: tuple[ir.Body, ...], shapes: Shapes, offsets: np.ndarray, symbol) -> None:
        for i, body in enumerate(parts):
            if offsets[i + 1] > offsets[i]:
                self.run(body, shapes.take(slice(offsets[i], offsets[i + 1])), symbol, leaf_at_end=True)

    def group_split(self, op: ir.GroupSplit, cursor: Shapes, symbol: int) -> None:
        values = self.split_sizes(op, cursor, symbol, "split")
        kind = np.array([_SIZE_KIND[s.kind] for s in op.sizes], dtype=np.int64)
        groups = np.array(op.groups, dtype=np.int64)
        if op.repeat:
            groups = np.zeros_like(groups)
        n_groups = int(groups.max()) + 1 if len(groups) else 0
        parent, part, pos, length, index = split_kernels.group_split(
            np.ascontiguousarray(cursor.size[:, op.axis]), values, kind, groups, n_groups, TOL.zero)
        parent, part, pos, length, index, geometry = self.clip(cursor, op.axis, parent, part, pos, length,
                                                               index, symbol, op.span)
        order, offsets = group_by(part, len(op.parts))
        children = self.children(cursor, op.axis, parent, index, pos, length, op.site, order, geometry)
        self.count(children, symbol, op.span)
        self.run_parts(op.parts, children, offsets, symbol)


def _by_part(cell: np.ndarray, n_parts: int) -> tuple[np.ndarray, np.ndarray]:
    """Children ordered by body part (cell mod parts), and where each part's run starts (``group_by``)."""
    return group_by(cell % n_parts if n_parts > 1 else np.zeros_like(cell), n_parts)


def _pieces(extent: np.ndarray, offsets: np.ndarray, cuts: np.ndarray):
    """The pieces of each extent (n,) cut at its sorted positions ``cuts`` (``offsets`` (n+1,)): each
    piece's extent, its start and the extent it belongs to, (k,) each, in order."""
    count = np.diff(offsets) + 1
    parent = np.repeat(np.arange(len(extent)), count)
    j = np.arange(count.sum()) - np.repeat(offsets_from_counts(count)[:-1], count)
    bounds = np.concatenate([cuts, [0.0]])  # a harmless last entry for the gathers below
    at = offsets[parent] + j
    start = np.where(j > 0, bounds[at - 1], 0.0)
    end = np.where(j < count[parent] - 1, bounds[at], extent[parent])
    return parent, start, np.ascontiguousarray(end - start)


def _size_matrix(values: list, n: int) -> np.ndarray:
    """Split sizes as (n, P) float64, or (1, P) when every size is the same for all shapes."""
    if all(np.ndim(v) == 0 for v in values):
        return np.array([values], dtype=np.float64)
    return np.stack([np.broadcast_to(np.asarray(v, np.float64), (n,)) for v in values], axis=1)


#: GroupSplit size kinds for the kernel.
_SIZE_KIND = {ir.SizeKind.ABSOLUTE: 0, ir.SizeKind.RELATIVE: 1, ir.SizeKind.FLOATING: 2}
