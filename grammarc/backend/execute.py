"""Rules and successor bodies executed on whole batches of shapes.

``Executor.apply`` takes every pending shape of one symbol: guards partition the batch (the first rule
whose guard holds applies, in source order), one uniform draw per shape picks a stochastic alternative,
and each alternative's body runs on its shapes at once. A body is a sequence of operations on a *cursor*:
a ``Shapes`` batch whose scope columns the operations replace as they go (``T``, ``S``, ``R``, ``[ ]``).
Successor symbols are queued for later rounds; splits run their parts' bodies on the children at once,
one call per part. Python cost is per operation and batch, never per shape.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import replace

import numpy as np

from grammarc.backend import mesh_shapes, terminals
from grammarc.backend.chunk import Chunk
from grammarc.backend.evaluate import Env, elementwise, evaluate, evaluate_array
from grammarc.backend.face_operations import FaceOperations
from grammarc.backend.kernels import scope as scope_kernels
from grammarc.backend.kernels import split as split_kernels
from grammarc.backend.kernels.order import group_by
from grammarc.backend.plan import COLOR_SLOT, Plan, SymbolPlan, consumes
from grammarc.backend.random import child_keys, uniform
from grammarc.backend.selectors import classify_edges, classify_faces
from grammarc.backend.shapes import Shapes, asset_geom, asset_of
from grammarc.constants import TOL, Limits
from grammarc.errors import ChunkTooLarge, LimitError, LotFailure
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.clip import clip_to_slabs
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.geometry.reframe import NORMAL_OUT, NORMAL_UP, reframe
from grammarc.geometry.trim import side_face_planes
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_op
from grammarc.ragged import ragged_take, rank_within


class Executor(FaceOperations):
    """Derives one chunk: a worklist of pending batches per symbol, and the operations."""

    def __init__(self, plan: Plan, chunk: Chunk, limits: Limits, chunk_budget: int):
        self.plan = plan
        self.chunk = chunk
        self.limits = limits
        self.chunk_budget = chunk_budget
        self.pending: dict[int, list[Shapes]] = defaultdict(list)

    # ------------------------------------------------------------------------------------------ helpers
    def env(self, shapes: Shapes) -> Env:
        return Env(shapes, self.chunk, self.plan)

    def fail(self, shapes: Shapes, bad: np.ndarray, message: str, symbol: int, span) -> None:
        """Report the lots of shapes ``bad`` (bool mask) as failed: raises ``LotFailure``."""
        lots = np.unique(shapes.lot[bad])
        rule = self.plan.symbols[symbol].name
        raise LotFailure(f"{message} in rule `{rule}` at {span}", lots)

    def count(self, shapes: Shapes, symbol: int, span) -> None:
        """Add new shapes to the per-lot counters and enforce the shape limits."""
        if not len(shapes):
            return
        counts = self.chunk.shape_count
        counts += np.bincount(shapes.lot, minlength=len(counts))
        self.check_shape_limit(counts, symbol, span)
        if counts.sum() > self.chunk_budget and len(counts) > 1:
            raise ChunkTooLarge()

    # ---------------------------------------------------------------------------------- rule application
    def apply(self, sym: SymbolPlan, shapes: Shapes) -> None:
        """Apply the rules of ``sym`` to all of ``shapes``; shapes no rule applies to become leaves."""
        deepest = int(np.argmax(shapes.depth))
        if shapes.depth[deepest] >= self.limits.max_depth:
            rule = sym.rules[0]
            raise LimitError(
                f"derivation of lot {self.chunk.lot_ids[shapes.lot[deepest]]} reached --max-depth "
                f"{self.limits.max_depth} at rule `{sym.name}` ({rule.span}): runaway recursion? "
                "Raise the limit with --max-depth N."
            )
        remaining = shapes
        for rule in sym.rules:
            if not len(remaining):
                break
            if rule.guard is None:
                chosen, remaining = remaining, remaining.take(np.zeros(0, dtype=np.int64))
            else:
                holds = evaluate_array(rule.guard, self.env(remaining), dtype=bool)
                chosen, remaining = remaining.take(holds), remaining.take(~holds)
            if len(chosen):
                self.apply_rule(sym, rule, chosen)
        if len(remaining):
            terminals.emit_leaves(self.chunk, remaining, sym.id)

    def apply_rule(self, sym: SymbolPlan, rule: ir.Rule, shapes: Shapes) -> None:
        symbol = sym.id
        alts = rule.alternatives
        if len(alts) == 1:
            self.run(alts[0].body, shapes, symbol, leaf_at_end=True)
            return
        env = self.env(shapes)
        probs = np.stack([evaluate_array(a.prob, env) for a in alts], axis=1)
        bad = (np.abs(probs.sum(axis=1) - 1.0) > TOL.probability) | (probs < 0).any(axis=1)
        if bad.any():
            self.fail(shapes, bad, "probabilities do not sum to 1", symbol, rule.span)
        cumulative = np.cumsum(probs, axis=1)
        draw = uniform(shapes.key, rule.site)
        choice = np.minimum((draw[:, None] >= cumulative).sum(axis=1), len(alts) - 1)
        for i, alt in enumerate(alts):
            picked = shapes.take(choice == i)
            if len(picked):
                self.run(alt.body, picked, symbol, leaf_at_end=True)

    # ------------------------------------------------------------------------------------------- bodies
    def run(self, body: ir.Body, cursor: Shapes, symbol: int, leaf_at_end: bool = False) -> None:
        """Execute ``body`` on ``cursor``; operations replace its scope columns as they go.

        With CityEngine semantics and ``leaf_at_end`` (a rule's body, a split part, a case branch), a
        body that makes no successor leaves its shape as a leaf of ``symbol``.
        """
        stack: list[tuple] = []
        base = (cursor.origin, cursor.size, cursor.frame)  # what `center` centres on
        for op in body:
            if not len(cursor):
                return
            if isinstance(op, ir.Push):
                # the whole shape: its scope, its geometry and the attributes `set` gives it
                stack.append((cursor, base))
                base = (cursor.origin, cursor.size, cursor.frame)
            elif isinstance(op, ir.Pop):
                if stack:
                    cursor, base = stack.pop()
            elif isinstance(op, ir.Center):
                cursor = self.center(op, cursor, base)
            else:
                if type(op) not in _MESH_OPERATIONS and len(self.chunk.meshes):
                    self.refuse_meshes(op, cursor, symbol)
                # an operation either makes shapes (returns None) or changes the cursor (returns it)
                changed = _OPERATIONS[type(op)](self, op, cursor, symbol)
                if changed is not None:
                    cursor = changed
        if leaf_at_end and self.plan.leaf_bodies and len(cursor) and not consumes(body):
            terminals.emit_leaves(self.chunk, cursor, symbol)

    def refuse_meshes(self, op: ir.Op, cursor: Shapes, symbol: int) -> None:
        """Roofs take component splits and scope operations; other operations on them are reported."""
        mesh = is_mesh(cursor.geom)
        if mesh.any():
            name = print_op(op).split("(")[0]
            self.fail(cursor, mesh, f"`{name}` of a roof is not supported yet (split the roof into faces "
                      "with comp(f) first)", symbol, op.span)

    def insert(self, op: ir.Insert, cursor: Shapes, symbol: int) -> None:
        """The paper's ``I(name)``: an instance of the asset on the scope."""
        terminals.emit_instances(self.chunk, cursor, self.plan.grammar.asset_ids[op.asset], symbol)

    def nothing(self, op: ir.Empty | ir.NotApplied, cursor: Shapes, symbol: int) -> None:
        """``ε``, ``NIL``, and operations without effect on the record."""

    def successor(self, op: ir.Symbol, cursor: Shapes, symbol: int) -> None:
        sym = self.plan.symbols[self.plan.symbol_ids[op.name]]
        env = self.env(cursor)
        params = tuple(
            evaluate_array(arg, env, dtype=np.int32 if t is ir.Type.STR else np.float64)
            for arg, t in zip(op.args, sym.param_types)
        )
        shapes = Shapes(cursor.origin, cursor.size, cursor.frame, cursor.geom, cursor.lot,
                        child_keys(cursor.key, op.site), cursor.depth + 1, params, cursor.dynamic)
        self.count(shapes, symbol, op.span)
        if sym.terminal or op.leaf:
            terminals.emit_leaves(self.chunk, shapes, sym.id)
        else:
            self.pending[sym.id].append(shapes)

    def translate(self, op: ir.Translate, cursor: Shapes, symbol: int) -> Shapes:
        env = self.env(cursor)
        local = np.stack([evaluate_array(e, env) for e in op.vector], axis=1)
        delta = np.einsum("ni,nij->nj", local, self.chunk.frames[cursor.frame])
        return cursor.with_scope(cursor.origin + delta, cursor.size, cursor.frame, cursor.geom)

    def scale(self, op: ir.Scale, cursor: Shapes, symbol: int) -> Shapes:
        env = self.env(cursor)
        size = np.empty_like(cursor.size)
        for axis, s in enumerate(op.sizes):
            value = evaluate_array(s.value, env)
            size[:, axis] = value * cursor.size[:, axis] if s.kind is ir.SizeKind.RELATIVE else value
        bad = ~(size >= 0).all(axis=1)
        if bad.any():
            self.fail(cursor, bad, f"`S` gives a negative or NaN size ({_example(size, bad)})", symbol,
                      op.span)
        return cursor.with_scope(cursor.origin, size, cursor.frame, cursor.geom)

    def rotate(self, op: ir.Rotate, cursor: Shapes, symbol: int) -> Shapes:
        env = self.env(cursor)
        angles = [evaluate(e, env) for e in op.angles]
        frames = self.chunk.frames
        if all(np.ndim(a) == 0 for a in angles):
            # One rotation for all: rotate each distinct frame once.
            unique, inverse = np.unique(cursor.frame, return_inverse=True)
            matrix = _rotation(*(np.full(1, a, dtype=np.float64) for a in angles))[0]
            new = frames.add(np.einsum("ij,fjk->fik", matrix, frames[unique]))
            frame = new[inverse.reshape(-1)]
        else:
            n = len(cursor)
            matrices = _rotation(*(np.broadcast_to(np.asarray(a, np.float64), (n,)) for a in angles))
            frame = frames.add(np.einsum("nij,njk->nik", matrices, frames[cursor.frame]))
        return cursor.with_scope(cursor.origin, cursor.size, frame, cursor.geom)

    # ------------------------------------------------------------------------------------------- splits
    def split_sizes(self, op: ir.Split | ir.GroupSplit, cursor: Shapes, symbol: int, what: str) -> np.ndarray:
        """The parts' sizes, (n, P) or (1, P) when the same for all shapes; a negative or NaN one fails."""
        env = self.env(cursor)
        values = _size_matrix([evaluate(s.value, env) for s in op.sizes], len(cursor))
        bad = ~(values >= 0).all(axis=1)
        if bad.any():
            self.fail(cursor, bad, f"`{what}` has a negative or NaN size ({_example(values, bad)})", symbol,
                      op.span)
        return values

    def split(self, op: ir.Split, cursor: Shapes, symbol: int) -> None:
        values = self.split_sizes(op, cursor, symbol, "Subdiv")
        relative = np.array([s.kind is ir.SizeKind.RELATIVE for s in op.sizes])

        def cut(shapes: Shapes, level: int, axis: int):
            nonlocal values
            parent, part, pos, length = split_kernels.subdiv(
                np.ascontiguousarray(shapes.size[:, axis]), values, relative, TOL.zero
            )
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
            self.check_fan_out(shapes, counts, symbol, op.span)
            parent, part, pos, length = split_kernels.repeat(extent, counts)
            step = part * stride[parent]
            stride = stride[parent] * counts[parent]
            sizes = [s[parent] for s in sizes]  # the next axes' sizes follow the children
            return parent, step, pos, length

        self.fan_out(op, cursor, symbol, cut)

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
                shapes, offsets = self.grouped_children(shapes, axis, parent, cell, pos, length, op.site,
                                                        len(op.parts), geometry)
            else:
                shapes = self.children(shapes, axis, parent, cell, pos, length, op.site,
                                       geometry=geometry)
        self.count(shapes, symbol, op.span)
        self.run_parts(op.parts, shapes, offsets, symbol)

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
        order, offsets = group_by(cell % n_parts if n_parts > 1 else np.zeros_like(cell), n_parts)
        return self.children(shapes, axis, parent, cell, pos, length, site, order, geometry), offsets

    def run_parts(self, parts: tuple[ir.Body, ...], shapes: Shapes, offsets: np.ndarray, symbol) -> None:
        for i, body in enumerate(parts):
            if offsets[i + 1] > offsets[i]:
                self.run(body, shapes.take(slice(offsets[i], offsets[i + 1])), symbol, leaf_at_end=True)

    # ------------------------------------------------------------------------------------------- comp
    def comp(self, op: ir.Comp, cursor: Shapes, symbol: int) -> None:
        if comp_kernels.KIND_CODES[op.kind] not in mesh_shapes.MESH_KINDS:
            self.refuse_meshes(op, cursor, symbol)
        index_of = None
        if op.index is not None:
            index_of = evaluate_array(op.index, self.env(cursor))
        shapes, _, index, _ = self.components(comp_kernels.KIND_CODES[op.kind], cursor, op.site, index_of)
        self.count(shapes, symbol, op.span)
        order, offsets = group_by(index % len(op.parts), len(op.parts))
        self.run_parts(op.parts, shapes.take(order), offsets, symbol)

    def components(self, kind: int, cursor: Shapes, site: int, wanted=None):
        """Component shapes of ``cursor``, their normals in the parents' frames (m, 3), their indices
        among their parent's components (m,) and their parents (m,); ``wanted`` (n,) keeps, per shape,
        only that index. Roofs (meshes) have faces and edges (``comp_faces`` and ``comp`` check)."""
        chunk = self.chunk
        mesh = is_mesh(cursor.geom)
        pieces = []
        if not mesh.all():
            pieces.append(self.solid_components(kind, cursor, np.flatnonzero(~mesh)))
        if mesh.any():
            which = np.flatnonzero(mesh)
            parent, index, origin, axes, size, geom = mesh_shapes.mesh_components(chunk, cursor.take(which), kind)
            pieces.append((which[parent], index, origin, axes, size, geom, axes[:, 2]))
        parent, index, origin, axes, size, geom, normal = (
            pieces[0] if len(pieces) == 1 else
            (np.concatenate(columns) for columns in zip(*pieces)))
        if len(pieces) > 1:
            order = np.argsort(parent, kind="stable")
            parent, index, origin, axes, size, geom, normal = (
                a[order] for a in (parent, index, origin, axes, size, geom, normal))
        if wanted is not None:
            keep = index == np.round(wanted[parent])
            parent, index, origin, axes, size, geom, normal = (
                a[keep] for a in (parent, index, origin, axes, size, geom, normal))
        child = cursor.take(parent)
        parent_axes = chunk.frames[child.frame]
        world_origin = child.origin + np.einsum("ni,nij->nj", origin, parent_axes)
        frame = chunk.frames.add(np.einsum("nij,njk->nik", axes, parent_axes))
        shapes = Shapes(world_origin, size, frame, geom.astype(np.int32), child.lot,
                        child_keys(child.key, site, index), child.depth, child.params, child.dynamic)
        return self.with_context(shapes, "comp", index, parent, len(cursor)), normal, index, parent

    def solid_components(self, kind: int, cursor: Shapes, which: np.ndarray):
        """Components of the boxes, polygons and prisms ``which`` of ``cursor``: parent (into cursor),
        index, origin, axes, size (in the parents' frames), geom, normal."""
        shapes = cursor.take(which)
        coords, ring_offsets, shape_offsets, plane = self.polygons_of(shapes)
        parent, index, origin, axes, size, poly = comp_kernels.components(
            kind, coords, ring_offsets, shape_offsets, plane, shapes.size, TOL.zero)
        geom = np.full(len(parent), -1, dtype=np.int32)
        same = poly == comp_kernels.SAME_POLY
        geom[same] = shapes.geom[parent[same]]
        for code, cap in ((comp_kernels.BOTTOM_POLY, "bottom"), (comp_kernels.TOP_POLY, "top")):
            sel = (poly == code) & is_polygon(shapes.geom[parent])
            if sel.any():
                geom[sel] = self.cap_polygons(shapes.geom[parent[sel]], cap)
        # a flat shape's only face is itself: its normal is its plane's axis, not its frame's z
        normal = axes[:, 2].copy()
        normal[same] = np.eye(3)[plane[parent[same]]]
        return which[parent], index, origin, axes, size, geom, normal

    def polygons_of(self, shapes: Shapes):
        """Each shape's polygon as batch-local ragged arrays (implicit rectangles for scope shapes)."""
        polygons = self.chunk.polygons
        n = len(shapes)
        plane = comp_kernels.rect_plane(shapes.size, TOL.zero)
        is_poly = is_polygon(shapes.geom)
        plane[is_poly] = polygons.plane[shapes.geom[is_poly]]
        if not is_poly.any():
            coords = comp_kernels.rect_rings(plane)
            return (coords, np.arange(0, 4 * n + 1, 4, dtype=np.int64), np.arange(n + 1, dtype=np.int64),
                    plane)
        # Mixed batch: give scope shapes a stored rectangle so one gather serves all.
        geom = shapes.geom.copy()
        rects = np.flatnonzero(~is_poly)
        if len(rects):
            rect_coords = comp_kernels.rect_rings(plane[rects])
            geom[rects] = polygons.add(rect_coords, np.arange(0, 4 * len(rects) + 1, 4, dtype=np.int64),
                                       np.arange(len(rects) + 1, dtype=np.int64), plane[rects])
        coords, ring_offsets, shape_offsets = polygons.gather(geom)
        return coords, ring_offsets, shape_offsets, plane

    def cap_polygons(self, geom: np.ndarray, which: str) -> np.ndarray:
        """New store polygons for the bottom or top faces of prisms ``geom`` (in the face's own plane).

        The face's x is the polygon's first axis; its y runs along the second axis or against it, and
        the bottom face sees the rings from below, so they are reversed (see components.py).
        """
        polygons = self.chunk.polygons
        coords, ring_offsets, poly_offsets = polygons.gather(geom)
        plane = polygons.plane[geom]
        flip = (plane == 1) if which == "top" else (plane != 1)
        vertex_poly = np.repeat(np.repeat(np.arange(len(geom)), np.diff(poly_offsets)),
                                np.diff(ring_offsets))
        coords = coords.copy()
        coords[:, 1] = np.where(flip[vertex_poly], 1.0 - coords[:, 1], coords[:, 1])
        if which == "bottom":
            coords = comp_kernels.reverse_rings(coords, ring_offsets)
        return polygons.add(coords, ring_offsets, poly_offsets, np.full(len(geom), 2, dtype=np.int8))


    # ------------------------------------------------------------------------------ CityEngine operations
    def flat_axis(self, cursor: Shapes) -> np.ndarray:
        """The axis each shape is flat along (its face normal), -1 for solids, edges and assets."""
        flat = cursor.size <= TOL.zero
        axis = np.where(flat.sum(axis=1) == 1, np.argmax(flat, axis=1), -1)
        poly = is_polygon(cursor.geom)
        axis[poly] = np.where(flat[poly].sum(axis=1) >= 1, self.chunk.polygons.plane[cursor.geom[poly]], -1)
        axis[(cursor.geom < -1) | is_mesh(cursor.geom)] = -1
        return axis

    def extrude(self, op: ir.Extrude, cursor: Shapes, symbol: int) -> Shapes:
        """A face becomes a solid along its normal; a negative height extrudes behind the face. As in
        CityEngine, the solid's scope keeps x and has y along the extrusion: a face whose normal is
        another scope axis (a comp(f) face's z) is first re-expressed in such a scope."""
        height = evaluate_array(op.height, self.env(cursor))
        axis = self.flat_axis(cursor)
        bad = (axis < 0) | ~np.isfinite(height)
        if bad.any():
            self.fail(cursor, bad, "`extrude` needs a face (a flat shape) and a finite height", symbol,
                      op.span)
        cursor = self.turned(cursor, axis != 1, NORMAL_UP, axis, symbol, op.span)
        size = cursor.size.copy()
        size[:, 1] = np.abs(height)
        up = self.chunk.frames[cursor.frame][:, 1]
        origin = cursor.origin + np.minimum(height, 0.0)[:, None] * up
        return cursor.with_scope(origin, size, cursor.frame, cursor.geom)

    def center(self, op: ir.Center, cursor: Shapes, base) -> Shapes:
        """Centre the scope on ``base`` (the body's first scope or the last push) along ``op.axes``."""
        base_origin, base_size, base_frame = base
        frames = self.chunk.frames
        base_axes = frames[base_frame]
        axes = frames[cursor.frame]
        base_center = base_origin + np.einsum("ni,nij->nj", base_size / 2, base_axes)
        center = cursor.origin + np.einsum("ni,nij->nj", cursor.size / 2, axes)
        offset = base_center - center
        origin = cursor.origin.copy()
        for k in op.axes:
            origin += np.einsum("nj,nj->n", offset, axes[:, k])[:, None] * axes[:, k]
        return cursor.with_scope(origin, cursor.size, cursor.frame, cursor.geom)

    def align_scope(self, op: ir.AlignScope, cursor: Shapes, symbol: int) -> Shapes:
        """New scope axes around unchanged geometry (``geometry.reframe``)."""
        frames = self.chunk.frames
        axes = frames[cursor.frame]
        n = len(cursor)
        if op.mode == "world":
            new_axes = np.broadcast_to(np.eye(3), (n, 3, 3))
        elif op.mode == "y":
            up = np.array([0.0, 1.0, 0.0])
            x = axes[:, 0] - axes[:, 0, 1:2] * up
            flat = np.linalg.norm(x, axis=1) < 1e-9
            x[flat] = axes[flat, 2] - axes[flat, 2, 1:2] * up
            x /= np.linalg.norm(x, axis=1, keepdims=True)
            new_axes = np.stack([x, np.broadcast_to(up, x.shape), np.cross(x, up)], axis=1)
        elif op.mode == "rotate":
            env = self.env(cursor)
            angles = [np.broadcast_to(evaluate_array(e, env), (n,)) for e in op.angles]
            new_axes = np.einsum("nij,njk->nik", _rotation(*angles), axes)
        else:
            new_axes = self.geometry_axes(op, cursor, axes, symbol)
        return self.reframed(cursor, new_axes, symbol, op.span)

    def turned(self, cursor: Shapes, turn: np.ndarray, matrices: np.ndarray, axis: np.ndarray, symbol: int,
               span) -> Shapes:
        """``cursor`` with the shapes ``turn`` (mask) given the axes ``matrices[axis]`` (rows in their
        present frames: ``NORMAL_UP``, ``NORMAL_OUT``) around their unchanged geometry."""
        if not turn.any():
            return cursor
        rows, others = np.flatnonzero(turn), np.flatnonzero(~turn)
        sub = cursor.take(rows)
        new_axes = np.einsum("nij,njk->nik", matrices[axis[rows]], self.chunk.frames[sub.frame])
        return Shapes.merge([cursor.take(others), self.reframed(sub, new_axes, symbol, span)], [others, rows])

    def reframed(self, cursor: Shapes, new_axes: np.ndarray, symbol: int, span) -> Shapes:
        """The same geometry in scopes with ``new_axes`` (n, 3, 3), fitted to it (``geometry.reframe``;
        meshes: ``mesh_shapes.reframe_meshes``)."""
        mesh = is_mesh(cursor.geom)
        if mesh.any():
            new_axes = np.asarray(new_axes)
            if mesh.all():
                return mesh_shapes.reframe_meshes(self.chunk, cursor, new_axes)
            rows = np.flatnonzero(mesh)
            others = np.flatnonzero(~mesh)
            return Shapes.merge([mesh_shapes.reframe_meshes(self.chunk, cursor.take(rows), new_axes[rows]),
                                 self.reframed(cursor.take(others), new_axes[others], symbol, span)],
                                [rows, others])
        n = len(cursor)
        bad = cursor.geom < -1
        if bad.any():
            self.fail(cursor, bad, "aligning the scope of an inserted asset is not supported yet", symbol, span)
        coords, ring_offsets, shape_offsets, plane = self.polygons_of(cursor)
        ok, plane, origin, size, is_rect, new_coords = reframe(
            cursor.origin, cursor.size, self.chunk.frames[cursor.frame], coords, ring_offsets, shape_offsets,
            plane, new_axes)
        if not ok.all():
            self.fail(cursor, ~ok, "turning a scope out of its geometry's plane is not supported yet",
                      symbol, span)
        geom = np.full(n, -1, dtype=np.int32)
        poly = np.flatnonzero(~is_rect)
        if len(poly):
            rings, packed_shapes = ragged_take(shape_offsets, poly)
            vertices, packed_rings = ragged_take(ring_offsets, rings)
            geom[poly] = self.chunk.polygons.add(new_coords[vertices], packed_rings, packed_shapes,
                                                 plane[poly])
        return cursor.with_scope(origin, size, self.chunk.frames.add(np.ascontiguousarray(new_axes)), geom)

    def geometry_axes(self, op: ir.AlignScope, cursor: Shapes, axes: np.ndarray, symbol: int):
        """Axes of ``alignScopeToGeometry``: up along the face's normal, x along its edge ``k``."""
        flat = cursor.size <= TOL.zero
        bad = flat.sum(axis=1) != 1
        if bad.any():
            self.fail(cursor, bad, "alignScopeToGeometry of a solid is not supported yet (only faces)",
                      symbol, op.span)
        coords, ring_offsets, shape_offsets, plane = self.polygons_of(cursor)
        rows = np.arange(len(cursor))
        edge = np.round(evaluate_array(op.angles[0], self.env(cursor))).astype(np.int64)
        start = ring_offsets[shape_offsets[:-1]]
        count = ring_offsets[shape_offsets[:-1] + 1] - start
        j = start + np.mod(edge, count)
        k = start + np.mod(edge + 1, count)
        a, b = PLANE_U[plane], PLANE_V[plane]

        def world(v):
            return ((coords[v, 0] * cursor.size[rows, a])[:, None] * axes[rows, a]
                    + (coords[v, 1] * cursor.size[rows, b])[:, None] * axes[rows, b])

        x = world(k) - world(j)
        x /= np.linalg.norm(x, axis=1, keepdims=True)
        normal = axes[rows, plane]
        if op.mode == "geometry-y":
            return np.stack([x, normal, np.cross(x, normal)], axis=1)
        return np.stack([x, np.cross(normal, x), normal], axis=1)

    def mirror(self, op: ir.Mirror, cursor: Shapes, symbol: int) -> Shapes:
        """Mirror the geometry inside its scope: assets flip (a bit of their geometry code), polygons
        are stored flipped with their rings reversed (so they still wind around their normal); a scope
        box is its own mirror image."""
        env = self.env(cursor)
        flips = [np.broadcast_to(evaluate_array(f, env, dtype=bool), (len(cursor),)) for f in op.axes]
        bits = flips[0] * 1 + flips[1] * 2 + flips[2] * 4
        geom = cursor.geom.copy()
        assets = (geom < -1) & (bits > 0)
        if assets.any():
            asset, mirrored = asset_of(geom[assets])
            geom[assets] = asset_geom(asset, mirrored ^ bits[assets])
        poly = np.flatnonzero(is_polygon(geom) & (bits > 0))
        if len(poly):
            store = self.chunk.polygons
            coords, ring_offsets, poly_offsets = store.gather(geom[poly])
            plane = store.plane[geom[poly]]
            vertex_poly = np.repeat(np.repeat(np.arange(len(poly)), np.diff(poly_offsets)),
                                    np.diff(ring_offsets))
            a = np.where(plane == 0, 1, 0)[vertex_poly]  # the plane's in-plane axes
            b = np.where(plane == 2, 1, 2)[vertex_poly]
            shape_bits = bits[poly][vertex_poly]
            flip_u = (shape_bits >> a) & 1
            flip_v = (shape_bits >> b) & 1
            coords = coords.copy()
            coords[:, 0] = np.where(flip_u, 1.0 - coords[:, 0], coords[:, 0])
            coords[:, 1] = np.where(flip_v, 1.0 - coords[:, 1], coords[:, 1])
            once = (flip_u ^ flip_v).astype(bool)  # one flip turns the winding round
            coords = np.where(once[:, None], comp_kernels.reverse_rings(coords, ring_offsets), coords)
            geom[poly] = store.add(coords, ring_offsets, poly_offsets, plane)
        return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)

    def use_asset(self, op: ir.UseAsset, cursor: Shapes, symbol: int) -> Shapes:
        """The geometry becomes the asset fitted to the scope (a cube is the scope box itself)."""
        if op.name is None:
            asset = np.full(len(cursor), self.plan.grammar.asset_ids[op.asset], dtype=np.int32)
        else:
            names = evaluate_array(op.name, self.env(cursor), dtype=np.int32)
            lookup = self.plan.asset_of_string
            asset = np.array([lookup.get(int(s), -1) for s in np.unique(names)], dtype=np.int32)[
                np.unique(names, return_inverse=True)[1].reshape(-1)]
            bad = asset < 0
            if bad.any():
                name = list(self.plan.strings.ids)[int(names[np.flatnonzero(bad)[0]])]
                self.fail(cursor, bad, f"`i` of `{name}`, which is not an asset of the grammar", symbol,
                          op.span)
        geom = np.where(asset == 0, -1, asset_geom(asset)).astype(np.int32)  # asset 0 is builtin:cube
        return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)

    def set_color(self, op: ir.SetColor, cursor: Shapes, symbol: int) -> Shapes:
        """The shape's colour as 0xRRGGBB: from components in [0, 1], or parsed from "#rrggbb"."""
        env = self.env(cursor)
        n = len(cursor)
        if len(op.values) == 3:
            parts = [np.clip(np.round(np.broadcast_to(evaluate_array(v, env), (n,)) * 255), 0, 255)
                     for v in op.values]
            packed = parts[0] * 65536 + parts[1] * 256 + parts[2]
        else:
            ids = np.broadcast_to(evaluate_array(op.values[0], env, dtype=np.int32), (n,))
            names = list(self.plan.strings.ids)
            distinct, inverse = np.unique(ids, return_inverse=True)
            packed = np.array([_hex_color(names[int(i)]) for i in distinct])[inverse.reshape(-1)]
            bad = np.isnan(packed)
            if bad.any():
                text = names[int(ids[np.flatnonzero(bad)[0]])]
                self.fail(cursor, bad, f'color("{text}") is not a colour "#rrggbb"', symbol, op.span)
        index = self.plan.dynamic[COLOR_SLOT]
        dynamic = cursor.dynamic[:index] + (packed.astype(np.float64),) + cursor.dynamic[index + 1:]
        return replace(cursor, dynamic=dynamic)

    def set_attr(self, op: ir.SetAttr, cursor: Shapes, symbol: int) -> Shapes:
        index = self.plan.dynamic[op.name]
        column = cursor.dynamic[index]
        value = evaluate_array(op.value, self.env(cursor), dtype=column.dtype)
        dynamic = cursor.dynamic[:index] + (value,) + cursor.dynamic[index + 1:]
        return Shapes(cursor.origin, cursor.size, cursor.frame, cursor.geom, cursor.lot, cursor.key,
                      cursor.depth, cursor.params, dynamic)

    def report(self, op: ir.Report, cursor: Shapes, symbol: int) -> None:
        env = self.env(cursor)
        key = evaluate_array(op.key, env, dtype=np.int32)
        value = evaluate(op.value, env)
        self.chunk.outputs.reports.append(report_rows(cursor.lot, key, value, len(cursor)))

    def branch(self, op: ir.Case | ir.Stochastic, cursor: Shapes, symbol: int) -> None:
        """``case`` and ``p%`` blocks: each shape runs one branch, the default when none is taken."""
        env = self.env(cursor)
        n = len(cursor)
        taken = np.full(n, len(op.branches), dtype=np.int64)
        if isinstance(op, ir.Case):
            for i in range(len(op.branches) - 1, -1, -1):
                holds = evaluate_array(op.branches[i][0], env, dtype=bool)
                taken[holds] = i
        else:
            percent = np.stack([evaluate_array(c, env) for c, _ in op.branches], axis=1)
            cumulative = np.cumsum(percent, axis=1) / 100.0
            draw = uniform(cursor.key, op.site)
            taken = (draw[:, None] >= cumulative).sum(axis=1)
        bodies = [body for _, body in op.branches] + [op.default]
        order, offsets = group_by(taken, len(bodies))
        self.run_parts(tuple(bodies), cursor.take(order), offsets, symbol)

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

    def face_scopes(self, shapes: Shapes, cursor: Shapes, parent: np.ndarray, symbol: int, span) -> Shapes:
        """A flat shape's face component is the shape itself; as every CityEngine face scope, it gets z
        along the face's normal (x kept, y = z cross x)."""
        axis = self.flat_axis(cursor)[parent]
        turn = (axis >= 0) & (axis != 2) & (shapes.geom > -2) & ~is_mesh(shapes.geom)
        turn &= (shapes.size <= TOL.zero).sum(axis=1) == 1
        return self.turned(shapes, turn, NORMAL_OUT, axis, symbol, span)

    def comp_faces(self, op: ir.CompFaces, cursor: Shapes, symbol: int) -> None:
        """CityEngine ``comp(f|e|v)``: components to the first selector they match."""
        if op.offset is not None:
            self.refuse_meshes(op, cursor, symbol)
            self.offset_faces(op, cursor, symbol)
            return
        bad = cursor.geom < -1
        if bad.any():
            self.fail(cursor, bad, "`comp` of an inserted asset is not supported yet", symbol, op.span)
        kind = {"f": "faces", "e": "edges", "v": "vertices"}[op.kind]
        shapes, normal, _, parent = self.components(comp_kernels.KIND_CODES[kind], cursor, op.site)
        if op.kind == "f":
            shapes = self.face_scopes(shapes, cursor, parent, symbol, op.span)
        if op.kind == "f" and self.chunk.trim_slot is not None:
            # the faces' trim planes where they meet their neighbours (``geometry.trim``)
            up = self.chunk.frames[cursor.frame[parent]][:, 1]
            planes = side_face_planes(self.chunk.frames[shapes.frame], shapes.origin, shapes.size, parent, up)
            slot = self.chunk.trim_slot
            dynamic = list(shapes.dynamic)
            dynamic[slot:slot + 8] = list(planes.T)
            shapes = replace(shapes, dynamic=tuple(dynamic))
        if op.kind == "f":
            which = classify_faces(normal, op.selectors, self.selector_frames(normal, cursor, parent,
                                                                                op.selectors))
        else:
            direction = self.chunk.frames[shapes.frame][:, 0] if op.kind == "e" else None
            which = classify_edges(direction, op.selectors, len(shapes))
        keep = which < len(op.selectors)
        shapes, which, parent = shapes.take(keep), which[keep], parent[keep]
        if {"comp.index", "comp.total", "comp.sel"} & set(self.plan.dynamic):
            # CityEngine numbers the components of each selector: the front face is 0 of 1
            group = parent * (len(op.selectors) + 1) + which
            rank = rank_within(group)
            ids = np.array([self.plan.strings.ids[s] for s in op.selectors], dtype=np.int32)
            shapes = self.with_context(shapes, "comp", rank, group, int(group.max(initial=0)) + 1,
                                       selector=ids[which])
        self.count(shapes, symbol, op.span)
        order, offsets = group_by(which, len(op.parts))
        self.run_parts(op.parts, shapes.take(order), offsets, symbol)


#: Operation type -> the Executor method that runs it (``[``, ``]`` and ``center`` are handled in ``run``).
_OPERATIONS = {
    ir.Symbol: Executor.successor, ir.Translate: Executor.translate, ir.Scale: Executor.scale,
    ir.Rotate: Executor.rotate, ir.Insert: Executor.insert, ir.Split: Executor.split,
    ir.Repeat: Executor.repeat, ir.Comp: Executor.comp, ir.Extrude: Executor.extrude,
    ir.AlignScope: Executor.align_scope, ir.Mirror: Executor.mirror, ir.Offset: Executor.offset,
    ir.SetColor: Executor.set_color, ir.UseAsset: Executor.use_asset, ir.SetAttr: Executor.set_attr,
    ir.Report: Executor.report, ir.Case: Executor.branch, ir.Stochastic: Executor.branch,
    ir.GroupSplit: Executor.group_split, ir.CompFaces: Executor.comp_faces, ir.Empty: Executor.nothing,
    ir.NotApplied: Executor.nothing, ir.Setback: Executor.setback, ir.Roof: Executor.roof,
    ir.InnerRectangle: Executor.inner_rectangle, ir.Convexify: Executor.convexify,
    ir.CleanupGeometry: Executor.cleanup_geometry,
}
#: Operations that take roofs (meshes): scope changes, component splits, successors, leaves, cleanup.
_MESH_OPERATIONS = frozenset({
    ir.Symbol, ir.Translate, ir.Scale, ir.Rotate, ir.Insert, ir.Comp, ir.CompFaces, ir.Empty, ir.NotApplied,
    ir.SetColor, ir.UseAsset, ir.SetAttr, ir.Report, ir.Case, ir.Stochastic, ir.Split, ir.Repeat, ir.GroupSplit,
    ir.AlignScope, ir.CleanupGeometry,
})


def _hex_color(text: str) -> float:
    """0xRRGGBB of "#rrggbb" (or "#rgb"), NaN when the text is no such colour."""
    digits = text.strip().lstrip("#")
    if len(digits) == 3:
        digits = "".join(c * 2 for c in digits)
    try:
        return float(int(digits, 16)) if len(digits) == 6 else float("nan")
    except ValueError:
        return float("nan")




def _rotation(ax: np.ndarray, ay: np.ndarray, az: np.ndarray) -> np.ndarray:
    """(n, 3, 3) matrices M with new axes = M @ axes: about x, then the new y, then the new z (degrees)."""
    n = len(ax)
    out = np.empty((n, 3, 3))
    cx, sx = _cos_sin(ax)
    cy, sy = _cos_sin(ay)
    cz, sz = _cos_sin(az)
    one, zero = np.ones(n), np.zeros(n)
    mx = np.stack([np.stack([one, zero, zero], 1), np.stack([zero, cx, sx], 1),
                   np.stack([zero, -sx, cx], 1)], 1)
    my = np.stack([np.stack([cy, zero, -sy], 1), np.stack([zero, one, zero], 1),
                   np.stack([sy, zero, cy], 1)], 1)
    mz = np.stack([np.stack([cz, sz, zero], 1), np.stack([-sz, cz, zero], 1),
                   np.stack([zero, zero, one], 1)], 1)
    np.matmul(mz, np.matmul(my, mx), out=out)
    return out


def _cos_sin(degrees: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = np.ascontiguousarray(degrees, dtype=np.float64)
    return elementwise(1, d), elementwise(0, d)


def _example(values: np.ndarray, bad: np.ndarray) -> str:
    row = values[np.flatnonzero(bad)[0]]
    return ", ".join(f"{v:g}" for v in np.atleast_1d(row))


def _size_matrix(values: list, n: int) -> np.ndarray:
    """Split sizes as (n, P) float64, or (1, P) when every size is the same for all shapes."""
    if all(np.ndim(v) == 0 for v in values):
        return np.array([values], dtype=np.float64)
    return np.stack([np.broadcast_to(np.asarray(v, np.float64), (n,)) for v in values], axis=1)


#: GroupSplit size kinds for the kernel.
_SIZE_KIND = {ir.SizeKind.ABSOLUTE: 0, ir.SizeKind.RELATIVE: 1, ir.SizeKind.FLOATING: 2}
def report_rows(lot: np.ndarray, key, value, n: int) -> tuple:
    """One ``report`` call's rows: lot (n,), key ids (n,), values (n,) float64 and the value kind
    ("num", "bool" or "str"; strings as their ids)."""
    key = np.broadcast_to(np.asarray(key, dtype=np.int32), (n,))
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, np.ndarray) and value.dtype == bool):
        kind = "bool"
    elif isinstance(value, (int, np.integer)) or (isinstance(value, np.ndarray) and value.dtype == np.int32):
        kind = "str"
    else:
        kind = "num"
    values = np.broadcast_to(np.asarray(value, dtype=np.float64), (n,))
    return lot, key, values, kind
