"""frontend/cga2006/assembly.py: a file's statements into one module (priorities, continuation lines,
the start rule)."""

from __future__ import annotations

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir.printer import print_module

from .lowered import FILE, compile_ir, rules


def test_stochastic_continuation_lines_indented_and_at_column1():
    text = "a ~> b : 0.5\n    ~> c : 0.25\n; d : 0.125\n\u2192 e : 0.125\nf ~> g"
    assert rules(text) == ["a ~> b : 0.5 ~> c : 0.25 ~> d : 0.125 ~> e : 0.125", "f ~> g : 1"]


def test_priority_blocks_assign_priorities():
    text = "a ~> b\nPRIORITY 1:\nb ~> c\nc ~> d\nPRIORITY 3:\nd ~> e\nPRIORITY 2:\ne ~> f"
    module, diags = compile_ir(text)
    assert not diags
    priorities = [(r.symbol, r.priority) for r in module.rules]
    assert priorities == [("a", 0), ("b", 1), ("c", 1), ("d", 3), ("e", 2)]
    assert print_module(module).splitlines()[:3] == ["PRIORITY 0:", "a ~> b : 1", "PRIORITY 1:"]


def test_start_is_the_first_rule():
    module, _ = compile_ir("attr x = 1\nlot ~> a\na ~> b")
    assert module.start == "lot"


def test_stochastic_continuation_without_a_rule():
    diags = Diagnostics()
    parse_source("// nothing before\n~> x : 1", FILE, diags)
    [d] = diags
    assert (d.span.line, d.span.col) == (2, 1)
    assert d.message == "a stochastic alternative needs a rule before it"
