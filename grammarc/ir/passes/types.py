"""Type and arity checking: every expression has a type, every successor symbol the right arity.

Assumes: names resolved. Guarantees: guards are bool, sizes, angles and probabilities are numbers,
operators get operands of the types they take; each successor ``sym(args)`` of a symbol with rules passes
as many arguments as its rules take parameters, and the rules of one symbol agree on that number.
Parameter types are inferred from the call sites (a parameter never passed a value is a number); the
module comes back with ``param_types`` and typed ``attrs``.
"""

from __future__ import annotations

import functools
from dataclasses import replace

from grammarc.diagnostics import Diagnostics
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_ops

T = ir.Type


def infer_types(module: ir.Module, diags: Diagnostics) -> ir.Module:
    attr_types: dict[str, ir.Type] = {}
    attrs = []
    for attr in module.attrs:
        t = type_of(attr.default, attr_types, (), diags)
        attr_types[attr.name] = t
        attrs.append(replace(attr, type=t))

    arity = _check_arity(module, diags)
    param_types = _infer_param_types(module, attr_types, arity)

    for rule in module.rules:
        check = functools.partial(_check, attrs=attr_types, params=param_types.get(rule.symbol, ()),
                                  diags=diags)
        if rule.guard is not None:
            check(rule.guard, T.BOOL, "a guard")
        for alt in rule.alternatives:
            if alt.prob is not None:
                check(alt.prob, T.NUM, "a probability")
            for op in iter_ops(alt.body):
                _check_op(op, check, param_types, diags)
    return replace(module, attrs=tuple(attrs), param_types=tuple(sorted(param_types.items())))


def _check(expr, want, what, *, attrs, params, diags) -> None:
    _expect(expr, want, what, attrs, params, diags)


def _check_op(op, check, param_types, diags) -> None:
    if isinstance(op, ir.Symbol):
        want = param_types.get(op.name)
        for i, arg in enumerate(op.args):
            expected = want[i] if want is not None and i < len(want) else None
            if expected is not None:
                check(arg, expected, f"argument {i + 1} of `{op.name}`")
    elif isinstance(op, ir.Translate):
        for e in op.vector:
            check(e, T.NUM, "a translation")
    elif isinstance(op, ir.Rotate):
        for e in op.angles:
            check(e, T.NUM, "an angle")
    elif isinstance(op, (ir.Scale, ir.Split)):
        for s in op.sizes:
            check(s.value, T.NUM, "a size")
    elif isinstance(op, ir.Repeat):
        for e in op.sizes:
            check(e, T.NUM, "a size")
    elif isinstance(op, ir.Comp) and op.index is not None:
        check(op.index, T.NUM, "a component index")
    elif isinstance(op, ir.GroupSplit):
        for s in op.sizes:
            check(s.value, T.NUM, "a size")
    elif isinstance(op, ir.Extrude):
        check(op.height, T.NUM, "a height")
    elif isinstance(op, ir.Offset):
        check(op.distance, T.NUM, "an offset distance")
    elif isinstance(op, ir.Convexify) and op.max_length is not None:
        check(op.max_length, T.NUM, "a split line length")
    elif isinstance(op, ir.CleanupGeometry):
        check(op.tolerance, T.NUM, "a cleanup tolerance")
    elif isinstance(op, ir.Roof):
        check(op.value, T.NUM, "a roof height" if op.by_height else "a roof angle")
        for e in (op.overhang, op.overhang_y):
            if e is not None:
                check(e, T.NUM, "an overhang")
        check(op.index, T.NUM, "an edge index")
        if op.cap is not None:
            check(op.cap, T.NUM, "a height")
        for height, angle in op.sides:
            check(height, T.NUM, "a base height")
            check(angle, T.NUM, "an angle")
    elif isinstance(op, ir.SetColor):
        want = T.STR if len(op.values) == 1 else T.NUM
        for v in op.values:
            check(v, want, "a colour" if want is T.STR else "a colour component")
    elif isinstance(op, ir.CompFaces) and op.offset is not None:
        check(op.offset, T.NUM, "an offset distance")
    elif isinstance(op, ir.Setback):
        for _, d in op.distances:
            check(d, T.NUM, "a setback distance")
    elif isinstance(op, ir.Mirror):
        for e in op.axes:
            check(e, T.BOOL, "a mirror flag")
    elif isinstance(op, ir.AlignScope) and op.angles is not None:
        for e in op.angles:
            check(e, T.NUM, "an angle")
    elif isinstance(op, ir.UseAsset) and op.name is not None:
        check(op.name, T.STR, "an asset name")
    elif isinstance(op, ir.Case):
        for cond, _ in op.branches:
            check(cond, T.BOOL, "a case condition")
    elif isinstance(op, ir.Stochastic):
        for chance, _ in op.branches:
            check(chance, T.NUM, "a percentage")
    elif isinstance(op, ir.SetAttr):
        want = ir.SHAPE_ATTRIBUTES.get(op.name) or check.keywords["attrs"].get(op.name)
        if want is not None and want is not T.UNKNOWN:
            check(op.value, want, f"the value of `{op.name}`")


def _check_arity(module: ir.Module, diags: Diagnostics) -> dict[str, int]:
    arity: dict[str, int] = {}
    first: dict[str, ir.Rule] = {}
    for rule in module.rules:
        if rule.symbol not in arity:
            arity[rule.symbol] = len(rule.params)
            first[rule.symbol] = rule
        elif arity[rule.symbol] != len(rule.params):
            diags.error(
                "arity",
                f"rules of `{rule.symbol}` disagree: this one takes {len(rule.params)} parameters, "
                f"the one at line {first[rule.symbol].span.line} takes {arity[rule.symbol]}",
                rule.span,
            )
    for rule in module.rules:
        for alt in rule.alternatives:
            for op in iter_ops(alt.body):
                if not isinstance(op, ir.Symbol):
                    continue
                want = arity.get(op.name)
                if want is None:
                    if op.args:
                        diags.warning("terminal-args", f"`{op.name}` has no rule, so its arguments are "
                                      "not used", op.span)
                elif want != len(op.args):
                    diags.error("arity", f"`{op.name}` takes {want} argument{'s' if want != 1 else ''}, "
                                f"got {len(op.args)}", op.span)
    return arity


def _infer_param_types(module, attr_types, arity) -> dict[str, tuple[ir.Type, ...]]:
    """Fixed point over call sites: a parameter takes the type of the arguments passed to it."""
    types = {sym: [T.UNKNOWN] * n for sym, n in arity.items()}
    for _ in range(len(types) + 2):
        changed = False
        for rule in module.rules:
            ptypes = tuple(types[rule.symbol])
            for alt in rule.alternatives:
                for op in iter_ops(alt.body):
                    if not isinstance(op, ir.Symbol) or op.name not in types:
                        continue
                    slots = types[op.name]
                    for i, arg in enumerate(op.args[: len(slots)]):
                        t = type_of(arg, attr_types, ptypes, Diagnostics())
                        if slots[i] is T.UNKNOWN and t is not T.UNKNOWN:
                            slots[i] = t
                            changed = True
        if not changed:
            break
    return {sym: tuple(T.NUM if t is T.UNKNOWN else t for t in ts) for sym, ts in types.items()}


def _expect(expr, want, what, attr_types, ptypes, diags) -> None:
    got = type_of(expr, attr_types, ptypes, diags)
    if got is not T.UNKNOWN and got is not want:
        diags.error("type", f"{what} must be a {want.value}, got a {got.value}", expr.span)


def type_of(expr: ir.Expr, attrs: dict, params: tuple, diags: Diagnostics) -> ir.Type:
    """The type of ``expr``; operator misuse is reported to ``diags`` and typed UNKNOWN."""
    if isinstance(expr, ir.Num):
        return T.NUM
    if isinstance(expr, ir.Str):
        return T.STR
    if isinstance(expr, ir.Bool):
        return T.BOOL
    if isinstance(expr, ir.ScopeRef):
        return T.NUM
    if isinstance(expr, ir.ContextRef):
        return ir.CONTEXT_FIELDS[expr.name]
    if isinstance(expr, ir.Occlusion):
        if expr.distance is not None:
            _expect(expr.distance, T.NUM, "a distance", attrs, params, diags)
        return T.STR if expr.kind == "occ" else T.BOOL  # inside, overlaps, touches, visible
    if isinstance(expr, ir.AttrRef):
        return attrs.get(expr.name, T.UNKNOWN)
    if isinstance(expr, ir.Param):
        return params[expr.index] if expr.index < len(params) else T.UNKNOWN
    if isinstance(expr, ir.Select):
        _expect(expr.cond, T.BOOL, "a condition", attrs, params, diags)
        then = type_of(expr.then, attrs, params, diags)
        other = type_of(expr.other, attrs, params, diags)
        if T.UNKNOWN not in (then, other) and then is not other:
            diags.error("type", f"the branches give a {then.value} and a {other.value}", expr.span)
            return T.UNKNOWN
        return then if then is not T.UNKNOWN else other
    if isinstance(expr, ir.Call) and expr.func in ir.CONVERSIONS:
        for a in expr.args:
            type_of(a, attrs, params, diags)
        return ir.CONVERSIONS[expr.func]
    if isinstance(expr, ir.Call):
        for a in expr.args:
            _expect(a, T.NUM, f"an argument of `{expr.func}`", attrs, params, diags)
        return ir.FUNCTIONS[expr.func][2]
    if isinstance(expr, ir.Unary):
        want = T.BOOL if expr.op == "!" else T.NUM
        _expect(expr.operand, want, f"the operand of `{expr.op}`", attrs, params, diags)
        return want
    if isinstance(expr, ir.Binary):
        left = type_of(expr.left, attrs, params, diags)
        right = type_of(expr.right, attrs, params, diags)
        if T.UNKNOWN in (left, right):
            return T.BOOL if expr.op in ir.COMPARE_OPS | ir.LOGIC_OPS else T.UNKNOWN
        if expr.op in ir.LOGIC_OPS:
            ok, result = left is T.BOOL and right is T.BOOL, T.BOOL
        elif expr.op in ("==", "!="):
            # the paper compares truth values with numbers (``Shape.visible("Street") == 0``): 1 or 0
            ok, result = left is right or {left, right} == {T.BOOL, T.NUM}, T.BOOL
        elif expr.op in ir.COMPARE_OPS:
            ok, result = left is T.NUM and right is T.NUM, T.BOOL
        elif expr.op == "+" and T.STR in (left, right):
            # CityEngine's string concatenation: "Height." + 3 is "Height.3"
            ok, result = True, T.STR
        else:
            ok, result = left is T.NUM and right is T.NUM, T.NUM
        if not ok:
            diags.error("type", f"`{expr.op}` cannot combine a {left.value} and a {right.value}", expr.span)
            return T.UNKNOWN
        return result
    return T.UNKNOWN
