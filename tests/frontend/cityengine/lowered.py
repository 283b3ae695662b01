"""CityEngine text to IR for the tests of this package: after the IR passes (verified after each), printed as
canonical text (``$p`` parameters, ``@name`` attributes, binaries parenthesized), or the errors it gives.
The grammars are written the way public CityEngine rule files use the features.
"""

from __future__ import annotations

import re
from pathlib import Path

from grammarc.diagnostics import Diagnostics, render_all
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_rule

FILE = "g.cga"
GRAMMARS = Path(__file__).parents[1] / "grammars" / "cityengine"
VERSION = 'version "2022.0"\n'


def compile_ir(text: str) -> tuple[ir.Module, Diagnostics]:
    """Lower and run the passes with the IR verified after each (CityEngine dialect)."""
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True)
    return module, diags


def module_of(text: str) -> ir.Module:
    module, diags = compile_ir(text)
    assert not diags.has_errors, render_all(diags, {FILE: text})
    return module


def rules(text: str) -> dict[str, str]:
    """Symbol -> printed rule, for a grammar without errors."""
    return {r.symbol: print_rule(r) for r in module_of(text).rules}


def body_of(text: str, symbol: str = "Lot") -> str:
    """The printed body of ``symbol``'s rule (between the arrow and the probability)."""
    printed = rules(text)[symbol]
    return printed.split(" ~> ", 1)[1].removesuffix(" : 1")


def errors(text: str) -> list[tuple[int, int, str]]:
    """(line, col, message) of every error, lowering and passes."""
    diags = Diagnostics()
    run_passes(parse_source(text, FILE, diags, "cityengine"), diags)
    return [(d.span.line, d.span.col, d.message) for d in diags if d.is_error]



def assert_unsupported_at(line: str, name: str, at: str) -> None:
    """``line`` (the second of a file) gives one error, ``unsupported: name``, where ``at`` starts."""
    text = VERSION + line + "\nOther --> A\n"
    found = errors(text)
    col = line.index(at) + 1
    assert len(found) == 1, found
    got_line, got_col, message = found[0]
    assert (got_line, got_col) == (2, col), found
    assert re.fullmatch(rf"unsupported: {re.escape(name)}( \(.*\))?", message), message
