"""Grammar text to IR, for both dialects of CGA, with every problem reported as a diagnostic with its span.

- ``parse``: picks the dialect, cuts the text into statements, parses each and names syntax errors for
  people; its table ``DIALECTS`` names each dialect's grammar, splitter, lowering and assembly.
- ``parsers``: the lark parsers, their tables cached in the user's own cache folder.
- ``statements``: the cutting of a file into statements (column 1 in the paper notation, where the next
  declaration begins in CityEngine CGA).
- ``grammars/``: the lark grammars, ``cga2006.lark`` and ``cityengine.lark``, which import the expressions
  both write alike from ``expressions.lark``.
- ``lowering``: what the two lowerings share (spans, sites, expression operators, argument lists, arity
  checks, ``direct`` for an operation whose arguments are its IR node's fields).
- ``cga2006/`` (the paper notation) and ``cityengine/`` (CityEngine CGA), laid out alike: ``nodes`` (the
  dialect's statements before assembly), ``lowering`` (one statement's parse tree to IR), ``operations``
  (the operation handlers and their tables), ``assembly`` (a file's statements into one ``ir.Module``).

A new operation is a line in its dialect's ``OPERATIONS`` (or ``PART_OPERATIONS``, with parts): ``direct(node)``
where its arguments are the node's fields in order, a handler where they need work.
"""
