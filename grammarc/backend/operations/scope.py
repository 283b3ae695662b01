"""Scope operations: ``T``/``S``/``R`` (``t s r``), CityEngine's ``translate`` and ``rotate`` in a coordinate
system, ``extrude``, ``alignScopeToAxes``/``alignScopeToGeometry``/``rotateScope``, ``mirror``,
``mirrorScope`` and ``setPivot``; and ``center``, which the body runner calls (it centres on the scope the
body began with or last pushed, which only the runner holds).

They change the cursor's scope and return it. Reads: the scope (``origin``, ``size``, ``frame``), ``geom``
(extrude, align, mirror), and what their expressions read. Writes: ``T``, ``translate`` and ``center`` the
``origin``, ``S`` the ``size`` (CityEngine's ``s`` of a negative size the ``origin`` and ``geom`` too),
``R`` and ``rotate`` the ``frame`` (and ``r(scopeCenter, ...)`` the ``origin``, to keep the centre),
``mirror`` the ``geom``; ``extrude``, the alignments, ``mirrorScope`` and ``setPivot`` all four of the scope
and geometry, as they turn scopes around their geometry (``backend.reframing``), and ``setPivot`` the
pivot's columns too (``backend.pivot``).
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import corners
from grammarc.backend.context import Context
from grammarc.backend.euler import orientation, rotation
from grammarc.backend.evaluate import evaluate, evaluate_array
from grammarc.backend.functions.coordinates import system
from grammarc.backend.kernels.scope import centred, translated
from grammarc.backend.mesh_shapes import store_fitted
from grammarc.backend.operations.table import operation
from grammarc.backend.outlines import flat_axis, polygons_of
from grammarc.backend.pivot import corner_axes, pivot_frames, pivot_system, relative_angles, with_pivot
from grammarc.backend.reframing import reframed, turned
from grammarc.backend.shapes import Shapes, asset_geom, asset_of
from grammarc.backend.terminals import marked_inserted
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.align import EDGE_MODES, FACE_MODES, aligned_axes, bbox_turns, pick_edges
from grammarc.geometry.clip import oriented_rings, scope_polygons
from grammarc.geometry.extrusion import extruded_meshes
from grammarc.geometry.meshes import MESH_BASE, face_vertices, is_mesh, is_polygon, ring_vector_areas
from grammarc.geometry.polygons import PLANE_U, PLANE_V, plane_to_scope
from grammarc.geometry.queries import face_shapes, shape_faces
from grammarc.geometry.reframe import NORMAL_UP
from grammarc.ir import nodes as ir
from grammarc.ragged import ragged_take, segment_of, segment_reduce

_SCOPE = ("origin", "size", "frame", "geom")
#: The columns of operations that fit scopes to their geometry again (``backend.reframing``): the scope, and
#: the corner a box's ring starts at (``backend.box_rings``), one of the dynamic columns.
_REFRAMED = (*_SCOPE, "dynamic")


@operation(ir.Translate, writes=("origin",), meshes=True)
def translate(ctx: Context, cursor: Shapes, op: ir.Translate) -> Shapes:
    env = ctx.env(cursor)
    local = np.stack([evaluate_array(e, env) for e in op.vector], axis=1)  # (n, 3) float64, one row a shape
    origin = translated(cursor.origin, local, ctx.chunk.frames.data, cursor.frame)
    return cursor.with_scope(origin, cursor.size, cursor.frame, cursor.geom)


@operation(ir.Scale, writes=("origin", "size", "geom"), meshes=True)
def scale(ctx: Context, cursor: Shapes, op: ir.Scale) -> Shapes:
    """``S``: the scope's new size. CityEngine's ``s`` mirrors the shape along an axis given a negative size,
    its normals inverted, as the reference says (``_inside_out``); the paper's ``S`` fails the shape."""
    env = ctx.env(cursor)
    size = np.empty_like(cursor.size)
    for axis, s in enumerate(op.sizes):
        value = evaluate_array(s.value, env)
        size[:, axis] = value * cursor.size[:, axis] if s.kind is ir.SizeKind.RELATIVE else value
    flips = size < 0
    if op.mirrors and flips.any():
        nan = np.isnan(size).any(axis=1)
        if nan.any():
            ctx.fail_each(cursor, nan, lambda i: f"`s` gives a NaN size ({', '.join(f'{v:g}' for v in size[i])})",
                          op.span)
        return _inside_out(ctx, cursor.with_scope(cursor.origin, np.abs(size), cursor.frame, cursor.geom), flips)
    ctx.fail_negative(cursor, size, "`S` gives a negative or NaN size", op.span)
    return cursor.with_scope(cursor.origin, size, cursor.frame, cursor.geom)


def _inside_out(ctx: Context, shapes: Shapes, flips: np.ndarray) -> Shapes:
    """``shapes`` mirrored along their scope axes ``flips`` (n, 3) bool through their scopes' origins, as
    CityEngine's ``s`` mirrors a shape given a negative size: each flipped axis runs from the origin
    backwards, so the scope's origin moves to that far end and its size stays the absolute value (grammarc's
    scopes have no negative sizes: ``scope.sx`` reads it, where CityEngine's would read the negative size).
    The faces keep their vertex order, so they wind around inward normals: "the normals are inverted", and a
    box's back face is the mirrored box's ``front`` for ``comp(f)``. Such faces are stored as a mesh (the
    polygon store keeps outward faces; a scope box or a polygon becomes its faces); an asset is mirrored as
    ``mirror`` mirrors it; a line or a point keeps its scope box.

    Parameters
    ----------
    shapes : Shapes
        n shapes whose ``size`` (n, 3) is already the absolute value of the sizes given.
    flips : (n, 3) bool
        The axes whose size was negative.
    """
    axes = ctx.chunk.frames[shapes.frame]
    origin = shapes.origin - np.einsum("ni,nij->nj", np.where(flips, shapes.size, 0.0), axes)
    bits = (flips * np.array([1, 2, 4])).sum(axis=1)
    geom = _mirrored_assets(shapes.geom, bits)
    solid = np.flatnonzero((geom >= -1) & (bits > 0))
    faces = shape_faces(shapes.size[solid], geom[solid], ctx.chunk.polygons, ctx.chunk.meshes)
    vertex_shape = faces.vertex_shape()
    size = shapes.size[solid][vertex_shape]
    verts = np.where(flips[solid][vertex_shape], size - faces.verts, faces.verts)
    ids = ctx.chunk.meshes.add(verts / np.where(size > TOL.zero, size, np.inf), faces.ring_offsets,
                               faces.face_offsets, faces.shape_offsets)
    has_faces = np.diff(faces.shape_offsets) > 0
    geom[solid[has_faces]] = (MESH_BASE + ids[has_faces]).astype(np.int32)
    return shapes.with_scope(origin, shapes.size, shapes.frame, geom)


@operation(ir.Rotate, writes=("origin", "frame"), meshes=True)
def rotate(ctx: Context, cursor: Shapes, op: ir.Rotate) -> Shapes:
    """``R`` about the scope's own turning axes, CityEngine's ``r(x, y, z)`` about its axes as they were
    (``op.fixed``), around its origin; ``r(scopeCenter, x, y, z)`` turns the same way and moves the origin
    so that the scope's centre stays where it was.

    Where the grammar keeps pivots (``backend.pivot``), CityEngine's ``r`` is the reference's
    ``rotate(rel, pivot, x, y, z)``: the angles are added to the scope's angles in its pivot's frame, so a
    second ``r`` after a first adds to its angles; a scope aligned with its pivot (the same frame) has
    angles exactly zero, and turns as without pivots."""
    env = ctx.env(cursor)
    angles = [evaluate(e, env) for e in op.angles]
    bad = ~np.logical_and.reduce([np.isfinite(np.broadcast_to(a, (len(cursor),))) for a in angles])
    if bad.any():  # a NaN or infinite angle turns a scope into no frame at all
        ctx.fail(cursor, bad, "a rotation by an angle that is not finite", op.span)
    frames = ctx.chunk.frames
    if op.fixed and ctx.plan.pivot_slot is not None:
        frame = frames.add(_about_pivot(ctx, cursor, angles))
    elif all(np.ndim(a) == 0 for a in angles):
        # One rotation for all: rotate each distinct frame once.
        turn = orientation if op.fixed else rotation
        unique, inverse = np.unique(cursor.frame, return_inverse=True)
        matrix = turn(*(np.full(1, a, dtype=np.float64) for a in angles))[0]
        new = frames.add(np.einsum("ij,fjk->fik", matrix, frames[unique]))
        frame = new[inverse.reshape(-1)]
    else:
        turn = orientation if op.fixed else rotation
        n = len(cursor)
        matrices = turn(*(np.broadcast_to(np.asarray(a, np.float64), (n,)) for a in angles))
        frame = frames.turned(matrices, cursor.frame)[0]  # shapes of one frame turned alike share a row
    origin = cursor.origin
    if op.center:
        half = cursor.size / 2
        origin = origin + np.einsum("ni,nij->nj", half, frames[cursor.frame] - frames[frame])
    return cursor.with_scope(origin, cursor.size, frame, cursor.geom)


def _about_pivot(ctx: Context, cursor: Shapes, angles) -> np.ndarray:
    """The axes (n, 3, 3) of the shapes' scopes with ``angles`` (three scalars or (n,) arrays, degrees) added
    to their angles in their pivots' frames (``backend.pivot``)."""
    n = len(cursor)
    slot = ctx.plan.pivot_slot
    _, pivot_axes = pivot_system(slot, ctx.chunk, cursor)
    added = np.stack([np.broadcast_to(np.asarray(a, np.float64), (n,)) for a in angles], axis=1)
    return _added_angles(ctx, cursor, pivot_axes, cursor.frame == pivot_frames(slot, cursor), added)


def _added_angles(ctx: Context, cursor: Shapes, axes: np.ndarray, aligned: np.ndarray | bool,
                  added: np.ndarray) -> np.ndarray:
    """The axes (n, 3, 3) of the shapes' scopes whose angles in the frames ``axes`` (n, 3, 3) grow by ``added``
    (n, 3) degrees; the scopes ``aligned`` (n,) bool share those frames (their angles are exactly zero)."""
    angles = added + relative_angles(ctx.chunk.frames[cursor.frame], axes, aligned)
    return np.einsum("nij,njk->nik", orientation(*angles.T), axes)


@operation(ir.Transform, writes=("origin", "frame"), meshes=True)
def transform(ctx: Context, cursor: Shapes, op: ir.Transform) -> Shapes:
    """CityEngine ``translate`` and ``rotate`` in a coordinate system (``functions.coordinates.system``;
    the pivot is the shape's, ``backend.pivot``).

    ``translate``: ``rel`` adds the vector along the system's axes, ``abs`` puts the scope origin at the
    position in the system. ``rotate``: the scope's orientation in the system, as the angles ``scope.r``
    reads (about the system's x, then y, then z: ``backend.euler``), becomes the given angles (``abs``) or
    those angles plus the given ones (``rel``, as the reference says: the angles are added); the scope turns
    around its origin. In the scope system the scope's own angles are 0, so ``rel`` and ``abs`` agree there:
    a turn about the scope's axes in that order.

    The reference calls ``r(x, y, z)`` the same as ``rotate(rel, pivot, x, y, z)``, which grammarc's ``r``
    is where the grammar keeps pivots (``rotate`` above).
    """
    env = ctx.env(cursor)
    n = len(cursor)
    values = np.stack([np.broadcast_to(evaluate_array(e, env), (n,)) for e in op.values], axis=1)
    origin, axes = system(op.system, env)
    frames = ctx.chunk.frames
    if op.kind == "translate":
        base = cursor.origin if op.relative else origin  # the scope system's origin is the scope's
        new_origin = base + np.einsum("ni,nij->nj", values, axes)
        return cursor.with_scope(new_origin, cursor.size, cursor.frame, cursor.geom)
    if op.relative and op.system != "scope":
        ids = pivot_frames(ctx.plan.pivot_slot, cursor) if op.system == "pivot" else None
        frame = frames.add(_added_angles(ctx, cursor, axes, False if ids is None else cursor.frame == ids, values))
    else:
        frame = frames.add(np.einsum("nij,njk->nik", orientation(*values.T), axes))
    return cursor.with_scope(cursor.origin, cursor.size, frame, cursor.geom)


def center(ctx: Context, cursor: Shapes, op: ir.Center, base) -> Shapes:
    """Centre the scope on ``base`` (origin, size, frame: the body's first scope or the last push) along
    ``op.axes`` (``kernels.scope.centred``)."""
    base_origin, base_size, base_frame = base
    origin = centred(cursor.origin, cursor.size, cursor.frame, base_origin, base_size, base_frame,
                     ctx.chunk.frames.data, np.asarray(op.axes, dtype=np.int64))
    return cursor.with_scope(origin, cursor.size, cursor.frame, cursor.geom)


@operation(ir.Extrude, writes=_REFRAMED, meshes=True)
def extrude(ctx: Context, cursor: Shapes, op: ir.Extrude) -> Shapes:
    """The solids of ``_extruded``: the shape's own geometry, which its trim planes do not cut even where
    it extrudes an inserted face (CityEngine trims geometry as it is inserted).

    A mesh's solids have up to six vertices for each of its own (each face's bottom and top, a quad per
    edge), so a geometry extruded again and again grows sixfold each time: those vertices count as shapes
    toward --max-shapes, refused before they are made, and such a lot fails as a shape explosion does."""
    mesh = np.flatnonzero(is_mesh(cursor.geom))
    if len(mesh):
        made = 6 * ctx.chunk.meshes.vertex_counts(cursor.geom[mesh] - MESH_BASE)
        ctx.check_fan_out(cursor.take(mesh), made.astype(np.float64), op.span)
        ctx.count_lots(cursor.lot[mesh], op.span, per_row=made)
    return marked_inserted(ctx.plan, _extruded(ctx, cursor, op), False)


def _extruded(ctx: Context, cursor: Shapes, op: ir.Extrude) -> Shapes:
    """A face becomes a solid along its normal; a negative height extrudes behind the face. As in
    CityEngine, the solid's scope keeps x and has y along the extrusion: a face whose normal is
    another scope axis (a comp(f) face's z) is first re-expressed in such a scope.

    ``vertex.normal`` is ``face.normal``: a shape here is one plane, so all its vertex normals are its
    face's. ``world.up`` extrudes a face looking up as its normal would; any other face becomes a mesh
    in a scope with y up and x the old x laid level, each vertex moved straight up, and
    ``world.up.flatTop`` moves them to one level: ``h`` above the lowest vertex, at least up to the
    highest; with a negative ``h`` down from the highest, at least to the lowest.

    A shape of several faces in one plane (an offset's pieces, convexify's parts) becomes a mesh of
    their solids, each face extruded along its own normal (``_extruded_faces``); so does a roof, whose
    faces lie in several planes (``_extruded_roofs``)."""
    height = np.broadcast_to(evaluate_array(op.height, ctx.env(cursor)), (len(cursor),))
    axis = flat_axis(ctx.chunk, cursor)
    mesh = is_mesh(cursor.geom)
    roofs = np.zeros(len(cursor), dtype=bool)
    if mesh.any():  # a flat mesh is extruded across its plane; a roof's faces lie in several planes
        flat = cursor.size <= TOL.zero
        axis[mesh] = np.where(flat[mesh].sum(axis=1) == 1, np.argmax(flat[mesh], axis=1), -1)
        roofs = mesh & (axis < 0)
        if roofs.any() and op.direction != "face.normal":
            ctx.fail(cursor, roofs, f"`extrude` along {op.direction} of a roof is not supported yet (only "
                     "along each face's normal; split the roof into faces with comp(f) first)", op.span)
        elif roofs.any():
            rows, others = np.flatnonzero(roofs), np.flatnonzero(~roofs)
            solids = _extruded_roofs(ctx, cursor.take(rows), height[rows])
            rest = _extruded(ctx, cursor.take(others), op) if len(others) else solids.take([])
            return Shapes.merge([rest, solids], [others, rows])
    bad = (axis < 0) | ~np.isfinite(height)
    if bad.any():
        ctx.fail(cursor, bad, "`extrude` needs a face (a flat shape) and a finite height", op.span)
    if op.direction in ("world.up", "world.up.flatTop"):
        height = np.broadcast_to(height, (len(cursor),))
        normal_y = ctx.chunk.frames[cursor.frame][np.arange(len(cursor)), np.maximum(axis, 0), 1]
        slanted = (normal_y < 1 - TOL.zero) & (axis >= 0)
        if (slanted & mesh).any():
            ctx.fail(cursor, slanted & mesh, "`extrude` along the world's up of faces that are not level and "
                     "not one face is not supported yet", op.span)
        if slanted.any():
            rows, others = np.flatnonzero(slanted), np.flatnonzero(~slanted)
            meshes = _extruded_upwards(ctx, cursor.take(rows), height[rows], op.direction == "world.up")
            level = _extruded_along_normal(ctx, cursor.take(others), height[others], axis[others], op.span)
            return Shapes.merge([level, meshes], [others, rows])
    return _extruded_along_normal(ctx, cursor, height, axis, op.span)


def _extruded_along_normal(ctx: Context, cursor: Shapes, height, axis: np.ndarray, span) -> Shapes:
    cursor = turned(ctx, cursor, axis != 1, NORMAL_UP, axis, span)
    size = cursor.size.copy()
    size[:, 1] = np.abs(height)
    up = ctx.chunk.frames.data[cursor.frame, 1]
    origin = cursor.origin + np.minimum(height, 0.0)[:, None] * up
    extruded = cursor.with_scope(origin, size, cursor.frame, cursor.geom)
    mesh = is_mesh(cursor.geom)
    if not mesh.any():
        return extruded
    rows, others = np.flatnonzero(mesh), np.flatnonzero(~mesh)
    # GEOS joins the faces' outlines, and loops on coordinates near float's limit (s(0, 1, -1e308))
    huge = ~(np.abs(np.column_stack([cursor.size[rows], height[rows]])) <= TOL.coordinate).all(axis=1)
    if huge.any():
        ctx.fail_lots(cursor.lot[rows[huge]], "`extrude` of a face whose size or height is beyond any geometry "
                      f"(over {TOL.coordinate:g} m)", span)
    return Shapes.merge([extruded.take(others), _extruded_faces(ctx, cursor.take(rows), height[rows])],
                        [others, rows])


def _extruded_faces(ctx: Context, cursor: Shapes, height: np.ndarray) -> Shapes:
    """Flat meshes lying across their scopes' y (``turned``) made into meshes of solids: each face
    extruded by ``height`` along its own normal (an offset's pieces all face along the scope's y; one
    that faces the other way goes the other way, as CityEngine extrudes every face along its own
    normal), its bottom and top kept. As in CityEngine no lamina faces are made: the walls stand
    around the outline of each shape's faces together (convexify's parts give the walls of the face
    they were cut from; a straight run of the outline is one wall), facing as the shape's first face
    does. The scope keeps its axes and is fitted
    to the solids."""
    chunk = ctx.chunk
    n = len(cursor)
    verts, ring_offsets, face_offsets, mesh_offsets, _ = face_vertices(chunk.meshes, cursor.geom - MESH_BASE,
                                                                       cursor.size)
    face_mesh = segment_of(mesh_offsets)
    vertex_face = segment_of(face_offsets)[segment_of(ring_offsets)]
    # the sign of each face's normal along y, from its outer ring's vector area
    facing = np.where(ring_vector_areas(verts, ring_offsets)[face_offsets[:-1], 1] < 0, -1.0, 1.0)
    top = verts.copy()
    top[:, 1] += (height[face_mesh] * facing)[vertex_face]
    caps = extruded_meshes(verts, top, ring_offsets, face_offsets, height[face_mesh] >= 0)
    # the outline of each shape's faces, wound around the normal of its first face
    ids, _ = mesh_shapes.flat_mesh_faces(chunk, cursor)
    polygons = scope_polygons(chunk.polygons, ids, cursor.size[face_mesh])
    outline = np.full(n, shapely.Polygon(), dtype=object)
    has_faces = np.diff(mesh_offsets) > 0
    rows = np.flatnonzero(has_faces)
    # the parts joined, without the vertices their joins leave along straight runs of the outline
    outline[rows] = shapely.simplify(shapely.buffer(shapely.multipolygons(polygons, indices=face_mesh)[rows], 0.0),
                                     0.0)
    parts, owner = shapely.get_parts(outline, return_index=True)
    first = np.where(has_faces, facing[np.minimum(mesh_offsets[:-1], len(facing) - 1)], 1.0)
    # oriented_rings winds plane 1's rings around +y, and (x, z) rings of another plane code around -y
    _, uv, outline_rings, outline_faces = oriented_rings(parts, np.where(first[owner] > 0, 1, 2))
    outline_vertex = owner[segment_of(outline_faces)[segment_of(outline_rings)]]
    bottom = plane_to_scope(uv, np.ones(len(uv), dtype=np.int64))
    lifted = bottom.copy()
    lifted[:, 1] += (height * first)[outline_vertex]
    walls = extruded_meshes(bottom, lifted, outline_rings, outline_faces, height[owner] >= 0)
    # each face's bottom and top (the first two faces of its solid), then each outline part's walls
    cap_faces = np.sort(np.r_[caps[3][:-1], caps[3][:-1] + 1])
    wall_faces = np.setdiff1d(np.arange(len(walls[2]) - 1), np.r_[walls[3][:-1], walls[3][:-1] + 1])
    owners = np.r_[face_mesh[segment_of(caps[3])[cap_faces]], owner[segment_of(walls[3])[wall_faces]]]
    merged = _merged_faces(caps, walls, cap_faces, wall_faces, np.argsort(owners, kind="stable"))
    geom, low, size = store_fitted(chunk, *merged, np.r_[0, np.cumsum(np.bincount(owners, minlength=n))])
    origin = cursor.origin + np.einsum("ni,nij->nj", low, chunk.frames[cursor.frame])
    return cursor.with_scope(origin, size, cursor.frame, geom)


def _extruded_roofs(ctx: Context, cursor: Shapes, height: np.ndarray) -> Shapes:
    """Roofs (meshes whose faces lie in several planes) made into meshes of solids: each face extruded
    by ``height`` along its own normal, as CityEngine's default ``face.normal`` extrudes every face of a
    geometry (the bottom face downwards, the roof's planes outwards). Faces that meet at an angle keep
    their own walls, so neighbouring solids overlap or open along the edge they shared. The scope keeps
    its axes and is fitted to the solids."""
    chunk = ctx.chunk
    verts, ring_offsets, face_offsets, mesh_offsets, _ = face_vertices(chunk.meshes, cursor.geom - MESH_BASE,
                                                                       cursor.size)
    face_mesh = segment_of(mesh_offsets)
    vertex_face = segment_of(face_offsets)[segment_of(ring_offsets)]
    normal = ring_vector_areas(verts, ring_offsets)[face_offsets[:-1]]
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    top = verts + (height[face_mesh][:, None] * normal)[vertex_face]
    solid_verts, solid_rings, solid_faces, solid_meshes = extruded_meshes(verts, top, ring_offsets, face_offsets,
                                                                          height[face_mesh] >= 0)
    geom, low, size = store_fitted(chunk, solid_verts, solid_rings, solid_faces, solid_meshes[mesh_offsets])
    origin = cursor.origin + np.einsum("ni,nij->nj", low, chunk.frames[cursor.frame])
    return cursor.with_scope(origin, size, cursor.frame, geom)


def _merged_faces(a, b, faces_a: np.ndarray, faces_b: np.ndarray, order: np.ndarray):
    """Faces ``faces_a`` of mesh arrays ``a`` and ``faces_b`` of ``b`` (each verts, ring_offsets,
    face_offsets, ...) as one ragged mesh, the faces (a's, then b's) taken in ``order``: verts,
    ring_offsets, face_offsets."""
    verts = np.concatenate([a[0], b[0]])
    rings = np.r_[a[1][:-1], b[1] + len(a[0])]
    faces = np.r_[a[2][:-1], b[2] + len(a[1]) - 1]
    picked = np.r_[faces_a, faces_b + len(a[2]) - 1][order]
    picked_rings, face_offsets = ragged_take(faces, picked)
    vertices, ring_offsets = ragged_take(rings, picked_rings)
    return verts[vertices], ring_offsets, face_offsets


def _extruded_upwards(ctx: Context, cursor: Shapes, height: np.ndarray, straight: bool) -> Shapes:
    """Faces that are not level extruded along the world's up axis into meshes in upright scopes:
    every vertex by ``height`` (``straight``) or to one level (flatTop)."""
    chunk = ctx.chunk
    axes = chunk.frames[cursor.frame]
    coords, ring_offsets, shape_offsets, plane = polygons_of(chunk, cursor, corners(ctx.plan, cursor))
    vertex_shape = segment_of(shape_offsets)[segment_of(ring_offsets)]
    rows = np.arange(len(cursor))
    scaled = coords * np.stack([cursor.size[rows, PLANE_U[plane]], cursor.size[rows, PLANE_V[plane]]], 1)[
        vertex_shape]
    in_scope = plane_to_scope(scaled, plane[vertex_shape])
    new_axes = _world_axis(axes, 1)  # y the world's up, x the old x laid level (or the old z)
    # a vertex in the upright scope, from the old origin: its scope point turned into the new axes
    bottom = np.einsum("vi,vij,vkj->vk", in_scope, axes[vertex_shape], new_axes[vertex_shape])
    if straight:
        lift = height[vertex_shape]
    else:
        vertex_offsets = ring_offsets[shape_offsets]
        low = segment_reduce(np.minimum, bottom[:, 1], vertex_offsets, 0.0)
        high = segment_reduce(np.maximum, bottom[:, 1], vertex_offsets, 0.0)
        level = np.where(height >= 0, np.maximum(low + height, high), np.minimum(high + height, low))
        lift = level[vertex_shape] - bottom[:, 1]
    top = bottom.copy()
    top[:, 1] += lift
    normal_y = axes[rows, plane, 1]
    verts, rings, faces, meshes = extruded_meshes(bottom, top, ring_offsets, shape_offsets,
                                                  (normal_y >= 0) == (height >= 0))
    geom, low, size = store_fitted(chunk, verts, rings, faces, meshes)
    origin = cursor.origin + np.einsum("ni,nij->nj", low, new_axes)
    return cursor.with_scope(origin, size, chunk.frames.add(np.ascontiguousarray(new_axes)), geom)


@operation(ir.AlignScope, writes=_REFRAMED, meshes=True)
def align_scope(ctx: Context, cursor: Shapes, op: ir.AlignScope) -> Shapes:
    """New scope axes around unchanged geometry (``backend.reframing``)."""
    frames = ctx.chunk.frames
    n = len(cursor)
    if op.mode == "world":  # one frame for all
        return reframed(ctx, cursor, np.broadcast_to(np.eye(3), (n, 3, 3)), op.span,
                        np.repeat(frames.add(np.eye(3)[None]), n))
    axes = frames[cursor.frame]
    if op.mode == "rotate":  # rotateScope: in xyz order as r, about the pivot's axes where it is kept
        env = ctx.env(cursor)
        angles = [np.broadcast_to(evaluate_array(e, env), (n,)) for e in op.angles]
        new_axes = _about_pivot(ctx, cursor, angles) if ctx.plan.pivot_slot is not None else \
            np.einsum("nij,njk->nik", orientation(*angles), axes)
    else:
        new_axes = _world_axis(axes, "xyz".index(op.mode))
    return reframed(ctx, cursor, new_axes, op.span)


#: Per world axis k of ``alignScopeToAxes(k)``: the scope axis projected onto the plane across it (the
#: reference's "second axis"), and the one projected instead where that one is parallel to axis k.
_SECOND_AXIS = ((2, 1), (0, 2), (0, 1))


def _world_axis(axes: np.ndarray, k: int) -> np.ndarray:
    """Axes (n, 3, 3) with axis k along world axis k and the second axis (``_SECOND_AXIS``) the old one
    projected across it; the third completes a right-handed frame."""
    world = np.eye(3)[k]
    second, fallback = _SECOND_AXIS[k]
    along = axes[:, second] - axes[:, second, k:k + 1] * world
    flat = np.linalg.norm(along, axis=1) < 1e-9
    along[flat] = axes[flat, fallback] - axes[flat, fallback, k:k + 1] * world
    along /= np.linalg.norm(along, axis=1, keepdims=True)
    new_axes = np.empty_like(axes)
    new_axes[:, k] = world
    new_axes[:, second] = along
    third = 3 - k - second
    new_axes[:, third] = np.cross(new_axes[:, (third + 1) % 3], new_axes[:, (third + 2) % 3])
    return new_axes


@operation(ir.AlignToGeometry, writes=_REFRAMED, meshes=True)
def align_to_geometry(ctx: Context, cursor: Shapes, op: ir.AlignToGeometry) -> Shapes:
    """``alignScopeToGeometry``: every shape's faces in world space, a face and an edge picked per shape
    (``geometry.align``), the scope turned to them around the unchanged geometry."""
    chunk = ctx.chunk
    n = len(cursor)
    env = ctx.env(cursor)
    axes = chunk.frames[cursor.frame]
    faces = shape_faces(cursor.size, cursor.geom, chunk.polygons, chunk.meshes, corners(ctx.plan, cursor))
    # world-oriented offsets from each scope's origin: a shape's own shift does not change its choices
    verts = np.einsum("vi,vij->vj", faces.verts, axes[faces.vertex_shape()])
    vector = face_shapes(verts, faces.ring_offsets, faces.face_offsets)[0]
    area = np.linalg.norm(vector, axis=1)

    def index(expr):
        if expr is None:
            return np.zeros(n, np.int64)
        return np.round(np.broadcast_to(evaluate_array(expr, env), (n,))).astype(np.int64)

    face, start, end = pick_edges(verts, faces.ring_offsets, faces.face_offsets, faces.shape_offsets, area,
                                  FACE_MODES[op.face], index(op.face_index), EDGE_MODES[op.edge],
                                  index(op.edge_index))
    found = face >= 0
    normal = np.full((n, 3), np.nan)
    normal[found] = vector[face[found]] / area[face[found], None]
    edge = np.zeros((n, 3))
    edge[found] = verts[end[found]] - verts[start[found]]
    new_axes, ok = aligned_axes(edge, normal, axes, op.up)
    if ok.all():
        return reframed(ctx, cursor, new_axes, op.span)
    # no face with an area, or no edge with a length (a line, a point, a degenerate face): the scope stays,
    # as CityEngine leaves it rather than stopping the model
    rows, others = np.flatnonzero(ok), np.flatnonzero(~ok)
    return Shapes.merge([reframed(ctx, cursor.take(rows), new_axes[rows], op.span), cursor.take(others)],
                        [rows, others])


@operation(ir.AlignScopeToBBox, writes=_REFRAMED, meshes=True)
def align_scope_to_bbox(ctx: Context, cursor: Shapes, op: ir.AlignScopeToBBox) -> Shapes:
    """``alignScopeToGeometryBBox``: each scope turned about its third axis so that the first of ``op.axes``
    runs along the longer side of the smallest rectangle around the geometry's vertices seen along that
    axis (``geometry.align.bbox_turns``), the nearer of its two senses; then fitted to the geometry. A shape
    whose vertices all lie on that axis keeps its scope. The pivot is the scope's origin in CityEngine;
    grammarc applies no pivot."""
    a, b = op.axes
    faces = shape_faces(cursor.size, cursor.geom, ctx.chunk.polygons, ctx.chunk.meshes)
    turn, ok = bbox_turns(faces.verts[:, [a, b]], faces.vertex_shape(), len(cursor))
    axes = ctx.chunk.frames[cursor.frame]
    new_axes = axes.copy()
    new_axes[:, a] = turn[:, :1] * axes[:, a] + turn[:, 1:] * axes[:, b]
    new_axes[:, b] = turn[:, :1] * axes[:, b] - turn[:, 1:] * axes[:, a]
    rows, others = np.flatnonzero(ok), np.flatnonzero(~ok)
    return Shapes.merge([reframed(ctx, cursor.take(rows), new_axes[rows], op.span), cursor.take(others)],
                        [rows, others])


@operation(ir.Mirror, writes=("geom",), meshes=True)
def mirror(ctx: Context, cursor: Shapes, op: ir.Mirror) -> Shapes:
    """Mirror the geometry inside its scope: assets flip (a bit of their geometry code), polygons and
    meshes (roofs) are stored flipped with their rings reversed where an odd number of axes flip (so they
    still wind around their outward normals); a scope box is its own mirror image."""
    env = ctx.env(cursor)
    flips = [np.broadcast_to(evaluate_array(f, env, dtype=bool), (len(cursor),)) for f in op.axes]
    bits = flips[0] * 1 + flips[1] * 2 + flips[2] * 4
    geom = _mirrored_assets(cursor.geom, bits)
    poly = np.flatnonzero(is_polygon(geom) & (bits > 0))
    if len(poly):
        store = ctx.chunk.polygons
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
    mesh = np.flatnonzero(is_mesh(geom) & (bits > 0))
    if len(mesh):
        meshes = ctx.chunk.meshes
        coords, ring_offsets, face_offsets, mesh_offsets = meshes.gather(geom[mesh] - MESH_BASE)
        vertex_mesh = segment_of(mesh_offsets)[segment_of(face_offsets)][segment_of(ring_offsets)]
        # an axis of no extent keeps its coordinate 0
        flip = ((bits[mesh, None] >> np.arange(3)) & 1).astype(bool) & (cursor.size[mesh] > TOL.zero)
        flip = flip[vertex_mesh]
        coords = np.where(flip, 1.0 - coords, coords)
        odd = flip.sum(axis=1) % 2 == 1
        coords = np.where(odd[:, None], comp_kernels.reverse_rings(coords, ring_offsets), coords)
        geom[mesh] = (MESH_BASE + meshes.add(coords, ring_offsets, face_offsets, mesh_offsets)).astype(np.int32)
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)


def _mirrored_assets(geom: np.ndarray, bits: np.ndarray) -> np.ndarray:
    """A copy of the ``geom`` codes (n,) with the inserted assets' mirror bits flipped by ``bits`` (n,) (1: x,
    2: y, 4: z)."""
    geom = geom.copy()
    assets = (geom < -1) & (bits > 0)
    if assets.any():
        asset, mirrored = asset_of(geom[assets])
        geom[assets] = asset_geom(asset, mirrored ^ bits[assets])
    return geom


@operation(ir.MirrorScope, writes=_REFRAMED, meshes=True)
def mirror_scope(ctx: Context, cursor: Shapes, op: ir.MirrorScope) -> Shapes:
    """``mirrorScope``: the flagged axes reversed around the unchanged geometry (``backend.reframing``:
    the box fitted again starts at their far ends). Two reversed axes are a half turn; one or three would
    make a left-handed scope, which grammarc's scopes (rotations, as CityEngine's ``scope.r``) cannot be:
    those shapes' lots fail by name."""
    env = ctx.env(cursor)
    flips = np.stack([np.broadcast_to(evaluate_array(f, env, dtype=bool), (len(cursor),)) for f in op.axes], axis=1)
    odd = flips.sum(axis=1) % 2 == 1
    if odd.any():
        ctx.fail(cursor, odd, "`mirrorScope` of one or three axes is not supported yet: the scope would be "
                 "left-handed (reverse two axes, or mirror the geometry with `mirror`)", op.span)
    if not flips.any():
        return cursor
    new_axes = ctx.chunk.frames[cursor.frame] * np.where(flips, -1.0, 1.0)[:, :, None]
    return reframed(ctx, cursor, new_axes, op.span)


@operation(ir.SetPivot, writes=(*_SCOPE, "dynamic"), meshes=True)
def set_pivot(ctx: Context, cursor: Shapes, op: ir.SetPivot) -> Shapes:
    """``setPivot(axisMap, cornerIndex)``: the pivot moves to the scope's corner ``cornerIndex`` (modulo 8:
    ``backend.pivot.CORNERS``), its axes the scope's as ``axisMap`` renames them, each pointing into the
    scope (``pivot.corner_axes``); the scope becomes the same box in the pivot's axes, from that corner (its
    ``scope.t`` and ``scope.r`` zero), the geometry where it was. A box or rectangle keeps its scope exactly;
    other geometry gets the scope fitted to it in the new axes (``backend.reframing``), which is the same box
    where the geometry fills its scope."""
    n = len(cursor)
    corner = np.floor(np.broadcast_to(evaluate_array(op.corner, ctx.env(cursor)), (n,))).astype(np.int64)
    ends, turn = corner_axes(op.axes, corner)
    frames = ctx.chunk.frames
    axes = frames[cursor.frame]
    new_axes = np.einsum("nij,njk->nik", turn, axes)
    box = cursor.geom == -1
    origin = cursor.origin + np.einsum("ni,nij->nj", ends * cursor.size, axes)
    # a new axis is an old one, reversed or not: its size is that one's
    size = np.abs(np.einsum("nij,nj->ni", turn, cursor.size))
    moved = cursor.with_scope(origin, size, frames.add(np.ascontiguousarray(new_axes)), cursor.geom)
    if not box.all():
        rows, others = np.flatnonzero(~box), np.flatnonzero(box)
        moved = Shapes.merge([moved.take(others), reframed(ctx, cursor.take(rows), new_axes[rows], op.span,
                                                           moved.frame[rows])], [others, rows])
    return with_pivot(ctx.plan.pivot_slot, moved, moved.origin, moved.frame)
