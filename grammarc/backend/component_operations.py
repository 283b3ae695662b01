"""The component splits of ``Executor``: the paper's ``Comp`` and CityEngine's ``comp(f|e|v)`` on
boxes, prisms, polygons and meshes, with the face scopes, selectors, context and trim planes they set.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend import mesh_shapes
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.random import child_keys
from grammarc.backend.selectors import classify_edges, classify_faces
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.geometry.reframe import NORMAL_OUT
from grammarc.geometry.trim import side_face_planes
from grammarc.ir import nodes as ir
from grammarc.ragged import rank_within


class ComponentOperations:
    """The component splits of ``Executor`` (which provides ``plan``, ``chunk``, ``env``, ``fail``, ``count``
    and the others' methods)."""

    def comp(self, op: ir.Comp, cursor: Shapes, symbol: int) -> None:
        if comp_kernels.KIND_CODES[op.kind] not in mesh_shapes.MESH_KINDS:
            self.refuse_meshes(op, cursor, symbol)
        index_of = None
        if op.index is not None:
            index_of = evaluate_array(op.index, self.env(cursor))
        shapes, _, index, parent = self.components(comp_kernels.KIND_CODES[op.kind], cursor, op.site, index_of)
        shapes = self.occluding(cursor, shapes, parent, symbol)
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
        shapes = self.occluding(cursor, shapes, parent, symbol)
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
            axes = self.chunk.frames[shapes.frame]
            base = (shapes.origin, shapes.origin + axes[:, 0] * shapes.size[:, :1])  # each face's bottom edge
            which = classify_faces(normal, op.selectors, self.selector_frames(normal, cursor, parent,
                                                                                op.selectors, base))
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
