"""backend/functions/strings.py: CityEngine's string functions and conversions, on one text (the values of
the reference's own examples, and the decisions where it is silent), in a derivation, on a batch of
distinct values, and the mixed-type operators (``passes.types`` and ``evaluate``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from reported import errors, reported

from grammarc.backend.functions import strings

CE = "cityengine rocks my world; cityengine should rock yours too"
RULE = "rule your city with cityengine"


@pytest.mark.parametrize("function, args, want", [
    # count
    (strings.count, ("cityengine", "e"), 2),
    (strings.count, (CE, "cityengine"), 2),
    # find
    (strings.find, ("CE_Zero CE_One CE_Two", "CE", 0), 0),
    (strings.find, ("CE_Zero CE_One CE_Two", "CE", 1), 8),
    (strings.find, (CE, "cityengine", 0), 0),
    (strings.find, (CE, "cityengine", 1), 27),
    (strings.find, ("CE_Zero CE_One CE_Two", "asdf", 1), -1),
    # substring
    (strings.substring, ("0123456789", 0, 5), "01234"),
    (strings.substring, ("0123456789", 2, 5), "234"),
    (strings.substring, ("0123456789", -20, 5), "01234"),
    (strings.substring, ("0123456789", 0, 20), "0123456789"),
    (strings.substring, ("0123456789", 5, 0), ""),
    # len
    (len, ("cityengine",), 10),
    (len, ("abc",), 3),
    # the utility library: findLast, getPrefix, getSuffix, getRange, replace
    (strings.find_last, (RULE, "city"), 20),
    (strings.prefix, (RULE, "city"), "rule your "),
    (strings.suffix, (RULE, "city"), "engine"),
    (strings.between, (RULE, "y", "city"), "our city with "),
    (strings.replace, (RULE, "your city", "designs"), "rule designs with cityengine"),
    # float and bool of strings
    (strings.parse_float, ("0.5",), 0.5),
    (strings.parse_float, ("001.5",), 1.5),
    (strings.parse_bool, ("1",), True),
    (strings.parse_bool, ("false",), False),
    (strings.parse_bool, ("f",), False),
    (strings.parse_bool, ("true",), True),
    (strings.parse_bool, ("beneath the remains",), True),
])
def test_reference_examples(function, args, want):
    assert function(*args) == want


@pytest.mark.parametrize("value, want", [(1.69, "1.69"), (1.69 - 69 / 100, "1"), (1.0, "1"), (True, "true")])
def test_str_writes_as_the_reference_shows(value, want):
    assert strings.format_value(value, False, []) == want


@pytest.mark.parametrize("function, args, want", [
    # an empty match is found nowhere
    (strings.count, ("abc", ""), 0),
    (strings.find, ("abc", "", 0), -1),
    (strings.replace, ("abc", "", "x"), "abc"),
    # the n-th occurrence: non-overlapping, from 0, truncated; none past the last or before the first
    (strings.find, ("aaaa", "aa", 1), 2),
    (strings.find, ("aaaa", "aa", 2), -1),
    (strings.find, ("a;b;c;", ";", 1.9), 3),
    (strings.find, ("a;b;c;", ";", -1), -1),
    (strings.find, ("a;b;c;", ";", math.nan), -1),
    (strings.find_last, ("abc", "x"), -1),
    # indices: fractions truncated, infinities clamped, NaN gives nothing
    (strings.substring, ("0123456789", 2.7, 5.2), "234"),
    (strings.substring, ("0123456789", -math.inf, math.inf), "0123456789"),
    (strings.substring, ("0123456789", math.nan, 5), ""),
    # a missing end of getRange is the text's own end; getPrefix and getSuffix without a match: the text
    (strings.between, ("a[b", "[", "]"), "b"),
    (strings.between, ("a]b", "[", "]"), "a"),
    (strings.between, ("ab", "[", "]"), "ab"),
    (strings.prefix, ("ab", "x"), "ab"),
    (strings.suffix, ("a.b.obj", "."), "obj"),
    # float: the missing value (NaN) when the text is no number; bool: "" and numbers equal to 0 are false
    (strings.parse_float, (" 2.5 ",), 2.5),
    (strings.parse_bool, ("",), False),
    (strings.parse_bool, ("0.0",), False),
    (strings.parse_bool, ("FALSE",), False),
    (strings.parse_bool, ("0.1",), True),
])
def test_where_the_reference_is_silent(function, args, want):
    assert function(*args) == want


@pytest.mark.parametrize("text", ["abc", "", "1_0", "1 2"])
def test_float_of_a_text_that_is_no_number_is_the_missing_value(text):
    assert math.isnan(strings.parse_float(text))


@pytest.mark.parametrize("value, want", [(1e-7, "1e-07"), (-0.0, "0"), (math.inf, "inf"), (1e20, "1e+20"),
                                         (-2.5, "-2.5"), (False, "false")])
def test_str_of_numbers_the_reference_does_not_show(value, want):
    assert strings.format_value(value, False, []) == want


# ------------------------------------------------------------------------------------------- in derivations


def test_each_function_in_a_derivation(write):
    got, = reported(write, (
        'Lot --> report("count", count("cityengine", "e")) report("find", find("CE_Zero CE_One CE_Two", "CE", 1))\n'
        '    report("len", len("cityengine")) report("sub", substring("0123456789", 2, 5))\n'
        f'    report("last", findLast("{RULE}", "city")) report("prefix", getPrefix("{RULE}", "city"))\n'
        f'    report("suffix", getSuffix("{RULE}", "city")) report("range", getRange("{RULE}", "y", "city"))\n'
        f'    report("replace", replace("{RULE}", "your city", "designs"))\n'
        '    report("str", str(1.69)) report("strb", str(true)) report("float", float("001.5"))\n'
        '    report("floatb", float(true)) report("bool", bool("f")) report("boolf", bool(6.66)) X.\n'))
    assert got == {"count": 2, "find": 8, "len": 10, "sub": "234", "last": 20, "prefix": "rule your ",
                   "suffix": "engine", "range": "our city with ", "replace": "rule designs with cityengine",
                   "str": "1.69", "strb": "true", "float": 1.5, "floatb": 1, "bool": False, "boolf": True}


def test_a_batch_of_distinct_values_gives_what_each_gives_alone(write):
    rng = np.random.default_rng(7)
    words = ["".join(rng.choice(list("ab_c"), size=rng.integers(0, 9))) for _ in range(60)]
    words[:3] = ["", "_", "a_b_c"]
    start = rng.integers(-2, 10, size=60).astype(float)
    got = reported(write, (
        'attr name = ""\nattr k = 0\n'
        'Lot --> report("count", count(name, "a")) report("find", find(name, "_", k))\n'
        '    report("sub", substring(name, k, k + 3)) report("prefix", getPrefix(name, "_"))\n'
        '    report("replace", replace(name, "a", "xy")) report("float", float(name)) report("bool", bool(name))\n'
        '    report("str", str(k / 4)) report("len", len(name)) X.\n'), lots=60, attrs={"name": words, "k": start})
    for lot, (word, k) in enumerate(zip(words, start)):
        want = {"count": strings.count(word, "a"), "find": strings.find(word, "_", k),
                "sub": strings.substring(word, k, k + 3), "prefix": strings.prefix(word, "_"),
                "replace": strings.replace(word, "a", "xy"), "float": strings.parse_float(word),
                "bool": strings.parse_bool(word), "str": strings.format_value(k / 4, False, []), "len": len(word)}
        assert got[lot] == pytest.approx(want, nan_ok=True), (lot, word, k)


# ------------------------------------------------------------------------------------------ mixed types


def test_concatenation_writes_numbers_and_truth_values_into_the_string(write):
    got, = reported(write, 'Lot --> report("a", "a" + 1) report("b", 1 + "th Rule") report("c", true + "x")\n'
                           '    report("d", "Rule: " + 2.5 + false) report("e", "City" + "Engine") X.\n')
    assert got == {"a": "a1", "b": "1th Rule", "c": "truex", "d": "Rule: 2.5false", "e": "CityEngine"}


def test_a_string_compares_with_a_number_or_a_truth_value_as_strings(write):
    got, = reported(write, 'Lot --> report("a", "1" == 1) report("b", 1 != "1") report("c", "1.0" == 1)\n'
                           '    report("d", "true" == true) report("e", 0 == "") report("f", 1 == true) X.\n')
    assert got == {"a": True, "b": False, "c": False, "d": True, "e": False, "f": True}


def test_strings_are_ordered_by_their_text(write):
    # the interned ids are in the order the strings first appear: "b" before "a"
    got = reported(write, 'attr s = "b"\nLot --> report("lt", s < "a") report("ge", "a" >= s) X.\n',
                   lots=3, attrs={"s": ["b", "a", "ab"]})
    assert [(g["lt"], g["ge"]) for g in got] == [(False, False), (False, True), (False, False)]


def test_a_number_parameter_compared_with_the_empty_string(write):
    # public files test whether a value was given with `mix != ""`; a number always was
    got = reported(write, 'attr n = 0\nLot --> Generate(n)\nGenerate(mix) -->\n'
                          '    case mix != "": report("given", mix * 2) X.\n    else: report("none", 1) X.\n',
                   lots=2, attrs={"n": [3.0, 0.0]})
    assert got == [{"given": 6}, {"given": 0}]


def test_a_parameter_used_as_a_number_and_compared_with_a_string_is_a_number(write):
    # no call site types `p` (Lib is a library's rule): its arithmetic does, before its comparison
    got, = reported(write, 'Lot --> report("ok", 1) X.\nLib(p) -->\n    case p != "": s(p * 2, 1, 1) X.\n'
                           '    else: X.\n')
    assert got == {"ok": 1}


def test_operators_that_do_not_combine_a_string_and_a_number(write):
    assert errors(write, 'Lot -->\n    case "a" < 1: X.\n    else: X.\nX --> Y.\n') == [
        (3, 14, "`<` cannot combine a str and a num")]
    assert errors(write, 'Lot --> s("2" * 2, 1, 1) X.\n') == [(2, 15, "`*` cannot combine a str and a num")]


# ------------------------------------------------------------------------------------------- splitString


@pytest.mark.parametrize("text, delimiter, want", [
    ("a.b.c", ".", ["a", "b", "c"]),
    (".b.", ".", ["", "b", ""]),
    ("a.b\nc.d", "\n", ["a.b", "c.d"]),
    ("a\\b\\c", "\\", ["a", "b", "c"]),
    ("abc", "", ["", "a", "b", "c", ""]),
    ("a;b;c", "$;", ["a", "b", "c"]),
    ("a.b.c", "$\\.", ["a", "b", "c"]),
    ("a\t\tb\tc", "$\t+", ["a", "b", "c"]),
    ("a b c", "$\\s+", ["a", "b", "c"]),
    ("a$b$c", "$\\$", ["a", "b", "c"]),
    ("abc", "$\\B", ["a", "b", "c"]),
    ("abacba", "$(?<=a)b(?=a)", ["a", "acba"]),
])
def test_split_string_reference_examples(text, delimiter, want):
    assert strings.split(text, delimiter) == want


def test_split_string_gives_an_array_per_shape(write):
    got = reported(write, 'attr path = ""\nattr parts = splitString(path, "/")\n'
                          'Lot --> report("n", size(parts)) report("last", parts[size(parts) - 1])\n'
                          '    report("first", splitString(path, "$[/.]")[0]) X.\n',
                   lots=3, attrs={"path": ["assets/doors/door.obj", "", "x.y"]})
    assert got == [{"n": 3, "last": "door.obj", "first": "assets"}, {"n": 1, "last": "", "first": ""},
                   {"n": 1, "last": "x.y", "first": "x"}]


def test_split_string_by_no_regular_expression_fails_the_lots_that_split_by_it(write):
    got = reported(write, 'attr d = "."\nLot --> report("n", size(splitString("a.b", d))) X.\n',
                   lots=2, attrs={"d": [".", "$("]})
    assert got == [{"n": 2}, {}]
