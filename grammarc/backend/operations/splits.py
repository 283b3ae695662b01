"""Splits: the paper's ``Subdiv`` and ``Repeat`` (on one axis or several), CityEngine's ``split`` with repeat
groups and its ``splitArea`` (the same layout over the geometry's area), also in texture space
(``split(u|v, ...)``: along x of the shapes turned the way u or v grows, ``operations.texture``), and the
paper's ``Snap``/``SnapLines``, whose planes snapped splits move their cuts to.

A split makes children (``backend.children``: scopes moved and cut along the axis, polygons and meshes cut to
their slabs, new keys, ``split.index``/``split.total``) and returns them as ``Parts`` for its bodies; parts
that only place an asset take a shortcut to their records (``backend.leaf_parts``). Reads: the scope
(``origin``, ``size``, ``frame``), ``geom``, ``lot``, ``key``, ``depth``, ``params`` and ``dynamic`` (the
children inherit them), and what the sizes read. Writes: no column of the cursor; ``Snap`` adds planes to
the chunk.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.box_rings import as_polygons
from grammarc.backend.children import by_part, children, clip, grouped_children
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate, evaluate_array
from grammarc.backend.kernels import split as split_kernels
from grammarc.backend.kernels.order import group_by
from grammarc.backend.leaf_parts import LeafPart
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.operations.texture import texture_axis
from grammarc.backend.reframing import reframed
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry.area_cuts import area_positions, total_areas
from grammarc.geometry.queries import shape_faces
from grammarc.ir import nodes as ir
from grammarc.ragged import offsets_from_counts, rank_within


@operation(ir.Split, meshes=True, consumes=True)
def split(ctx: Context, cursor: Shapes, op: ir.Split) -> Parts | None:
    values = _split_sizes(ctx, cursor, op, "Subdiv")
    relative = np.array([s.kind is ir.SizeKind.RELATIVE for s in op.sizes])

    def cut(shapes: Shapes, level: int, axis: int):
        nonlocal values
        parent, part, pos, length = split_kernels.subdiv(
            np.ascontiguousarray(shapes.size[:, axis]), values, relative, TOL.zero
        )
        if op.snap:
            split_kernels.snap_subdiv(parent, pos, length, *_snaps_across(ctx, shapes, axis, op.snap_label))
        if values.shape[0] > 1:
            values = values[parent]  # the next axis' sizes follow the children
        return parent, part * len(op.sizes) ** level, pos, length

    return _fan_out(ctx, cursor, op, cut)


@operation(ir.Repeat, meshes=True, consumes=True)
def repeat(ctx: Context, cursor: Shapes, op: ir.Repeat) -> Parts | None:
    env = ctx.env(cursor)
    sizes = [evaluate_array(e, env) for e in op.sizes]
    stride = np.ones(len(cursor), dtype=np.int64)

    def cut(shapes: Shapes, level: int, axis: int):
        nonlocal sizes, stride
        size = sizes[level]
        bad = ~(size > 0)
        if bad.any():
            ctx.fail_each(shapes, bad, lambda i: f"`Repeat` needs a positive size, got {size[i]:g}", op.span)
        extent = np.ascontiguousarray(shapes.size[:, axis])
        counts = split_kernels.repeat_counts(extent, size, TOL.zero)
        if op.snap:  # each snap plane adds one element at most
            offsets, snaps = _snaps_across(ctx, shapes, axis, op.snap_label)
            ctx.check_fan_out(shapes, counts + np.diff(offsets), op.span)
            # the snap planes cut the scope first and each piece repeats on its own (Fig. 9)
            piece_parent, start, piece = _pieces(extent, offsets, snaps)
            piece_counts = split_kernels.repeat_counts(piece, size[piece_parent], TOL.zero)
            child, _, pos, length = split_kernels.repeat(piece, piece_counts)
            parent = piece_parent[child]
            pos += start[child]
            part = rank_within(parent)
            counts = np.bincount(parent, minlength=len(shapes))
        else:
            ctx.check_fan_out(shapes, counts, op.span)
            parent, part, pos, length = split_kernels.repeat(extent, counts)
        step = part * stride[parent]
        stride = stride[parent] * counts[parent]
        sizes = [s[parent] for s in sizes]  # the next axes' sizes follow the children
        return parent, step, pos, length

    return _fan_out(ctx, cursor, op, cut)


@operation(ir.GroupSplit, meshes=True, consumes=True)
def group_split(ctx: Context, cursor: Shapes, op: ir.GroupSplit) -> Parts:
    values = _split_sizes(ctx, cursor, op, "split")
    axis, frame = op.axis, None
    if op.uv_set >= 0:  # texture space: a split along x turned the way u (v) grows, sizes in metres
        cursor, metres, frame = texture_axis(ctx, cursor, op)
        relative = split_kernels.group_arrays(op)[0] == split_kernels.SIZE_KINDS[ir.SizeKind.RELATIVE]
        values = np.where(relative, values, values * metres[:, None])
        axis = 0
    extent = np.ascontiguousarray(cursor.size[:, axis])
    # parts of PRT's length limit or shorter are not made (complexpatterns' red window frames of 0.4 mm)
    parent, part, pos, length, index = _group_layout(ctx, cursor, op, values, extent, TOL.merge)
    return _group_children(ctx, cursor, op, axis, parent, part, pos, length, index, frame)


@operation(ir.SplitArea, consumes=True)
def split_area(ctx: Context, cursor: Shapes, op: ir.SplitArea) -> Parts:
    """``splitArea``: the split's layout over each shape's area, each part's cumulative area turned into
    the position along the axis where the faces before it have that area (``geometry.area_cuts``)."""
    chunk = ctx.chunk
    faces = shape_faces(cursor.size, cursor.geom, chunk.polygons, chunk.meshes)
    rings, offsets = (faces.verts, faces.ring_offsets, faces.face_offsets), faces.shape_offsets
    total = total_areas(*rings, offsets)
    values = _split_sizes(ctx, cursor, op, "splitArea")
    parent, part, start, area, index = _group_layout(ctx, cursor, op, values, total, TOL.zero)
    extent = cursor.size[parent, op.axis]
    ends = [area_positions(*rings, offsets, op.axis, parent, a, extent, total[parent])
            for a in (start, start + area)]
    return _group_children(ctx, cursor, op, op.axis, parent, part, ends[0], ends[1] - ends[0], index)


def _group_layout(ctx: Context, cursor: Shapes, op: ir.GroupSplit, values: np.ndarray, extent: np.ndarray,
                  shortest: float):
    """The parts of CityEngine's split of sizes ``values`` (n, P) or (1, P) over ``extent`` (n,) of
    ``cursor``'s shapes: parent, part, position, length and index of each (``kernels.split.group_split``),
    counted first: a lot they would take over --max-shapes fails before they are made. Parts of length
    ``shortest`` or less are not made."""
    kind, groups, n_groups = split_kernels.group_arrays(op)
    plan = split_kernels.group_counts(extent, values, kind, groups, n_groups, TOL.zero)
    ctx.check_fan_out(cursor, plan[-1], op.span)
    return split_kernels.group_split(extent, values, kind, groups, *plan, shortest)


def _group_children(ctx: Context, cursor: Shapes, op: ir.GroupSplit, axis: int, parent, part, pos, length, index,
                    frame: np.ndarray | None = None) -> Parts:
    """The children of a split's parts along ``axis``, their geometry cut to their slabs, by part; with the
    parents' ``frame`` ids (a split in texture space, its shapes turned) they take those frames again. A box
    whose ring starts elsewhere than corner 0 is cut as its polygon (``box_rings.as_polygons``)."""
    cursor = as_polygons(ctx.plan, ctx.chunk, cursor, axis)
    parent, part, pos, length, index, geometry = clip(ctx.chunk, cursor, axis, parent, part, pos, length,
                                                      index, op.adjust, turn_cuts=True)
    order, offsets = group_by(part, len(op.parts))
    made = children(ctx, cursor, axis, parent, index, pos, length, op.site, order, geometry)
    if frame is not None:  # the children take their parent's frame again
        frame = frame[parent[order]]
        made = reframed(ctx, made, ctx.chunk.frames[frame], op.span, frame)
    ctx.count(made, op.span)
    return Parts(op.parts, made, offsets)


@operation(ir.Snap, meshes=True)
def snap(ctx: Context, cursor: Shapes, op: ir.Snap) -> None:
    """``Snap`` / ``SnapLines``: the lot's construction planes across the scope axis ``op.normal``,
    through the scope's origin (and, for lines, its far end too)."""
    axes = ctx.chunk.frames[cursor.frame]
    normal = np.ascontiguousarray(axes[:, op.normal])
    ctx.chunk.snaps.add(cursor.lot, cursor.origin.copy(), normal, op.label)
    if op.lines:
        far = cursor.origin + normal * cursor.size[:, op.normal, None]
        ctx.chunk.snaps.add(cursor.lot, far, normal, op.label)


def _split_sizes(ctx: Context, cursor: Shapes, op: ir.Split | ir.GroupSplit, what: str) -> np.ndarray:
    """The parts' sizes, (n, P) or (1, P) when the same for all shapes; a NaN one fails.

    CityEngine's ``split`` and ``splitArea`` take a negative size as 0, as PRT does (candler's
    ``winSideW = (TileWidth - FrontWindowWidth) / 2`` goes below 0 for a window wider than its tile, and
    PRT's model is then the one of a window as wide as the tile); the paper's ``Subdiv`` fails the shape.
    """
    env = ctx.env(cursor)
    values = _size_matrix([evaluate(s.value, env) for s in op.sizes], len(cursor))
    if isinstance(op, ir.GroupSplit):
        values = np.where(values < 0, 0.0, values)
    ctx.fail_negative(cursor, values, f"`{what}` has a negative or NaN size", op.span)
    return values


def _snaps_across(ctx: Context, shapes: Shapes, axis: int, label: str | None) -> tuple[np.ndarray, np.ndarray]:
    """Where the snap planes of each shape's lot cross its scope along ``axis`` (``SnapStore.across``)."""
    axes = ctx.chunk.frames[shapes.frame]
    return ctx.chunk.snaps.across(shapes.lot, shapes.origin, np.ascontiguousarray(axes[:, axis]),
                                  np.ascontiguousarray(shapes.size[:, axis]), label, TOL.zero)


def _fan_out(ctx: Context, cursor: Shapes, op: ir.Split | ir.Repeat, cut) -> Parts | None:
    """Split ``cursor`` along each of ``op.axes`` in turn: the cells, for the parts.

    ``cut(shapes, level, axis)`` returns the children of one axis as (parent, cell step, position,
    length); a cell's number adds up the steps, the first axis varying fastest.
    """
    shapes = cursor
    cell = np.zeros(len(cursor), dtype=np.int64)
    for level, axis in enumerate(op.axes):
        parent, step, pos, length = cut(shapes, level, axis)
        shapes = as_polygons(ctx.plan, ctx.chunk, shapes, axis)
        parent, step, pos, length, _, geometry = clip(ctx.chunk, shapes, axis, parent, step, pos, length,
                                                      np.zeros(len(parent), dtype=np.int64))
        cell = cell[parent] + step
        if level == len(op.axes) - 1:
            leaves = _leaf_parts(ctx, op.parts, shapes, geometry)
            if leaves is not None:
                return _fan_out_leaves(ctx, op, shapes, axis, parent, cell, pos, length, leaves)
            shapes, offsets = grouped_children(ctx, shapes, axis, parent, cell, pos, length, op.site,
                                               len(op.parts), geometry)
        else:
            shapes = children(ctx, shapes, axis, parent, cell, pos, length, op.site, geometry=geometry)
    ctx.count(shapes, op.span)
    return Parts(op.parts, shapes, offsets)


def _leaf_parts(ctx: Context, parts: tuple[ir.Body, ...], shapes: Shapes, geometry) -> list | None:
    """Per body part, the ``LeafInsert`` of the symbol it names if its records can be written straight
    from the parent's scope (``backend.leaf_parts``), else None; None if no part can."""
    plan = ctx.plan
    inserts = plan.leaf_inserts
    if not inserts or geometry is not None or "split.total" in plan.dynamic:
        return None
    leaves = [inserts.get(plan.symbol_ids[body[0].name])
              if len(body) == 1 and isinstance(body[0], ir.Symbol) and not body[0].args and not body[0].leaf
              else None for body in parts]
    # the successor would be one rule application deeper: where that reaches --max-depth, the
    # general path reports it
    if not any(leaves) or int(shapes.depth.max()) + 1 >= ctx.limits.max_depth:
        return None
    return leaves


def _fan_out_leaves(ctx: Context, op, shapes: Shapes, axis: int, parent, cell, pos, length,
                    leaves: list) -> Parts:
    """The last axis of ``_fan_out`` when some parts only place an asset: their records are computed from
    ``shapes`` and the cuts when the runner reaches their part (``LeafPart``); the other parts' children
    are made as usual. Shape counts are kept as the general path keeps them."""
    n_parts = len(op.parts)
    order, offsets = by_part(cell, n_parts)
    # the children, as `_fan_out` counts them: per parent, each in its lot
    ctx.count_lots(shapes.lot, op.span, np.bincount(parent, minlength=len(shapes)))
    rows = [order[offsets[i]:offsets[i + 1]] for i in range(n_parts)]
    general = [i for i, leaf in enumerate(leaves) if leaf is None]
    kept = np.concatenate([rows[i] for i in general]) if general else order[:0]
    made = children(ctx, shapes, axis, parent, cell, pos, length, op.site, kept) if general else shapes.take(kept)
    parts = tuple(None if leaf is None or not len(rows[i]) else
                  LeafPart(leaf, shapes, axis, rows[i], parent, pos, length) for i, leaf in enumerate(leaves))
    sizes = [len(rows[i]) if leaves[i] is None else 0 for i in range(n_parts)]
    return Parts(op.parts, made, offsets_from_counts(np.array(sizes, dtype=np.int64)), parts)


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
