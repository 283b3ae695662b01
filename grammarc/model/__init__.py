"""The data model: the types every layer passes around, and nothing that computes them.

The checked grammar (``grammar``), and the lots, records and assets that readers, the derivation and the
writers hand to each other: they import these types from here, not from one another. A grammar holds
its checked IR module, so the model sits on ``grammarc.ir.nodes`` and on nothing that reads, derives or
writes.
"""
