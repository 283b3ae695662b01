"""The per-shape columns the derivation keeps beside the grammar's own attributes, by name.

``Plan.dynamic`` numbers every per-shape value a grammar needs (``Shapes.dynamic``): the attributes its rules
``set``, the split and component context it reads (``split.index``...), and these, which the derivation adds
for operations that need them. They are named here, below the plan and the modules that decide whether a
grammar needs them (``plan``, ``leaf_parts``, ``occlusion``), so that none of those imports another for a name.
"""

from __future__ import annotations

#: The shape's colour set by ``color()``: 0xRRGGBB as a float, white to begin with.
COLOR_SLOT = "#color"
WHITE_RGB = float(0xFFFFFF)

#: A shape's trim planes: an id (int32) into the chunk's ``TrimPlanes`` (0: none), whose row holds its two
#: vertical planes, (nx, ny, nz, d) each in world coordinates relative to its lot's origin (inserted geometry
#: keeps the side where n . X + d >= 0; NaN: no plane), then, where the grammar turns them on, its horizontal
#: ones. A ``comp(f)`` sets both kinds at once and everything else keeps or drops them together, so one id
#: names them: children share their parent's row instead of copying eight columns or more.
TRIM_PLANES = "trim.planes"
#: ``set(trim.vertical, false)`` turns the planes off for a shape and its successors (1: on, 0: off).
TRIM_SWITCH = "trim.vertical"
#: Whether a shape's geometry was inserted (1: ``i()`` or a ``primitive*()`` made it, or cut it out of what
#: they made; 0: the lot's, or what ``extrude`` made). CityEngine trims geometry as it is inserted, and a
#: shape's own only at ``trim()``, so a leaf box is cut at its trim planes only where it is inserted: an
#: extruded window frame stands whole across a plane where an inserted cube beside it is cut.
TRIM_INSERTED = "trim.inserted"
#: Whether a shape's horizontal trim planes (``geometry.trim.shallow_edge_planes``, in its ``TRIM_PLANES``
#: row where the grammar may turn them on) cut: ``set(trim.horizontal, ...)`` (0: off, CityEngine's
#: default; 1: on).
HORIZONTAL_SWITCH = "trim.horizontal"

#: The ids of a shape's nearest occluding ancestors (NaN: none), nearest first (``backend.occlusion``).
ANCESTORS = tuple(f"occluder.{k}" for k in range(4))

#: Texture set s's projection, as ``setupProjection`` set it up, and its texture coordinates, as ``projectUV``
#: applied it: ids (int32) of affine maps from world coordinates to (u, v) in the chunk's ``TextureMaps``
#: (0: none). A planar projection is affine in space, so one map per shape gives every vertex of its faces
#: its coordinates, and a split or a component split keeps them continuous without touching them.


def uv_slots(uv_set: int) -> tuple[str, str]:
    """The two per-shape columns of texture set ``uv_set``: its projection's map id, its coordinates'."""
    return f"uv{uv_set}.projection", f"uv{uv_set}.coordinates"

#: A shape's pivot (``backend.pivot``): its origin in world coordinates (three float64 columns) and its axes,
#: an id (int32) into the chunk's ``Frames``.
PIVOT_SLOTS = ("pivot.px", "pivot.py", "pivot.pz", "pivot.frame")

#: The corner a scope box's ring starts at (``backend.box_rings``): an index into its implicit rectangle's
#: corners, 0 where the ring starts as that rectangle does. Kept as float64, as the context columns are.
RING_START = "ring.start"
