"""grammarc: a compiler from CGA shape grammars to batched numeric code.

The packages are floors, each importing only from those below it (docs/architecture.md;
tests/test_layout.py checks), from the ground up:

- ``constants``, ``diagnostics``, ``ragged``, ``atomic``, ``errors``: tolerances and limits, diagnostics
  with spans, ragged arrays, files written atomically, the exceptions.
- ``grammarc.ir``: the language's meaning, independent of syntax (nodes, one traversal, passes, printer).
- ``grammarc.model``: the data every layer passes (the checked grammar, lots, record chunks, reports,
  asset meshes).
- ``grammarc.frontend``: grammar text to IR (a lark grammar and a lowering per dialect, every error with
  its span); ``grammarc.geometry``: polygon and mesh kernels on arrays.
- ``grammarc.compiler``: text to the checked grammar; ``grammarc.backend``: the derivation, the IR's
  operations over columns of shapes.
- ``grammarc.io``: lots in, records out (a table of formats each way); ``grammarc.render``: pictures.
- ``grammarc.workers``, ``grammarc.build``, ``grammarc.cluster``, ``grammarc.conform``,
  ``grammarc.commands``, ``grammarc.cli``: the ``grammarc`` command.
"""

__version__ = "0.1.0"
