"""The operations of the derivation, one function each, registered by IR node type in one table.

An operation is an ordinary function ``f(ctx, shapes, node)`` of the derivation context
(``backend.context``), the batch it runs on (the body's cursor) and its IR node; ``@operation(ir.Node, ...)``
beside it registers it in ``OPERATIONS`` with what it declares (``table``): which shape columns it writes,
whether it takes roofs, whether it replaces its shape. The body runner (``backend.execute``) looks each
operation up there. The families, each module stating what its operations read and write of the shape
columns:

- ``scope``: ``T S R``, ``extrude``, the scope alignments, ``mirror``, ``center``;
- ``splits``: ``Subdiv``/``Repeat``, CityEngine's ``split``, ``Snap``;
- ``component_splits``: ``Comp``, ``comp(f|e|v)``;
- ``cuts``: ``Cut``, a footprint divided by a line between two of its edges (the ice-ray grammar);
- ``faces``: ``convexify``, ``cleanupGeometry``, ``deleteHoles``, and what the face operations share;
- ``offsets``: ``offset``, ``footprint``, ``rectify``;
- ``setbacks``: ``setback``, ``setbackToArea``, ``shapeL/U/O``, ``innerRectangle``;
- ``roofing``: the roofs, ``envelope``, ``taper``;
- ``inserts``: ``I``, ``i``, ``label``;
- ``along_uv``: ``insertAlongUV``, an asset laid along texture coordinates as the shape's mesh;
- ``primitives``: CityEngine's ``primitiveCube/Quad/Disk/Cylinder/Sphere/Cone``;
- ``successors``: successor symbols, ``ε``/``NIL`` and operations without effect;
- ``values``: ``set``, ``color``, the opacity, ``report``;
- ``control``: ``case`` and ``p%`` blocks;
- ``scatter``: ``scatter``, point shapes on, in or around the shape;
- ``texture``: ``setupProjection``, ``projectUV`` and the other operations on texture coordinates.
- ``trims``: ``trim()``, the shape's geometry cut by its trim planes;
- ``simplify``: ``reduceGeometry``, polygons with fewer vertices;
- ``reset``: ``resetGeometry``, the lot's initial shape again.

A new operation is its IR node, its lowering and its function here: importing this package registers them.
"""

from grammarc.backend.operations import (  # noqa: F401 - each registers its operations
    along_uv,
    component_splits,
    control,
    cuts,
    faces,
    inserts,
    offsets,
    primitives,
    reset,
    roofing,
    scatter,
    scope,
    setbacks,
    simplify,
    splits,
    successors,
    texture,
    trims,
    values,
)
from grammarc.backend.operations.table import OPERATIONS, Operation, Parts

__all__ = ["OPERATIONS", "Operation", "Parts"]
