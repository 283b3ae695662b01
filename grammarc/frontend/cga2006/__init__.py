"""The paper notation of CGA shape (Mueller et al. 2006, and the Puuc paper's additions), lowered to IR:
``nodes`` (its statements), ``lowering`` (one statement's parse tree of ``grammars/cga2006.lark`` to
IR), ``operations`` (the operation handlers and their tables), ``assembly`` (the statements of a file into a
module).
"""

from grammarc.frontend.cga2006.assembly import assemble

__all__ = ["assemble"]
