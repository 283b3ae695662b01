"""Helpers of the function tests: a CityEngine grammar derived on unit lots, what it reported per lot, and
the errors a grammar gives."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.errors import GrammarError
from grammarc.io.lots import lots_from_polygons

VERSION = 'version "2022.0"\n'
SQUARE = [np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)]


def reported(write, text: str, lots: int = 1, attrs=None, **options) -> list[dict]:
    """Per lot, ``{key: value}`` of what ``text`` reported (each lot reports each key once here)."""
    grammar = compile_grammar(write("g.cga", VERSION + text))
    records = derive(grammar, lots_from_polygons([SQUARE] * lots, attrs=attrs), BuildOptions(**options))
    per_lot = records["reports"].lots
    return [{key: bool(e["sum"]) if e["kind"] == "bool" else e["sum"] for key, e in per_lot.get(lot, {}).items()}
            for lot in range(lots)]


def errors(write, text: str) -> list[tuple[int, int, str]]:
    """(line, column, message) of each error of ``text`` (after the version line, as its line 2...)."""
    with pytest.raises(GrammarError) as info:
        compile_grammar(write("g.cga", VERSION + text))
    return sorted((d.span.line, d.span.col, d.message) for d in info.value.diagnostics if d.is_error)
