"""``grammarc check`` (``commands/grammar_report.py``): the summary of a grammar, why symbols are not fused,
the IR dumped, errors with exit code 2, the start rule it takes."""

from __future__ import annotations

from grammarc.cli import main


def test_check_prints_a_summary(write, capsys):
    grammar = write("g.cga", "lot ~> S(1r, 3, 1r) grow(2)\ngrow(n) : n > 0 ~> grow(n - 1) leaf\n"
                             "grow(n) ~> ε\n")
    assert main(["check", str(grammar)]) == 0
    out = capsys.readouterr().out
    assert "rules:     3 (2 symbols with rules)" in out
    assert "terminals: leaf" in out and "recursive: grow" in out


def test_check_summary_of_a_grammar_of_many_rules_stays_short(write, capsys):
    leaves = " ".join(f"W{i}." for i in range(45))
    grammar = write("g.cga", f'version "2022.0"\n@StartRule\nLot --> {leaves}\n')
    assert main(["check", str(grammar)]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "terminals:" in s)
    assert line.endswith("W39 and 5 more") and "W40" not in line


def test_check_says_why_symbols_are_not_fused(write, capsys):
    grammar = write("g.cga", 'version "2022.0"\n@StartRule\nLot --> extrude(3) comp(f){ top: Roof | all: W. }\n'
                             "Roof --> rotateScope(0, 90, 0) R.\nW --> case touches(): NIL else: X.\n")
    assert main(["check", "--fusion", str(grammar)]) == 0
    out = capsys.readouterr().out
    assert "fusion:    the whole grammar is interpreted: occlusion" in out
    assert "    Lot: an operation no kernel takes: `extrude(3)` at " in out
    assert "    Roof: an operation no kernel takes: `rotateScope(0, 90, 0)` at " in out
    assert "most frequent: an operation no kernel takes `extrude` (1), an operation no kernel takes `rotateScope` (1)" in out


def test_check_dump_ir(write, capsys):
    assert main(["check", "--dump-ir", str(write("g.cga", "attr h = 2 * 3\nlot ~> S(1r, h, 1r) x\n"))]) == 0
    assert "lot ~> S(1r, @h, 1r) x" in capsys.readouterr().out


def test_check_reports_errors_exit_2(write, capsys):
    assert main(["check", str(write("g.cga", "lot ~> T(1, 2)\n"))]) == 2
    assert "`T` takes 3 arguments, got 2" in capsys.readouterr().err


def test_check_says_which_rule_starts_without_start_rule(write, capsys):
    assert main(["check", str(write("g.cga", 'version "2022.0"\nLot --> extrude(3) Mass\nMass --> X\n'))]) == 0
    assert "warning: no @StartRule: starting with `Lot`, the first rule" in capsys.readouterr().err
