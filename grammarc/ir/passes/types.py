"""Type and arity checking: every expression has a type, every successor symbol the right arity.

Assumes: names resolved. Guarantees: guards are bool, sizes, angles and probabilities are numbers,
operators get operands of the types they take; each successor ``sym(args)`` of a symbol with rules passes
as many arguments as its rules take parameters, and the rules of one symbol agree on that number.
Parameter types are inferred from the call sites, else from their uses (a parameter neither passed a
value nor used as a typed value is a number); the module comes back with ``param_types`` and typed
``attrs``.

CityEngine's arrays (``num[]``, ``bool[]``, ``str[]``) are values of attributes, constants and
expressions; an operation takes none, and an array passed to a rule's parameter or reported is an
``unsupported`` error at its span (the derivation carries no array per shape from rule to rule).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import replace

from grammarc.diagnostics import Diagnostics
from grammarc.ir import nodes as ir
from grammarc.ir.functions import ARRAY_FUNCTIONS, FUNCTIONS
from grammarc.ir.traverse import all_exprs, expr_fields, field_exprs, iter_exprs, iter_nodes, iter_ops

T = ir.Type


#: The operations whose backend takes an array where their node declares one.
TAKE_ARRAYS = (ir.SetMaterial,)


def infer_types(module: ir.Module, diags: Diagnostics) -> ir.Module:
    attr_types: dict[str, ir.Type] = {}
    attrs = []
    for attr in module.attrs:
        t = type_of(attr.default, attr_types, (), diags)
        for expr in iter_exprs(attr.default):
            if isinstance(expr, (ir.Choose, ir.Aggregate)):
                diags.error("choose" if isinstance(expr, ir.Choose) else "aggregate",
                            f"`{'choose' if isinstance(expr, ir.Choose) else expr.func}` in the default of "
                            f"`{attr.name}`: a lot's attribute is neither a design's choice nor its value; "
                            "write it in a rule", expr.span)
        attr_types[attr.name] = t
        attrs.append(replace(attr, type=t))

    arity = _check_arity(module, diags)
    param_types = _infer_param_types(module, attr_types, arity)

    for rule in module.rules:
        params = param_types.get(rule.symbol, ())
        for node in iter_nodes(rule):
            for expr, want, what in _wanted(node, attr_types, param_types):
                if want is not None:
                    got = _expect(expr, want, what, attr_types, params, diags)
                else:  # any type (its operands checked); an array where the backend takes a value is refused
                    got = type_of(expr, attr_types, params, diags)
                if got.is_array and (want is None or want.is_array) and type(node) not in TAKE_ARRAYS:
                    diags.error("unsupported", f"unsupported: an array as {what}", expr.span)
        _check_search_exprs(all_exprs(rule), design=False, diags=diags)
    for objective in module.objectives:
        _expect(objective.expr, ir.OBJECTIVES[objective.kind], f"the {objective.kind}", attr_types, (), diags)
        _check_search_exprs(iter_exprs(objective.expr), design=objective.kind != "cost", diags=diags)
    return replace(module, attrs=tuple(attrs), param_types=tuple(sorted(param_types.items())))


def _check_search_exprs(exprs, *, design: bool, diags: Diagnostics) -> None:
    """Aggregates are values of a whole design: only ``goal:``, ``heuristic:`` and ``prune:`` read them, and
    not inside one another; ``choose`` makes consequents of a rule, never of a search statement."""
    for expr in exprs:
        if isinstance(expr, ir.Aggregate) and not design:
            diags.error("aggregate", f"`{expr.func}` of \"{expr.symbol}\" is a value of a whole design: only "
                        "`goal:`, `heuristic:` and `prune:` read it", expr.span)
        elif isinstance(expr, ir.Aggregate) and expr.value is not None and any(
                isinstance(e, ir.Aggregate) for e in iter_exprs(expr.value)):
            diags.error("aggregate", f"an aggregate inside `{expr.func}`: it reads one shape's values", expr.span)
        elif isinstance(expr, ir.Choose) and design:
            diags.error("choose", "`choose` makes the consequents of a rule, not of a search statement", expr.span)


def _wanted(node, attr_types, param_types) -> Iterator[tuple[ir.Expr, ir.Type | None, str]]:
    """(expression, the type it must have or None, its noun) for each expression of a rule, alternative or
    operation, as its class declares them (``nodes.child``), but for two whose type comes from the rest
    of the module, not from the node: a successor's arguments take the parameter types of its symbol's
    rules (inferred from every call site), ``set``'s value the type of its attribute. A child without a
    wanted type is not checked (``report`` takes any key and value)."""
    if type(node) is ir.Symbol:
        want = param_types.get(node.name, ())
        for i, (arg, t) in enumerate(zip(node.args, want)):
            yield arg, t, f"argument {i + 1} of `{node.name}`"
    elif type(node) is ir.SetAttr:
        want = ir.SHAPE_ATTRIBUTES.get(node.name) or attr_types.get(node.name)
        yield node.value, None if want is T.UNKNOWN else want, f"the value of `{node.name}`"
    else:
        yield from _declared(node)


def _declared(node) -> list[tuple[ir.Expr, ir.Type | None, str]]:
    """(expression, its wanted type or None, its noun) for each expression ``node`` holds directly."""
    found = []
    for name, spec in expr_fields(type(node)):
        exprs = field_exprs(getattr(node, name), spec.holds)
        if exprs:
            what = spec.what_of(node)
            nouns = itertools.cycle(what) if isinstance(what, tuple) else itertools.repeat(what)
            found.extend(zip(exprs, itertools.repeat(spec.want_of(node)), nouns))
    return found


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
    for op in iter_ops(module):
        if not isinstance(op, ir.Symbol) or op.leaf:  # a leaf `X.` applies no rule of X
            continue
        want = arity.get(op.name)
        if want is None:
            if op.args:
                diags.warning("terminal-args", f"`{op.name}` has no rule, so its arguments are not used",
                              op.span)
        elif want != len(op.args):
            diags.error("arity", f"`{op.name}` takes {want} argument{'s' if want != 1 else ''}, "
                        f"got {len(op.args)}", op.span)
    return arity


def _infer_param_types(module, attr_types, arity) -> dict[str, tuple[ir.Type, ...]]:
    """Fixed point over call sites: a parameter takes the type of the arguments passed to it."""
    types = {sym: [T.UNKNOWN] * n for sym, n in arity.items()}
    calls = [(rule.symbol, [op for op in iter_ops(rule) if isinstance(op, ir.Symbol) and op.name in types])
             for rule in module.rules]
    for _ in range(len(types) + 2):
        changed = False
        for symbol, successors in calls:
            ptypes = tuple(types[symbol])
            for op in successors:
                slots = types[op.name]
                for i, arg in enumerate(op.args[: len(slots)]):
                    t = type_of(arg, attr_types, ptypes, Diagnostics())
                    if slots[i] is T.UNKNOWN and t is not T.UNKNOWN:
                        slots[i] = t
                        changed = True
        if not changed:
            break
    for rule in module.rules:
        if T.UNKNOWN in types.get(rule.symbol, ()):
            _infer_from_uses(rule, types[rule.symbol], attr_types)
    _infer_from_successors(calls, types)
    return {sym: tuple(T.NUM if t is T.UNKNOWN else t for t in ts) for sym, ts in types.items()}


def _infer_from_successors(calls, types) -> None:
    """A parameter still untyped that its rule passes on to a successor takes the type of the parameter it
    is passed to: a start rule's parameters, which no call gives values, handing them down
    (``Stairway(colour) --> Level(colour)`` where ``Level`` uses its ``colour`` as a string)."""
    changed = True
    while changed:  # each round types at least one more parameter, or ends
        changed = False
        for symbol, successors in calls:
            slots = types[symbol]
            for op in successors:
                for arg, t in zip(op.args, types[op.name]):
                    if isinstance(arg, ir.Param) and arg.index < len(slots) and slots[arg.index] is T.UNKNOWN \
                            and t is not T.UNKNOWN:
                        slots[arg.index] = t
                        changed = True


def _infer_from_uses(rule: ir.Rule, slots: list, attr_types) -> None:
    """A parameter that no call passes a value to (a library's rule, called from the files that import
    it) takes its type from its rule's uses: given where a type is wanted (``i(name)``, ``s(n, 1, 1)``,
    ``texture(name)``, ``set(attribute, value)``),
    an operand of ``&&`` or ``||``, of ``-``, ``*``, ``/`` or ``%``, else compared with a typed value
    (``type == "nailed"``). Comparisons come last: CityEngine compares a number with a string too
    (``mix != ""``), so a parameter used as a number elsewhere stays a number."""
    def settle(expr, want):
        if isinstance(expr, ir.Param) and expr.index < len(slots) and slots[expr.index] is T.UNKNOWN \
                and want not in (None, T.UNKNOWN):
            slots[expr.index] = want

    for node in iter_nodes(rule):
        for expr, want, _ in _wanted(node, attr_types, {}):
            settle(expr, want)
    compared = []
    for expr in all_exprs(rule):
        if isinstance(expr, ir.Binary) and expr.op in ir.LOGIC_OPS | _ARITHMETIC:
            settle(expr.left, T.BOOL if expr.op in ir.LOGIC_OPS else T.NUM)
            settle(expr.right, T.BOOL if expr.op in ir.LOGIC_OPS else T.NUM)
        elif isinstance(expr, ir.Binary) and expr.op in ir.COMPARE_OPS:
            compared.append(expr)
        elif isinstance(expr, ir.Call) and expr.func not in ARRAY_FUNCTIONS:
            for this, want in zip(expr.args, FUNCTIONS[expr.func].params):
                settle(this, want)
        else:
            for this, want, _ in _declared(expr):
                settle(this, want)
    for expr in compared:
        for this, other in ((expr.left, expr.right), (expr.right, expr.left)):
            settle(this, type_of(other, attr_types, tuple(slots), Diagnostics()))


#: The operators that take numbers only (``+`` writes strings too).
_ARITHMETIC = frozenset({"-", "*", "/", "%"})


def _expect(expr, want, what, attr_types, ptypes, diags) -> ir.Type:
    got = type_of(expr, attr_types, ptypes, diags)
    if got is not T.UNKNOWN and got is not want:
        diags.error("type", f"{what} must be a {want.value}, got a {got.value}", expr.span)
    return got


def type_of(expr: ir.Expr, attrs: dict, params: tuple, diags: Diagnostics) -> ir.Type:
    """The type of ``expr``; operator misuse is reported to ``diags`` and typed UNKNOWN.

    The children of an expression are checked against their declared types (an operand of ``!`` is a
    bool...) and typed; the expression's own type comes from those of its children where it depends on
    them (``_RESULTS``)."""
    cls = type(expr)
    leaf = _LEAVES.get(cls)
    if leaf is not None:
        return leaf(expr, attrs, params)
    got = [type_of(e, attrs, params, diags) if want is None else _expect(e, want, what, attrs, params, diags)
           for e, want, what in _declared(expr)]
    result = _RESULTS.get(cls)
    return T.UNKNOWN if result is None else result(expr, got, diags)


#: The types of expressions without children.
_LEAVES = {
    ir.Num: lambda e, attrs, params: T.NUM,
    ir.Str: lambda e, attrs, params: T.STR,
    ir.Bool: lambda e, attrs, params: T.BOOL,
    ir.ScopeRef: lambda e, attrs, params: T.NUM,
    ir.ContextRef: lambda e, attrs, params: ir.CONTEXT_FIELDS[e.name],
    ir.AttrRef: lambda e, attrs, params: attrs.get(e.name, T.UNKNOWN),
    ir.Param: lambda e, attrs, params: params[e.index] if e.index < len(params) else T.UNKNOWN,
}


def _same(expr, got: list[ir.Type], diags: Diagnostics, what: str) -> ir.Type:
    """The one type of values that must have one (``choose``'s options)."""
    known = [t for t in got if t is not T.UNKNOWN]
    if any(t is not known[0] for t in known):
        diags.error("type", f"{what} give a {known[0].value} and a "
                    f"{next(t for t in known if t is not known[0]).value}", expr.span)
        return T.UNKNOWN
    return known[0] if known else T.UNKNOWN


def _select(expr: ir.Select, got: list[ir.Type], diags: Diagnostics) -> ir.Type:
    _, then, other = got
    if T.UNKNOWN not in (then, other) and then is not other:
        diags.error("type", f"the branches give a {then.value} and a {other.value}", expr.span)
        return T.UNKNOWN
    return then if then is not T.UNKNOWN else other


def _binary(expr: ir.Binary, got: list[ir.Type], diags: Diagnostics) -> ir.Type:
    left, right = got
    if T.UNKNOWN in (left, right):
        return T.BOOL if expr.op in ir.COMPARE_OPS | ir.LOGIC_OPS else T.UNKNOWN
    if expr.op.startswith("."):
        return _elementwise(expr, left, right, diags)
    if left.is_array or right.is_array:
        # CityEngine compares whole arrays with `==` and `!=`; its other operators on arrays are dotted
        if expr.op in ("==", "!=") and left is right:
            return T.BOOL
        if expr.op in ir.COMPARE_OPS and left is right or expr.op == "+" and T.STR in (left, right):
            # CityEngine orders whole arrays and writes them into strings; grammarc does not (yet)
            what = "the order of whole arrays" if expr.op != "+" else "an array written into a string"
            diags.error("unsupported", f"unsupported: {what} (`{expr.op}`)", expr.span)
            return T.UNKNOWN
        diags.error("type", f"`{expr.op}` cannot combine a {left.value} and a {right.value}", expr.span)
        return T.UNKNOWN
    if expr.op in ir.LOGIC_OPS:
        ok, result = left is T.BOOL and right is T.BOOL, T.BOOL
    elif expr.op in ("==", "!="):
        # any two values: the paper compares truth values with numbers (``Shape.visible("Street") == 0``: 1
        # or 0); a string and a number or a truth value compare as strings, the other written as ``str``
        # writes it (``mix != ""``; ``"1" == 1``), as ``+`` writes it into a string
        ok, result = True, T.BOOL
    elif expr.op in ir.COMPARE_OPS:
        # numbers by value, strings in the order of their text (CityEngine's relational operators)
        ok, result = left is right and left in (T.NUM, T.STR), T.BOOL
    elif expr.op == "+" and T.STR in (left, right):
        # CityEngine's string concatenation: "Height." + 3 is "Height.3", true + "x" is "truex"
        ok, result = True, T.STR
    else:
        ok, result = left is T.NUM and right is T.NUM, T.NUM
    if not ok:
        diags.error("type", f"`{expr.op}` cannot combine a {left.value} and a {right.value}", expr.span)
        return T.UNKNOWN
    return result


def _elementwise(expr: ir.Binary, left: ir.Type, right: ir.Type, diags: Diagnostics) -> ir.Type:
    """CityEngine's element-wise operators: an array and an array or a scalar, element by element."""
    op, a, b = expr.op[1:], left.element, right.element
    if op in ir.LOGIC_OPS:
        ok, result = a is b is T.BOOL, T.BOOLS
    elif op in ("==", "!="):
        ok, result = a is b, T.BOOLS
    elif op in ir.COMPARE_OPS:
        ok, result = a is b and a in (T.NUM, T.STR), T.BOOLS
    elif op == "+" and T.STR in (a, b):
        ok, result = True, T.STRS
    else:
        ok, result = a is b is T.NUM, T.NUMS
    if not ok or not (left.is_array or right.is_array):
        diags.error("type", f"`{expr.op}` cannot combine a {left.value} and a {right.value}", expr.span)
        return T.UNKNOWN
    return result


def _array(expr: ir.ArrayLit, got: list[ir.Type], diags: Diagnostics) -> ir.Type:
    """The values of an array literal, scalars or arrays, share one element type."""
    elements = {t.element for t in got if t is not T.UNKNOWN}
    if len(elements) > 1:
        names = " and a ".join(sorted(t.value for t in elements))
        diags.error("type", f"the values of an array are a {names}", expr.span)
        return T.UNKNOWN
    return elements.pop().array if elements else T.UNKNOWN


def _index(expr: ir.Index, got: list[ir.Type], diags: Diagnostics) -> ir.Type:
    """An element for number indices, an array when an index is an array (of numbers or bools)."""
    array, *indices = got
    if array is not T.UNKNOWN and not array.is_array:
        diags.error("type", f"only an array can be indexed, got a {array.value}", expr.array.span)
        return T.UNKNOWN
    for t, e in zip(indices, [expr.index, expr.column]):
        if t not in (T.NUM, T.NUMS, T.BOOLS, T.UNKNOWN):
            diags.error("type", f"an index must be a num, a num[] or a bool[], got a {t.value}", e.span)
            return T.UNKNOWN
    if array is T.UNKNOWN:
        return T.UNKNOWN
    return array if any(t.is_array for t in indices) else array.element


#: What each array function takes: a predicate of its first argument's type, and the noun of the error.
_ARRAY_ARGUMENT = {
    "sortIndices": (lambda t: t in (T.NUMS, T.STRS), "a num[] or a str[]"),
    "sortRowIndices": (lambda t: t in (T.NUMS, T.STRS), "a num[] or a str[]"),
    "isNull": (lambda t: t in (T.NUM, T.STR), "a num or a str"),
    # ce.lib's `findFirst(text, match)` on strings predates the array function
    "findFirst": (lambda t: t.is_array or t is T.STR, "an array or a str"),
}


def _call(expr: ir.Call, got: list[ir.Type], diags: Diagnostics) -> ir.Type:
    signature = FUNCTIONS[expr.func]
    if not signature.takes(len(got)):
        noun = "argument" if signature.arity() == "1" else "arguments"
        diags.error("arity", f"`{expr.func}` takes {signature.arity()} {noun}, got {len(got)}", expr.span)
        return T.UNKNOWN
    if expr.func == "print":  # gives its value, of any type
        return got[0]
    if expr.func not in ARRAY_FUNCTIONS:
        for t, want, arg in zip(got, signature.params, expr.args):
            if want is None and t.is_array:  # any scalar
                diags.error("type", f"`{expr.func}` takes no array, got a {t.value}", arg.span)
                return T.UNKNOWN
            if want is not None and t is not T.UNKNOWN and t is not want:
                diags.error("type", f"an argument of `{expr.func}` must be a {want.value}, got a {t.value}",
                            arg.span)
                return T.UNKNOWN
        return signature.result
    result = signature.result
    if not got:  # `floatArray()`: an empty array
        return result
    first = got[0]
    ok, noun = _ARRAY_ARGUMENT.get(expr.func, (lambda t: t.is_array, "an array"))
    if first is not T.UNKNOWN and not ok(first):
        diags.error("type", f"the argument of `{expr.func}` must be {noun}, got a {first.value}",
                    expr.args[0].span)
        return T.UNKNOWN
    if expr.func == "findFirst":
        value = got[1]
        if T.UNKNOWN not in (first, value) and value is not first.element:
            diags.error("type", f"`findFirst` looks for a {first.element.value} in a {first.value}, "
                        f"got a {value.value}", expr.args[1].span)
        if len(got) == 3 and first not in (T.NUMS, T.UNKNOWN):
            diags.error("type", f"a tolerance of `findFirst` is for a num[], not a {first.value}",
                        expr.args[2].span)
        elif len(got) == 3 and got[2] not in (T.NUM, T.UNKNOWN):
            diags.error("type", f"the tolerance of `findFirst` must be a num, got a {got[2].value}",
                        expr.args[2].span)
    if expr.func == "sum" and first is T.STRS:  # the strings concatenated
        return T.STR
    return first if expr.func == "transpose" else result


#: The types of expressions with children, from the children's types.
_RESULTS = {
    ir.Choose: lambda e, got, diags: _same(e, got, diags, "the options of `choose`"),
    ir.Aggregate: lambda e, got, diags: T.NUM,
    ir.Occlusion: lambda e, got, diags: T.STR if e.kind == "occ" else T.NUM if e.kind in ir.CONTEXT_KINDS \
    else T.BOOL,  # inside, overlaps, touches, visible; minimumDistance, contextCount
    ir.Select: _select,
    ir.Call: _call,
    ir.ArrayLit: _array,
    ir.Range: lambda e, got, diags: T.NUMS,
    ir.Index: _index,
    ir.Unary: lambda e, got, diags: ir.UNARY_TYPES[e.op],  # the type it takes
    ir.Binary: _binary,
}
