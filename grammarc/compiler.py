"""Grammar file -> checked grammar ready for the backend: read, parse, run the passes, raise every error.

The passes (``ir.pipeline``) check the module, analyse its rule graph and resolve its assets; the
compiler only reads the file, tells the passes the start symbol and the asset folders, and raises
``GrammarError`` with every error if there is any. Warnings come back with the grammar so that the
command line can show them.
"""

from __future__ import annotations

import hashlib
from dataclasses import replace
from pathlib import Path

from grammarc.diagnostics import Diagnostics, Severity, Span
from grammarc.errors import GrammarError, UsageError
from grammarc.frontend.imports import find_roots
from grammarc.frontend.parse import parse_source
from grammarc.frontend.source import encoding_warning, read_grammar_text
from grammarc.frontend.start import with_start
from grammarc.ir.pipeline import run_passes
from grammarc.model.grammar import Grammar

__all__ = ["Grammar", "compile_grammar"]


def compile_grammar(path: str | Path, *, text: str | None = None, start: str | None = None,
                    asset_roots: tuple[Path, ...] = (), dialect: str | None = None,
                    display: str | None = None, workspace: Path | None = None, derive: bool = True,
                    warnings_as_errors: bool = False) -> Grammar:
    """Parse, check and analyse a grammar file; raise ``GrammarError`` listing every error.

    ``start`` overrides the grammar's start symbol, or calls a start rule with parameters
    (``Lot(10, "tall")``, ``frontend.start``); assets are resolved in the grammar's folder, its
    CityEngine project (``assets``, then the project's root), then in ``asset_roots`` and the workspace
    (``workspace``, a folder of CityEngine projects, or the folder holding the grammar's project), where
    imports are looked up too (``frontend.imports``). ``display`` names the file in diagnostics (a rule
    file inside a package: ``candler.rpk/rules/x.cga``). A file that is not UTF-8 is read as
    Windows-1252, with a warning (``frontend.source``). A grammar to ``derive`` needs rules and the
    arguments of a start rule with parameters (``UsageError`` without them); ``grammarc check`` checks a
    file of declarations only, or one whose start rule takes parameters, with a warning. With
    ``warnings_as_errors`` every warning is an error (``--warnings-as-errors``).
    """
    path = Path(path)
    file = display or str(path)
    diags = Diagnostics()
    if text is None:
        try:
            text, fallback = read_grammar_text(path)
        except OSError as error:
            raise UsageError(f"cannot read grammar {path}: {error.strerror or error}") from None
        if fallback is not None:
            diags.warning("encoding", encoding_warning(file), Span(file, 1, 1, 1, 1))
    sources = {file: text}
    roots = find_roots(path, workspace)
    module = parse_source(text, file, diags, dialect, path=path, sources=sources, roots=roots)
    module = replace(module, roots=roots.asset_roots(tuple(asset_roots)))
    if start:
        module = with_start(module, start)
    module = run_passes(module, diags)
    if warnings_as_errors:
        diags = Diagnostics(replace(d, severity=Severity.ERROR) for d in diags)
    if diags.has_errors:
        raise GrammarError(diags, sources)
    unfed = next((d for d in diags if d.code in ("start-params", "no-rules")), None)
    if derive and unfed is not None:
        raise UsageError(unfed.message)
    return Grammar(path=file, digest=hashlib.sha256(text.encode()).hexdigest(), module=module,
                   warnings=tuple(d for d in diags if not d.is_error), sources=sources, asset_roots=module.roots)
