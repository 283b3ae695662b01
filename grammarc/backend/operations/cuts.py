"""``Cut(e1, t1, e2, t2){ A | B }``: a shape's polygon divided by a line between two of its edges.

Stiny's ice-ray grammar divides a lattice's cells (triangles, quadrilaterals, pentagons) by segments
from edge to edge; GRAMATICA's example derives it. A shape's polygon is its footprint in the scope's
x-z plane: its rectangle (a lot, a split part) or its polygon of the store (a piece of an earlier cut);
``geometry.edge_cuts`` divides them all at once, and each piece becomes a child whose scope is the piece's
bounding box in its parent's frame (as a polygon split across its plane gives its pieces), its polygon
normalized to it in the store. Reads: the scope, ``geom``, ``lot``, ``key``, ``depth``, ``params`` and
``dynamic`` (the pieces inherit them), and what the edge numbers and fractions read. Writes: no column
of the cursor; the pieces' polygons go to the chunk's store.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.children import with_context
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import piece_keys
from grammarc.geometry.components import rect_rings
from grammarc.geometry.edge_cuts import cut_rings
from grammarc.ir import nodes as ir
from grammarc.ragged import segment_of, segment_reduce

#: The plane of footprints in the polygon store: (u, v) along the scope's (x, z).
FOOTPRINT = 1


@operation(ir.Cut, consumes=True)
def cut(ctx: Context, shapes: Shapes, op: ir.Cut) -> Parts:
    env = ctx.env(shapes)
    e1, e2 = (evaluate_array(e, env) for e in op.edges)
    t1, t2 = (evaluate_array(t, env) for t in op.at)
    xy, offsets = _footprints(ctx, shapes, op)
    first, first_offsets, second, second_offsets, bad = cut_rings(
        xy, offsets, np.floor(e1).astype(np.int64), t1, np.floor(e2).astype(np.int64), t2)
    if bad.any():
        ctx.fail(shapes, bad, "`Cut` between one edge and itself, or along an edge or through one vertex "
                 "only (a piece of fewer than three corners)", op.span)
    n = len(shapes)
    parents = np.concatenate([np.arange(n), np.arange(n)])
    index = np.repeat(np.array([0, 1]), n)
    pieces = np.concatenate([first, second])
    piece_offsets = np.concatenate([first_offsets, second_offsets[1:] + first_offsets[-1]])
    low = segment_reduce(np.minimum, pieces, piece_offsets, 0.0)
    high = segment_reduce(np.maximum, pieces, piece_offsets, 0.0)
    extent = high - low
    owner = segment_of(piece_offsets)
    coords = (pieces - low[owner]) / np.where(extent > 0, extent, 1.0)[owner]
    geom = ctx.chunk.polygons.add(coords, piece_offsets, np.arange(2 * n + 1, dtype=np.int64),
                                  np.full(2 * n, FOOTPRINT, dtype=np.int8))
    axes = ctx.chunk.frames[shapes.frame[parents]]
    origin = shapes.origin[parents] + low[:, :1] * axes[:, 0] + low[:, 1:] * axes[:, 2]
    size = np.stack([extent[:, 0], shapes.size[parents, 1], extent[:, 1]], axis=1)
    made = Shapes(origin, size, shapes.frame[parents], geom, shapes.lot[parents],
                  piece_keys(ctx.plan.sequential_random, shapes.key[parents], index, op.site), shapes.depth[parents],
                  tuple(p[parents] for p in shapes.params), tuple(d[parents] for d in shapes.dynamic))
    made = with_context(ctx.plan, made, "split", index, parents, n)
    ctx.count(made, op.span)
    return Parts(op.parts, made, np.array([0, n, 2 * n], dtype=np.int64))


def _footprints(ctx: Context, shapes: Shapes, op: ir.Cut) -> tuple[np.ndarray, np.ndarray]:
    """The shapes' polygons in their scopes' (x, z), as rings (V, 2) with offsets (n+1,): a scope's
    rectangle, or a footprint of the store with no hole. Other geometry fails its lot."""
    store = ctx.chunk.polygons
    geom = shapes.geom
    polygon = geom >= 0
    plane = np.where(polygon, store.plane[np.maximum(geom, 0)] if len(store) else FOOTPRINT, FOOTPRINT)
    rings = np.zeros(len(shapes), dtype=np.int64)
    if polygon.any():
        rings[polygon] = np.diff(store.poly_offsets)[geom[polygon]]
    wrong = (geom < -1) | (polygon & ((plane != FOOTPRINT) | (rings != 1)))
    if wrong.any():
        ctx.fail(shapes, wrong, "`Cut` of an inserted asset, a roof, a face or a polygon with holes is not "
                 "supported (it cuts footprints in the scope's x-z plane)", op.span)
    count = np.where(polygon, 0, 4)
    coords, ring_offsets, _ = store.gather(geom[polygon])
    count[polygon] = np.diff(ring_offsets)
    offsets = np.concatenate([[0], np.cumsum(count)])
    uv = np.empty((offsets[-1], 2))
    owner = segment_of(offsets)
    box = ~polygon[owner]
    uv[box] = rect_rings(np.full(int((~polygon).sum()), FOOTPRINT))
    uv[~box] = coords
    return uv * shapes.size[owner][:, [0, 2]], offsets
