"""frontend/cityengine/assembly.py: a file's declarations and the files it imports into one module: the
start rule, functions and constants inlined, rules overloaded by arity, imported rules and attributes under
their prefixes.
"""

from __future__ import annotations

import signal

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir.pipeline import run_passes
from grammarc.ir.printer import print_rule

from .lowered import VERSION, body_of, errors, module_of, rules

# ---------------------------------------------------------------------------------------- the start rule


def test_start_rule_annotation_picks_the_start():
    module = module_of(VERSION + "Helper --> A\n@StartRule\nLot --> Helper\n@StartRule\nOther --> A\n")
    assert module.start == "Lot"


def test_without_start_rule_the_first_rule_starts():
    assert module_of(VERSION + "Helper --> A\nLot --> Helper\n").start == "Helper"



# -------------------------------------------------------------------------------------------- functions


def test_functions_with_parameters_are_inlined():
    text = VERSION + """attr h = 10
window_w(w) = case w > 3 : w * 0.6 else : w * 0.5
half(x) = x / 2
Lot --> extrude(half(h)) s(window_w(scope.sx), '1, '1) A
"""
    assert body_of(text) == ("extrude((@h / 2)) S(((Scope.sx > 3) ? (Scope.sx * 0.6) : (Scope.sx * 0.5)), "
                             "1r, 1r) A")


def test_zero_argument_functions_are_inlined_where_named():
    text = VERSION + "attr a = 2\nattr b = 3\ntileW = a + b\nfloors = tileW * 2\nLot --> extrude(floors) A\n"
    assert body_of(text) == "extrude(((@a + @b) * 2)) A"


def test_functions_call_functions_and_rules_pass_parameters():
    text = VERSION + ("twice(x) = x * 2\nquad(x) = twice(twice(x))\n"
                      "Lot --> A(3)\nA(n) --> extrude(quad(n + 1))\n")
    assert body_of(text, "A") == "extrude(((($n + 1) * 2) * 2))"


def test_a_function_sees_attributes_not_the_parameters_of_the_rule_that_calls_it():
    """A function body's names are its parameters and the attributes (CityEngine scopes them so), even
    when the calling rule has a parameter of the same name."""
    text = VERSION + ("attr h = 5\ntall = h * 2\nplus(x) = x + h\n"
                      "Lot --> A(1)\nA(h) --> extrude(tall) s(plus(h), 1, 1)\n")
    module = module_of(text)
    assert print_rule(module.rules[1]) == "A(h) ~> extrude((@h * 2)) S(($h + @h), 1, 1) : 1"


def test_an_argument_named_like_a_function_stays_the_callers_parameter():
    text = VERSION + "w = 3\ntwice(x) = x * 2\nLot --> A(1)\nA(w) --> extrude(twice(w))\n"
    assert body_of(text, "A") == "extrude(($w * 2))"


def _alarm(signum, frame):
    raise TimeoutError("lowering did not finish")


@pytest.mark.parametrize("functions", [
    "fib(n) = fib(n - 1) + 1\n",
    "fib(n) = case n < 2 : n else : fib(n - 1) + fib(n - 2)\n",
    ("even(n) = case n == 0 : true else : odd(n - 1)\nodd(n) = case n == 0 : false else : even(n - 1)\n"
     "fib(n) = case even(n) : 1 else : 2\n"),
])
def test_recursive_function_is_unsupported(functions):
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(10)
    try:
        found = errors(VERSION + functions + "Lot --> extrude(fib(5)) A\n")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    assert found, "a recursive function must be an error"
    assert all(m.startswith("unsupported: recursive function") for _, _, m in found), found
    assert len(found) <= 2  # reported where it recurses, not once per expansion


def test_unknown_function_and_wrong_arity_are_errors():
    text = VERSION + "half(x) = x / 2\nLot --> extrude(halve(4)) s(half(1, 2), 1, 1) A\n"
    assert errors(text) == [(3, 17, "unknown function `halve` (did you mean `half`?)"),
                            (3, 29, "`half` takes 1 arguments, got 2")]


def test_a_built_in_of_the_reference_that_grammarc_does_not_compute_is_unsupported():
    text = VERSION + 'Lot --> extrude(contextCompare(intra, "x") + 1) A\nA --> report("k", getTreeKey()) X.\n'
    assert errors(text) == [(2, 17, "unsupported: contextCompare"), (3, 19, "unsupported: getTreeKey")]


def test_functions_of_an_imported_file_see_its_attributes(tmp_path):
    """An imported file's functions read its attributes under its prefix, or the importer's attribute of
    the same name (forwarding), as its rules do."""
    (tmp_path / "facade.cga").write_text(VERSION + "attr depth = 7\nattr width = 2\nthick = depth / 2\n"
                                         "wide = width * 3\nFacade --> extrude(thick) s(wide, '1, '1) X\n")
    (tmp_path / "main.cga").write_text(VERSION + 'import f : "facade.cga"\nattr width = 5\n'
                                       "Lot --> extrude(width) f.Facade\n")
    # not compile_grammar: the strict IR check refuses spans from imported files for now
    diags = Diagnostics()
    main = tmp_path / "main.cga"
    module = run_passes(parse_source(main.read_text(), str(main), diags, path=main), diags, check=False)
    assert not diags.has_errors, diags
    assert [a.name for a in module.attrs] == ["width", "f.depth"]
    assert [print_rule(r) for r in module.rules] == [
        "Lot ~> extrude(@width) f.Facade : 1",
        "f.Facade ~> extrude((@f.depth / 2)) S((@width * 3), 1r, 1r) f.X : 1"]



# -------------------------------------------------------------------------------------------- overloads


def test_rules_overloaded_by_arity_get_one_symbol_each():
    text = VERSION + """Lot --> Pipe(2)
Pipe(a) --> Pipe(a, 1, 2)
Pipe(a, b, c) --> s(a, b, c) Pipe.
Single(x) --> A
"""
    printed = rules(text)
    assert printed == {
        "Lot": "Lot ~> Pipe/1(2) : 1",
        "Pipe/1": "Pipe/1(a) ~> Pipe/3($a, 1, 2) : 1",
        "Pipe/3": "Pipe/3(a, b, c) ~> S($a, $b, $c) Pipe. : 1",
        "Single": "Single(x) ~> A : 1",
    }


def test_a_function_of_the_file_wins_over_the_array_builtin_of_its_name():
    """ESRI.lib's string utilities define `findFirst(text, match)`: the file's function is called."""
    assert body_of(VERSION + 'findFirst(text, match) = len(text) - len(match)\n'
                   'Lot --> extrude(findFirst("abc", "b")) X\n') == 'extrude((len("abc") - len("b"))) X'
