"""Name resolution: every ``Name`` becomes a rule ``Param`` or an ``AttrRef``.

Assumes: a lowered module. Guarantees: no ``Name`` is left; an identifier that is neither a parameter of
its rule nor a declared attribute is an error that names it (attribute defaults may only use attributes
declared before them). A CityEngine attribute whose default uses itself, through other attributes or
constants (``attr a = b``, ``attr b = a``; functions are inlined by then, so cycles through them count) has
no value: an error at its declaration naming the cycle (``attr a -> b -> a``), once per cycle.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import count

from grammarc.diagnostics import Diagnostics, suggest
from grammarc.ir import nodes as ir
from grammarc.ir.functions import FUNCTIONS
from grammarc.ir.traverse import iter_exprs, iter_ops, rewrite_expr, rewrite_node, rewrite_rule


def resolve_names(module: ir.Module, diags: Diagnostics) -> ir.Module:
    declared: list[str] = []
    all_attrs = [a.name for a in module.attrs]
    attrs = []
    # CityEngine evaluates attributes lazily, so a default may use an attribute declared after it (the
    # backend evaluates them in dependency order); the paper notation reads top to bottom.
    lazy = module.dialect == "cityengine"
    sites = count(_BARE_SITES)
    for attr in module.attrs:
        where = f"attribute `{attr.name}`"
        visible = all_attrs if lazy else declared
        default = rewrite_expr(attr.default, _resolver({}, visible, diags, where, sites, later=all_attrs))
        attrs.append(attr if default is attr.default else replace(attr, default=default))
        declared.append(attr.name)
    if lazy:
        _check_cycles(attrs, diags)
    rules = []
    for rule in module.rules:
        params = {name: i for i, name in enumerate(rule.params)}
        for name in rule.params:
            if name in all_attrs:
                diags.warning("shadow", f"parameter `{name}` of `{rule.symbol}` hides the attribute `{name}`",
                              rule.span)
        rules.append(rewrite_rule(rule, _resolver(params, all_attrs, diags, f"rule `{rule.symbol}`", sites)))
        _check_set_targets(rule, module, diags)
    # a search statement reads the design's aggregates and the lot's attributes, no rule's parameters
    objectives = tuple(rewrite_node(o, _resolver({}, all_attrs, diags, f"`{o.kind}:`", sites))
                       for o in module.objectives)
    if all(a is b for a, b in zip(attrs, module.attrs)) and all(a is b for a, b in zip(rules, module.rules)) \
            and all(a is b for a, b in zip(objectives, module.objectives)):
        return module
    return replace(module, attrs=tuple(attrs), rules=tuple(rules), objectives=objectives)


def _check_cycles(attrs: list[ir.AttrDecl], diags: Diagnostics) -> None:
    """An error for each cycle of attribute defaults, at the attribute of it declared first."""
    uses = {a.name: [e.name for e in iter_exprs(a.default) if isinstance(e, ir.AttrRef)] for a in attrs}
    on_cycle: set[str] = set()
    for attr in attrs:
        if attr.name in on_cycle:
            continue
        # breadth first from the attribute: the shortest way back to it, if there is one
        came_from: dict[str, str] = {}
        frontier = [attr.name]
        while frontier and attr.name not in came_from:
            following = []
            for name in frontier:
                for used in uses.get(name, ()):
                    if used not in came_from:
                        came_from[used] = name
                        following.append(used)
            frontier = following
        if attr.name not in came_from:
            continue
        cycle = [attr.name]
        while came_from[cycle[-1]] != attr.name:
            cycle.append(came_from[cycle[-1]])
        cycle.reverse()
        on_cycle.update(cycle)
        diags.error("attr-cycle", f"attribute `{attr.name}` has no value: its default uses itself "
                    f"(attr {' -> '.join([attr.name, *cycle[:-1], attr.name])})", attr.span)


#: Built-in functions that take no argument and may be written without parentheses (after the rule's
#: parameters and the attributes, which win over them).
_BARE_CALLS = frozenset(name for name, sig in FUNCTIONS.items() if "." not in name and len(sig.params) == sig.optional)
_BARE_SITES = 1 << 40


def _resolver(params: dict[str, int], attrs: list[str], diags: Diagnostics, where: str, sites,
              later: list[str] | tuple[str, ...] = ()):
    """Name -> Param or AttrRef; ``later`` are attributes declared after the one being resolved."""

    def resolve(expr: ir.Expr) -> ir.Expr:
        if not isinstance(expr, ir.Name):
            return expr
        if expr.name in params:
            return ir.Param(params[expr.name], expr.name, expr.span)
        if expr.name in attrs:
            return ir.AttrRef(expr.name, expr.span)
        if expr.name in _BARE_CALLS:  # CityEngine reads a built-in without arguments written bare: `rand`
            return ir.Call(expr.name, (), expr.span, next(sites))
        if expr.name in later:
            diags.error("attr-order", f"attribute `{expr.name}` is used in {where} before its declaration",
                        expr.span, hint=f"declare `{expr.name}` above the attributes that use it")
            return ir.placeholder(expr.span)
        known = list(params) + list(attrs)
        diags.error(
            "unknown-name",
            f"unknown identifier `{expr.name}` in {where}{suggest(expr.name, known)}",
            expr.span,
            hint="declare it with `attr name = value`, or make it a parameter of the rule",
        )
        return ir.placeholder(expr.span)

    return resolve


def _check_set_targets(rule: ir.Rule, module: ir.Module, diags: Diagnostics) -> None:
    """``set(name, v)`` needs an attribute (not a constant) called ``name``."""
    attrs = {a.name: a for a in module.attrs}
    for op in iter_ops(rule):
        if not isinstance(op, ir.SetAttr) or op.name in ir.SHAPE_ATTRIBUTES:
            continue
        attr = attrs.get(op.name)
        if attr is None:
            diags.error("unknown-name", f"`set` of `{op.name}`, which is not an attribute"
                        f"{suggest(op.name, attrs)}", op.span)
        elif attr.const:
            diags.error("const", f"`set` of the constant `{op.name}`", op.span)
