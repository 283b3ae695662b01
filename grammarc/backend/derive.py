"""Derive one chunk of lots: initial shapes, attributes, the staged worklist, sorted records.

The schedule (paper section 2, "Production process"): stages follow the rules' priorities from the lowest;
within a stage, rounds visit the symbols in a fixed order (their ids) and apply each symbol's rules to all
of its pending shapes at once, until no shape of the stage is pending. Because the schedule is the same for
every lot and each operation is elementwise, the records of a lot do not depend on which other lots share
its chunk; sorting the chunk's records by lot (stably) makes the output independent of the chunking.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend.aggregates import judge
from grammarc.backend.attributes import attribute_columns
from grammarc.backend.choices import Choices
from grammarc.backend.chunk import Chunk, Frames, TrimPlanes
from grammarc.backend.context import Context
from grammarc.backend.evaluate import Env
from grammarc.backend.execute import apply_pending
from grammarc.backend.kernels.order import place, put, scatter_rows, tally
from grammarc.backend.materials import MAP_FIELDS, collect_materials
from grammarc.backend.occlusion import Occluders
from grammarc.backend.pivot import initial_column as initial_pivot
from grammarc.backend.plan import Plan
from grammarc.backend.report_rows import aggregate_chunk
from grammarc.backend.shapes import Shapes
from grammarc.backend.slots import (
    ANCESTORS,
    COLOR_SLOT,
    HORIZONTAL_SWITCH,
    PIVOT_SLOTS,
    RING_START,
    TRIM_INSERTED,
    TRIM_PLANES,
    TRIM_SWITCH,
    WHITE_RGB,
)
from grammarc.backend.streams import lot_keys
from grammarc.backend.texture_space import initial_column
from grammarc.constants import Limits
from grammarc.errors import check_stopped
from grammarc.geometry.footprint import footprint_polygons, lot_scopes
from grammarc.geometry.polygons import PolygonStore
from grammarc.geometry.streets import lot_streets
from grammarc.model.lots import Lots
from grammarc.model.records import LotOrigins, MeshChunk, TerminalChunk
from grammarc.ragged import ragged_take

_NO_WEIGHTS = np.zeros(0, np.int64)  # ``tally``: each row counts 1


def initial_chunk(lots: Lots, seed: int, foreign: Occluders | None = None,
                  sequential: bool = False, scopes: tuple | None = None) -> tuple[Chunk, Shapes]:
    """The chunk state and initial shapes (one per lot) of ``lots``, their random keys from ``seed`` (and
    the lots' ``seed`` properties where they draw from a ``sequential`` stream, ``backend.streams``);
    ``foreign`` the occluders of every lot from a first pass (``derive_chunk``); ``scopes`` the lots'
    ``lot_scopes`` where they are known (``repeated_scopes``)."""
    origin, axes, size, local = lot_scopes(lots) if scopes is None else scopes
    is_rect, coords, ring_offsets, poly_offsets = footprint_polygons(lots, size, local)
    frames = Frames(capacity=max(256, 4 * len(lots)))
    polygons = PolygonStore()
    geom = np.full(len(lots), -1, dtype=np.int32)
    geom[~is_rect] = polygons.add(coords, ring_offsets, poly_offsets,
                                  np.ones(int((~is_rect).sum()), dtype=np.int8))
    key = lot_keys(sequential, seed, lots.index, lots.attrs.get("seed"))
    chunk = Chunk(lot_index=lots.index, lot_ids=lots.ids, lot_key=key, attrs={}, lot_origin=origin, lot_axes=axes,
                  streets=lot_streets(lots.vertices, lots.ring_offsets, lots.lot_offsets, lots.street, axes),
                  frames=frames, polygons=polygons, foreign=foreign)
    n = len(lots)
    shapes = Shapes(origin, size, frames.add(axes), geom, np.arange(n, dtype=np.int32), key.copy(),
                    np.zeros(n, dtype=np.int32))  # a sequential stream's draws advance the copy
    chunk.lot_shapes = (shapes.size, shapes.frame, shapes.geom)
    return chunk, shapes


def repeated_scopes(lots: Lots, rows: np.ndarray) -> tuple:
    """``lot_scopes`` of ``lots.take(rows)``, each lot measured once however often ``rows`` takes it."""
    distinct, inverse = np.unique(rows, return_inverse=True)
    once = lots.take(distinct)
    origin, axes, size, local = lot_scopes(once)
    vertices, _ = ragged_take(once.ring_offsets[once.lot_offsets], inverse)
    return origin[inverse], axes[inverse], size[inverse], local[vertices]


def derive_chunk(plan: Plan, lots: Lots, *, seed: int, limits: Limits, overrides: dict,
                 chunk_budget: int, foreign: Occluders | None = None,
                 occluders_only: bool = False, choices: Choices | None = None,
                 records: bool = True, rows: np.ndarray | None = None) -> tuple[TerminalChunk | None, dict] | Occluders:
    """Derive ``lots``: their records and their reports per lot (``reports.aggregate_chunk``).

    ``foreign`` are the occluders of every lot from a first pass, for ``inter`` queries; with
    ``occluders_only`` this is that first pass: the derivation stops where the first query would run
    and returns the occluders made up to there. ``choices``: the lots are a search's states, whose
    choices they fix and whose outcomes (stop, cost, goal...) they receive (``backend.choices``);
    without ``records`` none are collected (None). ``rows``: the chunk's lots are ``lots``' rows
    ``rows``, a lot as often as it comes there (a search's states are their lot, many times over).

    Raises ``LotFailure`` naming lots to skip (a limit reached among them), or ``ChunkTooLarge``.
    """
    scopes = None
    if rows is not None:
        scopes = repeated_scopes(lots, rows)
        lots = lots.take(rows)
    chunk, shapes = initial_chunk(lots, seed, foreign, plan.sequential_random, scopes)
    if plan.trim_slot is not None:
        chunk.trim_planes = TrimPlanes(plan.trim_width)
    attribute_columns(plan.grammar.module, Env(shapes, chunk, plan), lots.attrs, overrides, plan.strings)
    shapes = replace(shapes, dynamic=tuple(initial_dynamic(plan, name, chunk, shapes) for name in plan.dynamic))
    chunk.choices = choices
    ctx = Context(plan, chunk, limits, chunk_budget)
    pending = ctx.pending
    pending[plan.start].append(shapes)
    for stage in plan.stages:
        # A fixed visiting order per round: whether a lot's shapes are processed in a round depends only
        # on that lot, never on which other lots have shapes pending (see the module docstring). Rules
        # that ask occlusion queries wait until nothing else of the stage is pending.
        order = [s.id for s in plan.symbols if s.rules and s.priority <= stage]
        others = [s for s in order if s not in plan.queries]
        while any(pending.get(s) for s in order):
            check_stopped()
            if occluders_only and not any(pending.get(s) for s in others):
                return chunk.occluders.table()
            for sym_id in order:
                # a lot's queries run once it has nothing else pending: waiting for other lots too
                # changes nothing of its own derivation
                if sym_id in plan.queries and (occluders_only or any(pending.get(s) for s in others)):
                    continue
                batches = pending.pop(sym_id, None)
                if batches:
                    apply_pending(ctx, plan.symbols[sym_id], batches)
    if occluders_only:
        return chunk.occluders.table()
    if choices is not None:
        judge(plan.grammar.module, choices, Env(shapes, chunk, plan))
        # a search's states share their lot's number (and so its random keys): its records number the states
        chunk.lot_index = np.arange(len(lots)) + choices.first
    reports = aggregate_chunk(chunk.outputs.reports, chunk.lot_index, list(plan.strings.ids))
    return collect(chunk, plan) if records else None, reports


def initial_dynamic(plan: Plan, name: str, chunk: Chunk, shapes: Shapes) -> np.ndarray:
    """A lot's starting value of a per-shape column: its attribute, or the context of no split yet."""
    n = len(shapes)
    if name == COLOR_SLOT:
        return np.full(n, WHITE_RGB)
    if name == "comp.sel" or name in MAP_FIELDS:
        return np.full(n, plan.strings.intern(""), dtype=np.int32)
    if name in ("split.total", "comp.total"):
        return np.ones(n)
    if name in ("split.index", "comp.index"):
        return np.zeros(n)
    if name == TRIM_PLANES:  # none
        return np.zeros(n, dtype=np.int32)
    if name in ANCESTORS:
        return np.full(n, np.nan)
    if name == TRIM_SWITCH:
        return np.ones(n)
    if name == TRIM_INSERTED:  # a lot's geometry is its own
        return np.zeros(n)
    if name == HORIZONTAL_SWITCH:
        return np.zeros(n)
    if name in PIVOT_SLOTS:
        return initial_pivot(name, chunk, shapes)
    if name == RING_START:
        return np.zeros(n)
    if plan.uv_slots:
        texture = initial_column(plan, name, chunk, shapes)
        if texture is not None:
            return texture
    return chunk.attrs[name][shapes.lot]


def collect(chunk: Chunk, plan: Plan) -> TerminalChunk:
    """The chunk's records, sorted stably by lot, with lots numbered as in the input, relative to their lots'
    scope origins (``LotOrigins``).

    Rows are scattered straight from the pieces the operations emitted into their sorted places (a counting
    sort: one pass over the rows' lots to count, one to place them), so each column is copied once; a
    piece's asset and symbol, one id each, are written there. Texture channels become the chunk's table of
    materials (``backend.materials``).
    """
    out = chunk.outputs
    lot = np.concatenate(out.lot) if out.lot else np.zeros(0, dtype=np.int32)
    counts = np.zeros(len(chunk.lot_index), np.int64)
    tally(counts, lot, _NO_WEIGHTS)
    fill = np.zeros(len(counts), np.int64)
    np.cumsum(counts[:-1], out=fill[1:])
    dest = place(lot, fill)  # a stable counting sort: each row's place among the chunk's sorted rows
    bounds = np.cumsum([0, *map(len, out.lot)])
    columns = {}
    for name, ids in (("asset", out.asset), ("symbol", out.symbol)):  # one id for each piece of rows
        columns[name] = np.empty(len(lot), np.int32)
        for k, value in enumerate(ids):
            put(value, dest[bounds[k]:bounds[k + 1]], columns[name])
    names = [("xform", (3, 4), np.float32)]
    if out.color:
        names.append(("color", (4,), np.uint8))
    if plan.material_slots:
        names.append(("material", (len(plan.material_slots),), np.int32))
    if out.uv:
        names.append(("uv", (2, 4), np.float32))
    for name, row_shape, dtype in names:
        column = np.empty((len(lot), *row_shape), dtype=dtype)
        width = int(np.prod(row_shape))
        flat = column.reshape(len(lot), width)
        start = 0
        for piece in getattr(out, name):
            stop = start + len(piece)
            scatter_rows(np.ascontiguousarray(piece).reshape(len(piece), width), dest[start:stop], flat)
            start = stop
        columns[name] = column
    index = chunk.lot_index.astype(np.int32)
    mesh = MeshChunk.concat(out.meshes) if out.meshes else MeshChunk.empty()
    face_order = np.argsort(mesh.lot, kind="stable")
    if len(mesh.lot):
        mesh = _sort_mesh(mesh, face_order)
    material = materials = mesh_material = None
    if plan.material_slots:
        width = len(plan.material_slots)
        faces = np.concatenate(out.mesh_material)[face_order] if out.mesh_material else np.zeros((0, width), np.int32)
        materials, both = collect_materials(plan, np.concatenate([columns["material"], faces]))
        material, mesh_material = both[:len(lot)], both[len(lot):]
    mesh = MeshChunk(mesh.vertices, mesh.ring_offsets, mesh.face_offsets, index[mesh.lot], mesh.symbol,
                     mesh.color, mesh_material, materials, mesh.uv)
    return TerminalChunk(asset=columns["asset"], xform=columns["xform"], lot=np.repeat(index, counts),
                         symbol=columns["symbol"], mesh=mesh, color=columns.get("color"), material=material,
                         materials=materials, uv=columns.get("uv"),
                         origins=LotOrigins.of_lots(index, chunk.lot_origin))


def _sort_mesh(mesh: MeshChunk, order: np.ndarray) -> MeshChunk:
    """The faces ``order`` of ``mesh``, their rows gathered by ``np.take`` (whole rows, see ``Shapes.take``)."""
    rings, face_offsets = ragged_take(mesh.face_offsets, order)
    vertices, ring_offsets = ragged_take(mesh.ring_offsets, rings)
    return MeshChunk(np.take(mesh.vertices, vertices, axis=0), ring_offsets, face_offsets, mesh.lot[order],
                     mesh.symbol[order], np.take(mesh.color, order, axis=0) if mesh.color is not None else None,
                     uv=np.take(mesh.uv, vertices, axis=0) if mesh.uv is not None else None)
