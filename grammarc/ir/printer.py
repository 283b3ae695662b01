"""IR as compact canonical text: what tests compare and what ``grammarc check --dump-ir`` shows.

The text is the paper notation with every binary expression parenthesized, resolved names marked
(``$h`` is a rule parameter, ``@height`` an attribute) and one rule per line.

Each node type has its format in a table; an operation without one prints from its declared children
(``nodes.child``) as ``name(arguments){ bodies }``, so a new operation prints before it has a format.
"""

from __future__ import annotations

from grammarc.ir import nodes as ir
from grammarc.ir.traverse import EXPRESSIONS

_AXES = "XYZ"


def print_expr(e: ir.Expr) -> str:
    form = _EXPR_FORMATS.get(type(e))
    if form is None:
        raise TypeError(f"not an expression: {e!r}")
    return form(e)


def _occlusion(e: ir.Occlusion) -> str:
    if e.kind == "visible":
        return 'Shape.visible("street")'
    if e.kind == "occ":
        which = e.label if e.label is not None else "active" if e.active else "all" if e.parents else "noparent"
        distance = f', "distance", {print_expr(e.distance)}' if e.distance is not None else ""
        return f'Shape.occ("{which}"{distance})'
    target = e.target if e.which is None else f"sel({print_expr(e.which)})"
    label = f', "{e.label}"' if e.label is not None else f", {print_expr(e.named)}" if e.named is not None else ""
    return f"{e.kind}({target}{label})"


_EXPR_FORMATS = {
    ir.Num: lambda e: f"{e.value:g}",
    ir.Str: lambda e: f'"{e.value}"',
    ir.Bool: lambda e: "true" if e.value else "false",
    ir.Name: lambda e: e.name,
    ir.Param: lambda e: f"${e.name}",
    ir.AttrRef: lambda e: f"@{e.name}",
    ir.ScopeRef: lambda e: f"Scope.{e.field}",
    ir.Unary: lambda e: f"{e.op}{print_expr(e.operand)}",
    ir.Binary: lambda e: f"({print_expr(e.left)} {e.op} {print_expr(e.right)})",
    ir.Call: lambda e: f"{e.func}({_list(e.args)})",
    ir.Occlusion: _occlusion,
    ir.ContextRef: lambda e: e.name,
    ir.Select: lambda e: f"({print_expr(e.cond)} ? {print_expr(e.then)} : {print_expr(e.other)})",
    ir.ArrayLit: lambda e: f"[{' ; '.join(_list(row) for row in e.rows)}]",
    ir.Range: lambda e: f"[{print_expr(e.base)}:{print_expr(e.step)}:{print_expr(e.limit)}]",
    ir.Index: lambda e: f"{print_expr(e.array)}[{print_expr(e.index)}"
                        f"{'' if e.column is None else ', ' + print_expr(e.column)}]",
    ir.Choose: lambda e: f"choose({_list(e.options)})",
    ir.Aggregate: lambda e: f'{e.func}({"" if e.value is None else print_expr(e.value) + " of "}"{e.symbol}")',
}


def _list(exprs) -> str:
    return ", ".join(print_expr(e) for e in exprs)


def _size(s: ir.Size) -> str:
    text = print_expr(s.value)
    if s.kind is ir.SizeKind.FLOATING:
        return f"~{text}"
    return f"{text}r" if s.kind is ir.SizeKind.RELATIVE else text


def _branches(op) -> str:
    head = "case" if isinstance(op, ir.Case) else "%"
    parts = [f"{head} {print_expr(c)}: {_body(b)}" for c, b in op.branches]
    return "{ " + " ".join(parts) + f" else: {_body(op.default)} }}"


def _axes(axes: tuple[int, ...], snap: bool = False) -> str:
    return '"' + "".join(_AXES[a] for a in axes) + ("S" if snap else "") + '"'


def _label(label: str | None) -> str:
    return f', "{label}"' if label is not None else ""


def _body(body: ir.Body) -> str:
    return print_body(body) or "ε"


def _parts(parts) -> str:
    return "{ " + " | ".join(_body(p) for p in parts) + " }"


def _selected(selectors, parts) -> str:
    return "{ " + " | ".join(f"{s}: {_body(b)}" for s, b in zip(selectors, parts)) + " }"


def _group_split(op: ir.GroupSplit) -> str:
    items, group = [], None
    for size, body, g in zip(op.sizes, op.parts, op.groups):
        text = f"{_size(size)}: {_body(body)}"
        if g >= 0 and g == group:
            items[-1].append(text)
        else:
            items.append([text] if g < 0 else ["{", text])
        group = g
    shown = [" | ".join(i) if i[0] != "{" else "{ " + " | ".join(i[1:]) + " }*" for i in items]
    options = "" if op.adjust else ", noAdjust"
    name = "splitArea" if isinstance(op, ir.SplitArea) else "split"
    head = f"{'xyz'[op.axis]}{options}" if op.uv_set < 0 else \
        f"{'uv'[op.axis]}, {'unitSpace' if op.unit_space else 'uvSpace'}, {op.uv_set}"
    return f"{name}({head}){{ {' | '.join(shown)} }}{'*' if op.repeat else ''}"


def _roof(op: ir.Roof) -> str:
    args = [("byHeight" if op.by_height else "byAngle"), print_expr(op.value), print_expr(op.overhang)]
    if op.overhang_y is not None:
        args.append(print_expr(op.overhang_y))
    if op.cap is not None:
        args.append(f"cap={print_expr(op.cap)}")
    args += [f"{print_expr(h)}/{print_expr(a)}" for h, a in op.sides]
    return f"{op.kind}({', '.join(args)}, index={print_expr(op.index)})"


def comp_selectors(op: ir.CompFaces) -> list[str]:
    """The selectors of ``op`` as written, an index expression ``#k`` as its expression: also what
    ``comp.sel`` gives the shapes they select."""
    return [print_expr(op.picks[int(s[1:])]) if s.startswith("#") else s for s in op.selectors]


def _setback(op: ir.Setback) -> str:
    moves = ", ".join(f"{s}={print_expr(d)}" for s, d in op.distances)
    if op.per_edge:
        moves = f"comp(fe){{ {moves} }}"
    return f"setback({moves}){_selected(op.selectors, op.parts)}"


def _setback_to_area(op: ir.SetbackToArea) -> str:
    bounds = "".join(f", comp(fe){{ {', '.join(f'{s}={print_expr(d)}' for s, d in side)} }}"
                     for side in (op.minimum, op.maximum) if side)
    return f"setbackToArea({print_expr(op.area)}{bounds}){_selected(op.selectors, op.parts)}"


#: The axes of a snap plane, by the scope axis across it.
_SNAP_AXES = {0: "Y", 1: "XZ", 2: "XY"}


def _align_scope(op: ir.AlignScope) -> str:
    if op.angles is not None:
        return f"rotateScope({_list(op.angles)})"
    return "alignScopeToAxes()" if op.mode == "world" else f"alignScopeToAxes({op.mode})"


def _asset(op: ir.UseAsset | ir.InsertAlongUV) -> str:
    """An inserted asset as written: its computed name, or its path quoted."""
    return print_expr(op.name) if op.name is not None else f'"{op.asset}"'


def _scatter(op: ir.Scatter) -> str:
    spread = (f"gaussian, {op.mean}, {print_expr(op.stddev)}{'r' if op.relative else ''}" if op.gaussian
              else "uniform")
    return f"scatter({op.domain}, {print_expr(op.count)}, {spread}){_parts(op.parts)}"


_OP_FORMATS = {
    ir.Symbol: lambda op: op.name + (f"({_list(op.args)})" if op.args else "") + ("." if op.leaf else ""),
    ir.Empty: lambda op: "ε",
    ir.Translate: lambda op: f"T({_list(op.vector)})",
    ir.Scale: lambda op: f"S({', '.join(_size(s) for s in op.sizes)})",
    ir.Rotate: lambda op: f"{'r' if op.fixed else 'R'}({'scopeCenter, ' if op.center else ''}{_list(op.angles)})",
    ir.Transform: lambda op: f"{op.kind}({'rel' if op.relative else 'abs'}, {op.system}, {_list(op.values)})",
    ir.SetPivot: lambda op: f"setPivot({op.axes}, {print_expr(op.corner)})",
    ir.Push: lambda op: "[",
    ir.Pop: lambda op: "]",
    ir.Insert: lambda op: f'I("{op.asset}")',
    ir.Split: lambda op: (f"Subdiv({_axes(op.axes, op.snap)}, {', '.join(_size(s) for s in op.sizes)}"
                          f"{_label(op.snap_label)}){_parts(op.parts)}"),
    ir.Repeat: lambda op: (f"Repeat({_axes(op.axes, op.snap)}, {_list(op.sizes)}{_label(op.snap_label)})"
                           f"{_parts(op.parts)}"),
    ir.Label: lambda op: f"label({print_expr(op.name)})",
    ir.Snap: lambda op: f'{"SnapLines" if op.lines else "Snap"}("{_SNAP_AXES[op.normal]}"{_label(op.label)})',
    ir.Comp: lambda op: (f'Comp("{op.kind}"{f", {print_expr(op.index)}" if op.index is not None else ""})'
                         f"{_parts(op.parts)}"),
    ir.GroupSplit: _group_split,
    ir.SplitArea: _group_split,
    ir.SetColor: lambda op: f"color({_list(op.values)})",
    ir.Offset: lambda op: f"offset({print_expr(op.distance)}, {op.select})",
    ir.Convexify: lambda op: f"convexify({print_expr(op.max_length) if op.max_length is not None else ''})",
    ir.CleanupGeometry: lambda op: f"cleanupGeometry({op.component}, {print_expr(op.tolerance)})",
    ir.InnerRectangle: lambda op: f"innerRectangle({op.align}){_selected(op.selectors, op.parts)}",
    ir.Roof: _roof,
    ir.CompFaces: lambda op: ((f"offset({print_expr(op.offset)}) " if op.offset is not None else "")
                              + f"comp({op.kind}){_selected(comp_selectors(op), op.parts)}"),
    ir.Setback: _setback,
    ir.SetbackToArea: _setback_to_area,
    ir.AlignScopeToBBox: lambda op: f"alignScopeToGeometryBBox({''.join('xyz'[a] for a in op.axes)})",
    ir.Case: _branches,
    ir.Stochastic: _branches,
    ir.Extrude: lambda op: ("extrude(" + ("" if op.direction == "face.normal" else f"{op.direction}, ")
                            + f"{print_expr(op.height)})"),
    ir.Center: lambda op: f"center({''.join('xyz'[a] for a in op.axes)})",
    ir.UseAsset: lambda op: "i(" + ", ".join([
        _asset(op), *([op.up, op.mode] if (op.up, op.mode) != ("yUp", ir.INSERT_MODES[0]) else [])]) + ")",
    ir.SetAttr: lambda op: f"set({op.name}, {print_expr(op.value)})",
    ir.Report: lambda op: f"report({print_expr(op.key)}, {print_expr(op.value)})",
    ir.Mirror: lambda op: f"mirror({_list(op.axes)})",
    ir.AlignScope: _align_scope,
    ir.AlignToGeometry: lambda op: "alignScopeToGeometry(" + ", ".join([
        op.up, op.face if op.face_index is None else print_expr(op.face_index),
        op.edge if op.edge_index is None else print_expr(op.edge_index)]) + ")",
    ir.NotApplied: lambda op: f"{op.name}(...)",
    ir.Scatter: _scatter,
    ir.Primitive: lambda op: f"primitive{op.kind.title()}({_list(op.segments + (op.sizes or ()))})",
    ir.SetOpacity: lambda op: f"set(material.opacity, {print_expr(op.value)})",
    ir.SetupProjection: lambda op: (f"setupProjection({op.uv_set}, {op.frame}.{'xyz'[op.u_axis]}{'xyz'[op.v_axis]}, "
                                    f"{', '.join(_size(s) for s in op.sizes + op.offsets)})"),
    ir.ProjectUV: lambda op: f"{'deleteUV' if op.delete else 'projectUV'}({op.uv_set})",
    ir.TransformUV: lambda op: f"{op.kind}UV({op.uv_set}, {_list(op.values)})",
    ir.TileUV: lambda op: f"tileUV({op.uv_set}, {', '.join(_size(s) for s in op.sizes)})",
    ir.NormalizeUV: lambda op: f"normalizeUV({op.uv_set}, {op.mode})",
    ir.CopyUV: lambda op: f"copyUV({op.source}, {op.uv_set})",
    ir.ResetMaterial: lambda op: "resetMaterial()",
    ir.SetMaterial: lambda op: f"setMaterial({print_expr(op.material)})",
    ir.InsertAlongUV: lambda op: f"insertAlongUV({op.uv_set}, " + ", ".join([
        _asset(op), print_expr(op.height),
        *([op.direction, op.alignment] if (op.direction, op.alignment) != (
            ir.ALONG_UV_DIRECTIONS[0], ir.ALONG_UV_ALIGNMENTS[0]) else [])]) + ")",
}


def print_op(op: ir.Op) -> str:
    form = _OP_FORMATS.get(type(op))
    if form is not None:
        return form(op)
    if type(op) in EXPRESSIONS or not hasattr(type(op), "__dataclass_fields__"):
        raise TypeError(f"not an operation: {op!r}")
    return _declared(op)


def _declared(op) -> str:
    """An operation without a format, from its declared children: its name (the class attribute
    ``cga_name``, or the class name in lower camel case), its arguments, then its bodies in braces."""
    cls = type(op)
    name = getattr(cls, "cga_name", None) or cls.__name__[0].lower() + cls.__name__[1:]
    args, bodies = [], []
    for field, spec in ir.children(cls):
        value = getattr(op, field)
        if spec.holds is ir.Holds.EXPRS:
            args.extend(_arguments(value))
        elif spec.holds is ir.Holds.BODY:
            bodies.append(_body(value))
        elif spec.holds is ir.Holds.BODIES:
            bodies.extend(_body(b) for b in value)
        elif spec.holds is ir.Holds.BRANCHES:
            bodies.extend(f"{print_expr(c)}: {_body(b)}" for c, b in value)
    return f"{name}({', '.join(args)})" + ("{ " + " | ".join(bodies) + " }" if bodies else "")


def _arguments(value) -> list[str]:
    """The printed arguments in an argument field: expressions, sizes and plain values, tuples flattened,
    None left out."""
    if value is None:
        return []
    if type(value) is tuple:
        return [text for v in value for text in _arguments(v)]
    if type(value) is ir.Size:
        return [_size(value)]
    if type(value) in EXPRESSIONS:
        return [print_expr(value)]
    if isinstance(value, bool):
        return ["true" if value else "false"]
    return [f"{value:g}" if isinstance(value, float) else str(value)]


def print_body(body: ir.Body) -> str:
    return " ".join(print_op(op) for op in body)


def print_rule(rule: ir.Rule) -> str:
    head = rule.symbol + (f"({', '.join(rule.params)})" if rule.params else "")
    if rule.guard is not None:
        head += f" : {print_expr(rule.guard)}"
    alts = []
    for alt in rule.alternatives:
        prob = " ?" if alt.choice else f" : {print_expr(alt.prob)}" if alt.prob is not None else ""
        alts.append(f"~> {_body(alt.body)}{prob}")
    return f"{head} " + " ".join(alts)


def print_module(module: ir.Module) -> str:
    lines = [f"attr {a.name} = {print_expr(a.default)}" for a in module.attrs]
    priority = None
    for rule in module.rules:
        if rule.priority != priority:
            priority = rule.priority
            lines.append(f"PRIORITY {priority}:")
        lines.append(print_rule(rule))
    lines += [f"{o.kind}: {print_expr(o.expr)}" for o in module.objectives]
    return "\n".join(lines)
