"""ir/passes/resolve.py: names become rule parameters (``$x``) or attributes (``@x``)."""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.passes.resolve import resolve_names
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_module, print_rule

FILE = "g.cga"


def resolve(text: str) -> tuple[ir.Module, Diagnostics]:
    diags = Diagnostics()
    module = parse_source(text, FILE, diags)
    assert not diags
    return resolve_names(module, diags), diags


@pytest.mark.parametrize("text, expected", [
    ("a(x) ~> T(x, 0, 0)", "a(x) ~> T($x, 0, 0)"),
    ("attr h = 3\na ~> T(h, 0, 0)", "a ~> T(@h, 0, 0)"),
    ("attr h = 3\na(w) : w > h ~> b(h, w) : h", "a(w) : ($w > @h) ~> b(@h, $w) : @h"),
    ('attr h = 3\na ~> Subdiv("Y", h, 1r, 1r){ b(h) | Comp("edge", h){ c(h) } | Repeat("X", h){ d } }',
     'a ~> Subdiv("Y", @h, 1r, 1r){ b(@h) | Comp("edge", @h){ c(@h) } | Repeat("X", @h){ d } }'),
    ("a(x, y, z) ~> T(z, y, x)", "a(x, y, z) ~> T($z, $y, $x)"),
    ("attr h = 1\na ~> T(sin(h), Scope.sx, -h)", "a ~> T(sin(@h), Scope.sx, -@h)"),
])
def test_names_resolve(text, expected):
    module, diags = resolve(text)
    assert not diags
    assert print_rule(module.rules[-1]) == expected


def test_parameter_indices():
    module, _ = resolve("a(x, y) ~> T(y, x, y)")
    assert [e.index for e in module.rules[0].alternatives[0].body[0].vector] == [1, 0, 1]


def test_parameter_shadows_attribute_with_a_warning():
    module, diags = resolve("attr h = 3\na(h) ~> T(h, 0, 0)\nb ~> T(h, 0, 0)")
    assert print_rule(module.rules[0]) == "a(h) ~> T($h, 0, 0)"
    assert print_rule(module.rules[1]) == "b ~> T(@h, 0, 0)"
    [d] = diags
    assert (d.severity.value, d.code, d.span.line, d.span.col) == ("warning", "shadow", 2, 1)
    assert d.message == "parameter `h` of `a` hides the attribute `h`"


def test_attribute_default_may_use_an_earlier_attribute():
    module, diags = resolve("attr a = 2\nattr b = a * 3\nx ~> y")
    assert not diags
    assert print_module(module).splitlines()[:2] == ["attr a = 2", "attr b = (@a * 3)"]


def test_attribute_default_may_not_use_a_later_attribute():
    _, diags = resolve("attr c = d + 1\nattr d = 1\nx ~> y")
    [d] = diags
    assert (d.code, d.span.line, d.span.col) == ("attr-order", 1, 10)
    assert d.message == "attribute `d` is used in attribute `c` before its declaration"


def test_attribute_default_may_not_use_itself():
    _, diags = resolve("attr c = c + 1\nx ~> y")
    assert [(d.span.line, d.span.col, d.message) for d in diags] == [
        (1, 10, "attribute `c` is used in attribute `c` before its declaration")]


def test_parameters_are_not_visible_in_attribute_defaults():
    _, diags = resolve("attr c = x\nr(x) ~> y")
    [d] = diags
    assert d.message.startswith("unknown identifier `x` in attribute `c`")


def test_unknown_identifier_names_it_and_suggests():
    _, diags = resolve("attr height = 3\na(width) ~> T(hieght, widht, zz)")
    assert [(d.span.col, d.message) for d in diags] == [
        (15, "unknown identifier `hieght` in rule `a` (did you mean `height`?)"),
        (23, "unknown identifier `widht` in rule `a` (did you mean `width`?)"),
        (30, "unknown identifier `zz` in rule `a`"),
    ]
    assert all(d.hint.startswith("declare it with `attr") for d in diags)


def test_parameters_of_one_rule_are_not_visible_in_another():
    _, diags = resolve("a(x) ~> b\nb ~> T(x, 0, 0)")
    [d] = diags
    assert (d.span.line, d.message) == (2, "unknown identifier `x` in rule `b`")


def test_unknown_identifier_becomes_a_placeholder_that_does_not_cascade():
    # `frieze_decoration == "none"` with the attribute missing is one error, not also a type error
    diags = Diagnostics()
    run_passes(parse_source('frieze : frieze_decoration == "none" ~> wall', FILE, diags), diags, check=True)
    assert [d.message for d in diags] == ["unknown identifier `frieze_decoration` in rule `frieze`"]


def test_nothing_to_resolve_returns_the_same_module():
    diags = Diagnostics()
    module = parse_source('attr a = 1\nx ~> T(1, 2, 3) Subdiv("X", 1r){ y }', FILE, diags)
    assert resolve_names(module, diags) is module


@pytest.mark.parametrize("declarations, expected", [
    ("attr a = b\nattr b = a\n", [(2, "attribute `a` has no value: its default uses itself (attr a -> b -> a)")]),
    ("attr a = a + 1\n", [(2, "attribute `a` has no value: its default uses itself (attr a -> a)")]),
    # through a constant, and through a function (inlined by then)
    ("attr a = 2 * c\nconst c = b\nattr b = a\n",
     [(2, "attribute `a` has no value: its default uses itself (attr a -> c -> b -> a)")]),
    ("f(x) = x + e\nattr e = f(1)\n", [(3, "attribute `e` has no value: its default uses itself (attr e -> e)")]),
    # an attribute that uses a cycle is not on it: one error, at the cycle
    ("attr g = a\nattr a = b\nattr b = a\n",
     [(3, "attribute `a` has no value: its default uses itself (attr a -> b -> a)")]),
    ("attr a = b\nattr b = 3\n", []),  # a later attribute, no cycle
])
def test_a_cycle_of_cityengine_attributes_is_an_error_naming_it(declarations, expected):
    text = 'version "2022.0"\n' + declarations + "@StartRule\nLot --> X\n"
    diags = Diagnostics()
    run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True)
    assert [(d.span.line, d.message) for d in diags if d.code == "attr-cycle"] == expected
    assert [d.code for d in diags if d.is_error and d.code != "attr-cycle"] == []


def test_a_builtin_without_arguments_may_be_written_bare():
    """CityEngine reads ``rand`` alone as ``rand()``; each bare call draws at a site of its own, and a
    parameter or attribute of that name wins."""
    module, diags = resolve("a ~> T(rand, rand, 0)")
    assert not diags
    first, second = module.rules[0].alternatives[0].body[0].vector[:2]
    assert (first.func, second.func) == ("rand", "rand") and first.site != second.site
    module, _ = resolve("attr rand = 2\nb ~> T(rand, 0, 0)")
    assert print_rule(module.rules[0]) == "b ~> T(@rand, 0, 0)"
