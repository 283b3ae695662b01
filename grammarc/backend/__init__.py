"""The derivation: a checked grammar and lots in, record chunks out, on whole batches of shapes.

From the top: ``derive`` (a chunk's schedule: stages, rounds, sorted records) applies rules with
``execute`` (guards, stochastic choice, bodies run operation by operation), which looks each operation up
in ``operations`` (one function per IR node type, in modules by family) and runs it in a ``context`` (the
chunk's state and the helpers every operation uses). Below them: ``plan`` (the grammar numbered for the
derivation, with ``slots``: the per-shape columns the derivation adds), ``attributes`` (the lots' attribute
columns), ``shapes`` (a batch as columns), ``chunk`` (a chunk's stores and outputs), ``evaluate``
(expressions on a batch), ``terminals`` (records), ``report_rows``, and the helpers the operations share
(``children``, ``reframing``, ``outlines``, ``selectors``, ``mesh_shapes``, ``occlusion``, ``snaps``,
``leaf_parts``, ``random``, ``kernels``).
"""
