"""Parse grammar text into IR with every syntax error reported, not just the first.

Two dialects, one IR: the paper notation (``grammars/cga2006.lark``, the ``cga2006`` package) and
CityEngine CGA (``grammars/cityengine.lark``, the ``cityengine`` package), laid out alike; both grammars
import their expressions from ``grammars/expressions.lark``; their parsers come from ``parsers.py``. The
text is cut into statements (``statements.py``, each dialect its way); each is parsed on its own, with
leading newlines so that lark's line numbers are the file's, checked for a nesting that the recursive
passes after it could not take, lowered to IR by the dialect's ``Lowering``, and the statements are
assembled into a module by its ``assemble``. A file's statements that the user's cache folder keeps
(``lowered_cache``) are not parsed again: lark and the lowerings are imported only where a statement is.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import TYPE_CHECKING

from grammarc.diagnostics import Diagnostics, Span
from grammarc.frontend import lowered_cache
from grammarc.frontend.imports import Roots, find_roots, load_import
from grammarc.frontend.sites import Sites
from grammarc.frontend.statements import Statement, split_cityengine, split_paper
from grammarc.ir import nodes as ir

if TYPE_CHECKING:
    from lark import Tree
    from lark.exceptions import UnexpectedInput


@dataclass(frozen=True, slots=True)
class Dialect:
    """How a dialect is read: its lark grammar (a file of the package), how its text is cut into statements,
    the module whose ``Lowering`` (a lark Transformer) lowers one statement, and the package whose
    ``assemble`` assembles the lowered statements of a file into a module (imported where a file of the
    dialect is: a build of the other's does without it)."""

    grammar: str
    split: Callable[[str], list[Statement]]
    lowering: str
    package: str

    def assemble(self, *args, **kwargs) -> ir.Module:
        return import_module(self.package).assemble(*args, **kwargs)


DIALECTS = {
    "cga2006": Dialect("grammars/cga2006.lark", split_paper, "grammarc.frontend.cga2006.lowering",
                       "grammarc.frontend.cga2006"),
    "cityengine": Dialect("grammars/cityengine.lark", split_cityengine, "grammarc.frontend.cityengine.lowering",
                          "grammarc.frontend.cityengine"),
}
#: Text that only CityEngine CGA has: its version line, annotations, lower-case operations, const.
_CITYENGINE_MARKS = re.compile(r'^[ \t]*(version\s+"|@StartRule|const\s)|\b(extrude|split|comp)\s*\(',
                               re.MULTILINE)
#: Text that only the paper notation has: its arrows, PRIORITY blocks, capitalised operations.
_PAPER_MARKS = re.compile(r"~>|\u2192|\u21dd|^[ \t]*(PRIORITY\b|\d+\s*:)|\b(Subdiv|Repeat|Comp|I|S|T)\s*\(",
                          re.MULTILINE)


def detect_dialect(text: str) -> str:
    """``cityengine`` for CityEngine CGA, ``cga2006`` for the paper notation.

    A rule arrow ``-->`` is CityEngine's unless the text has the paper notation's own marks. The marks
    that stand at a line's start allow blanks before them but no line break (``^\\s*`` would try every
    following blank line from every line start: quadratic).
    """
    if _CITYENGINE_MARKS.search(text):
        return "cityengine"
    return "cityengine" if "-->" in text and not _PAPER_MARKS.search(text) else "cga2006"

#: How terminals are named in messages.
_TERMINALS = {
    "ARROW": "`~>`", "NAME": "a name", "NUMBER": "a number", "INT": "an integer", "STRING": "a string",
    "RELATIVE": "a relative size", "EMPTY": "`ε`", "LPAR": "`(`", "RPAR": "`)`", "LBRACE": "`{`",
    "RBRACE": "`}`", "LSQB": "`[`", "RSQB": "`]`", "VBAR": "`|`", "COMMA": "`,`", "COLON": "`:`",
    "COMPARE": "a comparison", "ADD": "`+` or `-`", "MUL": "`*`, `/` or `%`", "EQUAL": "`=`",
    "DOT": "`.`", "MINUS": "`-`", "PLUS": "`+`", "BANG": "`!`", "TRUE": "`true`", "FALSE": "`false`",
    "AND": "`&&`", "OR": "`||`", "NOT": "`not`", "PRIORITY": "`PRIORITY`", "ATTR": "`attr`",
    "PRIME": "`'`", "TILDE": "`~`", "$END": "the end of the statement",
}


def parse_source(text: str, file: str, diags: Diagnostics, dialect: str | None = None, *,
                 path: Path | None = None, sources: dict[str, str] | None = None, sites=None,
                 importing: tuple[Path, ...] = (), roots: Roots | None = None,
                 exports: dict | None = None) -> ir.Module:
    """Parse and lower ``text`` (named ``file`` in diagnostics); problems go to ``diags``.

    ``dialect`` is ``cga2006`` or ``cityengine``; by default it is detected from the text. ``path`` is
    the file on disk, from which CityEngine ``import``s are resolved inside ``roots`` (by default those
    of ``path``, ``imports.find_roots``); the texts of imported files are added to ``sources`` (for
    diagnostics); ``sites`` numbers random-stream sites across imported files. A CityEngine file's
    functions, which an importing file calls as ``prefix.name(...)``, go to ``exports`` (``assemble``).
    """
    text = text.removeprefix("\ufeff")  # a UTF-8 byte order mark, read as text
    name = dialect or detect_dialect(text)
    spec = DIALECTS[name]
    sites = sites if sites is not None else Sites()
    first_site = sites.next_site
    kept = lowered_cache.lookup(name, file, text, first_site)
    if kept is not None:
        lowered, warnings, sites.next_site = kept
        diags.extend(warnings)
    else:
        said = len(diags)
        lowered = _lower(spec, text, file, diags, sites)
        if not any(d.is_error for d in diags[said:]):
            lowered_cache.keep(name, file, text, first_site, lowered, diags[said:], sites.next_site)
    if spec is not DIALECTS["cityengine"]:  # the paper notation imports no files
        return spec.assemble(file, lowered, diags)
    from grammarc.frontend.cityengine.nodes import Import

    imports = []
    for st in lowered:
        declaration = getattr(st, "declaration", st)
        if isinstance(declaration, Import):
            imported = _import(declaration, file, path, diags, sources, sites, importing, roots)
            if imported is not None:
                imports.append((declaration, *imported))
    return spec.assemble(file, lowered, diags, imports, exports)


def _lower(spec: Dialect, text: str, file: str, diags: Diagnostics, sites: Sites) -> list:
    """Each statement of ``text`` parsed and lowered on its own (an error in one leaves the others)."""
    from lark.exceptions import UnexpectedInput

    from grammarc.frontend.parsers import parser_for

    parser, lowering = parser_for(spec.grammar), import_module(spec.lowering).Lowering
    lowered = []
    for statement in spec.split(text):
        try:
            tree = parser.parse("\n" * (statement.line - 1) + statement.text)
        except UnexpectedInput as error:
            _syntax_error(error, file, statement.text, statement.line, diags)
            continue
        if _too_deep(tree):
            column = len(statement.text) - len(statement.text.lstrip()) + 1
            diags.error("nesting", f"nesting too deep: grammarc reads statements of up to {MAX_NESTING} "
                        "levels of brackets and operators", Span(file, statement.line, column,
                                                                 statement.line, column + 1))
            continue
        lowered.append(lowering(file, diags, sites).transform(tree))
    return lowered


#: The deepest parse tree a statement may have. Lowering, the IR passes and the derivation walk a
#: statement's tree and the IR made from it recursively, a few calls per level: at this depth they stay
#: well within Python's recursion limit (tests/frontend/test_parse.py builds the deepest accepted nesting
#: of either dialect). One level of brackets or of an operator is a level or two of the tree.
MAX_NESTING = 150


def _too_deep(tree: Tree) -> bool:
    """Whether ``tree`` is deeper than ``MAX_NESTING``, found without recursion (the tree may be deeper
    than Python's recursion limit)."""
    from lark import Tree

    stack = [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_NESTING:
            return True
        stack.extend((child, depth + 1) for child in node.children if isinstance(child, Tree))
    return False


def _import(statement, file: str, path: Path | None, diags: Diagnostics, sources, sites, importing, roots):
    """The module and the functions of the file an ``import`` names (``imports.load_import`` finds and
    reads it)."""
    roots = roots or (find_roots(path) if path is not None else None)
    loaded = load_import(statement, file, path, roots, importing, diags)
    if loaded is None:
        return None
    display, text, target = loaded
    if sources is not None:
        sources[display] = text
    exports: dict = {}
    module = parse_source(text, display, diags, "cityengine", path=target, sources=sources, sites=sites,
                          importing=(*importing, path.resolve()), roots=roots, exports=exports)
    return module, exports


def _syntax_error(error: UnexpectedInput, file: str, text: str, first_line: int, diags: Diagnostics):
    from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedToken

    if isinstance(error, UnexpectedCharacters):
        span = Span(file, error.line, error.column, error.line, error.column + 1)
        char = error.char if hasattr(error, "char") else "?"
        diags.error("syntax", f"unexpected character `{char}`", span)
        return
    expected = sorted(
        _TERMINALS.get(t, f"`{t}`") for t in getattr(error, "expected", ()) or () if not t.startswith("__")
    )
    if isinstance(error, UnexpectedEOF) or (
        isinstance(error, UnexpectedToken) and error.token.type == "$END"
    ):
        if getattr(error, "line", -1) > 0 and getattr(error, "column", -1) > 0:
            # lark places the end at the last token: the caret goes under it, not under a comment after it
            span = Span(file, error.line, error.column, error.line, error.column + 1)
        else:
            lines = text.splitlines() or [""]
            line = first_line + len(lines) - 1
            col = len(lines[-1]) + 1
            span = Span(file, line, max(col - 1, 1), line, col)
        message = "unexpected end of statement"
        unclosed = _unclosed(text)
        if unclosed:
            # Point at the bracket left open, not at the end: it may be lines above.
            bracket, row, column = unclosed
            message = f"unclosed `{bracket}`"
            span = Span(file, first_line + row, column, first_line + row, column + 1)
        elif "`~>`" in expected:
            message = "a rule needs an arrow `~>` and a successor"
        diags.error("syntax", message, span, hint=_expected_hint(expected))
        return
    token = error.token
    end_col = token.end_column if token.end_column else token.column + len(str(token))
    span = Span(file, token.line, token.column, token.line, end_col)
    message = f"unexpected `{token}`"
    before = text[: max(token.start_pos - (first_line - 1), 0)] if token.start_pos is not None else text
    starts_successor = token.type in ("NAME", "EMPTY", "LSQB", "RSQB")
    if starts_successor and "`~>`" in expected \
            and not _ARROW.search(_BRACKET_SCAN.sub(_blank_strings, before)):
        message = f"a rule needs an arrow `~>` before `{token}`"
    elif expected:
        message += f", expected {_expected_hint(expected, prefix='')}"
    hint = ""
    if token.column == 1 and token.line > first_line:
        opened = _unclosed("\n".join(text.splitlines()[: token.line - first_line]))
        if opened:
            hint = f"a `{opened[0]}` on line {first_line + opened[1]} of this rule is not closed"
    diags.error("syntax", message, span, hint=hint)


def _expected_hint(expected: list[str], prefix: str = "expected ") -> str:
    if not expected:
        return ""
    if len(expected) > 6:
        expected = expected[:6] + ["..."]
    return prefix + (expected[0] if len(expected) == 1 else "one of " + ", ".join(expected))


def _unclosed(text: str) -> tuple[str, int, int] | None:
    """The innermost bracket left open at the end of ``text`` with its 0-based line and 1-based column,
    ignoring strings (straight or typographic quotes) and comments."""
    stack = []
    for match in _BRACKET_SCAN.finditer(text):
        c = match.group()
        if c in ("(", "[", "{"):
            row = text.count("\n", 0, match.start())
            col = match.start() - (text.rfind("\n", 0, match.start()) + 1) + 1
            stack.append((c, row, col))
        elif c in (")", "]", "}") and stack:
            stack.pop()
    return stack[-1] if stack else None


#: The rule arrows of cga2006.lark.
_ARROW = re.compile("~>|-->|->|;|\u2192|\u21dd")


def _blank_strings(match: re.Match) -> str:
    """Strings and comments become blanks (an arrow inside them is not an arrow); brackets stay."""
    return match.group() if len(match.group()) == 1 else " "


#: Brackets, and the strings and comments whose brackets do not count.
_BRACKET_SCAN = re.compile(r'"[^"\n]*"?|[\u201c\u201d][^\u201c\u201d"\n]*[\u201c\u201d]?|//[^\n]*|#[^\n]*'
                           r"|/\*.*?(\*/|$)|[()\[\]{}]", re.DOTALL)
