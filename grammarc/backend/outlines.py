"""The outlines of shapes for the operations that work on polygons: each shape's polygon as ragged arrays
(a scope box or rectangle as its implicit rectangle), and the axis a flat shape is flat along.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.chunk import Chunk
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.ragged import segment_of


def polygons_of(chunk: Chunk, shapes: Shapes, corner: np.ndarray | None = None):
    """Each shape's polygon as batch-local ragged arrays (implicit rectangles for scope shapes, starting at
    their ``corner`` (n,) as ``box_rings.corners`` gives it, None for corner 0): coords (V, 2) float64 in
    the plane's units, ring_offsets (R+1,) and shape_offsets (n+1,) int64, and each shape's plane (n,) (the
    scope axis its polygon is flat across)."""
    polygons = chunk.polygons
    n = len(shapes)
    plane = comp_kernels.rect_plane(shapes.size, TOL.zero)
    is_poly = is_polygon(shapes.geom)
    plane[is_poly] = polygons.plane[shapes.geom[is_poly]]
    if not is_poly.any():
        coords = comp_kernels.rect_rings(plane, corner)
        return (coords, np.arange(0, 4 * n + 1, 4, dtype=np.int64), np.arange(n + 1, dtype=np.int64),
                plane)
    # Mixed batch: give scope shapes a stored rectangle so one gather serves all.
    geom = shapes.geom.copy()
    rects = np.flatnonzero(~is_poly)
    if len(rects):
        rect_coords = comp_kernels.rect_rings(plane[rects], None if corner is None else corner[rects])
        geom[rects] = polygons.add(rect_coords, np.arange(0, 4 * len(rects) + 1, 4, dtype=np.int64),
                                   np.arange(len(rects) + 1, dtype=np.int64), plane[rects])
    coords, ring_offsets, shape_offsets = polygons.gather(geom)
    return coords, ring_offsets, shape_offsets, plane


def side_turns(chunk: Chunk, shapes: Shapes, ring_offsets: np.ndarray, shape_offsets: np.ndarray) -> np.ndarray:
    """Where the side faces over the edges of ``polygons_of``'s outlines start their rings (V,) int8
    (``geometry.polygons``' ``turn``): the stored polygons' turns, ``ALONG`` on implicit rectangles."""
    turn = np.zeros(ring_offsets[-1], dtype=np.int8)
    poly = is_polygon(shapes.geom)
    if poly.any():
        turn[poly[segment_of(shape_offsets)[segment_of(ring_offsets)]]] = chunk.polygons.turns(shapes.geom[poly])
    return turn


def flat_axis(chunk: Chunk, shapes: Shapes) -> np.ndarray:
    """The axis each shape is flat along (its face normal) (n,), -1 for solids, edges and assets."""
    flat = shapes.size <= TOL.zero
    axis = np.where(flat.sum(axis=1) == 1, np.argmax(flat, axis=1), -1)
    poly = is_polygon(shapes.geom)
    axis[poly] = np.where(flat[poly].sum(axis=1) >= 1, chunk.polygons.plane[shapes.geom[poly]], -1)
    axis[(shapes.geom < -1) | is_mesh(shapes.geom)] = -1
    return axis
