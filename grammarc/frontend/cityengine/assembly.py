"""Assembly of a CityEngine CGA file's lowered statements into one IR module: the start rule, rules
overloaded by arity (one symbol per arity), functions and constants inlined, imported modules merged
under their prefixes.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import replace
from functools import partial

from grammarc.diagnostics import Diagnostics, Span, suggest
from grammarc.frontend.cityengine.nodes import Annotated, EdgeTable, FunctionDef, Import, RuleDef, Style
from grammarc.frontend.cityengine.operations import check_calls
from grammarc.ir import nodes as ir
from grammarc.ir.functions import FUNCTIONS, UNSUPPORTED_FUNCTIONS
from grammarc.ir.traverse import rewrite_body, rewrite_expr, rewrite_ops


def assemble(file: str, statements: list, diags: Diagnostics, imports=(), exports: dict | None = None) -> ir.Module:
    """Declarations in source order -> Module: start rule, overloads by arity, functions inlined, the
    imported modules' rules, attributes and functions merged under their prefixes. Without ``@StartRule``
    the start is None: ``passes.rulegraph`` starts with the first rule and says so.

    ``imports`` are (``Import``, module, its exports) of the files imported; ``exports``, when given, is
    filled with this file's functions for a file that imports it: name -> (``FunctionDef``, a callable
    giving its body in this file's scope, ``_Inliner.exported``), the functions of its own imports under
    their prefixes included. A body is inlined when a caller asks for it, so that a function nobody
    calls is never inlined (nor reported) twice.
    """
    attrs: list[ir.AttrDecl] = []
    functions: dict[str, FunctionDef] = {}
    rules: list[tuple[RuleDef, tuple]] = []
    extensions: list[tuple[RuleDef, tuple]] = []
    style = None
    prefixes: set[str] = set()
    for st in statements:
        if not isinstance(st, Annotated):
            st = Annotated((), st)  # a declaration without annotations comes bare from the parser
        decl = st.declaration
        if isinstance(decl, Style):
            if style is None:
                diags.warning("style", f"style `{decl.name}` is not derived: grammarc derives the Default "
                              "style (PRT's Default$...)", decl.span)
            style = decl
            continue
        if style is not None and isinstance(decl, ir.AttrDecl):
            continue  # a redefinition for the style
        if isinstance(decl, EdgeTable):
            attrs.extend(_table_attrs(decl))
            continue
        if isinstance(decl, ir.AttrDecl):
            if any(a.name == decl.name for a in attrs):
                diags.error("duplicate-attr", f"attribute `{decl.name}` is declared twice", decl.span)
            attrs.append(replace(decl, annotations=st.annotations))
        elif isinstance(decl, FunctionDef):
            functions[decl.name] = decl
        elif isinstance(decl, RuleDef):
            rules.append((decl, st.annotations))
        elif isinstance(decl, Import):  # `import p : "f.cga" (Ext --> ...)` redefines p.Ext here
            prefixes.add(decl.prefix)
            extensions.extend((replace(r, name=_in(decl.prefix, r.name)), ()) for r in decl.extensions)
    rules.extend(extensions)  # after the file's own rules: never its first rule
    arities: dict[str, set[int]] = {}
    for rule, _ in rules:
        arities.setdefault(rule.name, set()).add(len(rule.params))

    def symbol_name(name: str, arity: int) -> str:
        return f"{name}/{arity}" if len(arities.get(name, ())) > 1 else name

    inline = _Inliner(functions, {a.name for a in attrs}, diags)
    # a name or call through the prefix of an import that failed is not reported: the import's error says why
    inline.unread = prefixes - {statement.prefix for statement, _, _ in imports} - {None}
    forwarding = []
    for statement, module, functions_of in imports:
        forwarded = set() if statement.protect_all else \
            {a.name for a in attrs} - set(statement.protected) - {v.name for v in statement.values}
        inline.take(functions_of, statement.prefix, {a.name for a in module.attrs} - forwarded)
        forwarding.append(forwarded)
    if exports is not None:
        exports.update((name, (fn, partial(inline.exported, name))) for name, fn in inline.functions.items())
    attrs = [replace(a, default=inline.expr(a.default, frozenset())) for a in attrs]
    start = None
    lowered: list[ir.Rule] = []
    for rule, notes in rules:
        name = symbol_name(rule.name, len(rule.params))
        if any(a[0] == "StartRule" for a in notes) and start is None:
            start = name
        params = frozenset(rule.params)
        # a leaf `X.` names a shape, not a rule: it keeps its name when rules `X` are overloaded
        body = _map_symbols(rule.body, lambda op: replace(op, name=symbol_name(op.name, len(op.args)))
                            if op.name in arities and not op.leaf else op)
        body = rewrite_body(_without_numbers(body, diags), lambda e, p=params: inline.expr(e, p))
        lowered.append(ir.Rule(symbol=name, params=rule.params, guard=None,
                               alternatives=(ir.Alternative(body, None, rule.span),), priority=0,
                               span=rule.span, site=rule.site))
    lowered = check_calls(lowered, [module for _, module, _ in imports], diags)
    imported = []
    own = {rule.symbol for rule in lowered}
    for (statement, module, _), forwarded in zip(imports, forwarding):
        values = {v.name: inline.expr(v.default, frozenset()) for v in statement.values}
        for name in sorted(set(values) - {a.name for a in module.attrs}):
            diags.warning("import", f"`{statement.path}` declares no attribute `{name}`: its value is not "
                          "used", statement.span)
        more_attrs, more_rules = _prefixed(module, statement.prefix, forwarded, values)
        attrs.extend(more_attrs)
        # a rule the importing file defines as `prefix.Rule` replaces the imported one, also where the
        # imported file calls it (its calls are prefixed too)
        lowered.extend(rule for rule in more_rules if rule.symbol not in own)
        imported.extend((module.file, *module.imported))
    lowered = _setbacks_by_table(lowered, attrs)
    return ir.Module(file=file, attrs=tuple(attrs), rules=tuple(lowered), start=start, dialect="cityengine",
                     imported=tuple(dict.fromkeys(imported)))


#: The constants a ``const name = comp(fe){ sel: d | ... }`` becomes: ``name{k:sel}``, the k-th distance (no
#: name of the source can be one: braces end an identifier), so that an importing file gets them under its
#: prefix as it gets any attribute, and name resolution types them.
_TABLE_ENTRY = re.compile(r"^(?P<name>.+)\{(?P<k>\d+):(?P<selector>[^{}]+)\}$")


def _table_attrs(table: EdgeTable) -> list[ir.AttrDecl]:
    return [ir.AttrDecl(f"{table.name}{{{k}:{selector}}}", value, table.distances.span, const=True)
            for k, (selector, value) in enumerate(table.distances.values)]


def _setbacks_by_table(rules: list[ir.Rule], attrs: list[ir.AttrDecl]) -> list[ir.Rule]:
    """``setback(name){ ... }`` of a constant ``name = comp(fe){ sel: d | ... }`` (of this file or an
    imported one: ``setback(p.name)``) as ``setback(comp(fe){ sel: d | ... }){ ... }``, its distances per
    edge; CityEngine files keep their setback distances per street side in such constants."""
    tables: dict[str, list[tuple[int, str, str]]] = {}
    for a in attrs:
        entry = _TABLE_ENTRY.match(a.name)
        if entry is not None:
            tables.setdefault(entry["name"], []).append((int(entry["k"]), entry["selector"], a.name))
    if not tables:
        return rules

    def visit(op):
        if not isinstance(op, ir.Setback) or op.per_edge or not op.distances:
            return op
        named = {d.name if isinstance(d, ir.Name) else None for _, d in op.distances}
        table = tables.get(named.pop()) if len(named) == 1 else None
        if table is None:
            return op
        span = op.distances[0][1].span
        distances = tuple((selector, ir.Name(name, span)) for _, selector, name in sorted(table))
        return replace(op, distances=distances, per_edge=True)

    return [replace(rule, alternatives=tuple(replace(alt, body=rewrite_ops(alt.body, visit))
                                             for alt in rule.alternatives)) for rule in rules]


def _in(prefix: str | None, name: str) -> str:
    return name if prefix is None else f"{prefix}.{name}"


def _prefixed(module: ir.Module, prefix: str | None, forwarded: set[str], values: dict[str, ir.Expr]):
    """An imported module's attributes and rules under ``prefix.``; its ``forwarded`` attributes (those
    the importing file declares too and does not protect) are dropped, so that their names resolve to the
    importer's, and those in ``values`` take the importing file's expression as their default."""
    if prefix is None:
        return [replace(a, default=values[a.name]) if a.name in values else a
                for a in module.attrs if a.name not in forwarded], list(module.rules)
    own_attrs = {a.name for a in module.attrs} - forwarded
    rename = partial(_renaming, prefix, own_attrs)
    attrs = [replace(a, name=f"{prefix}.{a.name}", default=values[a.name] if a.name in values
                     else rewrite_expr(a.default, rename(())))
             for a in module.attrs if a.name in own_attrs]
    rules = []
    for rule in module.rules:
        bodies = []
        for alt in rule.alternatives:
            body = _map_symbols(alt.body, lambda op: replace(op, name=f"{prefix}.{op.name}"))
            bodies.append(replace(alt, body=rewrite_body(body, rename(set(rule.params)))))
        rules.append(replace(rule, symbol=f"{prefix}.{rule.symbol}", alternatives=tuple(bodies)))
    return attrs, rules


def _renaming(prefix: str, own_attrs: set[str], params):
    """The rewrite that names an imported file's own attributes (``own_attrs``, not those forwarded to the
    importing file's) ``prefix.name`` in one of its expressions, where ``params`` are no attributes."""
    def visit(e):
        if isinstance(e, ir.Name) and e.name in own_attrs and e.name not in params:
            return replace(e, name=f"{prefix}.{e.name}")
        if isinstance(e, ir.AttrRef) and e.name in own_attrs:  # from an inlined function
            return replace(e, name=f"{prefix}.{e.name}")
        return e
    return visit


def _renamed(body: Callable[[], ir.Expr], visit) -> ir.Expr:
    return rewrite_expr(body(), visit)


def _without_numbers(body: ir.Body, diags: Diagnostics) -> ir.Body:
    """A part's body may parse as a number, for ``comp(fe){ all : 3 }``'s distances; in any other part
    it is an error."""
    def visit(op):
        if isinstance(op, ir.Num):
            diags.error("syntax", "a number where operations are expected", op.span)
            return ir.Empty(op.span)
        return op
    return rewrite_ops(body, visit)


def _map_symbols(body: ir.Body, fn) -> ir.Body:
    """``body`` with ``fn`` applied to every successor symbol, nested bodies included."""
    return rewrite_ops(body, lambda op: fn(op) if isinstance(op, ir.Symbol) else op)


class _Inliner:
    """Replaces calls of user functions (and bare names of parameterless ones) by their bodies.

    A function's body is inlined in its own scope (its parameters, then the attributes) before the
    caller's arguments are bound, so that its names never see the parameters of the rule that calls it.
    """

    def __init__(self, functions: dict[str, FunctionDef], attrs: set[str], diags: Diagnostics):
        self.functions = functions
        self.attrs = attrs
        self.diags = diags
        #: Function name -> its body with the functions it calls inlined (computed once per function).
        self.bodies: dict[str, ir.Expr] = {}
        #: An imported function's name here -> what gives its body in this file's terms (``take``).
        self.foreign: dict[str, Callable[[], ir.Expr]] = {}
        #: The prefixes of the imports that could not be read.
        self.unread: set[str] = set()

    def take(self, exports: dict, prefix: str | None, own_attrs: set[str]) -> None:
        """Make an imported file's functions (its ``exports``) callable here as ``prefix.name(...)``,
        or by their names for an import without a prefix (a function of this file's own wins, as its
        rules do). As CityEngine resolves an imported function, its body sees the imported file's
        attributes and constants, named ``prefix.attr`` here (``own_attrs``), except those forwarded to
        this file's attributes of the same name."""
        for name, (fn, body) in exports.items():
            called = name if prefix is None else f"{prefix}.{name}"
            if called in self.functions:
                continue
            self.functions[called] = replace(fn, name=called)
            self.foreign[called] = body if prefix is None else \
                partial(_renamed, body, _renaming(prefix, own_attrs, set(fn.params)))

    def exported(self, name: str) -> ir.Expr:
        """The body of this file's function ``name`` for a file that imports it: the functions it calls
        inlined, this file's attributes and constants as ``AttrRef``, its parameters as names."""
        fn = self.functions[name]
        return rewrite_expr(self.inlined(fn, ()), lambda e: ir.AttrRef(e.name, e.span) if isinstance(e, ir.Name)
                            and e.name in self.attrs and e.name not in fn.params else e)

    def inlined(self, fn: FunctionDef, calling: tuple[str, ...]) -> ir.Expr:
        """``fn``'s body with the functions it calls inlined, its parameters bare names."""
        if fn.name not in self.bodies:
            foreign = self.foreign.get(fn.name)
            self.bodies[fn.name] = foreign() if foreign is not None else \
                self.expr(fn.value, frozenset(fn.params), (*calling, fn.name))
        return self.bodies[fn.name]

    def expr(self, expr: ir.Expr, params: frozenset, calling: tuple[str, ...] = ()) -> ir.Expr:
        """``expr`` with user functions inlined; ``calling`` are the functions being inlined around it."""
        def visit(e: ir.Expr) -> ir.Expr:
            called = e.name if isinstance(e, ir.Name) else e.func if isinstance(e, ir.Call) else ""
            if "." in called and called.partition(".")[0] in self.unread:
                return ir.placeholder(e.span)
            if isinstance(e, ir.Name) and e.name not in params and e.name not in self.attrs \
                    and e.name in self.functions and not self.functions[e.name].params:
                return self.call(self.functions[e.name], (), e.span, calling)
            # a function of the file's own wins over a built-in of its name (ESRI.lib's string
            # `findFirst(text, match)` predates the array one)
            if isinstance(e, ir.Call) and (e.func in self.functions or e.func not in FUNCTIONS):
                fn = self.functions.get(e.func)
                if fn is None and e.func in UNSUPPORTED_FUNCTIONS:
                    self.diags.error("unsupported", f"unsupported: {e.func}", e.span)
                    return ir.placeholder(e.span)
                if fn is None:
                    self.diags.error("unknown-function", f"unknown function `{e.func}`"
                                     f"{suggest(e.func, [*FUNCTIONS, *self.functions])}", e.span)
                    return ir.placeholder(e.span)
                if len(fn.params) != len(e.args):
                    self.diags.error("arity", f"`{e.func}` takes {len(fn.params)} arguments, got "
                                     f"{len(e.args)}", e.span)
                    return ir.placeholder(e.span)
                return self.call(fn, e.args, e.span, calling)
            return e

        return rewrite_expr(expr, visit)

    def call(self, fn: FunctionDef, args: tuple, span: Span, calling: tuple[str, ...]) -> ir.Expr:
        """``fn`` applied to ``args``: its body with the arguments in place of its parameters.

        A recursive function stays an error, though CityEngine evaluates one. Inlined, its depth would
        be unbounded; evaluated batched, it would need function values in the IR (their parameter and
        result types inferred through the recursion, a fixed point) and an evaluation that walks the
        recursion level by level, each level's calls masked by the conditions that reach them (``case``
        lowers to a ``Select`` that evaluates both branches, which would recurse forever below a base
        case). Few public files recurse (ESRI.lib's plant distributor filters its string lists so); the
        error names the function where it calls itself.
        """
        if fn.name in calling:
            # reported where the function calls itself, once (its body is inlined once)
            self.diags.error("unsupported", f"unsupported: recursive function `{fn.name}` (functions are "
                             "inlined, and a recursion's depth is not known before the derivation)", span)
            return ir.placeholder(span)
        body = self.inlined(fn, calling)
        bound = dict(zip(fn.params, args))

        def substitute(e: ir.Expr) -> ir.Expr:
            if not isinstance(e, ir.Name):
                return e
            if e.name in bound:
                return bound[e.name]  # the caller's expression, already inlined in the caller's scope
            return ir.AttrRef(e.name, e.span) if e.name in self.attrs else e

        return rewrite_expr(body, substitute)
