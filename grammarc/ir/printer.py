"""IR as compact canonical text: what tests compare and what ``grammarc check --dump-ir`` shows.

The text is the paper notation with every binary expression parenthesized, resolved names marked
(``$h`` is a rule parameter, ``@height`` an attribute) and one rule per line.
"""

from __future__ import annotations

from grammarc.ir import nodes as ir

_AXES = "XYZ"


def print_expr(e: ir.Expr) -> str:
    if isinstance(e, ir.Num):
        return f"{e.value:g}"
    if isinstance(e, ir.Str):
        return f'"{e.value}"'
    if isinstance(e, ir.Bool):
        return "true" if e.value else "false"
    if isinstance(e, ir.Name):
        return e.name
    if isinstance(e, ir.Param):
        return f"${e.name}"
    if isinstance(e, ir.AttrRef):
        return f"@{e.name}"
    if isinstance(e, ir.ScopeRef):
        return f"Scope.{e.field}"
    if isinstance(e, ir.Unary):
        return f"{e.op}{print_expr(e.operand)}"
    if isinstance(e, ir.Binary):
        return f"({print_expr(e.left)} {e.op} {print_expr(e.right)})"
    if isinstance(e, ir.Call):
        return f"{e.func}({', '.join(print_expr(a) for a in e.args)})"
    if isinstance(e, ir.Occlusion):
        if e.kind == "visible":
            return 'Shape.visible("street")'
        if e.kind == "occ":
            which = e.label if e.label is not None else "active" if e.active else "all" if e.parents else "noparent"
            distance = f', "distance", {print_expr(e.distance)}' if e.distance is not None else ""
            return f'Shape.occ("{which}"{distance})'
        label = f', "{e.label}"' if e.label is not None else ""
        return f"{e.kind}({e.target}{label})"
    if isinstance(e, ir.ContextRef):
        return e.name
    if isinstance(e, ir.Select):
        return f"({print_expr(e.cond)} ? {print_expr(e.then)} : {print_expr(e.other)})"
    raise TypeError(f"not an expression: {e!r}")


def _size(s: ir.Size) -> str:
    text = print_expr(s.value)
    if s.kind is ir.SizeKind.FLOATING:
        return f"~{text}"
    return f"{text}r" if s.kind is ir.SizeKind.RELATIVE else text


def _branches(op) -> str:
    head = "case" if isinstance(op, ir.Case) else "%"
    parts = [f"{head} {print_expr(c)}: {print_body(b) or 'ε'}" for c, b in op.branches]
    return "{ " + " ".join(parts) + f" else: {print_body(op.default) or 'ε'} }}"


def _axes(axes: tuple[int, ...], snap: bool = False) -> str:
    return '"' + "".join(_AXES[a] for a in axes) + ("S" if snap else "") + '"'


def _label(label: str | None) -> str:
    return f', "{label}"' if label is not None else ""


def _parts(parts) -> str:
    return "{ " + " | ".join(print_body(p) or "ε" for p in parts) + " }"


def print_op(op: ir.Op) -> str:
    if isinstance(op, ir.Symbol):
        args = f"({', '.join(print_expr(a) for a in op.args)})" if op.args else ""
        return op.name + args + ("." if op.leaf else "")
    if isinstance(op, ir.Empty):
        return "ε"
    if isinstance(op, ir.Translate):
        return f"T({', '.join(print_expr(e) for e in op.vector)})"
    if isinstance(op, ir.Scale):
        return f"S({', '.join(_size(s) for s in op.sizes)})"
    if isinstance(op, ir.Rotate):
        return f"R({', '.join(print_expr(e) for e in op.angles)})"
    if isinstance(op, ir.Push):
        return "["
    if isinstance(op, ir.Pop):
        return "]"
    if isinstance(op, ir.Insert):
        return f'I("{op.asset}")'
    if isinstance(op, ir.Split):
        sizes = ", ".join(_size(s) for s in op.sizes)
        return f"Subdiv({_axes(op.axes, op.snap)}, {sizes}{_label(op.snap_label)}){_parts(op.parts)}"
    if isinstance(op, ir.Repeat):
        sizes = ", ".join(print_expr(e) for e in op.sizes)
        return f"Repeat({_axes(op.axes, op.snap)}, {sizes}{_label(op.snap_label)}){_parts(op.parts)}"
    if isinstance(op, ir.Label):
        return f'label("{op.name}")'
    if isinstance(op, ir.Snap):
        axes = {0: "Y", 1: "XZ", 2: "XY"}[op.normal]
        return f'{"SnapLines" if op.lines else "Snap"}("{axes}"{_label(op.label)})'
    if isinstance(op, ir.Comp):
        index = f", {print_expr(op.index)}" if op.index is not None else ""
        return f'Comp("{op.kind}"{index}){_parts(op.parts)}'
    if isinstance(op, ir.GroupSplit):
        items, group = [], None
        for size, body, g in zip(op.sizes, op.parts, op.groups):
            text = f"{_size(size)}: {print_body(body) or 'ε'}"
            if g >= 0 and g == group:
                items[-1].append(text)
            else:
                items.append([text] if g < 0 else ["{", text])
            group = g
        shown = [" | ".join(i) if i[0] != "{" else "{ " + " | ".join(i[1:]) + " }*" for i in items]
        return f"split({'xyz'[op.axis]}){{ {' | '.join(shown)} }}{'*' if op.repeat else ''}"
    if isinstance(op, ir.SetColor):
        return f"color({', '.join(print_expr(v) for v in op.values)})"
    if isinstance(op, ir.Offset):
        return f"offset({print_expr(op.distance)}, {op.select})"
    if isinstance(op, ir.Convexify):
        return f"convexify({print_expr(op.max_length) if op.max_length is not None else ''})"
    if isinstance(op, ir.CleanupGeometry):
        return f"cleanupGeometry({op.component}, {print_expr(op.tolerance)})"
    if isinstance(op, ir.InnerRectangle):
        return f"innerRectangle({op.align}){{ " + " | ".join(f"{s}: {print_body(b) or 'ε'}"
                                                          for s, b in zip(op.selectors, op.parts)) + " }"
    if isinstance(op, ir.Roof):
        args = [("byHeight" if op.by_height else "byAngle"), print_expr(op.value), print_expr(op.overhang)]
        if op.overhang_y is not None:
            args.append(print_expr(op.overhang_y))
        if op.cap is not None:
            args.append(f"cap={print_expr(op.cap)}")
        args += [f"{print_expr(h)}/{print_expr(a)}" for h, a in op.sides]
        return f"{op.kind}({', '.join(args)}, index={print_expr(op.index)})"
    if isinstance(op, ir.CompFaces):
        head = f"offset({print_expr(op.offset)}) " if op.offset is not None else ""
        return head + f"comp({op.kind}){{ " + " | ".join(f"{s}: {print_body(b) or 'ε'}"
                                         for s, b in zip(op.selectors, op.parts)) + " }"
    if isinstance(op, ir.Setback):
        moves = ", ".join(f"{s}={print_expr(d)}" for s, d in op.distances)
        if op.per_edge:
            moves = f"comp(fe){{ {moves} }}"
        return f"setback({moves}){{ " + " | ".join(f"{s}: {print_body(b) or 'ε'}"
                                                  for s, b in zip(op.selectors, op.parts)) + " }"
    if isinstance(op, (ir.Case, ir.Stochastic)):
        return _branches(op)
    if isinstance(op, ir.Extrude):
        return f"extrude({print_expr(op.height)})"
    if isinstance(op, ir.Center):
        return f"center({''.join('xyz'[a] for a in op.axes)})"
    if isinstance(op, ir.UseAsset):
        return f"i({print_expr(op.name)})" if op.name is not None else f'i("{op.asset}")'
    if isinstance(op, ir.SetAttr):
        return f"set({op.name}, {print_expr(op.value)})"
    if isinstance(op, ir.Report):
        return f"report({print_expr(op.key)}, {print_expr(op.value)})"
    if isinstance(op, ir.Mirror):
        return f"mirror({', '.join(print_expr(a) for a in op.axes)})"
    if isinstance(op, ir.AlignScope):
        if op.mode.startswith("geometry"):
            return f"alignScopeToGeometry({op.mode[-1]}Up, 0, {print_expr(op.angles[0])})"
        if op.angles is not None:
            return f"rotateScope({', '.join(print_expr(a) for a in op.angles)})"
        return "alignScopeToAxes()" if op.mode == "world" else f"alignScopeToAxes({op.mode})"
    if isinstance(op, ir.NotApplied):
        return f"{op.name}(...)"
    raise TypeError(f"not an operation: {op!r}")


def print_body(body: ir.Body) -> str:
    return " ".join(print_op(op) for op in body)


def print_rule(rule: ir.Rule) -> str:
    head = rule.symbol + (f"({', '.join(rule.params)})" if rule.params else "")
    if rule.guard is not None:
        head += f" : {print_expr(rule.guard)}"
    alts = []
    for alt in rule.alternatives:
        prob = f" : {print_expr(alt.prob)}" if alt.prob is not None else ""
        alts.append(f"~> {print_body(alt.body) or 'ε'}{prob}")
    return f"{head} " + " ".join(alts)


def print_module(module: ir.Module) -> str:
    lines = [f"attr {a.name} = {print_expr(a.default)}" for a in module.attrs]
    priority = None
    for rule in module.rules:
        if rule.priority != priority:
            priority = rule.priority
            lines.append(f"PRIORITY {priority}:")
        lines.append(print_rule(rule))
    return "\n".join(lines)
