"""diagnostics.py: spans rendered with a caret, and the names suggested for a misspelt one."""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics, Span, render, suggest, typo_of


def test_render_shows_the_line_and_a_caret_under_the_span():
    diags = Diagnostics()
    diags.error("unknown-op", "unknown operation `Subdv`", Span("g.cga", 1, 6, 1, 11), hint="check it")
    assert render(diags[0], {"g.cga": "a ~> Subdv(1)\n"}) == (
        "g.cga:1:6: error: unknown operation `Subdv`\n 1 | a ~> Subdv(1)\n   |      ^^^^^\n  hint: check it")


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
