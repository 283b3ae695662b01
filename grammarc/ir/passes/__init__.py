"""The passes over a module: each takes a module and the diagnostics and returns a module.

Name resolution (``resolve``), types and arities (``types``), constant folding (``fold``), probabilities
(``probabilities``), the rule graph (``rulegraph``) and asset resolution (``assets``); the order they run
in is ``ir.pipeline``'s.
"""
