"""String functions and CityEngine's conversions between strings, numbers and flags.

A string value is an interned id (``Plan.strings``): an ``int`` or an int32 array, where numbers are
float64 and flags bool (``is_string`` tells them apart). Each function is written twice over: once on one
text (``count``, ``find``, ``substring``..., the specification, tested against the reference's examples) and
once on a batch, where ``texts`` runs it once per distinct argument tuple (``table.distinct``) and interns
what it makes.

CityEngine's own functions are ``count find len splitString substring`` and the conversions ``str float bool``; its
utility library (``ce.lib``, callable without an import) adds ``findLast getPrefix getSuffix getRange replace``
written in CGA on top of them, and these follow that CGA: ``replace`` with nothing to replace gives the text
back, ``getPrefix`` without the match the whole text. Where the reference is silent: an empty match string
is found nowhere (``count`` 0, ``find`` -1), an index is truncated toward zero, as CGA's floats become
indices.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.arrays import Arrays
from grammarc.backend.functions.table import distinct, function
from grammarc.errors import LotFailure
from grammarc.ir.functions import FUNCTIONS
from grammarc.ir.nodes import Type

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: The batch dtype of each result type.
_DTYPES = {Type.STR: np.int32, Type.NUM: np.float64, Type.BOOL: np.bool_}
#: A scalar result in its batch type (a count is a float: a Python int would read as a string id).
_CASTS = {Type.NUM: float, Type.BOOL: bool}
#: Texts ``bool`` reads as false, besides those of numbers equal to 0 (``"0"``, ``"0.0"``).
_FALSE = frozenset({"", "f", "false"})


def is_string(value) -> bool:
    """String values are interned ids: Python ints or int32 arrays (numbers are float, flags bool)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)) or (
        isinstance(value, np.ndarray) and value.dtype == np.int32)


# ---------------------------------------------------------------------------------------------- one text


def format_value(value, is_str: bool, names: list[str]) -> str:
    """A value as CityEngine prints it in strings: 3.0 -> "3", 2.5 -> "2.5", True -> "true".

    The reference shows whole numbers without a decimal point (``str(001)`` is "1") and others with their
    digits (``str(1.69)``); where it is silent, a number is written with the fewest digits that read back
    to it (``1e-07``, ``inf``, ``nan``)."""
    if is_str:
        return names[int(value)]
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)


def count(text: str, match: str) -> int:
    """The number of non-overlapping occurrences of ``match`` in ``text``."""
    return text.count(match) if match else 0


def find(text: str, match: str, n: float) -> int:
    """The index of the ``n``-th (from 0) non-overlapping occurrence of ``match`` in ``text``, or -1."""
    if not match or not math.isfinite(n) or int(n) < 0:
        return -1
    at = text.find(match)
    for _ in range(int(n)):
        if at < 0:
            break
        at = text.find(match, at + len(match))
    return at


def find_last(text: str, match: str) -> int:
    """``findLast``: the index of the last occurrence of ``match``, or -1."""
    return find(text, match, count(text, match) - 1)


def substring(text: str, start: float, end: float) -> str:
    """The characters from ``start`` to ``end`` (excluded); indices clamped to the text, "" when none."""
    if math.isnan(start) or math.isnan(end):
        return ""
    low = 0 if start < 0 else min(int(start), len(text)) if math.isfinite(start) else len(text)
    high = len(text) if end > len(text) else int(end) if math.isfinite(end) else 0
    return text[low:high] if low < high else ""


def prefix(text: str, match: str) -> str:
    """``getPrefix``: the text before the first ``match``, or the whole text when there is none."""
    return text[:find(text, match, 0)] if count(text, match) else text


def suffix(text: str, match: str) -> str:
    """``getSuffix``: the text after the last ``match``, or the whole text when there is none."""
    return text[find_last(text, match) + len(match):] if count(text, match) else text


def between(text: str, left: str, right: str) -> str:
    """``getRange``: the text from after the first ``left`` to the last ``right``; a missing end is the
    text's own end, both missing the whole text."""
    low = find(text, left, 0) + len(left) if count(text, left) else 0
    high = find_last(text, right) if count(text, right) else len(text)
    return substring(text, low, high) if count(text, left) or count(text, right) else text


def replace(text: str, old: str, new: str) -> str:
    """``replace``: every non-overlapping ``old``, left to right, replaced by ``new``."""
    return text.replace(old, new) if old else text


def split(text: str, delimiter: str) -> list[str]:
    """``splitString``: the pieces of ``text`` between the delimiters; a delimiter starting with ``$`` is a
    regular expression (Python's, which reads the reference's examples as CityEngine's does), and the
    empty delimiter splits around every character (``"abc"``: "", "a", "b", "c", "").

    Raises ``re.error`` for a regular expression that is not one."""
    if delimiter.startswith("$"):
        return re.split(delimiter[1:], text)
    return re.split(re.escape(delimiter), text)


def parse_float(text: str) -> float:
    """``float(text)``: the number written in the text (blanks around it allowed), NaN (CGA's missing
    value) when it is not one."""
    try:
        return float(text) if "_" not in text else math.nan
    except ValueError:
        return math.nan


def parse_bool(text: str) -> bool:
    """``bool(text)``: false for "f", "false" (any case), the empty text and a number equal to 0
    ("0", "0.0"), true for any other text ("true", "beneath the remains")."""
    return not (text.strip().lower() in _FALSE or parse_float(text) == 0)


# ------------------------------------------------------------------------------------------------- batch


def texts(env: Env) -> list[str]:
    """The interned strings' texts by id."""
    return list(env.plan.strings.ids)


def on_texts(*names: str) -> Callable:
    """Register a function of texts and numbers (typed by its signature in ``ir.functions``) as the
    built-ins ``names``: computed once per distinct argument tuple, its text results interned."""
    def register(compute: Callable) -> Callable:
        @function(*names)
        def batch(call, args, env: Env):
            signature = FUNCTIONS[call.func]
            strings, known = env.plan.strings, texts(env)
            reads = [want is Type.STR for want in signature.params]

            def one(*values):
                out = compute(*(known[v] if text else v for v, text in zip(values, reads)))
                return strings.intern(out) if signature.result is Type.STR else _CASTS[signature.result](out)
            return distinct(one, *args, dtype=_DTYPES[signature.result])
        return compute
    return register


on_texts("count")(count)
on_texts("find")(find)
on_texts("findLast")(find_last)
on_texts("substring")(substring)
on_texts("getPrefix")(prefix)
on_texts("getSuffix")(suffix)
on_texts("getRange")(between)
on_texts("replace")(replace)
on_texts("len")(len)


@function("splitString")
def split_string(call, args, env: Env) -> Arrays:
    """``splitString(text, delimiter)``: per shape the array of its pieces, split once per distinct
    (text, delimiter); the lots of the shapes whose delimiter is no regular expression fail."""
    known = texts(env)

    def split_once(text: int, delimiter: int) -> list[str] | None:
        try:
            return split(known[text], known[delimiter])
        except re.error:
            return None
    return string_arrays(env, split_once, *args, failure=f"splitString: no regular expression at {call.span}")


def string_arrays(env: Env, names_of: Callable, *args, failure: str = "") -> Arrays:
    """Per shape the ``str[]`` (a row) ``names_of(*values)`` gives for its tuple of argument values, each
    distinct tuple's names computed and interned once. Where ``names_of`` gives None the lots of those
    shapes fail with ``failure``."""
    strings = env.plan.strings
    rows: list[list[int]] = []

    def one(*values) -> int:
        names = names_of(*values)
        if names is None:
            return -1
        rows.append([strings.intern(name) for name in names])
        return len(rows) - 1
    which = np.broadcast_to(np.asarray(distinct(one, *args), dtype=np.int64), (len(env.shapes),))
    bad = which < 0
    if bad.any():
        raise LotFailure(failure, np.unique(env.shapes.lot[bad]))
    sizes = np.array([len(r) for r in rows], dtype=np.int64)
    table = Arrays(np.array([i for r in rows for i in r], dtype=np.int32),
                   np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64), sizes)
    return table.take(which)


def as_string(value, strings):
    """A value (ids, numbers or flags, per shape or scalar) as interned strings, as ``str`` writes it."""
    if is_string(value):
        return value
    names = list(strings.ids)
    return distinct(lambda v: strings.intern(format_value(v, False, names)), value, dtype=np.int32)


def concatenate(left, right, strings) -> np.ndarray | int:
    """CityEngine's ``+`` on strings, per shape: once per distinct pair of operands, then spread."""
    names = list(strings.ids)
    left_str, right_str = is_string(left), is_string(right)
    return distinct(lambda a, b: strings.intern(format_value(a, left_str, names) + format_value(b, right_str, names)),
                    left, right, dtype=np.int32)


@function("str")
def to_string(call, args, env: Env):
    return as_string(args[0], env.plan.strings)


@function("float")
def to_float(call, args, env: Env):
    """``float(x)``: numbers stay, booleans become 0/1, strings are parsed (NaN when not a number)."""
    value = args[0]
    if not is_string(value):
        return np.asarray(value, dtype=np.float64)
    known = texts(env)
    return distinct(lambda i: parse_float(known[i]), value)


@function("bool")
def to_bool(call, args, env: Env):
    """``bool(x)``: a number is true unless 0 (NaN is true), a string as ``parse_bool`` reads it."""
    value = args[0]
    if not is_string(value):
        return np.asarray(value) != 0
    known = texts(env)
    return distinct(lambda i: parse_bool(known[i]), value, dtype=np.bool_)


def string_ranks(env: Env) -> np.ndarray:
    """(strings,) int64 the rank of each interned string's text in sorted order."""
    names = list(env.plan.strings.ids)
    ranks = np.empty(len(names), dtype=np.int64)
    ranks[np.argsort(np.array(names, dtype=object), kind="stable")] = np.arange(len(names))
    return ranks
