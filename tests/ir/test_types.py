"""ir/passes/types.py: expression types, successor arities and parameter types from call sites."""

from __future__ import annotations

from dataclasses import dataclass, replace

import pytest
from node_zoo import EXPRESSIONS, NODE_CLASSES, Zoo, sentinels

from grammarc.diagnostics import NO_SPAN, Diagnostics, Span
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.passes.types import infer_types
from grammarc.ir.pipeline import run_passes
from grammarc.ir.traverse import iter_nodes, rewrite_expr, rewrite_node

FILE = "g.cga"
T = ir.Type


def typed(text: str) -> tuple[ir.Module, Diagnostics]:
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags), diags, check=True, stop_after="types")
    return module, diags


def errors(text: str) -> list[tuple[int, int, str]]:
    return [(d.span.line, d.span.col, d.message) for d in typed(text)[1] if d.is_error]


@pytest.mark.parametrize("text, expected", [
    # guards are bool
    ("a : 3 ~> b", [(1, 5, "a guard must be a bool, got a num")]),
    ('attr s = "x"\na : s ~> b', [(2, 5, "a guard must be a bool, got a str")]),
    ("a(x) : x + 1 ~> b", [(1, 10, "a guard must be a bool, got a num")]),
    # operators
    ('a ~> T("a" * 1, 0, 0)', [(1, 12, "`*` cannot combine a str and a num")]),
    ('a ~> T(2 * "b", 0, 0)', [(1, 10, "`*` cannot combine a num and a str")]),
    ('a : 1 < "x" ~> b', [(1, 7, "`<` cannot combine a num and a str")]),
    ('a : "x" >= true ~> b', [(1, 9, "`>=` cannot combine a str and a bool")]),
    ("a : true < false ~> b", [(1, 10, "`<` cannot combine a bool and a bool")]),
    ("a : true + 1 > 0 ~> b", [(1, 10, "`+` cannot combine a bool and a num")]),
    ("a : 1 && true ~> b", [(1, 5, "`&&` cannot combine a num and a bool")]),
    ("a : !1 ~> b", [(1, 6, "the operand of `!` must be a bool, got a num")]),
    ("a ~> T(-true, 0, 0)", [(1, 9, "the operand of `-` must be a num, got a bool")]),
    ('a ~> T(sin("x"), 0, 0)', [(1, 12, "an argument of `sin` must be a num, got a str")]),
    # operations take numbers
    ('a ~> T("x", 0, 0)', [(1, 8, "a translation must be a num, got a str")]),
    ("a ~> S(1r, true, 1)", [(1, 12, "a size must be a num, got a bool")]),
    ('a ~> R(0, "x", 0)', [(1, 11, "an angle must be a num, got a str")]),
    ('a ~> Subdiv("X", "x", 1r){ b | c }', [(1, 18, "a size must be a num, got a str")]),
    ('a ~> Repeat("X", true){ b }', [(1, 18, "a size must be a num, got a bool")]),
    ('a ~> b : "p" ~> c : 0.5', [(1, 10, "a probability must be a num, got a str")]),
    # attribute defaults are checked too
    ('attr a = "x" - 1\nb ~> c', [(1, 14, "`-` cannot combine a str and a num")]),
    # well-typed: equality on any two values (a string and another as strings), order on numbers and on
    # strings, logic on bools
    ('a : "x" == "x" && true != false || !(1 >= 2) ~> b', []),
    ('a : 1 == "x" || "x" != true || "a" < "b" ~> b', []),
])
def test_type_errors(text, expected):
    assert errors(text) == expected


@pytest.mark.parametrize("text, expected", [
    ("a ~> b(1, 2)\nb(x) ~> c", [(1, 6, "`b` takes 1 argument, got 2")]),
    ("a ~> b\nb(x) ~> c", [(1, 6, "`b` takes 1 argument, got 0")]),
    ("a ~> b(1)\nb ~> c", [(1, 6, "`b` takes 0 arguments, got 1")]),
    ("a ~> b(1, 2)\nb(x, y, z) ~> c", [(1, 6, "`b` takes 3 arguments, got 2")]),
    ('a ~> Subdiv("X", 1r){ b(1, 2) }\nb(x) ~> c', [(1, 23, "`b` takes 1 argument, got 2")]),
    ("b(x) ~> c\nb ~> d",
     [(2, 1, "rules of `b` disagree: this one takes 0 parameters, the one at line 1 takes 1")]),
    ("b(x) ~> c\nb(x, y) : y > 0 ~> d",
     [(2, 1, "rules of `b` disagree: this one takes 2 parameters, the one at line 1 takes 1")]),
    ("b(x) ~> c\nb(y) : y > 0 ~> d", []),
])
def test_successor_arity(text, expected):
    assert errors(text) == expected


def test_symbol_without_rules_may_take_arguments_with_a_warning():
    _, diags = typed("a ~> leaf(1, 2)")
    [d] = diags
    assert (d.severity.value, d.code) == ("warning", "terminal-args")


def test_parameter_types_from_call_sites_including_strings():
    module, diags = typed('a ~> b("x", 1, true)\nb(s, n, f) : f && s == "x" ~> T(n, 0, 0)')
    assert not diags
    assert dict(module.param_types) == {"a": (), "b": (T.STR, T.NUM, T.BOOL)}


def test_parameter_types_flow_through_parameters():
    # c's parameter is a string because b passes on the string it got from a
    module, diags = typed('a ~> b("x")\nb(s) ~> c(s)\nc(t) ~> T(t, 0, 0)')
    assert dict(module.param_types)["c"] == (T.STR,)
    assert [(d.span.line, d.span.col, d.message) for d in diags] == [
        (3, 11, "a translation must be a num, got a str")]


def test_parameter_types_flow_through_a_long_chain_in_reverse_order():
    # the rules come in the reverse of the call order, so inference needs one round per link
    chain = [f"s{i}(p) ~> s{i + 1}(p)" for i in range(6, 0, -1)]
    text = "\n".join([*chain, 's0 ~> s1("x")', 's7(p) : p == "x" ~> z'])
    module, diags = typed(text)
    assert not diags
    assert dict(module.param_types)["s7"] == (T.STR,)


def test_parameter_types_from_attributes_and_expressions():
    module, _ = typed(
        'attr name = "n"\nattr big = 1 > 0\na ~> b(name, big, 1 + 2, Scope.sx < 1)\nb(p, q, r, s) ~> c')
    assert dict(module.param_types)["b"] == (T.STR, T.BOOL, T.NUM, T.BOOL)


def test_a_parameter_never_passed_a_value_is_a_number():
    module, _ = typed("a ~> c\nb(x) ~> T(x, 0, 0)")
    assert dict(module.param_types)["b"] == (T.NUM,)


def test_a_parameter_no_call_passes_takes_its_type_from_its_uses():
    # a library's rule, called only from the files that import it: CityEngine infers its parameters
    text = ('version "2022.0"\nPlank(kind, name, big, n, skin) -->\n    case kind == "nailed" && big :\n'
            '        s(n, 1, 1) texture(skin) i(name)\n    else : X.\n')
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True, stop_after="types")
    assert not diags.has_errors
    assert dict(module.param_types)["Plank"] == (T.STR, T.STR, T.BOOL, T.NUM, T.STR)


def test_a_parameter_only_passed_on_takes_the_type_of_the_parameter_it_is_passed_to():
    # a start rule's parameters, which no call gives values, handed down to rules that use them
    text = ('version "2022.0"\n@StartRule\nStairway(colour, steps) --> Level(colour, steps)\n'
            'Level(c, n) --> Step(c) split(x){ ~n : X. }*\nStep(c) --> color(c) Y.\n')
    diags = Diagnostics()
    module = run_passes(parse_source(text, FILE, diags, "cityengine"), diags, check=True, stop_after="types")
    assert not diags.has_errors
    assert dict(module.param_types)["Stairway"] == (T.STR, T.NUM)


def test_conflicting_call_sites_report_the_later_one():
    # the first call site decides the type; later ones are checked against it
    module, diags = typed('a ~> b(1) b("x")\nb(x) ~> c')
    assert dict(module.param_types)["b"] == (T.NUM,)
    assert [(d.span.col, d.message) for d in diags] == [(13, 'argument 1 of `b` must be a num, got a str')]


def test_attribute_types():
    module, diags = typed('attr a = 1\nattr b = a > 0\nattr c = "s"\nattr d = -a * 2\nattr e = !b\nx ~> y')
    assert not diags
    assert [(a.name, a.type) for a in module.attrs] == [
        ("a", T.NUM), ("b", T.BOOL), ("c", T.STR), ("d", T.NUM), ("e", T.BOOL)]


def test_types_pass_fills_param_types_for_every_symbol():
    diags = Diagnostics()
    module = parse_source("a ~> b(1)\nb(x) ~> c\nc ~> d", FILE, diags)
    from grammarc.ir.passes.resolve import resolve_names

    module = infer_types(resolve_names(module, diags), diags)
    assert module.param_types == (("a", ()), ("b", (T.NUM,)), ("c", ()))


# ------------------------------------------------------------------------------- the declarations drive it

#: A literal of each type, and one of another type.
_RIGHT = {T.NUM: ir.Num(1.0), T.BOOL: ir.Bool(True), T.STR: ir.Str("x.obj"), None: ir.Num(1.0),
          T.STRS: ir.ArrayLit(((ir.Str("color.r"), ir.Str("1")),))}
_WRONG = {T.NUM: ir.Str("x"), T.BOOL: ir.Num(1.0), T.STR: ir.Num(1.0), T.STRS: ir.Num(1.0)}


def _wanted(node) -> dict[int, tuple[ir.Type | None, str]]:
    """Sentinel id -> (its wanted type, its noun), from the declarations of the node that holds it."""
    found = {}
    for holder in [node] if type(node) in EXPRESSIONS else iter_nodes(node):
        for name, spec in ir.children(type(holder)):
            value = getattr(holder, name)
            if spec.holds is ir.Holds.BRANCHES:
                value = tuple(cond for cond, _ in value)
            elif spec.holds is not ir.Holds.EXPRS:
                continue
            what = spec.what_of(holder)
            nouns = what if isinstance(what, tuple) else (what,)
            for k, sentinel in enumerate(sentinels(value)):
                found[id(sentinel)] = spec.want_of(holder), nouns[k % len(nouns)]
    return found


def _type_errors(node) -> list[tuple[Span, str]]:
    """The type errors of ``node`` in a module: an expression as an attribute's default (an aggregate as a
    heuristic), an operation in a rule's body, an alternative or a rule as itself."""
    if type(node) in EXPRESSIONS:
        attrs, rules = (ir.AttrDecl("x", node),), ()
    else:
        alt = node if isinstance(node, ir.Alternative) else ir.Alternative((node,), ir.Num(1.0))
        attrs, rules = (), (node if isinstance(node, ir.Rule) else ir.Rule("a", (), None, (alt,), 0),)
    objectives = ()
    if type(node) is ir.Aggregate:  # a design's value: only the search statements read it
        attrs, objectives = (), (ir.Objective("heuristic", node),)
    diags = Diagnostics()
    infer_types(ir.Module("g.cga", attrs, rules, rules[0].symbol if rules else None, objectives=objectives), diags)
    return [(d.span, d.message) for d in diags if d.is_error]


CHECKED = [c for c in NODE_CLASSES if any(spec.want is not None for _, spec in ir.children(c))]


@pytest.mark.parametrize("cls", CHECKED, ids=lambda c: c.__name__)
def test_every_declared_child_is_checked_for_its_type(cls):
    """One wrong-typed expression in a checked child: one error, at it, naming it as declared."""
    node = Zoo().node(cls)
    wanted = _wanted(node)
    rewrite = rewrite_expr if cls in EXPRESSIONS else rewrite_node

    def filled(wrong=None):
        def fill(e):
            if id(e) not in wanted:
                return e
            literal = _WRONG[wanted[id(e)][0]] if e is wrong else _RIGHT[wanted[id(e)][0]]
            return replace(literal, span=e.span)
        return rewrite(node, fill)

    assert _type_errors(filled()) == []
    checked = [s for s in sentinels(node) if wanted.get(id(s), (None,))[0] is not None]
    assert checked
    for s in checked:
        want, what = wanted[id(s)]
        got = {T.NUM: T.STR}.get(want, T.NUM)
        assert _type_errors(filled(s)) == [(s.span, f"{what} must be a {want.value}, got a {got.value}")]


def test_a_new_operation_is_checked_from_its_declarations_alone():
    @dataclass(frozen=True, slots=True)
    class Twist:
        angle: ir.Expr = ir.child(ir.Type.NUM, "a twist angle")
        span: Span = NO_SPAN

    where = Span("g.cga", 1, 7, 1, 10)
    assert _type_errors(Twist(ir.Str("x", where))) == [(where, "a twist angle must be a num, got a str")]


# --------------------------------------------------------------------------------------------------- arrays


def cityengine_errors(text: str) -> list[tuple[int, int, str]]:
    diags = Diagnostics()
    run_passes(parse_source('version "2022.0"\n' + text, FILE, diags, "cityengine"), diags, check=True,
               stop_after="types")
    return [(d.span.line - 1, d.span.col, d.message) for d in diags if d.is_error]


def attr_types(text: str) -> dict[str, ir.Type]:
    diags = Diagnostics()
    module = run_passes(parse_source('version "2022.0"\n' + text + "\nLot --> X\n", FILE, diags, "cityengine"),
                        diags, check=True, stop_after="types")
    assert not diags.has_errors
    return {a.name: a.type for a in module.attrs}


def test_array_types_follow_their_elements_and_indices():
    got = attr_types('attr a = [1, 2 ; 3, 4]\nattr s = ["x", "y"]\nattr b = [true]\nattr r = [0 : 3]\n'
                     'attr i = a[1, 0]\nattr j = a[[0, 1]]\nattr k = s[a .> 2]\nattr n = size(s)\n'
                     'attr t = transpose(s)\nattr o = sortIndices(s)\nattr e = a == [1]\nattr w = s .+ 1\n'
                     'attr c = case n > 1 : a else : [0]\nattr f = findFirst(b, true)\nattr z = isNull("x")')
    assert got == {"a": T.NUMS, "s": T.STRS, "b": T.BOOLS, "r": T.NUMS, "i": T.NUM, "j": T.NUMS, "k": T.STRS,
                   "n": T.NUM, "t": T.STRS, "o": T.NUMS, "e": T.BOOL, "w": T.STRS, "c": T.NUMS, "f": T.NUM,
                   "z": T.BOOL}


@pytest.mark.parametrize("text, expected", [
    ('attr a = [1, "x"]', [(1, 10, "the values of an array are a num and a str")]),
    ('attr a = [1, ["x"]]', [(1, 10, "the values of an array are a num and a str")]),
    ("attr a = 3\nattr b = a[0]", [(2, 10, "only an array can be indexed, got a num")]),
    ('attr a = [1]\nattr b = a["x"]', [(2, 12, "an index must be a num, a num[] or a bool[], got a str")]),
    ('attr a = [1]\nattr b = a + 1', [(2, 12, "`+` cannot combine a num[] and a num")]),
    ('attr a = [1]\nattr b = a < [2]', [(2, 12, "unsupported: the order of whole arrays (`<`)")]),
    ('attr a = [1]\nattr b = "a: " + a', [(2, 16, "unsupported: an array written into a string (`+`)")]),
    ('attr a = [1]\nattr b = a - [2]', [(2, 12, "`-` cannot combine a num[] and a num[]")]),
    ('attr a = [1]\nattr b = a == ["x"]', [(2, 12, "`==` cannot combine a num[] and a str[]")]),
    ("attr b = 1 .+ 2", [(1, 12, "`.+` cannot combine a num and a num")]),
    ("attr b = [true] .+ [1]", [(1, 17, "`.+` cannot combine a bool[] and a num[]")]),
    ('attr b = [true] .< [false]', [(1, 17, "`.<` cannot combine a bool[] and a bool[]")]),
    ("attr b = size(3)", [(1, 15, "the argument of `size` must be an array, got a num")]),
    ("attr b = sortIndices([true])",
     [(1, 22, "the argument of `sortIndices` must be a num[] or a str[], got a bool[]")]),
    ('attr b = findFirst([1], "x")', [(1, 25, "`findFirst` looks for a num in a num[], got a str")]),
    ("attr b = nRows([1], [2])", [(1, 10, "`nRows` takes 1 argument, got 2")]),
    ('attr b = findFirst(["a"], "a", 0.5)', [(1, 32, "a tolerance of `findFirst` is for a num[], not a str[]")]),
    ("attr b = str([1, 2])", [(1, 14, "`str` takes no array, got a num[]")]),
    ("attr b = floor([1.5])", [(1, 16, "an argument of `floor` must be a num, got a num[]")]),
    ("attr b = [0 : true]", [(1, 15, "the end of a range must be a num, got a bool")]),
    ("Lot --> extrude([1, 2])", [(1, 17, "a height must be a num, got a num[]")]),
    ("attr h = [1]\nLot --> set(h, [2]) X", [(2, 16, "unsupported: an array as the value of `h`")]),
])
def test_array_type_errors(text, expected):
    assert cityengine_errors(text) == expected


@pytest.mark.parametrize("text, expected", [
    ('a ~> S(count("b"), 1, 1) b', (1, 8, ('`count` of "b" is a value of a whole design: only `goal:`, '
                                          '`heuristic:` and `prune:` read it'))),
    ("a ~> b\ngoal: choose(1, 2) > 1", (2, 7, "`choose` makes the consequents of a rule, not of a search statement")),
    ('a ~> S(choose(1, "x"), 1, 1) b', (1, 8, "the options of `choose` give a num and a str")),
    ('a ~> b\ngoal: sum(count("b") of "b") > 1', (2, 7, "an aggregate inside `sum`: it reads one shape's values")),
    ('a ~> b\ncost: count("b")', (2, 7, ('`count` of "b" is a value of a whole design: only `goal:`, '
                                        '`heuristic:` and `prune:` read it'))),
    ("a ~> b\nheuristic: true", (2, 12, "the heuristic must be a num, got a bool")),
    ("attr d = choose(2, 3)\na ~> b", (1, 10, ("`choose` in the default of `d`: a lot's attribute is neither a "
                                           "design's choice nor its value; write it in a rule"))),
    ("a ~> b\ngoal: 1", (2, 7, "the goal must be a bool, got a num")),
    ('a ~> b\ngoal: min(Scope.sx > 1 of "b") > 1', (2, 20, "the value `min` aggregates must be a num, got a bool")),
])
def test_search_statement_errors(text, expected):
    assert expected in errors(text)


def test_search_statements_read_attributes_and_aggregates():
    module, diags = typed('attr rooms = 2\na ~> b\ngoal: count("b") == rooms && mean(Scope.sx of "b") > 1\n'
                          "cost: Scope.sx\nprune: count(Scope.sx > 3 of \"b\") > 0\nheuristic: 0")
    assert not diags.has_errors
    assert [o.kind for o in module.objectives] == ["goal", "cost", "prune", "heuristic"]
