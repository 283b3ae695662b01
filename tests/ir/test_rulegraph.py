"""ir/passes/rulegraph.py: the start rule, terminals, reachable symbols, recursion and unreachable rules."""

from __future__ import annotations

import random
from dataclasses import replace

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.errors import UsageError
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.pipeline import run_passes

FILE = "g.cga"


def graph(text: str, start: str | None = None) -> tuple[ir.RuleGraph, Diagnostics]:
    diags = Diagnostics()
    module = parse_source(text, FILE, diags)
    module = run_passes(replace(module, start=start or module.start), diags, check=True)
    assert not diags.has_errors
    return module.graph, diags


def test_terminals_nonterminals_and_edges():
    g, diags = graph('a ~> b x [ y ]\nb ~> Subdiv("X", 1r, 1r){ c | z }\nc ~> Comp("faces"){ w | x }\nb ~> v')
    assert not diags
    assert g.start == "a"
    assert g.nonterminals == ("a", "b", "c")
    assert g.terminals == ("x", "y", "z", "w", "v")
    assert g.edges == {"a": ("b", "x", "y"), "b": ("c", "z", "v"), "c": ("w", "x")}
    assert g.reachable == frozenset("abcxyzwv")
    assert g.recursive == frozenset()


def test_symbols_in_nested_bodies_and_all_alternatives_count():
    g, _ = graph('a ~> Subdiv("Y", 1r){ Repeat("X", 1){ Comp("edges"){ deep } } } : 0.5 ~> other : 0.5')
    assert g.edges["a"] == ("deep", "other")


@pytest.mark.parametrize("text, recursive", [
    ("a ~> a", {"a"}),
    ("a ~> b\nb ~> b c", {"b"}),
    ("a ~> b\nb ~> c\nc ~> a", {"a", "b", "c"}),
    ("a ~> b\nb ~> c\nc ~> b", {"b", "c"}),
    ('a ~> Subdiv("X", 1r){ b }\nb : Scope.sx > 1 ~> a\nb ~> leaf', {"a", "b"}),
    ("a ~> b c\nb ~> d\nc ~> d\nd ~> leaf", set()),  # a diamond is not a cycle
    ("a ~> b\nb ~> a\nc ~> d\nd ~> c\nc ~> e", {"a", "b", "c", "d"}),
])
def test_recursion_direct_and_mutual(text, recursive):
    g, _ = graph(text)
    assert g.recursive == frozenset(recursive)


def test_unreachable_rules_warn():
    g, diags = graph("lot ~> a\na ~> b\nc ~> d\nd ~> c\nd ~> e")
    assert g.reachable == frozenset({"lot", "a", "b"})
    assert [(d.severity.value, d.span.line, d.message) for d in diags] == [
        ("warning", 3, "rule for `c` is never reached from `lot`"),
        ("warning", 4, "rule for `d` is never reached from `lot`"),
        ("warning", 5, "rule for `d` is never reached from `lot`"),
    ]


def test_a_recursion_whose_every_rule_has_a_guard_warns():
    """The shape that ends such a recursion stays in the record as a leaf: rarely meant."""
    text = 'lot ~> row(0)\nrow(k) : k < 2 ~> [ T(k * 2, 0, 0) S(1, 1, 1) post ] row(k + 1)\n'
    _, diags = graph(text)
    assert [(d.span.line, d.message) for d in diags] == [(2, (
        "every rule of recursive `row` has a guard: the shape that ends the recursion becomes a leaf (a box "
        "in the record); add `row ~> ε` to drop it"))]
    assert not list(graph(text + "row(k) ~> ε\n")[1])


def test_another_start_symbol():
    g, diags = graph("lot ~> a\na ~> b", start="a")
    assert g.reachable == frozenset({"a", "b"})
    assert [d.message for d in diags] == ["rule for `lot` is never reached from `a`"]


def _reaches(edges: dict[str, set[str]], src: str, dst: str) -> bool:
    """Whether ``dst`` is reachable from ``src`` in one or more steps."""
    seen, stack = set(), list(edges.get(src, ()))
    while stack:
        x = stack.pop()
        if x == dst:
            return True
        if x not in seen:
            seen.add(x)
            stack.extend(edges.get(x, ()))
    return False


def test_recursion_and_reachability_match_a_brute_force_reference():
    # a symbol is recursive iff it reaches itself in one or more steps
    rng = random.Random(7)
    for _ in range(40):
        names = [f"s{i}" for i in range(rng.randint(1, 9))]
        lines = []
        for name in names:
            targets = [t for t in names if rng.random() < 0.2] + ["leaf"]
            lines.append(f"{name} ~> {' '.join(targets)}")
        text = "\n".join(lines)
        g, _ = graph(text, start="s0")
        edges = {s: set(t) for s, t in g.edges.items()}
        assert g.recursive == frozenset(s for s in names if _reaches(edges, s, s)), text
        reached = {s for s in [*names, "leaf"] if _reaches(edges, "s0", s)}
        assert g.reachable == frozenset({"s0"} | reached), text


def test_the_pass_sets_the_graph_of_the_start_symbol_on_the_module():
    diags = Diagnostics()
    module = run_passes(parse_source("a ~> b\nb ~> c", FILE, diags), diags, check=True, stop_after="rulegraph")
    assert module.graph == ir.RuleGraph("a", ("a", "b"), ("c",), frozenset("abc"), frozenset(),
                                        {"a": ("b",), "b": ("c",)})


def test_a_start_rule_with_parameters_in_a_module_to_derive_warns():
    text = "lot(w) ~> b(w)\nb(x) ~> c"
    diags = Diagnostics()
    module = run_passes(replace(parse_source(text, FILE, diags), roots=()), diags, check=True)
    assert [(d.code, d.severity.value, d.span.line, d.message) for d in diags] == [
        ("start-params", "warning", 1, ("the start rule `lot` takes parameters (w): a lot has no arguments to "
         "pass; build it with --start 'lot(...)' giving their values"))]
    assert module.graph.start == "lot"  # made all the same
    # a fragment lowered by a test (no asset folders) is not derived: it may start anywhere
    diags = Diagnostics()
    assert run_passes(parse_source(text, FILE, diags), diags, check=True).graph.start == "lot"
    assert not diags


def test_a_cityengine_file_without_rules_is_a_warning():
    diags = Diagnostics()
    text = 'version "2023.1"\nconst h = 1\n'
    assert run_passes(parse_source(text, FILE, diags), diags, check=True).graph is None
    assert [(d.code, d.severity.name, d.span.line) for d in diags] == [("no-rules", "WARNING", 1)]


def test_no_rules_is_an_error_unless_rules_failed_to_parse():
    diags = Diagnostics()
    assert run_passes(parse_source("attr h = 1\n", FILE, diags), diags).graph is None
    assert [(d.code, d.span.line, d.span.col) for d in diags] == [("empty", 1, 1)]
    diags = Diagnostics()
    run_passes(parse_source("a ~> T(1,,2)", FILE, diags), diags)
    assert [d.code for d in diags] == ["syntax"]


def test_a_start_symbol_without_a_rule_is_the_callers_mistake_unless_errors_are_listed():
    module = parse_source("a ~> b", FILE, Diagnostics())
    with pytest.raises(UsageError, match=f"start symbol `zz` has no rule in {FILE}"):
        run_passes(replace(module, start="zz"), Diagnostics())
    diags = Diagnostics()
    diags.error("syntax", "the start rule failed to parse", module.rules[0].span)
    assert run_passes(replace(module, start="zz"), diags).graph is None


def test_a_cityengine_file_without_start_rule_starts_with_its_first_rule_and_says_so():
    diags = Diagnostics()
    text = 'version "2022.0"\nLot --> Helper\nHelper --> A\n'
    module = run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True)
    assert module.start == module.graph.start == "Lot"
    assert [(d.code, d.span.line, d.message) for d in diags] == [
        ("start-rule", 2, "no @StartRule: starting with `Lot`, the first rule")]
    # the paper's start is its first rule by definition: nothing to say
    assert not graph("a ~> b\nb ~> c")[1]


CITYENGINE = 'version "2022.0"\n@StartRule\nLot --> extrude(10) comp(f){ side : LEAF | top : Roof. }\n'


@pytest.mark.parametrize("leaf, warned", [
    ("facdes", "`facdes` has no rule, so it is a leaf (did you mean `facades`?)"),
    ("Facades", "`Facades` has no rule, so it is a leaf (did you mean `facades`?)"),  # letter case
    ("facades_window", None),  # no rule's name is close
    ("facade", None),  # a prefix of a rule's name: `Window` beside `Windows` is a naming habit
    ("facdes.", None),  # the leaf marker says it is meant
    ("fac", None),  # a short name: every short name is one letter from another
])
def test_a_bare_leaf_that_looks_like_a_typo_of_a_rule_warns(leaf, warned):
    text = CITYENGINE.replace("LEAF", leaf) + "facades --> split(y){ ~3 : Floor }*\n"
    diags = Diagnostics()
    run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True)
    found = [(d.span.line, d.span.col, d.message, d.hint) for d in diags if d.code == "undefined-rule"]
    col = text.splitlines()[2].index(leaf.rstrip(".")) + 1
    hint = f"write `{leaf}.` if it is meant as a leaf"
    assert found == ([] if warned is None else [(3, col, warned, hint)])


def test_the_paper_notation_warns_of_typos_too_without_the_leaf_marker_hint():
    g, diags = graph('lot ~> Subdiv("Y", 1r, 1r){ facdes | roof }\nfacades ~> wall')
    assert [(d.code, d.span.col, d.hint) for d in diags] == [("undefined-rule", 29, ""),
                                                              ("unreachable", 1, "")]
    assert "facdes" in g.terminals


@pytest.mark.parametrize("leaves, rules", [
    ("Bay3 Bay12", "Bay1 --> X\n"),  # a numbered family
    ("Window Tile", "Windows --> X\nTileRow --> X\n"),  # a prefix either way
])
def test_leaves_named_beside_rules_as_files_name_them_do_not_warn(leaves, rules):
    text = f'version "2022.0"\n@StartRule\nLot --> extrude(10) {leaves}\n{rules}'
    diags = Diagnostics()
    run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True)
    assert [d for d in diags if d.code == "undefined-rule"] == []
