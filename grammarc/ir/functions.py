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


#: The keywords ``convert`` takes for its coordinate, the systems it converts from and to, and what it converts.
CONVERT_SELECTORS = (("x", "y", "z"), ("scope", "pivot", "object", "world"), ("scope", "pivot", "object", "world"),
                     ("pos", "orient"))


FUNCTIONS: dict[str, Signature] = {
    # ------------------------------------------------------------------------------------ math (backend.functions.math)
    **{name: _numeric(1) for name in ("floor", "ceil", "round", "abs", "sqrt", "sin", "cos", "tan", "asin",
                                      "acos", "atan", "exp", "log", "log10")},
    **{name: _numeric(2) for name in ("atan2", "pow", "min", "max")},
    "isnan": Signature((T.NUM,), T.BOOL),
    "isinf": Signature((T.NUM,), T.BOOL),
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
    # a search query (``ir.file_search``) or a path; the choosers draw from the shape's stream
    "fileRandom": Signature((T.STR,), T.STR, shape=True),
    "fileSearch": Signature((T.STR,), T.STR),
    "filesSearch": Signature((T.STR,), T.STRS),
    "fileExists": Signature((T.STR,), T.BOOL),
    **{name: Signature((T.STR,), T.STR) for name in ("fileName", "fileBasename", "fileDirectory", "fileExtension")},
    # ---------------------------------------------------------------------------- assets (backend.functions.assets)
    # a selector (``sx``, ``xz``...) is lowered to its text; the sorting and choosing ones read the scope
    "assetInfo": Signature((T.STR, T.STR), T.NUM),
    "assetNamingInfo": Signature((T.STR, T.STR), T.STR),
    "assetNamingInfos": Signature((T.STR, T.STR), T.STRS),
    "assetsSortSize": Signature((T.STR, T.STR, T.NUM), T.STR, shape=True),
    "assetsSortRatio": Signature((T.STR, T.STR), T.STR, shape=True),
    "assetBestSize": Signature((T.STR, T.STR), T.STR, shape=True),
    "assetApproxSize": Signature((T.STR, T.STR, T.NUM), T.STR, shape=True),
    "assetFitSize": Signature((T.STR, T.STR, T.NUM), T.STR, shape=True),
    "assetBestRatio": Signature((T.STR, T.STR), T.STR, shape=True),
    "assetApproxRatio": Signature((T.STR, T.STR, T.NUM), T.STR, shape=True),
    # ---------------------------------------------------------------------------- images (backend.functions.images)
    "imageInfo": Signature((T.STR, T.STR), T.NUM),
    "imagesSortRatio": Signature((T.STR, T.STR), T.STR, shape=True),
    "imageBestRatio": Signature((T.STR, T.STR), T.STR, shape=True),
    "imageApproxRatio": Signature((T.STR, T.STR, T.NUM), T.STR, shape=True),
    # ---------------------------------------------------------------------------- tables (backend.functions.tables)
    "readTextFile": Signature((T.STR,), T.STR),
    "readStringTable": Signature((T.STR,), T.STRS),
    "readFloatTable": Signature((T.STR,), T.NUMS),
    # ---------------------------------------------------------------------------- colours (backend.functions.colors)
    "colorRamp": Signature((T.STR, T.NUM), T.STR),
    "colorRGBToHex": Signature((T.NUM,) * 3, T.STR),
    "colorRGBOToHex": Signature((T.NUM,) * 4, T.STR),
    "colorHSVToHex": Signature((T.NUM,) * 3, T.STR),
    "colorHSVOToHex": Signature((T.NUM,) * 4, T.STR),
    **{f"colorHexTo{c}": Signature((T.STR,), T.NUM) for c in "RGBOHSV"},
    # ---------------------------------------- coordinates and the initial shape (backend.functions.coordinates)
    # ``convert``'s first four arguments are its selectors as strings (``CONVERT_SELECTORS``): the lowering
    # makes them of CityEngine's keywords, and turns the form on an array into three calls
    "convert": Signature((T.STR,) * 4 + (T.NUM,) * 3, T.NUM, shape=True),
    "initialShape.name": Signature((), T.STR, shape=True),
    "initialShape.startRule": Signature((), T.STR),
    # ------------------------------------------------------------------------ geometry (backend.functions.geometry)
    # a selector argument (``top``, ``world.up``, ``maxSlope``) is its name as a constant string
    "geometry.area": Signature((T.STR,), T.NUM, optional=1, shape=True),
    "geometry.angle": Signature((T.STR,), T.NUM, shape=True),
    "geometry.isOriented": Signature((T.STR,), T.BOOL, shape=True),
    "geometry.isPlanar": Signature((T.NUM,), T.BOOL, shape=True),
    "geometry.isRectangular": Signature((T.NUM,), T.BOOL, shape=True),
    **{f"geometry.{name}": Signature((), T.NUM, shape=True)
       for name in ("volume", "nEdges", "nHoles", "boundaryLength", "height")},
    **{f"geometry.{name}": Signature((), T.BOOL, shape=True)
       for name in ("isConcave", "isClosedSurface", "isInstanced")},
    "geometry.nVertices": Signature((), T.NUM, shape=True),
    "geometry.nFaces": Signature((), T.NUM, shape=True),
    # texture space (backend.functions.texture): the uv set, a constant (0 when left out); du and dv measure
    # in "uvSpace" or "unitSpace" (metres on the surface)
    **{f"geometry.{name}": Signature((T.NUM,), T.NUM, optional=1, shape=True)
       for name in ("uMin", "uMax", "vMin", "vMax")},
    **{f"geometry.{name}": Signature((T.NUM, T.STR), T.NUM, shape=True) for name in ("du", "dv")},
    # ---------------------------------------------------------------------------- miscellaneous (backend.functions.math)
    # `print(x)` gives x (typed as x by ``passes.types``); grammarc prints nothing, as its `print` operation
    "print": Signature((None,), T.UNKNOWN),
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
    "sum": Signature((None,), T.NUM),  # a str for a str[]
    "floatArray": Signature((None,), T.NUMS, optional=1),
    "boolArray": Signature((None,), T.BOOLS, optional=1),
    "stringArray": Signature((None,), T.STRS, optional=1),
}
ARRAY_FUNCTIONS = frozenset({"size", "nRows", "nColumns", "findFirst", "transpose", "sortIndices",
                             "sortRowIndices", "isNull", "sum", "floatArray", "boolArray", "stringArray"})
#: Built-in functions of CityEngine's reference that grammarc does not compute: a call is ``unsupported``,
#: not an unknown name (materials are not kept, shapes are not ranked by `contextCompare`, lots
#: carry no geographic frame, edge attributes or shape-tree keys).
UNSUPPORTED_FUNCTIONS = frozenset({"getMaterial", "getGeoCoord", "getTreeKey", "contextCompare", "sel"})
#: The array conversions and the scalar conversion each applies to every element.
ARRAY_CONVERSIONS = {"floatArray": "float", "boolArray": "bool", "stringArray": "str"}
