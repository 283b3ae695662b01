"""Paper-notation text to IR for the tests of this package: after the IR passes (verified after each),
printed as canonical text (``$h`` parameters, ``@name`` attributes, binaries parenthesized, every
alternative with its probability), or the errors it gives.
"""

from __future__ import annotations

from grammarc.diagnostics import Diagnostics, render_all
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_rule

FILE = "g.cga"


def compile_ir(text: str) -> tuple[ir.Module, Diagnostics]:
    """Lower ``text`` and run the passes with the IR verified after each."""
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags), diags, check=True)
    return module, diags


def diagnose(text: str) -> Diagnostics:
    return compile_ir(text)[1]


def rules(text: str) -> list[str]:
    """The printed rules of a grammar without errors."""
    module, diags = compile_ir(text)
    assert not diags.has_errors, render_all(diags, {FILE: text})
    return [print_rule(r) for r in module.rules]


def errors(text: str) -> list[tuple[int, int, str]]:
    """(line, col, message) of every error, of lowering and the passes, in source order."""
    return sorted((d.span.line, d.span.col, d.message) for d in diagnose(text) if d.is_error)


def lowering_errors(text: str) -> list[tuple[int, int, str]]:
    """(line, col, message) of the errors of parsing and lowering alone, as reported."""
    diags = Diagnostics()
    parse_source(text, FILE, diags)
    return [(d.span.line, d.span.col, d.message) for d in diags if d.is_error]
