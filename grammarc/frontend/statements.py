"""Cut a grammar file into statements, so each can be parsed (and fail) on its own.

A statement starts on a line whose first character, in column 1, begins a token; lines that are indented,
that start with a bracket or ``|``, or that begin while a bracket is still open, continue the statement
before them. This is how the papers lay rules out (a rule's continuation lines are indented), and it lets
the parser report every syntax error of a file instead of the first.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_OPEN = "([{"
_CLOSE = ")]}"
_CONTINUATION_START = "{}[]()|"
#: A line that plainly starts a statement even inside an open bracket: an unclosed bracket in one rule
#: must not swallow the rules after it (their errors would be lost).
_OBVIOUS_START = re.compile(
    r"^(\d+\s*:|PRIORITY\b|attr\s|[A-Za-z_]\w*\s*(\([^()]*\))?\s*(:.*?)?"
    r"(~>|-->|->|;|\u2192|\u21dd))"
)


@dataclass(frozen=True, slots=True)
class Layout:
    """How a dialect lays statements out.

    ``obvious_start`` matches a line that begins a statement even inside an open bracket; lines starting
    with one of ``continuation_words`` continue the statement before them; with ``glue_annotations``, a
    statement made only of annotation lines (``@Range(...)``) continues into the declaration after it.
    """

    obvious_start: re.Pattern
    continuation_words: tuple[str, ...] = ()
    glue_annotations: bool = False


#: The paper notation: rules start in column 1 with an optional integer label.
PAPER = Layout(_OBVIOUS_START)
#: CityEngine CGA: declarations and rules start in column 1, annotations glue to what follows.
CITYENGINE = Layout(
    re.compile(r"^(@\w|attr\s|const\s|version\s|import\s|[A-Za-z_$][\w$]*\s*(\([^()]*\))?\s*-->)"),
    continuation_words=("case", "else"),
    glue_annotations=True,
)


@dataclass(frozen=True, slots=True)
class Statement:
    """One statement's text and its first line (1-based); the text starts in column 1."""

    text: str
    line: int


def split_statements(text: str, layout: Layout = PAPER) -> list[Statement]:
    """Split ``text`` into statements, skipping blank and comment-only lines between them."""
    statements: list[Statement] = []
    current: list[str] = []
    kept = 0  # lines of ``current`` up to its last one with code (or inside a block comment)
    start = 0
    depth = 0
    in_block_comment = False
    for number, line in enumerate(text.splitlines(), start=1):
        begins = (
            depth == 0
            and not in_block_comment
            and line[:1] not in ("", " ", "\t")
            and line[0] not in _CONTINUATION_START
            and not line.startswith(("//", "#", "/*"))
            and not _starts_with_word(line, layout.continuation_words)
            and not (layout.glue_annotations and current and _only_annotations(current[:kept]))
        )
        if not begins and depth > 0 and not in_block_comment and layout.obvious_start.match(line):
            begins, depth = True, 0
        after, in_comment_after, has_code = _scan(line, depth, in_block_comment)
        if not begins and not current and has_code:
            # Code before the first column-1 statement (an indented first rule) is parsed, not dropped.
            begins = True
        if begins:
            if current:
                statements.append(Statement("\n".join(current[:kept]), start))
            current, start = [line], number
        elif current:
            current.append(line)
        if current and (has_code or in_block_comment or in_comment_after):
            kept = len(current)
        depth, in_block_comment = after, in_comment_after
    if current:
        statements.append(Statement("\n".join(current[:kept]), start))
    return statements


def _starts_with_word(line: str, words: tuple[str, ...]) -> bool:
    return any(line.startswith(w) and not line[len(w):len(w) + 1].isalnum() for w in words)


_ANNOTATION = re.compile(r"@\w+\s*(\([^()]*\))?\s*")


def _only_annotations(lines: list[str]) -> bool:
    """Whether ``lines`` hold annotations and nothing else (``@Range(1, 5)`` yes, ``@Hidden attr x = 1``
    no: that line declares)."""
    code = [s.strip() for s in lines if s.strip() and not s.strip().startswith(("#", "//"))]
    return bool(code) and all(s.startswith("@") and not _ANNOTATION.sub("", s).strip() for s in code)


def _scan(line: str, depth: int, in_block_comment: bool) -> tuple[int, bool, bool]:
    """Bracket depth after ``line``, whether a block comment is still open, and whether the line has
    code (anything but blanks and comments); strings and comments are skipped."""
    i = 0
    n = len(line)
    has_code = False
    while i < n:
        if in_block_comment:
            end = line.find("*/", i)
            if end < 0:
                return depth, True, has_code
            in_block_comment = False
            i = end + 2
            continue
        c = line[i]
        if c == '"' or c in "\u201c\u201d":
            close = '"' if c == '"' else "\u201c\u201d"
            has_code = True
            j = i + 1
            while j < n and line[j] not in close:
                j += 1
            i = j + 1
            continue
        if line.startswith("//", i) or c == "#":
            break
        if line.startswith("/*", i):
            in_block_comment = True
            i += 2
            continue
        has_code = has_code or not c.isspace()
        if c in _OPEN:
            depth += 1
        elif c in _CLOSE:
            depth = max(depth - 1, 0)
        i += 1
    return depth, in_block_comment, has_code
