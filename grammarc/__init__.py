"""grammarc: a compiler from CGA shape grammars to batched numeric code.

The packages follow the data flow, in this order:

- ``grammarc.frontend``: grammar text to IR (lark grammar per dialect, lowering, diagnostics with spans).
- ``grammarc.ir``: the language's meaning, independent of syntax (nodes, verification, passes, printer).
- ``grammarc.geometry``: footprints to initial shapes, the ragged polygon store, component splits.
- ``grammarc.backend``: the IR as vectorized operations over columns of shapes, and the derivation.
- ``grammarc.io``: lots in, assets, instance records out.
- ``grammarc.build`` and ``grammarc.cli``: the ``grammarc`` command.
"""

__version__ = "0.1.0"
