"""Pictures of derived cities, drawn on the CPU: ``grammarc render RECORD -o city.png``.

The modules, in the order the data flows:

- ``camera``: a view (oblique perspective or top) fitted to the city's bounding box, and the sun.
- ``raster``: the numba z-buffer rasterizer, flat Lambert shading, instances drawn by size on screen.
- ``picture``: ``render``, which takes a record's columns, colours and draws them, and writes the PNG
  atomically.

The package knows no file format: the command line reads the record (``io.npz``) and hands it over.
"""

from grammarc.render.picture import render

__all__ = ["render"]
