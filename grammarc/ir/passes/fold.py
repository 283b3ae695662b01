"""Constant folding: operators and pure functions on constant operands become constants.

Assumes: names resolved and types checked. Guarantees: no ``Unary``, ``Binary`` or non-random ``Call``
has only constant operands. Attributes stay references (a lot may override them); ``rand`` stays a call. Arrays are not folded:
CityEngine's array literals, indexing and array functions (``functions.ARRAY_FUNCTIONS``) are evaluated by the
backend, on constants as on anything else.
A constant division by zero is an error at its span.
"""

from __future__ import annotations

import math
import operator

from grammarc.diagnostics import Diagnostics
from grammarc.ir import nodes as ir
from grammarc.ir.functions import FUNCTIONS
from grammarc.ir.traverse import rewrite_module

_ARITH = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv,
          "%": math.fmod}
_COMPARE = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
            "==": operator.eq, "!=": operator.ne}
#: Pure functions that fold (``rand`` does not). ``round`` rounds half away from zero, as CGA does.
PURE = {
    "floor": math.floor, "ceil": math.ceil, "round": lambda x: math.copysign(math.floor(abs(x) + 0.5), x),
    "abs": abs, "sqrt": math.sqrt, "exp": math.exp, "log": math.log,
    "sin": lambda d: math.sin(math.radians(d)), "cos": lambda d: math.cos(math.radians(d)),
    "tan": lambda d: math.tan(math.radians(d)),
    "asin": lambda x: math.degrees(math.asin(x)), "acos": lambda x: math.degrees(math.acos(x)),
    "atan": lambda x: math.degrees(math.atan(x)), "atan2": lambda y, x: math.degrees(math.atan2(y, x)),
    "pow": math.pow, "min": min, "max": max, "log10": math.log10, "isnan": math.isnan, "isinf": math.isinf,
}
_CONSTANT = (ir.Num, ir.Str, ir.Bool)


def fold_constants(module: ir.Module, diags: Diagnostics) -> ir.Module:
    """The module with constants folded: the same object when nothing folds."""
    return rewrite_module(module, _folder(diags))


def _folder(diags: Diagnostics):
    def fold(expr: ir.Expr) -> ir.Expr:
        if isinstance(expr, ir.Unary) and isinstance(expr.operand, _CONSTANT):
            value = expr.operand.value
            if expr.op == "-" and isinstance(expr.operand, ir.Num):
                return ir.Num(-value, expr.span)
            if expr.op == "!" and isinstance(expr.operand, ir.Bool):
                return ir.Bool(not value, expr.span)
        if isinstance(expr, ir.Binary) and isinstance(expr.left, _CONSTANT) \
                and isinstance(expr.right, _CONSTANT):
            a, b = expr.left.value, expr.right.value
            if expr.op in _ARITH and isinstance(a, float) and isinstance(b, float):
                if expr.op in "/%" and b == 0:
                    diags.error("division", "division by zero", expr.span)
                    return expr
                return ir.Num(float(_ARITH[expr.op](a, b)), expr.span)
            if expr.op in _COMPARE and type(a) is type(b):
                return ir.Bool(bool(_COMPARE[expr.op](a, b)), expr.span)
            if expr.op == "&&":
                return ir.Bool(bool(a and b), expr.span)
            if expr.op == "||":
                return ir.Bool(bool(a or b), expr.span)
        if isinstance(expr, ir.Select) and isinstance(expr.cond, ir.Bool):
            return expr.then if expr.cond.value else expr.other
        if isinstance(expr, ir.Call) and expr.func in PURE and FUNCTIONS[expr.func].takes(len(expr.args)) \
                and all(isinstance(a, ir.Num) for a in expr.args):  # a wrong count is the checker's error
            try:
                value = PURE[expr.func](*(a.value for a in expr.args))
                if isinstance(value, bool):
                    return ir.Bool(value, expr.span)
                return ir.Num(float(value), expr.span)
            except (ValueError, OverflowError):
                diags.error("domain", f"`{expr.func}` is undefined for these arguments", expr.span)
        return expr

    return fold
