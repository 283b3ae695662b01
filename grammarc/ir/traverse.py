"""Walk and rebuild IR: the one place that knows which fields of which node hold expressions and bodies.

``rewrite_expr`` applies a function bottom-up and returns the same object when nothing changed, so a pass
can tell whether it did anything by identity; ``rewrite_body``, ``rewrite_rule`` and ``rewrite_module``
apply an expression rewrite to every expression of a body (descending into split parts), rule or module;
``iter_ops`` and ``iter_exprs`` visit without rebuilding.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace

from grammarc.ir import nodes as ir

ExprFn = Callable[[ir.Expr], ir.Expr]


def rewrite_expr(expr: ir.Expr, fn: ExprFn) -> ir.Expr:
    """Rebuild ``expr`` bottom-up with ``fn`` applied to every node (children first)."""
    if isinstance(expr, ir.Unary):
        operand = rewrite_expr(expr.operand, fn)
        if operand is not expr.operand:
            expr = replace(expr, operand=operand)
    elif isinstance(expr, ir.Binary):
        left, right = rewrite_expr(expr.left, fn), rewrite_expr(expr.right, fn)
        if left is not expr.left or right is not expr.right:
            expr = replace(expr, left=left, right=right)
    elif isinstance(expr, ir.Call):
        args = _tuple(expr.args, lambda a: rewrite_expr(a, fn))
        if args is not expr.args:
            expr = replace(expr, args=args)
    elif isinstance(expr, ir.Occlusion) and expr.distance is not None:
        distance = rewrite_expr(expr.distance, fn)
        if distance is not expr.distance:
            expr = replace(expr, distance=distance)
    elif isinstance(expr, ir.Select):
        parts = _tuple((expr.cond, expr.then, expr.other), lambda a: rewrite_expr(a, fn))
        if parts is not (expr.cond, expr.then, expr.other) and any(
                a is not b for a, b in zip(parts, (expr.cond, expr.then, expr.other))):
            expr = replace(expr, cond=parts[0], then=parts[1], other=parts[2])
    return fn(expr)


def _tuple(items: tuple, fn) -> tuple:
    new = tuple(fn(i) for i in items)
    return items if all(a is b for a, b in zip(new, items)) else new


def _size(size: ir.Size, fn: ExprFn) -> ir.Size:
    value = rewrite_expr(size.value, fn)
    return size if value is size.value else replace(size, value=value)


def rewrite_op(op: ir.Op, fn: ExprFn) -> ir.Op:
    """``op`` with ``fn`` applied to each of its expressions, and to the bodies of its parts."""
    ex = lambda e: rewrite_expr(e, fn)
    if isinstance(op, ir.Symbol):
        args = _tuple(op.args, ex)
        return op if args is op.args else replace(op, args=args)
    if isinstance(op, ir.Translate):
        vec = _tuple(op.vector, ex)
        return op if vec is op.vector else replace(op, vector=vec)
    if isinstance(op, ir.Rotate):
        angles = _tuple(op.angles, ex)
        return op if angles is op.angles else replace(op, angles=angles)
    if isinstance(op, ir.Scale):
        sizes = _tuple(op.sizes, lambda s: _size(s, fn))
        return op if sizes is op.sizes else replace(op, sizes=sizes)
    if isinstance(op, ir.Split):
        sizes = _tuple(op.sizes, lambda s: _size(s, fn))
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        return op if sizes is op.sizes and parts is op.parts else replace(op, sizes=sizes, parts=parts)
    if isinstance(op, ir.Repeat):
        sizes = _tuple(op.sizes, ex)
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        return op if sizes is op.sizes and parts is op.parts else replace(op, sizes=sizes, parts=parts)
    if isinstance(op, ir.Comp):
        index = ex(op.index) if op.index is not None else None
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        return op if index is op.index and parts is op.parts else replace(op, index=index, parts=parts)
    if isinstance(op, ir.GroupSplit):
        sizes = _tuple(op.sizes, lambda s: _size(s, fn))
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        return op if sizes is op.sizes and parts is op.parts else replace(op, sizes=sizes, parts=parts)
    if isinstance(op, ir.CompFaces):
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        offset = ex(op.offset) if op.offset is not None else None
        return op if parts is op.parts and offset is op.offset else replace(op, parts=parts, offset=offset)
    if isinstance(op, ir.Setback):
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        distances = _tuple(op.distances, lambda sd: (sd[0], ex(sd[1])))
        if parts is op.parts and all(a[1] is b[1] for a, b in zip(distances, op.distances)):
            return op
        return replace(op, parts=parts, distances=distances)
    if isinstance(op, ir.InnerRectangle):
        parts = _tuple(op.parts, lambda b: rewrite_body(b, fn))
        return op if parts is op.parts else replace(op, parts=parts)
    if isinstance(op, ir.Convexify) and op.max_length is not None:
        max_length = ex(op.max_length)
        return op if max_length is op.max_length else replace(op, max_length=max_length)
    if isinstance(op, ir.CleanupGeometry):
        tolerance = ex(op.tolerance)
        return op if tolerance is op.tolerance else replace(op, tolerance=tolerance)
    if isinstance(op, ir.SetColor):
        values = _tuple(op.values, ex)
        return op if values is op.values else replace(op, values=values)
    if isinstance(op, ir.Offset):
        distance = ex(op.distance)
        return op if distance is op.distance else replace(op, distance=distance)
    if isinstance(op, ir.Roof):
        value, overhang, index = ex(op.value), ex(op.overhang), ex(op.index)
        overhang_y = ex(op.overhang_y) if op.overhang_y is not None else None
        cap = ex(op.cap) if op.cap is not None else None
        sides = _tuple(op.sides, lambda pair: _tuple(pair, ex))
        if (value is op.value and overhang is op.overhang and index is op.index and overhang_y is op.overhang_y
                and cap is op.cap and sides is op.sides):
            return op
        return replace(op, value=value, overhang=overhang, overhang_y=overhang_y, index=index, cap=cap,
                       sides=sides)
    if isinstance(op, (ir.Case, ir.Stochastic)):
        branches = _tuple(op.branches, lambda br: _branch(br, fn))
        default = rewrite_body(op.default, fn)
        if branches is op.branches and default is op.default:
            return op
        return replace(op, branches=branches, default=default)
    if isinstance(op, ir.Extrude):
        height = ex(op.height)
        return op if height is op.height else replace(op, height=height)
    if isinstance(op, ir.Mirror):
        axes = _tuple(op.axes, ex)
        return op if axes is op.axes else replace(op, axes=axes)
    if isinstance(op, ir.AlignScope) and op.angles is not None:
        angles = _tuple(op.angles, ex)
        return op if angles is op.angles else replace(op, angles=angles)
    if isinstance(op, ir.UseAsset) and op.name is not None:
        name = ex(op.name)
        return op if name is op.name else replace(op, name=name)
    if isinstance(op, ir.SetAttr):
        value = ex(op.value)
        return op if value is op.value else replace(op, value=value)
    if isinstance(op, ir.Report):
        key, value = ex(op.key), ex(op.value)
        return op if key is op.key and value is op.value else replace(op, key=key, value=value)
    return op


def _branch(branch: tuple, fn: ExprFn) -> tuple:
    cond, body = branch
    new_cond, new_body = rewrite_expr(cond, fn), rewrite_body(body, fn)
    return branch if new_cond is cond and new_body is body else (new_cond, new_body)


def rewrite_body(body: ir.Body, fn: ExprFn) -> ir.Body:
    return _tuple(body, lambda op: rewrite_op(op, fn))


def rewrite_rule(rule: ir.Rule, fn: ExprFn) -> ir.Rule:
    """``rule`` with ``fn`` applied to its guard, probabilities and bodies."""
    guard = rewrite_expr(rule.guard, fn) if rule.guard is not None else None

    def alt(a: ir.Alternative) -> ir.Alternative:
        body = rewrite_body(a.body, fn)
        prob = rewrite_expr(a.prob, fn) if a.prob is not None else None
        return a if body is a.body and prob is a.prob else replace(a, body=body, prob=prob)

    alts = _tuple(rule.alternatives, alt)
    if guard is rule.guard and alts is rule.alternatives:
        return rule
    return replace(rule, guard=guard, alternatives=alts)


def rewrite_module(module: ir.Module, fn: ExprFn) -> ir.Module:
    """``module`` with ``fn`` applied to every attribute default and rule; the same object if unchanged."""

    def attr(a: ir.AttrDecl) -> ir.AttrDecl:
        default = rewrite_expr(a.default, fn)
        return a if default is a.default else replace(a, default=default)

    attrs = _tuple(module.attrs, attr)
    rules = _tuple(module.rules, lambda r: rewrite_rule(r, fn))
    if attrs is module.attrs and rules is module.rules:
        return module
    return replace(module, attrs=attrs, rules=rules)


def iter_ops(body: ir.Body) -> Iterator[ir.Op]:
    """Every operation of ``body``, including those inside split parts, in source order."""
    for op in body:
        yield op
        for part in sub_bodies(op):
            yield from iter_ops(part)


def sub_bodies(op: ir.Op) -> tuple[ir.Body, ...]:
    """The bodies nested in ``op``: split parts, case and stochastic branches."""
    if isinstance(op, (ir.Split, ir.Repeat, ir.Comp, ir.GroupSplit, ir.CompFaces, ir.Setback,
                       ir.InnerRectangle)):
        return op.parts
    if isinstance(op, (ir.Case, ir.Stochastic)):
        return (*(body for _, body in op.branches), op.default)
    return ()


def op_exprs(op: ir.Op) -> Iterator[ir.Expr]:
    """The expressions directly held by ``op`` (not those of its parts)."""
    if isinstance(op, ir.Symbol):
        yield from op.args
    elif isinstance(op, ir.Translate):
        yield from op.vector
    elif isinstance(op, ir.Rotate):
        yield from op.angles
    elif isinstance(op, (ir.Scale, ir.Split)):
        yield from (s.value for s in op.sizes)
    elif isinstance(op, ir.Repeat):
        yield from op.sizes
    elif isinstance(op, ir.Comp) and op.index is not None:
        yield op.index
    elif isinstance(op, ir.GroupSplit):
        yield from (s.value for s in op.sizes)
    elif isinstance(op, (ir.Case, ir.Stochastic)):
        yield from (cond for cond, _ in op.branches)
    elif isinstance(op, ir.Extrude):
        yield op.height
    elif isinstance(op, ir.UseAsset) and op.name is not None:
        yield op.name
    elif isinstance(op, ir.AlignScope) and op.angles is not None:
        yield from op.angles
    elif isinstance(op, ir.Mirror):
        yield from op.axes
    elif isinstance(op, ir.Offset):
        yield op.distance
    elif isinstance(op, ir.Convexify) and op.max_length is not None:
        yield op.max_length
    elif isinstance(op, ir.CleanupGeometry):
        yield op.tolerance
    elif isinstance(op, ir.Roof):
        yield from (e for e in (op.value, op.overhang, op.overhang_y, op.index, op.cap) if e is not None)
        yield from (e for pair in op.sides for e in pair)
    elif isinstance(op, ir.SetColor):
        yield from op.values
    elif isinstance(op, ir.CompFaces) and op.offset is not None:
        yield op.offset
    elif isinstance(op, ir.Setback):
        yield from (d for _, d in op.distances)
    elif isinstance(op, ir.SetAttr):
        yield op.value
    elif isinstance(op, ir.Report):
        yield op.key
        yield op.value


def iter_exprs(expr: ir.Expr) -> Iterator[ir.Expr]:
    """``expr`` and all its sub-expressions."""
    yield expr
    if isinstance(expr, ir.Unary):
        yield from iter_exprs(expr.operand)
    elif isinstance(expr, ir.Binary):
        yield from iter_exprs(expr.left)
        yield from iter_exprs(expr.right)
    elif isinstance(expr, ir.Call):
        for a in expr.args:
            yield from iter_exprs(a)
    elif isinstance(expr, ir.Select):
        for a in (expr.cond, expr.then, expr.other):
            yield from iter_exprs(a)
    elif isinstance(expr, ir.Occlusion) and expr.distance is not None:
        yield from iter_exprs(expr.distance)
