"""diagnostics.py: spans rendered with a caret, and the names suggested for a misspelt one."""

from __future__ import annotations

import random

import pytest

from grammarc.diagnostics import (
    SHOWN_COLUMNS,
    Diagnostics,
    Span,
    Typos,
    _edits,
    render,
    render_all,
    suggest,
    typo_of,
)


def test_render_shows_the_line_and_a_caret_under_the_span():
    diags = Diagnostics()
    diags.error("unknown-op", "unknown operation `Subdv`", Span("g.cga", 1, 6, 1, 11), hint="check it")
    assert render(diags[0], {"g.cga": "a ~> Subdv(1)\n"}) == (
        "g.cga:1:6: error: unknown operation `Subdv`\n 1 | a ~> Subdv(1)\n   |      ^^^^^\n  hint: check it")


def test_a_long_line_is_shown_as_a_window_around_the_span():
    line = " ".join(f"extrude(u{i})" for i in range(400))
    col = line.index("u200") + 1
    diags = Diagnostics()
    diags.error("unknown-name", "unknown identifier `u200`", Span("g.cga", 1, col, 1, col + 4))
    _, shown, caret = render(diags[0], {"g.cga": line}).split("\n")
    assert shown.startswith(" 1 | ...") and shown.endswith("...")
    assert len(shown) <= len(" 1 | ") + SHOWN_COLUMNS + 6
    start = caret.index("^")
    assert caret.count("^") == 4 and shown[start:start + 4] == "u200"


def test_thousands_of_errors_on_one_line_cost_a_few_lines_each():
    """A generated one-line file with an error per word: the line is cut into lines once, and each message
    shows a window of it, not the whole line again."""
    line = " ".join(f"extrude(u{i})" for i in range(5000))
    diags = Diagnostics()
    for i in range(5000):
        col = line.index(f"(u{i})") + 2
        diags.error("unknown-name", f"unknown identifier `u{i}`", Span("g.cga", 1, col, 1, col + len(f"u{i}")))
    text = render_all(diags, {"g.cga": line})
    assert text.count("\n") == 3 * 5000 - 1
    assert len(text) < 5000 * (2 * SHOWN_COLUMNS + 100)


def test_suggest_the_likeliest_name():
    assert suggest("hieght", ["height", "width"]) == " (did you mean `height`?)"
    assert suggest("zz", ["height", "width"]) == ""


@pytest.mark.parametrize("name, candidates, typo", [
    ("facdes", ["facades", "roof"], "facades"),        # a letter missing
    ("spilt", ["split", "comp"], "split"),             # two letters swapped
    ("sqlit", ["split"], "split"),                     # a letter wrong
    ("faccade", ["facade"], "facade"),                 # a letter extra
    ("Facade", ["facade"], "facade"),                  # letter case only
    ("lot", ["Lot"], "Lot"),                           # a short name: its case only
    ("lot", ["lit"], None),
    ("paving", ["pine"], None),                        # what `suggest` would offer is not a typo
    ("groundflor_tile", ["groundfloor_tiles"], "groundfloor_tiles"),  # two edits in a long name
    ("window", ["door", "wall"], None),
    ("facade", ["facade"], None),                      # the name itself is no typo of itself
])
def test_typo_of_finds_names_one_or_two_edits_away(name, candidates, typo):
    assert typo_of(name, candidates) == typo


def test_the_index_finds_what_comparing_with_every_candidate_finds():
    # Typos compares a name only with the candidates that share a string of deletions with it: the same
    # answers as comparing it with all of them, in their order
    rng = random.Random(17)
    letters = "abcdeAB_1"

    def word():
        return "".join(rng.choice(letters) for _ in range(rng.randint(1, 11)))

    candidates = list(dict.fromkeys(word() for _ in range(300)))
    typos = Typos(candidates)
    for _ in range(500):
        name = rng.choice([word(), rng.choice(candidates)[:-1] + rng.choice(letters)])
        most = 0 if len(name) < 4 else 1 if len(name) < 8 else 2
        expected = next((c for c in candidates if c != name and abs(len(c) - len(name)) <= most
                         and _edits(name.lower(), c.lower(), most) <= most), None)
        assert typos.of(name) == expected, name
