"""CityEngine CGA (the CGA reference of Esri CityEngine 2019-2023), lowered to the same IR as the paper
notation: ``nodes`` (its declarations, split parts and pending operations), ``lowering`` (one statement's
parse tree of ``grammars/cityengine.lark`` to IR), ``operations`` (the operation handlers and their tables),
``assembly`` (the statements of a file and the files it imports into a module).
"""

from grammarc.frontend.cityengine.assembly import assemble

__all__ = ["assemble"]
