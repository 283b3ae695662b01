"""frontend/statements.py: paper notation cut at column-1 lines, CityEngine CGA where declarations begin."""

from __future__ import annotations

import pytest

from grammarc.frontend.statements import Statement, split_cityengine, split_paper


def cut(text: str) -> list[tuple[int, str]]:
    return [(s.line, s.text) for s in split_paper(text)]


def test_one_statement_per_column1_line():
    assert cut("a ~> b\nc ~> d\nattr x = 1\nPRIORITY 2:") == [
        (1, "a ~> b"), (2, "c ~> d"), (3, "attr x = 1"), (4, "PRIORITY 2:"),
    ]


def test_statement_is_a_frozen_record():
    assert split_paper("a ~> b") == [Statement("a ~> b", 1)]


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


# ------------------------------------------------------------------------------------------ CityEngine CGA
def ce(text: str) -> list[tuple[int, str]]:
    return [(s.line, s.text) for s in split_cityengine(text)]


def test_cityengine_indented_declarations_start_statements():
    # the indentation becomes blanks, one per character: the parser's columns are the file's
    text = 'version "2022.0"\n  attr h = 10\n\tconst w = 2\n    Lot --> extrude(h) A\n'
    assert ce(text) == [(1, 'version "2022.0"'), (2, "  attr h = 10"), (3, " const w = 2"),
                        (4, "    Lot --> extrude(h) A")]


def test_cityengine_bodies_go_on_in_column1():
    text = "Lot -->\nextrude(10)\ncomp(f) { top : Roof | side : Wall }\nRoof --> X."
    assert ce(text) == [(1, "Lot -->\nextrude(10)\ncomp(f) { top : Roof | side : Wall }"), (4, "Roof --> X.")]


def test_cityengine_several_statements_on_a_line_keep_their_columns():
    # a statement starting within a line is padded to its column
    assert ce("attr a = 1 attr b = 2 f(x) = x * a A --> B") == [
        (1, "attr a = 1"), (1, "           attr b = 2"), (1, "                      f(x) = x * a"),
        (1, "                                   A --> B"),
    ]


@pytest.mark.parametrize("head", ["R", "R(a, b)", "R(float h, string s, bool b, float[] a)", "vol.Slab",
                                  "R ( a )"])
@pytest.mark.parametrize("arrow", ["-->", "="])
def test_cityengine_declarations_begin_at_a_name_with_arrow_or_equals(head, arrow):
    assert [line for line, _ in ce(f"Lot --> A\n  B C\n{head} {arrow} D\n")] == [1, 3]


def test_cityengine_names_in_bodies_and_comparisons_start_nothing():
    text = 'Lot --> case style == "a" && version != 2 : A(1) B. else : C\n  D.E F(x) X'
    assert [line for line, _ in ce(text)] == [1]


def test_cityengine_annotations_glue_to_the_declaration_after_them():
    text = ('@Group("a (b") @Order(6)#@Range(0,6)\n  attr x = 1\n@Hidden\n@Range(min=0, max=10)\n'
            "attr y = 2\n@StartRule Lot --> A\n@Hidden attr z = 3")
    assert ce(text) == [
        (1, '@Group("a (b") @Order(6)#@Range(0,6)\n  attr x = 1'),
        (3, "@Hidden\n@Range(min=0, max=10)\nattr y = 2"), (6, "@StartRule Lot --> A"), (7, "@Hidden attr z = 3"),
    ]


def test_cityengine_strings_and_comments_hide_brackets_and_declarations():
    text = 'Lot --> print("( attr x = 1") A # (\n// B --> C\n/* D --> E\n*/ F\nG --> H'
    assert [line for line, _ in ce(text)] == [1, 5]


def test_cityengine_unclosed_bracket_does_not_swallow_declarations():
    text = "Lot --> extrude(10\n  A\nattr h = 1\n@Hidden\nB(x) --> s(1,\n  C --> D\nE = 1"
    assert [line for line, _ in ce(text)] == [1, 3, 4, 6, 7]


def test_cityengine_unclosed_block_comment_is_code():
    # the parser reports it, rather than the rest of the file vanishing into a comment
    assert ce("A --> B\n/* C --> D") == [(1, "A --> B\n/* C --> D")]


def test_cityengine_crlf_and_cr_line_ends():
    assert ce("A --> B\r\n  C\r\nD --> E\rF --> G") == [(1, "A --> B\n  C"), (3, "D --> E"), (4, "F --> G")]


def test_cityengine_split_is_linear():
    # a million blank lines, and a file of 20,000 statements: a few seconds at most (quadratic would be hours)
    import time

    start = time.perf_counter()
    assert ce("\n" * 1_000_000 + "A --> B") == [(1_000_001, "A --> B")]
    assert len(split_cityengine("attr a = f(1, 2) A(x) --> B(x) C.\n" * 10_000)) == 20_000
    assert time.perf_counter() - start < 30


def test_cityengine_statements_sharing_a_later_line():
    assert ce("A --> B\n  C --> D E --> F") == [(1, "A --> B"), (2, "  C --> D"), (2, "          E --> F")]
