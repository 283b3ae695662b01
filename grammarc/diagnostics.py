"""Spans and diagnostics: errors are data, rendered by one function.

Every IR node carries a ``Span``; every problem found in a grammar becomes a ``Diagnostic`` appended to
a list, so that all of them are reported at once. ``render`` prints the CGA-style message::

    city.cga:12:12: error: unknown operation `Subdv` (did you mean `Subdiv`?)
       12 | facade ~> Subdv("Y", 3){ floor }
          |           ^^^^^
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


@dataclass(frozen=True, slots=True)
class Span:
    """Where a construct is in its source: 1-based line and column, end exclusive."""

    file: str
    line: int
    col: int
    end_line: int
    end_col: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


NO_SPAN = Span("<builtin>", 0, 0, 0, 0)


class Severity(Enum):
    ERROR = "error"
    WARNING = "warning"


@dataclass(frozen=True, slots=True)
class Diagnostic:
    code: str
    severity: Severity
    message: str
    span: Span
    hint: str = ""

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR


class Diagnostics(list):
    """A list of ``Diagnostic`` with helpers to add errors and warnings."""

    def error(self, code: str, message: str, span: Span, hint: str = "") -> None:
        self.append(Diagnostic(code, Severity.ERROR, message, span, hint))

    def warning(self, code: str, message: str, span: Span, hint: str = "") -> None:
        self.append(Diagnostic(code, Severity.WARNING, message, span, hint))

    @property
    def has_errors(self) -> bool:
        return any(d.is_error for d in self)


#: Columns of a source line shown under a message: a longer line is cut to a window around the span, so
#: that thousands of errors on one long line (a minified or generated file) cost a screenful each, not the
#: line each.
SHOWN_COLUMNS = 120


def render(diag: Diagnostic, sources: dict[str, str]) -> str:
    """Render one diagnostic with the offending line and a caret under the span."""
    return _render(diag, _Lines(sources))


def render_all(diags: list[Diagnostic], sources: dict[str, str]) -> str:
    """Render every diagnostic, ordered by place; each file's text is cut into lines once."""
    lines = _Lines(sources)
    ordered = sorted(diags, key=lambda d: (d.span.file, d.span.line, d.span.col))
    return "\n".join(_render(d, lines) for d in ordered)


class _Lines:
    """The lines of each source, cut when first asked for."""

    def __init__(self, sources: dict[str, str]):
        self.sources = sources
        self.cut: dict[str, list[str]] = {}

    def line(self, span: Span) -> str | None:
        if span.file not in self.cut:
            text = self.sources.get(span.file)
            self.cut[span.file] = [] if text is None else text.splitlines()
        lines = self.cut[span.file]
        return lines[span.line - 1] if 0 < span.line <= len(lines) else None


def _render(diag: Diagnostic, lines: _Lines) -> str:
    head = f"{diag.span}: {diag.severity.value}: {diag.message}"
    shown = [head]
    src = lines.line(diag.span)
    if src is not None:
        src = src.expandtabs(1)
        width = 1
        if diag.span.end_line == diag.span.line and diag.span.end_col > diag.span.col:
            width = diag.span.end_col - diag.span.col
        col = diag.span.col - 1
        if len(src) > SHOWN_COLUMNS:  # a window around the span, the cuts marked
            start = max(0, min(col - SHOWN_COLUMNS // 3, len(src) - SHOWN_COLUMNS))
            window = src[start:start + SHOWN_COLUMNS]
            width = max(1, min(width, SHOWN_COLUMNS - (col - start)))
            src = ("..." if start else "") + window + ("..." if start + SHOWN_COLUMNS < len(src) else "")
            col = col - start + (3 if start else 0)
        num = str(diag.span.line)
        pad = " " * len(num)
        shown.append(f" {num} | {src}")
        shown.append(f" {pad} | {' ' * col}{'^' * width}")
    if diag.hint:
        shown.append(f"  hint: {diag.hint}")
    return "\n".join(shown)


def suggest(name: str, candidates) -> str:
    """`` (did you mean `x`?)`` for the closest candidate, or an empty string."""
    import difflib  # here: a compile that finds no unknown name does without it

    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.6)
    return f" (did you mean `{close[0]}`?)" if close else ""


def typo_of(name: str, candidates) -> str | None:
    """The candidate that ``name`` is a typo of, or None (see ``Typos``, for many names against one set)."""
    return Typos(candidates).of(name)


class Typos:
    """Which of a fixed set of names another name is a typo of: one edit away (a letter missing, extra,
    wrong, or two swapped) for names of four to seven letters, two for longer ones, letter case aside
    (names of one to three letters are all one edit apart: only their case). Stricter than ``suggest``,
    which picks the likeliest of names that must exist; a name that need not exist (a leaf) is only suspect
    when it is that close.

    The candidates are indexed by what is left of each (in lower case) after deleting up to two of its
    letters: two names at most k edits apart leave a common string after k deletions from each, so a name
    is compared only with the candidates that share one with it, not with all of them (a grammar of
    thousands of rules has thousands of leaves to look at).
    """

    def __init__(self, candidates):
        self.candidates = list(candidates)
        self.index: dict[str, list[int]] = {}
        for order, candidate in enumerate(self.candidates):
            for left in _deletions(candidate.lower(), 2):
                self.index.setdefault(left, []).append(order)

    def of(self, name: str) -> str | None:
        """The first candidate, in the given order, that ``name`` is a typo of; None if there is none."""
        most = 0 if len(name) < 4 else 1 if len(name) < 8 else 2
        lowered = name.lower()
        near = sorted({order for left in _deletions(lowered, most) for order in self.index.get(left, ())})
        for order in near:
            candidate = self.candidates[order]
            if candidate != name and abs(len(candidate) - len(name)) <= most \
                    and _edits(lowered, candidate.lower(), most) <= most:
                return candidate
        return None


def _deletions(word: str, most: int) -> set[str]:
    """``word`` and every string left of it after deleting up to ``most`` of its letters."""
    found = {word}
    layer = {word}
    for _ in range(most):
        layer = {w[:i] + w[i + 1:] for w in layer for i in range(len(w))}
        found |= layer
    return found


def _edits(a: str, b: str, most: int) -> int:
    """Optimal string alignment distance of ``a`` and ``b`` (insertions, deletions, substitutions and
    swaps of neighbours), or ``most + 1`` once it is sure to exceed ``most``."""
    before, row = None, list(range(len(b) + 1))
    for i, x in enumerate(a, 1):
        current = [i] + [0] * len(b)
        for j, y in enumerate(b, 1):
            current[j] = min(row[j] + 1, current[j - 1] + 1, row[j - 1] + (x != y))
            if before is not None and i > 1 and j > 1 and x == b[j - 2] and a[i - 2] == y:
                current[j] = min(current[j], before[j - 2] + 1)
        if min(current) > most:
            return most + 1
        before, row = row, current
    return row[-1]
