"""Operations on the outlines of faces: offset, setback and shapeL/U/O, innerRectangle, convexify, roofs,
cleanupGeometry.

``FaceOperations`` is a part of ``Executor`` (``backend.execute``), kept apart because these operations
share one pattern: the batch's faces as shapely polygons in their scopes' units (``face_polygons``),
one vectorized geometry step, then the pieces back as shapes (``pieces_by_parent``, ``run_regions``) or
the face's geometry replaced (meshes, ``backend.mesh_shapes``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely

from grammarc.backend import mesh_shapes
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.random import child_keys
from grammarc.backend.selectors import STREET_ALIASES, classify_faces
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.clip import fit_pieces, scope_polygons
from grammarc.geometry.convexify import convex_parts
from grammarc.geometry.inner_rectangle import largest_rectangles
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.geometry.polygons import plane_to_scope
from grammarc.geometry.setback import polygon_edges, setback_regions
from grammarc.geometry.streets import along_street
from grammarc.ir import nodes as ir
from grammarc.ragged import ragged_take, rank_within


class FaceOperations:
    """The face-outline operations of ``Executor`` (which provides ``env``, ``fail``, ``count``,
    ``flat_axis``, ``polygons_of``, ``run_parts`` and ``chunk``)."""

    def roof(self, op: ir.Roof, cursor: Shapes, symbol: int) -> Shapes:
        """A roof over each face (``backend.roofs``). CityEngine roofs faces; the paper's ``Roof`` roofs
        the footprint of a solid (its polygon, or the scope's x-z rectangle)."""
        env = self.env(cursor)
        n = len(cursor)
        value, overhang, index = (np.ascontiguousarray(np.broadcast_to(
            np.asarray(evaluate_array(e, env), dtype=np.float64), (n,))) for e in (op.value, op.overhang, op.index))
        checks = [
            (cursor.geom < -1, "of an inserted asset"),
            (~np.isfinite(value) | ~np.isfinite(overhang) | ~np.isfinite(index), "with a value that is not finite"),
            (~op.by_height & (np.abs(value) >= 90), "with an angle of 90 degrees or more"),
        ]
        # CityEngine roofs faces. A face that ``s`` gave a size across it stays flat in CityEngine but is a
        # box here: an envelope (candler sizes its ventilation faces so) takes the box's base
        if self.plan.leaf_bodies and op.kind != "envelope":
            checks.append((self.flat_axis(cursor) < 0, "of a solid (CityEngine roofs faces)"))
        cap = None
        if op.cap is not None:
            cap = np.broadcast_to(np.asarray(evaluate_array(op.cap, env), float), (n,))
            for height, angle in op.sides:
                differs = (np.abs(evaluate_array(height, env) - overhang) > TOL.zero) | (
                    np.abs(evaluate_array(angle, env) - value) > TOL.zero)
                why = "with different heights or angles per side (one slope all round is supported)"
                checks.append((differs, why))
        if op.overhang_y is not None:
            overhang_y = evaluate_array(op.overhang_y, env)
            checks.append((np.abs(overhang_y - overhang) > TOL.zero,
                           "with overhangY other than overhangX (gable ends overhang as eaves do)"))
        for bad, what in checks:
            if np.any(bad):
                self.fail(cursor, np.broadcast_to(bad, (n,)), f"`{op.kind}` {what}", symbol, op.span)
        roofed, failed = mesh_shapes.build_roofs(self.chunk, cursor, op.kind, self.polygons_of(cursor), value,
                                                 op.by_height, overhang, index, cap)
        if failed.any():
            self.fail(cursor, failed, f"`{op.kind}` found no roof for this polygon (its straight skeleton "
                      "did not close, or the overhang's outline crosses itself at a sharp corner)", symbol,
                      op.span)
        return roofed

    def face_polygons(self, cursor: Shapes, what: str, symbol: int, span) -> tuple[np.ndarray, np.ndarray]:
        """Shapely polygons (m,) of flat shapes in their scope units, and each one's plane (m,)."""
        bad = (cursor.size <= TOL.zero).sum(axis=1) != 1
        if bad.any():
            self.fail(cursor, bad, f"`{what}` of a solid is not supported yet (only of faces)", symbol, span)
        store = self.chunk.polygons
        geom = cursor.geom.copy()
        rects = np.flatnonzero(geom < 0)
        if len(rects):
            plane = comp_kernels.rect_plane(cursor.size[rects], TOL.zero)
            geom[rects] = store.add(comp_kernels.rect_rings(plane),
                                    np.arange(0, 4 * len(rects) + 1, 4, dtype=np.int64),
                                    np.arange(len(rects) + 1, dtype=np.int64), plane)
        return scope_polygons(store, geom, cursor.size), store.plane[geom]

    def offset_pieces(self, distance: ir.Expr, cursor: Shapes, symbol: int, span):
        """The inside and border pieces of each flat shape's polygon offset by ``distance``."""
        polygons, plane = self.face_polygons(cursor, "offset", symbol, span)
        d = evaluate_array(distance, self.env(cursor))
        inset = shapely.buffer(polygons, d, join_style="mitre", mitre_limit=1e6)
        border = shapely.difference(polygons, inset)
        return fit_pieces(inset, plane, cursor.size, polygons), fit_pieces(border, plane, cursor.size, polygons)

    def piece_shapes(self, cursor: Shapes, pieces, site: int) -> Shapes:
        """Shapes of clipped or offset pieces: the parent's frame, the piece's box and polygon."""
        child = cursor.take(pieces.source)
        geom = np.full(len(pieces.source), -1, dtype=np.int32)
        shaped = np.flatnonzero(~pieces.is_rect)
        if len(shaped):
            rings, poly_offsets = ragged_take(pieces.poly_offsets, shaped)
            vertices, ring_offsets = ragged_take(pieces.ring_offsets, rings)
            geom[shaped] = self.chunk.polygons.add(pieces.coords[vertices], ring_offsets, poly_offsets,
                                                   pieces.plane[shaped])
        origin = child.origin + np.einsum("ni,nij->nj", pieces.low, self.chunk.frames[child.frame])
        index = rank_within(pieces.source)
        return Shapes(origin, pieces.extent, child.frame, geom, child.lot,
                      child_keys(child.key, site, index), child.depth, child.params, child.dynamic)

    def offset(self, op: ir.Offset, cursor: Shapes, symbol: int) -> Shapes:
        """``offset(d, inside|border)``: the shape's face becomes its inset or the ring around it."""
        inside, border = self.offset_pieces(op.distance, cursor, symbol, op.span)
        pieces = inside if op.select == "inside" else border
        several = np.bincount(pieces.source, minlength=len(cursor)) > 1
        if not several.any():
            return self.piece_shapes(cursor, pieces, 0)
        # a face the offset parts into pieces stays one shape: a mesh of the pieces in one fitted scope
        rows = np.flatnonzero(several)
        mine = several[pieces.source]
        single = self.piece_shapes(cursor, pieces.take(~mine), 0)
        grouped = pieces.take(mine)
        grouped = replace(grouped, source=np.searchsorted(rows, grouped.source))
        meshes = mesh_shapes.piece_meshes(self.chunk, cursor.take(rows), grouped)
        meshes = replace(meshes, key=child_keys(meshes.key, 0, np.zeros(len(rows), dtype=np.int64)))
        return Shapes.merge([single, meshes], [pieces.source[~mine], rows])

    def setback(self, op: ir.Setback, cursor: Shapes, symbol: int) -> None:
        """``setback`` and ``shapeL/U/O``: the face's edge strips and its remainder to their parts."""
        polygons, plane = self.face_polygons(cursor, "setback", symbol, op.span)
        edges = polygon_edges(polygons)
        m = len(cursor)
        normal = plane_to_scope(-edges.inward, plane[edges.poly])
        frames = self.selector_frames(normal, cursor, edges.poly, (*op.selectors, *(s for s, _ in op.distances)),
                                      self.world_points(cursor, edges.poly, plane, (edges.start, edges.end)))
        # distances per face, or per edge (setback(comp(fe){...}): each edge is comp.index of comp.total)
        if op.per_edge:
            index = rank_within(edges.poly)
            shapes = self.with_context(cursor.take(edges.poly), "comp", index, edges.poly, m)
            column = np.arange(len(edges.poly))
        else:
            shapes, column = cursor, edges.poly
        env = self.env(shapes)
        table = np.zeros((len(op.distances) + 1, len(shapes)))
        for k, (_, expr) in enumerate(op.distances):
            table[k] = evaluate_array(expr, env)
        distance = table[classify_faces(normal, tuple(s for s, _ in op.distances), frames), column]
        owners = tuple(s for s in op.selectors if s != "remainder")
        regions, remainder = setback_regions(polygons, edges, distance,
                                             classify_faces(normal, owners, frames), len(owners))
        by_owner = dict(zip(owners, regions))
        self.run_regions(op, cursor, [by_owner[s] if s != "remainder" else remainder for s in op.selectors],
                         plane, symbol, polygons)

    def convexify(self, op: ir.Convexify, cursor: Shapes, symbol: int) -> Shapes:
        """``convexify``: the face becomes its convex parts (``geometry.convexify``), one shape whose
        faces they are (a mesh; a convex face stays as it is)."""
        polygons, plane = self.face_polygons(cursor, "convexify", symbol, op.span)
        limit = None
        if op.max_length is not None:
            limit = np.broadcast_to(np.asarray(evaluate_array(op.max_length, self.env(cursor)), float),
                                    (len(cursor),))
        parts, source = convex_parts(polygons, limit)
        return mesh_shapes.flat_meshes(self.chunk, cursor, parts, source, plane)

    def cleanup_geometry(self, op: ir.CleanupGeometry, cursor: Shapes, symbol: int) -> Shapes:
        """``cleanupGeometry``: polygons (faces, prisms through their base, flat rectangles) and meshes
        cleaned (``geometry.cleanup``) in their scopes, which stay: the operation is meant to keep a
        model's look, and the geometry only loses vertices and faces, so it stays inside its scope.
        A tolerance outside [0, 1] is taken as the nearer end. Scope boxes and inserted assets stay as
        they are: a box has no repeated or collinear vertices and no duplicate faces (that its faces
        could be too small or its edges too short to keep is ignored: as a mesh it would leave the
        instancing path), and an asset is an instance whose mesh grammarc does not open."""
        tolerance = np.broadcast_to(np.asarray(evaluate_array(op.tolerance, self.env(cursor)), float),
                                    (len(cursor),))
        bad = ~np.isfinite(tolerance)
        if bad.any():
            self.fail(cursor, bad, "`cleanupGeometry` with a tolerance that is not finite", symbol, op.span)
        tolerance = np.clip(tolerance, 0.0, 1.0)
        flat = (cursor.size <= TOL.zero).sum(axis=1) == 1
        geom = cursor.geom.copy()
        polygon = np.flatnonzero(is_polygon(geom) | ((geom == -1) & flat))
        if len(polygon):
            shapes = cursor.take(polygon)
            geom[polygon] = mesh_shapes.clean_polygons(self.chunk, shapes, self.polygons_of(shapes),
                                                       tolerance[polygon], op.component)
        mesh = np.flatnonzero(is_mesh(cursor.geom))
        if len(mesh):
            geom[mesh] = mesh_shapes.clean_meshes(self.chunk, cursor.take(mesh), tolerance[mesh], op.component)
        return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)

    def inner_rectangle(self, op: ir.InnerRectangle, cursor: Shapes, symbol: int) -> None:
        """``innerRectangle``: the face's largest inner rectangle (``geometry.inner_rectangle``) and the
        rest of the face, in the face's own scope frame (CityEngine keeps the scope's orientation)."""
        polygons, plane = self.face_polygons(cursor, "innerRectangle", symbol, op.span)
        rectangle = largest_rectangles(polygons, op.align)
        remainder = shapely.difference(polygons, rectangle)
        self.run_regions(op, cursor, [rectangle if s == "shape" else remainder for s in op.selectors], plane,
                         symbol, polygons)

    def run_regions(self, op: ir.Setback | ir.InnerRectangle, cursor: Shapes, regions: list, plane, symbol,
                    polygons):
        """Part k of ``op`` on the pieces of ``regions[k]`` (m,) (polygons in the shapes' scope units, cut
        from ``polygons``), each parent's pieces together, numbered in stream ``op.site`` part by part."""
        pieces = [fit_pieces(region, plane, cursor.size, polygons) for region in regions]
        shapes, kind = self.pieces_by_parent(cursor, pieces, [(op.site << 20) + k for k in range(len(pieces))])
        self.count(shapes, symbol, op.span)
        order, offsets = group_by(kind, len(op.parts))
        self.run_parts(op.parts, shapes.take(order), offsets, symbol)

    def pieces_by_parent(self, cursor: Shapes, pieces, sites) -> tuple[Shapes, np.ndarray]:
        """Shapes of several kinds of pieces (kind k: ``pieces[k]``, numbered in stream ``sites[k]``),
        each parent's pieces together in kind order, and each shape's kind."""
        shapes = Shapes.concat([self.piece_shapes(cursor, p, site) for p, site in zip(pieces, sites)])
        kind = np.concatenate([np.full(len(p.source), k, dtype=np.int64) for k, p in enumerate(pieces)])
        order = np.argsort(np.concatenate([p.source for p in pieces]), kind="stable")
        return shapes.take(order), kind[order]

    def selector_frames(self, normal: np.ndarray, cursor: Shapes, parent: np.ndarray, selectors,
                        base: tuple[np.ndarray, np.ndarray] | None = None) -> dict | None:
        """Normals (m, 3) in the world's, the lot's and its street's frames when a selector names them
        (``world.``, ``object.``, ``street.``), and which components lie along a street: their base
        edges ``base`` (start, end: (m, 3) world points), if given, on one of their lot's street edges."""
        if not any("." in s or s in STREET_ALIASES for s in selectors):
            return None
        world = np.einsum("mi,mij->mj", normal, self.chunk.frames[cursor.frame][parent])
        lot = cursor.lot[parent]
        frames = {"world": world, "object": np.einsum("mj,mij->mi", world, self.chunk.lot_axes[lot])}
        streets = self.chunk.streets
        if any(s.startswith("street.") or s in STREET_ALIASES for s in selectors):
            frames["street"] = np.einsum("mj,mij->mi", world, streets.axes[lot])
            frames["street_along"] = (along_street(streets, lot, base[0], base[1], world) if base is not None
                                      else np.zeros(len(lot), dtype=bool))
            frames["street_known"] = np.diff(streets.lot_offsets)[lot] > 0
        return frames

    def world_points(self, cursor: Shapes, row: np.ndarray, plane: np.ndarray, points) -> tuple:
        """In-plane points (k, 2) in the scope units of the shapes ``row`` (k,) of ``cursor``, whose
        polygons lie in ``plane`` (n,), as world points (k, 3)."""
        axes = self.chunk.frames[cursor.frame[row]]
        return tuple(cursor.origin[row] + np.einsum("ki,kij->kj", plane_to_scope(p, plane[row]), axes)
                     for p in points)

    def offset_faces(self, op: ir.CompFaces, cursor: Shapes, symbol: int) -> None:
        """``offset(d) comp(f){ inside: ... | border: ... }``: the offset's faces as components."""
        pieces = self.offset_pieces(op.offset, cursor, symbol, op.span)
        border_site = (op.site << 20) + 1  # another stream than the inside faces'
        shapes, kind = self.pieces_by_parent(cursor, pieces, [op.site, border_site])
        names = ("inside", "border")
        which = np.full(len(kind), len(op.selectors), dtype=np.int64)
        for i in range(len(op.selectors) - 1, -1, -1):
            selector = op.selectors[i]
            which[(selector == "all") | (np.array(names)[kind] == selector)] = i
        keep = which < len(op.selectors)
        shapes, which = shapes.take(keep), which[keep]
        self.count(shapes, symbol, op.span)
        order, offsets = group_by(which, len(op.parts))
        self.run_parts(op.parts, shapes.take(order), offsets, symbol)
