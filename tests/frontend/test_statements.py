"""frontend/statements.py: a file is cut into statements at column-1 lines."""

from __future__ import annotations

import pytest

from grammarc.frontend.statements import Statement, split_statements


def cut(text: str) -> list[tuple[int, str]]:
    return [(s.line, s.text) for s in split_statements(text)]


def test_one_statement_per_column1_line():
    assert cut("a ~> b\nc ~> d\nattr x = 1\nPRIORITY 2:") == [
        (1, "a ~> b"), (2, "c ~> d"), (3, "attr x = 1"), (4, "PRIORITY 2:"),
    ]


def test_statement_is_a_frozen_record():
    assert split_statements("a ~> b") == [Statement("a ~> b", 1)]


@pytest.mark.parametrize("indent", [" ", "    ", "\t"])
def test_indented_lines_continue(indent):
    assert cut(f"a ~> b\n{indent}c\nd ~> e") == [(1, f"a ~> b\n{indent}c"), (3, "d ~> e")]


@pytest.mark.parametrize("first", ["{", "|", "}", "]", ")", "[", "("])
def test_lines_starting_with_a_bracket_or_bar_continue(first):
    assert cut(f"a ~> b\n{first} c\nd ~> e") == [(1, f"a ~> b\n{first} c"), (3, "d ~> e")]


def test_column1_lines_inside_open_brackets_continue():
    text = 'a ~> Subdiv("X", 1r,\n1r){ b |\nc }\nd ~> e'
    assert cut(text) == [(1, 'a ~> Subdiv("X", 1r,\n1r){ b |\nc }'), (4, "d ~> e")]


def test_brackets_in_strings_and_comments_do_not_count():
    text = 'a ~> b("(") c(\u201d(\u201d) // (\nd ~> e # [\nf ~> g /* { */\nh ~> i'
    assert [line for line, _ in cut(text)] == [1, 2, 3, 4]


def test_arrow_lines_at_column1_are_statements_of_their_own():
    # a stochastic continuation at column 1 is a statement; assemble() attaches it to the rule before
    assert cut("a ~> b : 0.5\n~> c : 0.5\n; d") == [(1, "a ~> b : 0.5"), (2, "~> c : 0.5"), (3, "; d")]


def test_comment_only_lines_between_statements_are_skipped():
    text = "// head\n# hash\n\na ~> b\n// tail\n\n\nc ~> d\n// end\n"
    assert cut(text) == [(4, "a ~> b"), (8, "c ~> d")]


def test_comment_lines_inside_a_rule_are_kept():
    assert cut("a ~> b\n  // note\n  c\nd ~> e") == [(1, "a ~> b\n  // note\n  c"), (4, "d ~> e")]


def test_block_comment_spanning_lines_hides_column1_rules():
    text = "a ~> b\n/* old:\nx ~> y\n(\n*/\nc ~> d"
    assert cut(text) == [(1, "a ~> b\n/* old:\nx ~> y\n(\n*/"), (6, "c ~> d")]


def test_block_comment_before_the_first_rule():
    assert cut("/* header\nx ~> y\n*/\na ~> b") == [(4, "a ~> b")]


def test_unclosed_bracket_does_not_swallow_an_obvious_rule():
    text = ("a ~> T(1,\nb ~> c\nd(x) : x > 1 ~> e\n1: f ; g\nattr h = 1\nPRIORITY 2:\ni \u2192 j\nk \u21dd l"
            "\nm(x) : x < 2 ; n")
    assert [line for line, _ in cut(text)] == [1, 2, 3, 4, 5, 6, 7, 8, 9]


def test_unclosed_bracket_still_takes_column1_continuations():
    # `wall | door }` does not look like a rule: it continues the open `{`
    text = 'a ~> Subdiv("X", 1r, 1r){\nwall | door }\nb ~> c'
    assert [line for line, _ in cut(text)] == [1, 3]


def test_obvious_rule_inside_a_block_comment_stays_in_the_comment():
    text = "a ~> T(1,\n/*\nx ~> y\n*/ 2, 3)\nb ~> c"
    assert [line for line, _ in cut(text)] == [1, 5]


def test_indented_first_line_is_parsed_not_dropped():
    assert cut("  a ~> b\nc ~> d") == [(1, "  a ~> b"), (2, "c ~> d")]
    assert cut("/* note */ a ~> b") == [(1, "/* note */ a ~> b")]


def test_trailing_blank_and_comment_lines_are_not_part_of_a_statement():
    # an error at the end of a statement must point at its last line of code, not at a comment below
    assert cut("a ~> b :\n  // why\n\nc ~> d") == [(1, "a ~> b :"), (4, "c ~> d")]


def test_empty_and_comment_only_texts_have_no_statements():
    assert cut("") == []
    assert cut("\n\n  \n// x\n/* y\n z */\n") == []


def test_crlf_line_ends():
    assert cut("a ~> b\r\n  c\r\nd ~> e\r\n") == [(1, "a ~> b\n  c"), (3, "d ~> e")]
