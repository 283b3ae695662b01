"""frontend/cga2006/assembly.py: a file's statements into one module (priorities, continuation lines,
the start rule)."""

from __future__ import annotations

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir.printer import print_module

from .lowered import FILE, compile_ir, errors, rules


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


def test_search_statements_and_sets_of_consequents():
    text = ('lot ~> Subdiv("X", choose(1, 2, 3), 1r){ a | b }\nb ~> c ?\n  ~> d ?\n'
            'goal: count("a") >= 1 &&\n      min(Scope.sx of "a") >= 2\nprune: area("c") > 10\ncost: Scope.sx\n'
            "heuristic: volume(\"d\")")
    module, diags = compile_ir(text)
    assert not diags
    assert print_module(module).splitlines()[-6:] == [
        'lot ~> Subdiv("X", choose(1, 2, 3), 1r){ a | b } : 1',
        "b ~> c ? ~> d ?",
        'goal: ((count("a") >= 1) && (min(Scope.sx of "a") >= 2))',
        'prune: (area("c") > 10)',
        "cost: Scope.sx",
        'heuristic: volume("d")',
    ]


def test_search_statement_mistakes_are_errors_at_their_place():
    assert errors('a ~> b\ngoal: true\ngoal: false\nfoo: 1\nb ~> c\nx ~> S(choose(), 1, 1) y\n'
                  'g ~> h\nheuristic: area(Scope.sx of "h")') == [
        (3, 1, "`goal:` is given twice (first at line 2)"),
        (4, 1, ("`foo: ...` is neither a rule (it has no `~>` successor) nor a search statement "
               "(`goal:`, `prune:`, `cost:`, `heuristic:`)")),
        (6, 8, "`choose` takes one value or more"),
        (8, 12, ('`area(... of "symbol")` is not an aggregate: count, sum, min, max and mean take a value of each '
                "shape")),
    ]
