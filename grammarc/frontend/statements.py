"""Cut a grammar file into statements, so each can be parsed (and fail) on its own: the parser then reports
every syntax error of a file instead of the first.

The two dialects lay statements out differently. In the paper notation (``split_paper``) a statement starts
on a line whose first character, in column 1, begins a token; lines that are indented, that start with a
bracket or ``|``, or that begin while a bracket is still open, continue the statement before them: this is
how the papers lay rules out. CityEngine CGA is free-form (``split_cityengine``): a statement ends where
the next declaration begins, wherever it stands on its line.
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
class Statement:
    """One statement's text and its first line (1-based); the text starts in column 1."""

    text: str
    line: int


def split_paper(text: str) -> list[Statement]:
    """Split paper-notation ``text`` into statements, skipping blank and comment-only lines between them."""
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
        )
        if not begins and depth > 0 and not in_block_comment and _OBVIOUS_START.match(line):
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


# ------------------------------------------------------------------------------------------ CityEngine CGA
#: The tokens that decide where a CityEngine statement starts: strings and comments (skipped whole, their
#: brackets do not count), the arrow, `=` apart from the comparisons, numbers, words, a dot before a name
#: (``scope.sx``, ``volume.Slab``) apart from other dots (the leaf ``Facade.``), `@`, brackets. An unclosed
#: block comment runs to the end of the text and is code: the parser reports it.
_TOKEN = re.compile(
    r'(?P<string>"(?:\\.|[^"\\\n])*"?|[\u201c\u201d][^\u201c\u201d"\n]*[\u201c\u201d]?)'
    r"|(?P<comment>//[^\n]*|#[^\n]*|/\*.*?\*/)"
    r"|(?P<code>/\*.*)"
    r"|(?P<arrow>-->)"
    r"|(?P<compare>[<>!=]=)"
    r"|(?P<number>(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<word>[A-Za-z_$][\w$]*)"
    r"|(?P<member>\.(?=[A-Za-z_$]))"
    r"|(?P<punct>[=@()\[\]{},])"
    r"|(?P<other>\S)",
    re.DOTALL,
)
#: Words that begin a declaration, with the kinds of token that must follow them (``style`` and
#: ``version`` may also name an attribute: ``case style == "a"`` is no declaration).
_KEYWORDS = {"attr": ("word",), "const": ("word",), "style": ("word",), "import": ("word", "string"),
             "version": ("string",)}
#: Tokens that may stand between the brackets of a declaration's parameters (``(float h, string[] s)``).
_PARAMETER_TOKENS = frozenset(("word", ",", "[", "]"))
#: A line that plainly starts a declaration although a bracket before it is still open: an unclosed
#: bracket in one rule must not swallow the declarations after it (their errors would be lost).
_OBVIOUS_DECLARATION = re.compile(
    r"@\w|(?:attr|const|style)[ \t]+[A-Za-z_$]|import[ \t]+[A-Za-z_$\"]|version[ \t]+\""
    r"|[A-Za-z_$][\w$]*(?:\.[A-Za-z_$][\w$]*)*[ \t]*(?:\([^()\n]*\))?[ \t]*-->"
)
_OPENERS = frozenset("([{")
_CLOSERS = frozenset(")]}")


def split_cityengine(text: str) -> list[Statement]:
    """Split CityEngine CGA ``text`` into statements, as its grammar ends them.

    Outside brackets, a statement starts at an annotation ``@Name`` (annotations glue to the declaration
    after them), at ``attr``, ``const``, ``import``, ``version`` or ``style``, or at a name that begins a
    rule or a function: ``Name -->``, ``Name(params) -->``, ``Name =``, ``Name(params) =`` (parameters
    typed or not, the name maybe dotted: ``volume.Slab -->``). So layout is free: a declaration may be
    indented, a rule body may go on in column 1, several statements may share a line. Inside an open
    bracket, a line that plainly starts a declaration (``_OBVIOUS_DECLARATION``) starts a statement all the
    same, so that an unclosed bracket does not swallow the rest of the file.

    A statement that starts within its line is padded with blanks to its column, so that the parser's
    columns are the file's. Linear in the length of ``text``: each bracket is looked into at most once
    (``_declares``).
    """
    text = re.sub(r"\r\n?", "\n", text)
    tokens = [(m.group() if m.lastgroup == "punct" else m.lastgroup, m.start(), m.end())
              for m in _TOKEN.finditer(text) if m.lastgroup != "comment"]
    statements: list[Statement] = []
    begin = end = -1  # the current statement's text
    first = (1, 0)  # its line, and the offset where that line starts
    line, line_start, counted = 1, 0, 0  # the line of text[counted], and where that line starts
    previous_end = 0
    depth = 0
    annotations_only = False  # the current statement holds annotations and nothing else yet
    before = ""  # the kind of the token before; `@name` and `keyword` where they decide the next
    for i, (kind, start, stop) in enumerate(tokens):
        if depth > 0 and text.find("\n", previous_end, start) >= 0 \
                and _OBVIOUS_DECLARATION.match(text, start):
            depth = 0
        previous_end = stop
        starts = False
        if depth == 0:
            if kind == "@":
                starts, annotations_only = not annotations_only, True
            elif not (before == "@" or (kind == "(" and before == "@name")):  # not the annotation's own
                starts = kind == "word" and before not in ("member", "keyword") and not annotations_only \
                    and _declares(tokens, i, text)
                annotations_only = False
        # the name after a keyword is declared, not a declaration (`attr h = 1`)
        before = "@name" if before == "@" else "keyword" if text[start:stop] in _KEYWORDS else kind
        if starts or begin < 0:
            if begin >= 0:
                statements.append(_statement(text, begin, end, first))
            line += text.count("\n", counted, start)  # lines are counted from statement to statement
            line_start = max(line_start, text.rfind("\n", counted, start) + 1)
            counted = start
            begin, first = start, (line, line_start)
        end = stop
        if kind in _OPENERS:
            depth += 1
        elif kind in _CLOSERS:
            depth = max(depth - 1, 0)
    if begin >= 0:
        statements.append(_statement(text, begin, end, first))
    return statements


def _declares(tokens: list, i: int, text: str) -> bool:
    """Whether the word ``tokens[i]`` begins a declaration: a keyword of ``_KEYWORDS`` with what must follow it,
    or a name (dotted maybe) with parameters maybe, then ``-->`` or ``=``. Looks no further than the
    parameters go."""
    _, start, stop = tokens[i]
    j = i + 1
    follows = _KEYWORDS.get(text[start:stop])
    if follows is not None:
        return j < len(tokens) and tokens[j][0] in follows
    while j + 1 < len(tokens) and tokens[j][0] == "member" and tokens[j + 1][0] == "word":
        j += 2
    if j < len(tokens) and tokens[j][0] == "(":
        j += 1
        while j < len(tokens) and tokens[j][0] in _PARAMETER_TOKENS:
            j += 1
        if j >= len(tokens) or tokens[j][0] != ")":
            return False
        j += 1
    return j < len(tokens) and tokens[j][0] in ("arrow", "=")


def _statement(text: str, begin: int, end: int, first: tuple[int, int]) -> Statement:
    line, line_start = first
    return Statement(" " * (begin - line_start) + text[begin:end], line)
