"""frontend/start.py: ``--start`` names the start rule, imported ones too, or calls a start rule with
parameters with constant arguments through a rule of its own."""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.errors import UsageError
from grammarc.frontend.parse import parse_source
from grammarc.frontend.start import with_start
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_rule

VERSION = 'version "2022.0"\n'
TEXT = VERSION + '@StartRule\nLot(h, kind, flat) --> extrude(h) Mass(kind, flat)\nMass(kind, flat) --> X\n'


def started(text: str, start: str, path=None) -> ir.Module:
    diags = Diagnostics()
    module = parse_source(text, str(path or "g.cga"), diags, "cityengine", path=path)
    module = run_passes(with_start(module, start), diags, check=path is None)
    assert not diags.has_errors, diags
    return module


@pytest.mark.parametrize("start, call", [
    ('Lot(12, "tall", true)', 'Lot(12, "tall", true)'),
    ("  Lot ( -1.5e1 ,'a',false ) ", 'Lot(-15, "a", false)'),
    ("Lot(.5, \"\", true)", 'Lot(0.5, "", true)'),
])
def test_a_call_becomes_the_start_rule_calling_it(start, call):
    module = started(TEXT, start)
    assert module.start == module.graph.start == call
    assert print_rule(module.rules[-1]) == f"{call} ~> {call} : 1"  # its body is the call
    assert module.graph.reachable >= {call, "Lot", "Mass", "X"}


def test_a_name_starts_there():
    module = started(VERSION + "Lot --> A\nOther --> B\n", "Other")
    assert module.graph.start == "Other" and len(module.rules) == 2


def test_a_start_rule_overloaded_by_arity():
    text = VERSION + "Lot --> Lot(10)\nLot(h) --> extrude(h) X\n"
    assert started(text, "Lot").graph.start == "Lot/0"
    module = started(text, "Lot(4)")
    assert module.graph.start == "Lot(4)" and module.graph.edges["Lot(4)"] == ("Lot/1",)


def test_an_imported_rule_by_its_prefixed_name(tmp_path):
    (tmp_path / "house.cga").write_text(VERSION + "Building(h) --> extrude(h) X\nShed --> extrude(2) X\n")
    main = tmp_path / "main.cga"
    main.write_text(VERSION + 'import house : "house.cga"\nLot --> house.Shed\n')
    assert started(main.read_text(), "house.Shed", main).graph.start == "house.Shed"
    module = started(main.read_text(), "house.Building(7)", main)
    assert module.graph.start == "house.Building(7)"
    assert module.graph.edges["house.Building(7)"] == ("house.Building",)


@pytest.mark.parametrize("start, message", [
    ("Lot(1, 2)", r"--start calls `Lot` with 2 arguments; it takes 3 \(h, kind, flat\)"),
    ('Lot(1, "a", true, 4)', r"--start calls `Lot` with 4 arguments; it takes 3"),
    ("Lot(h, 1, 2)", r"--start arguments are numbers, strings and true/false: cannot read `h, 1, 2`"),
    ("Lot(1 + 2, 1, 2)", r"cannot read `\+ 2, 1, 2`|separated by commas"),
    ("Lot(1,, 2)", r"--start has an empty argument"),
    ("Lot(1, 2", r"--start takes a rule name or a call"),
    ("3Lot", r"--start takes a rule name or a call"),
    ('Lot(1, "a\\"b", true)', r"cannot read"),
])
def test_a_start_that_is_not_a_call_with_constants_is_a_usage_error(start, message):
    with pytest.raises(UsageError, match=message):
        started(TEXT, start)


def test_a_start_rule_without_a_rule_is_left_to_the_rule_graph():
    with pytest.raises(UsageError, match="start symbol `Lots` has no rule"):
        started(TEXT, "Lots(1)")
