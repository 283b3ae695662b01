"""Terminal records: instances mapping an asset's unit box onto a scope, and leaf geometry.

``kernels.scope.xforms`` builds the (n, 3, 4) record transform (README, "The record"): column j is scope axis j times
scope size j, column 3 the scope origin relative to its lot's origin (``model.records.LotOrigins``: records
and mesh vertices are float32 relative to it, the derivation is float64 in world). ``emit_leaves`` turns shapes whose symbol has no rule (or to which
no rule applied) into output, as CityEngine emits leaf geometry:

- a box scope -> ``builtin:cube``;
- a flat rectangle (one zero axis k) -> ``builtin:quad``, the unit square z = 0 with normal +z. Its
  columns are scope axes (k+1, k+2) mod 3 and a zero column, a cyclic permutation chosen so that the
  quad's normal is the scope's axis k (a footprint faces up, a facade out);
- an edge or a vertex (two or three zero axes) -> nothing: it has no surface;
- an inserted asset (CityEngine's ``i()``) -> an instance of that asset;
- a polygon -> faces of the mesh table (with holes); a prism -> its bottom, top and side faces;
- a roof (a mesh) -> its faces.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend.aggregates import collect
from grammarc.backend.context import Context
from grammarc.backend.kernels.scope import leaf_kinds, xforms
from grammarc.backend.kernels.texture import instance_maps, vertex_maps
from grammarc.backend.materials import material_ids, rgba
from grammarc.backend.mesh_shapes import mesh_leaves
from grammarc.backend.shapes import Z_UP, Shapes, asset_of
from grammarc.backend.texture_space import COORDINATES
from grammarc.constants import TOL
from grammarc.geometry.components import reverse_rings
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.geometry.trim import VERTICAL_PLANES, boxes_crossing, trim_triangles
from grammarc.model.records import MeshChunk
from grammarc.ragged import next_in_segment, offsets_from_counts, segment_of

CUBE, QUAD = 0, 1  # asset ids of the leaf built-ins (see ir.passes.assets)


def emit_instances(ctx: Context, shapes: Shapes, asset: int, symbol: int, mirrored: int = 0,
                   textured: bool = False, inserted: np.ndarray | None = None,
                   rows: np.ndarray | None = None) -> None:
    """Instances of ``asset`` on the scopes of ``shapes`` (their ``rows`` (m,) int64, default all: a leaf
    batch places its boxes without copying its other columns); ``mirrored`` bits (1 x, 2 y, 4 z) flip the
    asset along those scope axes (the column is negated and the origin moved to the far side); ``Z_UP``
    turns the asset in its box before that. Where the grammar trims inserts, those crossing their trim planes become the asset's
    triangles cut by them; ``inserted`` (m,) bool, when given, says which shapes' geometry was inserted, the
    others are not cut (a leaf box a shape extruded). ``textured``: they carry the shapes' texture
    coordinates (a leaf box); an inserted asset has its own, which grammarc does not keep, and carries none."""
    if rows is None:
        rows = np.arange(len(shapes))
    if not len(rows):
        return
    chunk = ctx.chunk
    xform = xforms(chunk.frames.data, shapes.frame, shapes.size, shapes.origin, shapes.lot, chunk.lot_origin, rows,
                   np.full(len(rows), -1, np.int8))
    for axis in range(3):
        if mirrored >> axis & 1:
            xform[:, :, 3] += xform[:, :, axis]
            xform[:, :, axis] *= -1
    if mirrored & Z_UP:  # the asset turns in its own box, before the mirror in the scope's
        xform = z_up(xform)
    place_instances(ctx, shapes, rows, xform, asset, symbol, textured, inserted)


def place_instances(ctx: Context, shapes: Shapes, rows: np.ndarray, xform: np.ndarray, asset: int, symbol: int,
                    textured: bool = False, inserted: np.ndarray | None = None) -> None:
    """The instances of ``asset`` placed by ``xform`` (m, 3, 4) on ``shapes`` rows ``rows`` (m,), as
    ``emit_instances`` places them: cut at their trim planes where they cross them, ``textured`` and
    ``inserted`` as there (a fused kernel's records, their transforms written by the kernel, come here
    with the rows of the shapes they come from)."""
    if ctx.plan.trim_slot is not None:
        planes = trim_planes(ctx.plan, ctx.chunk, shapes, rows)
        placed = xform.astype(np.float64)  # relative to the lot's origin, as the trim planes are
        cut = boxes_crossing(planes, placed, TOL.zero)
        if inserted is not None:
            cut &= inserted
        mesh = ctx.asset_mesh(asset) if cut.any() else None
        if mesh is not None:
            crossing = shapes.take(rows[cut])
            trimmed, owner = _trimmed(ctx.plan, crossing, placed[cut], planes[cut], mesh, symbol)
            append_mesh(ctx, _with_uv(ctx, crossing, owner, trimmed) if textured else trimmed, crossing, owner)
            rows, xform = rows[~cut], xform[~cut]
    append_instances(ctx, shapes, rows, xform, asset, symbol, textured)


def z_up(xform: np.ndarray) -> np.ndarray:
    """Transforms (n, 3, 4) of z-up assets: the unit box turned -90 degrees about x, (u, v, w) to
    (u, w, 1 - v), then placed by ``xform``; its columns become (x, -z, y), the origin moved along z."""
    turned = xform[:, :, [0, 2, 1, 3]]
    turned[:, :, 1] *= -1
    turned[:, :, 3] += xform[:, :, 2]
    return turned


def trim_planes(plan, chunk, shapes: Shapes, rows=slice(None)) -> np.ndarray:
    """The trim planes (m, ``plan.trim_width``) of ``shapes`` rows ``rows``, gathered from the ``chunk``'s
    table by id: the two vertical ones, NaN where there are none or ``set(trim.vertical, false)``; then,
    where the grammar turns them on, the horizontal ones, NaN where ``trim.horizontal`` is false."""
    planes = chunk.trim_planes[shapes.dynamic[plan.trim_slot][rows]]
    vertical = 4 * VERTICAL_PLANES
    if plan.trim_switch is not None:
        planes[shapes.dynamic[plan.trim_switch][rows] == 0, :vertical] = np.nan
    if plan.horizontal_planes:
        planes[shapes.dynamic[plan.horizontal_switch][rows] == 0, vertical:] = np.nan
    return planes


def marked_inserted(plan, shapes: Shapes, inserted: bool) -> Shapes:
    """``shapes`` with their geometry marked as inserted, which leaves cut at their trim planes, or as
    their own (``slots.TRIM_INSERTED``), where the grammar has trim planes."""
    slot = plan.inserted_slot
    if slot is None:
        return shapes
    dynamic = list(shapes.dynamic)
    dynamic[slot] = np.full(len(shapes), float(inserted))
    return replace(shapes, dynamic=tuple(dynamic))


def _trimmed(plan, shapes: Shapes, placed: np.ndarray, planes: np.ndarray, mesh,
             symbol: int) -> tuple[MeshChunk, np.ndarray]:
    """The asset's triangles placed by ``placed`` (n, 3, 4) float64 and cut by the shapes' trim
    ``planes``, both relative to their lots' origins, as mesh faces, and the row of ``shapes`` each face
    comes from."""
    vertices, ring_offsets, owner = trim_triangles(mesh.vertices, mesh.faces, placed, planes, TOL.zero)
    return MeshChunk(
        vertices=vertices.astype(np.float32), ring_offsets=ring_offsets,
        face_offsets=np.arange(len(owner) + 1, dtype=np.int64), lot=shapes.lot[owner].astype(np.int32),
        symbol=np.full(len(owner), symbol, dtype=np.int32),
        color=_colors(plan, shapes, owner)), owner


def _colors(plan, shapes: Shapes, rows=slice(None)) -> np.ndarray | None:
    """The colours (m, 4) uint8 of ``shapes`` rows ``rows``, where the grammar sets colours."""
    return rgba(shapes.dynamic[plan.color_slot][rows]) if plan.color_slot is not None else None


def append_mesh(ctx: Context, mesh: MeshChunk, shapes: Shapes, rows=slice(None)) -> None:
    """Add leaf faces, made of ``shapes`` rows ``rows`` face by face, with their texture channels where the
    grammar carries them (``backend.materials``)."""
    vertices = mesh.vertices
    if not np.isfinite(vertices).all():
        face = segment_of(mesh.face_offsets)[segment_of(mesh.ring_offsets)]
        bad = ~np.isfinite(vertices).all(axis=1)
        _fail_non_finite(ctx, mesh.lot[face[bad]], vertices[bad], "a mesh vertex")
    out = ctx.chunk.outputs
    out.meshes.append(mesh)
    if ctx.plan.material_slots:
        out.mesh_material.append(material_ids(ctx.plan, shapes, rows))


def append_instances(ctx: Context, shapes: Shapes, rows: np.ndarray, xform: np.ndarray, asset: int, symbol: int,
                     textured: bool = True) -> None:
    """Add the instance records placed by ``xform`` (m, 3, 4) of ``shapes`` rows ``rows`` (m,)."""
    color_slot = ctx.plan.color_slot
    append_records(ctx, xform, shapes.lot[rows], asset, symbol,
                   shapes.dynamic[color_slot][rows] if color_slot is not None else None,
                   material_ids(ctx.plan, shapes, rows), _instance_uv(ctx, shapes, rows, xform, textured))


def append_records(ctx: Context, xform: np.ndarray, lot: np.ndarray, asset: int, symbol: int,
                   color: np.ndarray | None, material: np.ndarray | None = None,
                   uv: np.ndarray | None = None) -> None:
    """Add instance records: transforms, lots, and colours (packed floats) and texture channels (string ids
    (n, k)) where the grammar sets them (``backend.materials``), and texture maps (``TerminalChunk.uv``)
    where it has texture coordinates."""
    # the sum is finite where every value is: one pass and no temporary for the usual case; a sum that
    # overflowed (which is no failure: not warned about), or a value that is not finite, is looked at
    # value by value
    with np.errstate(over="ignore", invalid="ignore"):
        total = xform.sum()
    if not np.isfinite(total):
        bad = ~np.isfinite(xform).all(axis=(1, 2))
        if bad.any():
            _fail_non_finite(ctx, lot[bad], xform[bad], "an instance")
    out = ctx.chunk.outputs
    if uv is not None:
        out.uv.append(uv)
    out.xform.append(xform)
    out.asset.append(asset)
    out.lot.append(lot.astype(np.int32, copy=False))
    out.symbol.append(symbol)
    if ctx.plan.color_slot is not None:
        out.color.append(rgba(color))
    if material is not None:
        out.material.append(material)


def _fail_non_finite(ctx: Context, lots: np.ndarray, rows: np.ndarray, what: str) -> None:
    """Fail ``lots``, whose record ``rows`` (float32) have a coordinate that is not finite: beyond 3.4e38
    (a size or a move far beyond any city) or made of inf and NaN (attributes such as ``height=inf``).
    The last guard before records are written, wherever the value came from; each lot's message quotes its
    first such value."""
    sym = ctx.plan.symbols[ctx.symbol]
    ctx.fail_quoting(lots, lambda row: f"{what} with a coordinate of {rows[row][~np.isfinite(rows[row])].flat[0]} "
                     "(not finite as float32)", sym.rules[0].span if sym.rules else None)


def _instance_uv(ctx: Context, shapes: Shapes, rows: np.ndarray, xform: np.ndarray,
                 textured: bool) -> np.ndarray | None:
    """(m, 2, 4) float32: the texture coordinates of set 0 of instances of ``shapes`` rows ``rows`` placed
    by ``xform`` as maps of their unit box's points, where the grammar has texture coordinates (NaN where
    a shape has none, or all of them unless ``textured``)."""
    start = ctx.plan.uv_slots.get(0)
    if start is None:
        return None
    if not textured:
        return np.full((len(rows), 2, 4), np.nan, np.float32)
    chunk = ctx.chunk
    return instance_maps(chunk.texture_maps.data, shapes.dynamic[start + COORDINATES], rows, chunk.lot_origin,
                         shapes.lot, xform)


def _with_uv(ctx: Context, shapes: Shapes, owner: np.ndarray, mesh: MeshChunk) -> MeshChunk:
    """``mesh`` with the texture coordinates of set 0 of its vertices (``MeshChunk.uv``), its faces those
    of ``shapes`` rows ``owner``, where the grammar has texture coordinates."""
    start = ctx.plan.uv_slots.get(0)
    if start is None:
        return mesh
    chunk = ctx.chunk
    vertex_shape = owner[segment_of(mesh.face_offsets)][segment_of(mesh.ring_offsets)]
    return replace(mesh, uv=vertex_maps(chunk.texture_maps.data, shapes.dynamic[start + COORDINATES],
                                        chunk.lot_origin, shapes.lot, vertex_shape, mesh.vertices))


def emit_leaves(ctx: Context, shapes: Shapes, symbol: int) -> None:
    """Emit the geometry of leaf shapes: instances for scope boxes and rectangles, meshes for polygons."""
    if not len(shapes):
        return
    chunk = ctx.chunk
    if chunk.choices is not None:  # a search state's design (``aggregates``), written where asked for
        if chunk.choices.aggregates:
            collect(chunk.choices, ctx.env(shapes), ctx.plan.symbols[symbol].name)
        if not chunk.choices.records:
            return
        # a stopped state's design is the leaves it made before its stop, not those of the option its
        # stopping body goes on with
        shapes = shapes.take(~chunk.choices.stopped[shapes.lot])
        if not len(shapes):
            return
    # instances are placed from the batch's rows, not from batches of them: a leaf batch has some twenty
    # columns, of which records read a few
    assets = shapes.geom < -1
    if assets.any():
        for code in np.unique(shapes.geom[assets]):
            asset, mirrored = asset_of(np.array([code]))
            emit_instances(ctx, shapes, int(asset[0]), symbol, int(mirrored[0]),
                           rows=np.flatnonzero(shapes.geom == code))
    kind = leaf_kinds(shapes.geom, shapes.size, TOL.zero)
    boxes = np.flatnonzero(kind == -1)
    slot = ctx.plan.inserted_slot
    emit_instances(ctx, shapes, CUBE, symbol, textured=True,
                   inserted=shapes.dynamic[slot][boxes] == 1 if slot is not None else None, rows=boxes)
    quads = np.flatnonzero((kind >= 0) & (kind < 3))
    if len(quads):
        xform = xforms(chunk.frames.data, shapes.frame, shapes.size, shapes.origin, shapes.lot, chunk.lot_origin,
                       quads, kind[quads])
        append_instances(ctx, shapes, quads, xform, QUAD, symbol)
    polygons = shapes.take(is_polygon(shapes.geom))
    if len(polygons):
        faces, owner = polygon_meshes(ctx, polygons, symbol)
        append_mesh(ctx, faces, polygons, owner)
    meshes = shapes.take(is_mesh(shapes.geom))
    if len(meshes):
        faces, owner = mesh_leaves(chunk, meshes, symbol, _colors(ctx.plan, meshes))
        append_mesh(ctx, _with_uv(ctx, meshes, owner, faces), meshes, owner)


def polygon_meshes(ctx: Context, shapes: Shapes, symbol: int) -> tuple[MeshChunk, np.ndarray]:
    """Faces of polygon shapes relative to their lots' origins: the polygon, or a prism's bottom, top and
    sides; and the shape each face comes from."""
    chunk = ctx.chunk
    coords, ring_offsets, poly_offsets = chunk.polygons.gather(shapes.geom)
    plane = chunk.polygons.plane[shapes.geom]
    a_axis, b_axis = PLANE_U[plane], PLANE_V[plane]
    rows = np.arange(len(shapes))
    axes = chunk.frames[shapes.frame]
    height = shapes.size[rows, plane]
    vertex_shape = segment_of(ring_offsets)
    vertex_shape = segment_of(poly_offsets)[vertex_shape]
    s = vertex_shape
    base = ((shapes.origin - chunk.lot_origin[shapes.lot])[s]
            + (coords[:, 0] * shapes.size[s, a_axis[s]])[:, None] * axes[s, a_axis[s]]
            + (coords[:, 1] * shapes.size[s, b_axis[s]])[:, None] * axes[s, b_axis[s]])
    lift = height[s, None] * axes[s, plane[s]]
    solid = height > TOL.zero

    faces_v, faces_rings, faces_shape = [], [], []
    # Flat polygons: one face each, as stored. Solids: the bottom reversed, then the top.
    n_rings = np.diff(poly_offsets)
    ring_shape = np.repeat(rows, n_rings)
    ring_counts = np.diff(ring_offsets)
    reversed_base = base[_reversed_order(ring_offsets)]
    for verts, which in ((np.where(solid[s, None], reversed_base, base), rows),
                         (base + lift, np.flatnonzero(solid))):
        keep_ring = np.isin(ring_shape, which)
        keep_vertex = keep_ring[segment_of(ring_offsets)]
        faces_v.append(verts[keep_vertex])
        faces_rings.append(ring_counts[keep_ring])
        faces_shape.append(n_rings[which])
    # Side quads of solids: vertex j, its successor, both lifted.
    side = solid[s]
    nxt = next_in_segment(ring_offsets)
    j = np.flatnonzero(side)
    quads = np.stack([base[j], base[nxt[j]], base[nxt[j]] + lift[j], base[j] + lift[j]], axis=1)
    faces_v.append(quads.reshape(-1, 3))
    faces_rings.append(np.full(len(j), 4, dtype=np.int64))
    faces_shape.append(np.ones(len(j), dtype=np.int64))

    vertices = np.concatenate(faces_v).astype(np.float32)
    ring_sizes = np.concatenate(faces_rings)
    rings_per_face = np.concatenate(faces_shape)
    face_owner = np.concatenate([rows, np.flatnonzero(solid), s[j]])
    return _with_uv(ctx, shapes, face_owner, MeshChunk(
        vertices=vertices,
        ring_offsets=offsets_from_counts(ring_sizes),
        face_offsets=offsets_from_counts(rings_per_face),
        lot=shapes.lot[face_owner].astype(np.int32),
        symbol=np.full(len(face_owner), symbol, dtype=np.int32),
        color=_colors(ctx.plan, shapes, face_owner),
    )), face_owner


def _reversed_order(ring_offsets: np.ndarray) -> np.ndarray:
    """Index that reverses every ring keeping its first vertex: ring [0,1,2,3] -> [0,3,2,1]."""
    index = np.arange(ring_offsets[-1], dtype=np.float64)[:, None]
    return reverse_rings(index, ring_offsets)[:, 0].astype(np.int64)
