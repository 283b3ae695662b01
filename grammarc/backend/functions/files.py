"""File functions: CityEngine's search queries answered in the grammar's roots, a file picked per shape, and
paths taken apart.

``fileSearch(query)`` lists the matching files as a string list (``"a.obj;b.obj;"``), ``filesSearch`` as
a ``str[]``, ``fileRandom(query)`` picks one per shape from its random stream (``""`` when none matches),
``fileExists(path)`` resolves a path as an insert does. The query language, the roots and the names
returned are ``ir.file_search``'s: a query is searched once per distinct text, its names interned, and the
shapes gather them. ``fileName``, ``fileBasename``, ``fileDirectory`` and ``fileExtension`` follow the CGA
reference's own definitions in its ``ce.lib`` (``fileExtension("assets/v1.2/x")`` is ``"2/x"`` there
too: it is the text after the last dot).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.strings import string_arrays
from grammarc.backend.functions.table import distinct, function, groups
from grammarc.backend.streams import draw
from grammarc.ir.asset_names import resolve_asset
from grammarc.ir.file_search import search

if TYPE_CHECKING:
    from grammarc.backend.env import Env


def roots(env: Env) -> tuple:
    """The folders the grammar's files are searched and resolved in (``Grammar.asset_roots``)."""
    return tuple(env.plan.grammar.asset_roots)


def found(env: Env, query: int) -> tuple[str, ...]:
    """The names of the files the query with string id ``query`` finds."""
    return search(list(env.plan.strings.ids)[query], roots(env))


def pick(choices: Callable[[tuple[int, ...], np.ndarray], np.ndarray], keys: list, call, env: Env) -> np.ndarray:
    """One choice per shape, drawn from its stream at the call's site: (n,) int32 string ids.

    ``choices(key, rows)`` gives, for the shapes ``rows`` (k,) of one distinct tuple of ``keys`` (string
    ids: a query, a selector), their candidates as interned ids, one row per shape or one row for all
    ((k, c) or (1, c) int32, a row's candidates first and -1 after them where a shape has fewer); a shape
    picks uniformly among its own, ``""`` when it has none."""
    n = len(env.shapes)
    u = draw(env.plan.sequential_random, env.shapes.key, call.site)
    out = np.full(n, env.plan.strings.intern(""), dtype=np.int32)
    for key, rows in groups(n, *keys):
        options = np.asarray(choices(key, rows))
        options = np.broadcast_to(options, (len(rows), options.shape[1]))
        count = (options >= 0).sum(axis=1)
        k = np.minimum((u[rows] * count).astype(np.int64), np.maximum(count - 1, 0))
        chosen = options[np.arange(len(rows)), k] if options.shape[1] else np.full(len(rows), -1)
        out[rows] = np.where(count > 0, chosen, out[rows])
    return out


def interned(env: Env, names) -> np.ndarray:
    """(1, c) int32 the ids of ``names``, as ``pick`` takes the same candidates for every shape."""
    return np.array([[env.plan.strings.intern(name) for name in names]], dtype=np.int32).reshape(1, -1)


@function("fileRandom")
def file_random(call, args, env: Env):
    return pick(lambda key, rows: interned(env, found(env, key[0])), [args[0]], call, env)


def string_list(names) -> str:
    """CityEngine's string list of ``names``: each item ended by ``;``. The reference's ``fileSearch``
    examples give ``";"`` when nothing matches, and so does this."""
    return "".join(f"{name};" for name in names) or ";"


@function("fileSearch")
def file_search(call, args, env: Env):
    strings = env.plan.strings
    return distinct(lambda query: strings.intern(string_list(found(env, query))), args[0], dtype=np.int32)


@function("filesSearch")
def files_search(call, args, env: Env):
    """``filesSearch(query)``: the matches as a ``str[]`` per shape (a row, as ``[a, b]`` is)."""
    return string_arrays(env, lambda query: found(env, query), args[0])


@function("fileExists")
def file_exists(call, args, env: Env):
    names = list(env.plan.strings.ids)
    return distinct(lambda path: resolve_asset(names[path], list(roots(env))).path is not None, args[0],
                    dtype=bool)


def _after(text: str, mark: str) -> str:
    """The text after the last ``mark`` (all of it without one): the reference's ``getSuffix``."""
    return text.rsplit(mark, 1)[1] if mark in text else text


def file_name(path: str) -> str:
    """``fileName``: the path without its folders (``/`` first, else ``\\``)."""
    return _after(path, "/") if "/" in path else _after(path, "\\")


PARTS = {
    "fileName": file_name,
    "fileExtension": lambda path: _after(path, ".") if "." in path else "",
    "fileBasename": lambda path: file_name(path.rsplit(".", 1)[0]) if "." in file_name(path) else file_name(path),
    "fileDirectory": lambda path: next((path[:path.rfind(mark) + 1] for mark in "/\\" if mark in path), ""),
}


@function(*PARTS)
def path_part(call, args, env: Env):
    strings = env.plan.strings
    names = list(strings.ids)
    part = PARTS[call.func]
    return distinct(lambda path: strings.intern(part(names[path])), args[0], dtype=np.int32)
