"""Kernels on polygons and meshes as arrays, for many shapes at once (numpy, numba, shapely).

They know shapes only as ragged arrays in scope units: the stores of a chunk's polygons (``polygons``) and
meshes (``meshes``); lots to initial shapes (``footprint``, ``streets``); the geometry of operations
(``components``, ``clip``, ``sections``, ``setback``, ``inner_rectangle``, ``convexify``, ``cleanup``,
``reframe``, ``skeleton`` and ``roofs``, ``trim``); queries (``measure``, ``occlusion``); and
``triangulation``, which render and the mesh writers share. The derivation (``grammarc.backend``) calls
them; they call nothing above the model.
"""
