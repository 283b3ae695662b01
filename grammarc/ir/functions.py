"""CGA's built-in functions: what each takes and gives, for the lowering, the checker and the folder.

One table, ``FUNCTIONS``, names every built-in the frontends accept (CityEngine's reference has a page per
function: it is the specification). A signature lists the parameter types (``None``: any scalar, as
``str(x)`` takes a number, a string or a bool), how many of them may be left out, the result type and
whether the function reads the shape or draws random numbers (then it is evaluated per shape and never
folded to a constant). The backend computes each one in ``backend.functions``, one module per family, as
this table is grouped.

CityEngine's array functions (``ARRAY_FUNCTIONS``) are typed by their arguments (``passes.types``): their
signature gives only the arity and the type of ``size``-like results.
"""

from __future__ import annotations

from dataclasses import dataclass

from grammarc.ir.nodes import Type

T = Type


@dataclass(frozen=True, slots=True)
class Signature:
    #: The type of each parameter; None takes any scalar type.
    params: tuple[Type | None, ...]
    result: Type
    #: Trailing parameters that may be left out.
    optional: int = 0
    #: Reads the shape (its scope, geometry, random key): evaluated per shape, never folded.
    shape: bool = False

    @property
    def least(self) -> int:
        return len(self.params) - self.optional

    def takes(self, count: int) -> bool:
        return self.least <= count <= len(self.params)

    def arity(self) -> str:
        """The number of arguments, for errors: "2", "1 or 2", "1 to 3"."""
        low, high = self.least, len(self.params)
        if low == high:
            return str(low)
        return f"{low} or {high}" if high == low + 1 else f"{low} to {high}"


def _numeric(count: int) -> Signature:
    return Signature((T.NUM,) * count, T.NUM)


FUNCTIONS: dict[str, Signature] = {
    # ------------------------------------------------------------------------------------ math (backend.functions.math)
    **{name: _numeric(1) for name in ("floor", "ceil", "round", "abs", "sqrt", "sin", "cos", "tan", "asin",
                                      "acos", "atan", "exp", "log", "log10")},
    **{name: _numeric(2) for name in ("atan2", "pow", "min", "max")},
    "isnan": Signature((T.NUM,), T.BOOL),
    "rand": Signature((T.NUM, T.NUM), T.NUM, optional=2, shape=True),
    "p": Signature((T.NUM,), T.BOOL, shape=True),
    # ------------------------------------------------------------------------------ strings (backend.functions.strings)
    "str": Signature((None,), T.STR),
    "float": Signature((None,), T.NUM),
    "bool": Signature((None,), T.BOOL),
    "len": Signature((T.STR,), T.NUM),
    "count": Signature((T.STR, T.STR), T.NUM),
    "find": Signature((T.STR, T.STR, T.NUM), T.NUM),
    "substring": Signature((T.STR, T.NUM, T.NUM), T.STR),
    "splitString": Signature((T.STR, T.STR), T.STRS),
    # CityEngine's utility library (ce.lib), built on the four above
    "findLast": Signature((T.STR, T.STR), T.NUM),
    "getPrefix": Signature((T.STR, T.STR), T.STR),
    "getSuffix": Signature((T.STR, T.STR), T.STR),
    "getRange": Signature((T.STR, T.STR, T.STR), T.STR),
    "replace": Signature((T.STR, T.STR, T.STR), T.STR),
    # ------------------------------------------------------------------------ string lists (backend.functions.lists)
    **{name: Signature((T.STR,), T.STR) for name in ("listTerminate", "listClean", "listFirst", "listLast")},
    **{name: Signature((T.STR, T.STR), T.STR) for name in ("listAdd", "listRemove", "listRemoveAll",
                                                           "listRetainAll")},
    "listSize": Signature((T.STR,), T.NUM),
    "listItem": Signature((T.STR, T.NUM), T.STR),
    "listRange": Signature((T.STR, T.NUM, T.NUM), T.STR),
    "listIndex": Signature((T.STR, T.STR), T.NUM),
    "listCount": Signature((T.STR, T.STR), T.NUM),
    "listRandom": Signature((T.STR,), T.STR, shape=True),
    # ---------------------------------------------------------------------------------- files (backend.functions.files)
    "fileRandom": Signature((), T.NUM, shape=True),
    # ---------------------------------------------------------------------------- assets (backend.functions.assets)
    # ---------------------------------------------------------------------------- images (backend.functions.images)
    # ---------------------------------------------------------------------------- tables (backend.functions.tables)
    # ---------------------------------------------------------------------------- colours (backend.functions.colors)
    # ------------------------------------------------------------------------ geometry (backend.functions.geometry)
    "geometry.area": Signature((), T.NUM, shape=True),
    "geometry.volume": Signature((), T.NUM, shape=True),
    "geometry.isRectangular": Signature((T.NUM,), T.BOOL, shape=True),
    "geometry.nVertices": Signature((), T.NUM, shape=True),
    "geometry.nFaces": Signature((), T.NUM, shape=True),
    # ---------------------------------------------------------------------------------- arrays (backend.functions.arrays)
    # their argument types, and some result types, depend on the arguments' (``passes.types``); the type here
    # is that of ``size``, ``nRows``, ``nColumns`` and ``findFirst``
    "size": Signature((None,), T.NUM),
    "nRows": Signature((None,), T.NUM),
    "nColumns": Signature((None,), T.NUM),
    "findFirst": Signature((None, None, None), T.NUM, optional=1),
    "transpose": Signature((None,), T.UNKNOWN),
    "sortIndices": Signature((None,), T.NUMS),
    "sortRowIndices": Signature((None,), T.NUMS),
    "isNull": Signature((None,), T.BOOL),
}
ARRAY_FUNCTIONS = frozenset({"size", "nRows", "nColumns", "findFirst", "transpose", "sortIndices",
                             "sortRowIndices", "isNull"})
