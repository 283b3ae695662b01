"""The start rule the command line names (``--start``): a symbol (``Lot``, an imported ``p.Lot``), or a call
of a start rule with parameters with constant arguments (``Lot(12, "tall", true)``).

CityEngine lets a start rule take parameters; a lot has no values for them, so they come from the command
line. A call becomes a rule of its own, named as the call (``Lot(12, "tall", true)``), whose body is the
call: the backend derives a module from a start symbol without parameters, and the types pass checks the
arguments against the rule's parameters as it checks every call. The new rule and its call are placed at
the called rule (their spans are its span), so that every node of the module stays in its files. The
arguments are numbers, strings and booleans, read by a small strict reader: an expression would need the
attributes of a lot that does not exist yet.
"""

from __future__ import annotations

import re
from dataclasses import replace

from grammarc.errors import UsageError
from grammarc.ir import nodes as ir

__all__ = ["with_start"]

_NAME = re.compile(r"\s*([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)\s*")
#: One argument: a number, a string in double or single quotes (no escapes), or a boolean.
_ARGUMENT = re.compile(r"""\s*(?:(?P<num>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"""
                       r"""|"(?P<dq>[^"\\]*)"|'(?P<sq>[^'\\]*)'|(?P<bool>true|false))\s*""")


def with_start(module: ir.Module, text: str) -> ir.Module:
    """``module`` starting as ``text`` says: the symbol it names, or a rule that calls it with the arguments.

    Raises ``UsageError`` when ``text`` is not a name or a call with constant arguments, or calls a rule
    with a wrong number of arguments. A name without a rule is left to ``passes.rulegraph`` to report.
    """
    name, args = _parse(text)
    arities = {r.symbol: len(r.params) for r in module.rules}
    if args is None:
        # a start rule overloaded by arity (`Lot/0`, `Lot/2`) is named by its name alone
        return replace(module, start=name if name in arities or f"{name}/0" not in arities else f"{name}/0")
    symbol = name if name in arities else f"{name}/{len(args)}"
    if symbol not in arities:
        if name not in {s.partition("/")[0] for s in arities}:
            return replace(module, start=name)  # no rule (or one that failed to parse): the pass says
        takes = sorted(n for s, n in arities.items() if s.partition("/")[0] == name)
        raise UsageError(f"--start calls `{name}` with {len(args)} arguments; its rules take "
                         f"{' or '.join(map(str, takes))}")
    called = next(r for r in module.rules if r.symbol == symbol)
    params, span = called.params, called.span
    args = tuple(replace(a, span=span) for a in args)
    if len(params) != len(args):
        raise UsageError(f"--start calls `{name}` with {len(args)} argument{'s' if len(args) != 1 else ''}; "
                         f"it takes {len(params)} ({', '.join(params) or 'none'})")
    call = f"{name}({', '.join(_shown(a) for a in args)})"
    rule = ir.Rule(symbol=call, params=(), guard=None,
                   alternatives=(ir.Alternative((ir.Symbol(symbol, args, span),), None, span),),
                   priority=0, span=span)
    return replace(module, rules=(*module.rules, rule), start=call)


def _parse(text: str) -> tuple[str, tuple[ir.Expr, ...] | None]:
    """``Name`` -> (Name, None); ``Name(1, "a", true)`` -> (Name, its arguments as IR constants)."""
    match = _NAME.match(text)
    if match is None:
        raise UsageError(f"--start takes a rule name or a call `Rule(1, \"a\", true)`, got `{text}`")
    name, at = match.group(1), match.end()
    if at == len(text):
        return name, None
    if text[at] != "(" or not text.rstrip().endswith(")"):
        raise UsageError(f"--start takes a rule name or a call `Rule(1, \"a\", true)`, got `{text}`")
    inner_end = text.rstrip().rindex(")")
    args: list[ir.Expr] = []
    at += 1
    if text[at:inner_end].strip():
        while True:
            arg = _ARGUMENT.match(text, at, inner_end)
            rest = text[at:inner_end].lstrip()
            if not rest or rest.startswith(","):
                raise UsageError(f"--start has an empty argument: `{text}`")
            if arg is None:
                raise UsageError(f"--start arguments are numbers, strings and true/false: cannot read "
                                 f"`{text[at:inner_end].strip()}` in `{text}`")
            args.append(_constant(arg))
            at = arg.end()
            if at == inner_end:
                break
            if text[at] != ",":
                raise UsageError(f"--start arguments are separated by commas: `{text}`")
            at += 1
    return name, tuple(args)


def _constant(match: re.Match) -> ir.Expr:
    if match.group("num") is not None:
        return ir.Num(float(match.group("num")))
    if match.group("bool") is not None:
        return ir.Bool(match.group("bool") == "true")
    return ir.Str(match.group("dq") if match.group("dq") is not None else match.group("sq"))


def _shown(arg: ir.Expr) -> str:
    if isinstance(arg, ir.Num):
        return f"{arg.value:g}"
    if isinstance(arg, ir.Bool):
        return "true" if arg.value else "false"
    return f'"{arg.value}"'
