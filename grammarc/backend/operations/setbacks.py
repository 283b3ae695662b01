"""Operations that cut a face into parts by its edges: ``setback``, ``setbackPerEdge``, ``setbackToArea``,
CityEngine's ``shapeL/U/O`` (setbacks of chosen edges) and ``innerRectangle``.

The batch's faces as shapely polygons in their scopes' units (``faces.face_polygons``), the regions cut
(``geometry.setback``, ``geometry.inner_rectangle``), then each region's pieces as the shapes of one part
(``Parts``), each parent's pieces together. Reads: the scope (``origin``, ``size``, ``frame``), ``geom``,
``lot`` (street selectors) and what their expressions read.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.backend.children import with_context
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.operations.faces import face_polygons, pieces_by_parent, world_points
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.selectors import classify_faces, selector_frames
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry.clip import fit_pieces
from grammarc.geometry.inner_rectangle import largest_rectangles
from grammarc.geometry.polygon_edges import polygon_edges
from grammarc.geometry.polygons import plane_to_scope
from grammarc.geometry.setback import distances_to_area, setback_regions
from grammarc.ir import nodes as ir
from grammarc.ragged import rank_within


@operation(ir.Setback, consumes=True)
def setback(ctx: Context, cursor: Shapes, op: ir.Setback) -> Parts:
    """``setback`` and ``shapeL/U/O``: the face's edge strips and its remainder to their parts."""
    face = _SetbackFaces(ctx, cursor, op, "setback", (*op.selectors, *(s for s, _ in op.distances)))
    distance = face.distances(ctx, cursor, op.distances, op.per_edge, 0.0)
    # an outline moved out beyond any coordinate (``Tol.far``) makes no record, and beyond float64's GEOS
    # raises; a NaN distance stays what it was: no setback, as PRT takes massing's (``setbackToArea``'s
    # maximums may be inf: it checks none)
    far = np.flatnonzero(distance > TOL.far)
    if len(far):
        ctx.fail_quoting(cursor.lot[face.edges.poly[far]],
                         lambda k: f"`setback` by {distance[far[k]]:g}, beyond any coordinate", op.span)
    return face.parts(ctx, cursor, op, distance)


@operation(ir.SetbackToArea, consumes=True)
def setback_to_area(ctx: Context, cursor: Shapes, op: ir.SetbackToArea) -> Parts:
    """``setbackToArea``: the setback of the selected edges whose remainder has the area asked
    (``geometry.setback.distances_to_area``), its strips and remainder to the parts as ``setback``'s."""
    names = (*op.selectors, *(s for s, _ in op.minimum), *(s for s, _ in op.maximum))
    face = _SetbackFaces(ctx, cursor, op, "setbackToArea", names)
    area = np.broadcast_to(np.asarray(evaluate_array(op.area, ctx.env(cursor)), float), (len(cursor),))
    bad = ~(area > 0) | ~np.isfinite(area)
    if bad.any():
        ctx.fail(cursor, bad, "`setbackToArea` with an area that is not a positive number", op.span)
    minimum = face.distances(ctx, cursor, op.minimum, True, 0.0)
    maximum = face.distances(ctx, cursor, op.maximum, True, np.inf)
    moving = face.owner < len(face.owners)
    distance = distances_to_area(face.polygons, face.edges, np.where(moving, minimum, 0.0), maximum, moving,
                                 area)
    return face.parts(ctx, cursor, op, distance)


class _SetbackFaces:
    """What ``setback`` and ``setbackToArea`` find of a batch of faces: their polygons and planes, their
    edges (``geometry.polygon_edges.Edges``) with their normals and the frames of the selectors ``names``, and
    the part (``owners``) each edge's strip goes to (``owner``, len(owners) for none)."""

    def __init__(self, ctx: Context, cursor: Shapes, op: ir.Setback | ir.SetbackToArea, what: str,
                 names: tuple[str, ...]):
        self.polygons, self.plane = face_polygons(ctx, cursor, what, op.span)
        self.edges = edges = polygon_edges(self.polygons)
        self.normal = plane_to_scope(-edges.inward, self.plane[edges.poly])
        self.frames = selector_frames(ctx.chunk, self.normal, cursor, edges.poly, names,
                                      world_points(ctx, cursor, edges.poly, self.plane, (edges.start, edges.end)))
        self.owners = tuple(s for s in op.selectors if s != "remainder")
        # only the outline's edges move: PRT sets back no hole edge of a courtyard, whatever the selectors
        # or the per-edge distances (measured through PyPRT on massing's shapeL/U on holed faces and
        # tiers on holed footprints), and its strips stop at the holes
        self.owner = np.where(edges.hole, len(self.owners), classify_faces(self.normal, self.owners, self.frames))

    def distances(self, ctx: Context, cursor: Shapes, distances, per_edge: bool, fill: float) -> np.ndarray:
        """(E,) each edge's distance: that of the first selector of ``distances`` (pairs of a selector and
        an expression) it matches, ``fill`` where none does; the expressions evaluated per face, or per
        edge (``comp.index`` of ``comp.total`` in the face's edges)."""
        poly = self.edges.poly
        if per_edge:
            shapes = with_context(ctx.plan, cursor.take(poly), "comp", rank_within(poly), poly, len(cursor))
            column = np.arange(len(poly))
        else:
            shapes, column = cursor, poly
        env = ctx.env(shapes)
        table = np.full((len(distances) + 1, len(shapes)), fill)
        for k, (_, expr) in enumerate(distances):
            table[k] = evaluate_array(expr, env)
        return table[classify_faces(self.normal, tuple(s for s, _ in distances), self.frames), column]

    def parts(self, ctx: Context, cursor: Shapes, op, distance: np.ndarray) -> Parts:
        """The parts of ``op`` on the strips of the edges moved by ``distance`` (E,) and the remainder."""
        regions, remainder = setback_regions(self.polygons, self.edges, distance, self.owner, len(self.owners))
        by_owner = dict(zip(self.owners, regions))
        # a region of strips starts at the first edge it sets back, as PRT's shapeL and shapeU
        vertices = len(shapely.get_coordinates(self.polygons)) - len(shapely.get_rings(self.polygons))
        moved = (distance > 0) & np.isfinite(distance)
        starts = {}
        for k, owner in enumerate(self.owners):
            starts[owner] = np.zeros(vertices, dtype=bool)
            starts[owner][self.edges.vertex[moved & (self.owner == k)]] = True
        # the remainder's edges come from the parent edges moved by their distances (of two parallel edges,
        # not the nearer one: a jog's far side's moved line beside the near side's, PRT's tier on
        # massing.tartu.8); an edge of no length keeps none known
        moves = np.full(vertices, np.nan)
        moves[self.edges.vertex] = np.where(moved & (self.owner < len(self.owners)), distance, 0.0)
        return _regions(ctx, op, cursor, [by_owner[s] if s != "remainder" else remainder for s in op.selectors],
                        self.plane, self.polygons, [starts.get(s) for s in op.selectors],
                        [moves if s == "remainder" else None for s in op.selectors])


@operation(ir.InnerRectangle, consumes=True)
def inner_rectangle(ctx: Context, cursor: Shapes, op: ir.InnerRectangle) -> Parts:
    """``innerRectangle``: the face's largest inner rectangle (``geometry.inner_rectangle``) and the
    rest of the face, in the face's own scope frame (CityEngine keeps the scope's orientation)."""
    polygons, plane = face_polygons(ctx, cursor, "innerRectangle", op.span)
    rectangle = largest_rectangles(polygons, op.align)
    remainder = shapely.difference(polygons, rectangle)
    return _regions(ctx, op, cursor, [rectangle if s == "shape" else remainder for s in op.selectors], plane,
                    polygons)



def _regions(ctx: Context, op: ir.Setback | ir.SetbackToArea | ir.InnerRectangle, cursor: Shapes, regions: list, plane,
             polygons, start_edges: list | None = None, moves: list | None = None) -> Parts:
    """Part k of ``op`` on the pieces of ``regions[k]`` (n,) (polygons in the shapes' scope units, cut
    from ``polygons``), each parent's pieces together, numbered in stream ``op.site`` part by part;
    ``start_edges[k]``: the parent edges its pieces start at, ``moves[k]`` how far each parent edge moved
    (``fit_pieces``), or None."""
    starts = start_edges or [None] * len(regions)
    distances = moves or [None] * len(regions)
    pieces = [fit_pieces(region, plane, cursor.size, polygons, start_edges=edges, moves=moved)
              for region, edges, moved in zip(regions, starts, distances)]
    shapes, kind = pieces_by_parent(ctx, cursor, pieces, [(op.site << 20) + k for k in range(len(pieces))])
    ctx.count(shapes, op.span)
    order, offsets = group_by(kind, len(op.parts))
    return Parts(op.parts, shapes.take(order), offsets)
