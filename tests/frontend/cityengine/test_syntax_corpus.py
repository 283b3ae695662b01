"""tests/frontend/grammars/cityengine/syntax: one small rule file per construct of CityEngine's free syntax
(indented declarations, bodies in column 1, annotations, case and p% expressions, case without else,
leaves of rules with parameters, typed parameters, a byte order mark), written the way public rule files
write them. Each parses and lowers without a problem and builds on a lot.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from grammarc.cli import main
from grammarc.compiler import compile_grammar

SYNTAX = Path(__file__).parents[1] / "grammars" / "cityengine" / "syntax"
FILES = sorted(SYNTAX.glob("*.cga"))


def test_the_corpus_has_a_file_per_construct():
    assert [f.stem for f in FILES] == [
        "annotations", "byte_order_mark", "case_expressions", "case_without_else", "column1_bodies",
        "indented_declarations", "parameterised_leaves", "typed_parameters",
    ]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_parses_lowers_and_builds(path, tmp_path):
    grammar = compile_grammar(path)
    assert grammar.module.dialect == "cityengine"
    assert grammar.warnings == ()
    assert main(["build", str(path), "--emit", str(tmp_path / "out.npz"), "--quiet", "--workers", "1"]) == 0
