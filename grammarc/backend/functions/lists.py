"""CityEngine's string lists: strings of ``;``-separated items (``"a;b;c;"``), per shape.

The list functions belong to CityEngine's utility library (``ce.lib``), written in CGA on CGA's string
functions; each is written here on one text as that CGA computes it, so that its answers on lists that are
not clean (no ``;`` at the end, empty items ``;;``) and on indices out of range are CityEngine's:

- an item is what lies between two ``;``: ``"a;;b;"`` has three items, the second empty; the last item
  needs no ``;`` (``listSize("a;b")`` is 2) and ``""`` has none;
- an index is truncated toward zero (``1.5`` is 1, ``-0.5`` is 0); ``listItem`` of an index out of range
  (below 0, or not below the size) is ``""``; ``listRange`` clamps its indices and ends its list with ``;``;
- a search string (``listIndex``, ``listCount``, ``listRemove``...) matches an item equal to it, or, with
  a ``*`` at its start, end or both, an item ending with, starting with or containing the rest.

On a batch each runs once per distinct argument tuple (``strings.on_texts``); ``listRandom`` cuts each
distinct list into its items once and gathers the item of an index drawn per shape from its random
stream, as ``rand`` draws.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.strings import count, find, find_last, on_texts, prefix, substring, texts
from grammarc.backend.functions.table import function
from grammarc.backend.streams import draw

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: ``listRandom`` draws an index below ``size - SHY``, never ``size`` itself, as ``ce.lib`` does.
SHY = 1e-7


@on_texts("listTerminate")
def terminate(items: str) -> str:
    """The list with a ``;`` at its end (an empty list stays empty)."""
    return items + ";" if items and not items.endswith(";") else items


@on_texts("listClean")
def clean(items: str) -> str:
    """The list without its empty items, ended with ``;``."""
    return "".join(item + ";" for item in items.split(";") if item)


@on_texts("listSize")
def size(items: str) -> int:
    """The number of items."""
    return count(terminate(items), ";")


@on_texts("listFirst")
def first(items: str) -> str:
    """The first item (the whole text when it has no ``;``)."""
    return prefix(items, ";")


@on_texts("listItem")
def item(items: str, index: float) -> str:
    """The item at ``index`` (from 0), ``""`` out of range."""
    if index == 0:
        return first(items)
    if index < size(items):
        return substring(items, find(items, ";", index - 1) + 1, find(terminate(items), ";", index))
    return ""


@on_texts("listLast")
def last(items: str) -> str:
    """The last item."""
    return item(items, size(items) - 1)


@on_texts("listAdd")
def add(items: str, more: str) -> str:
    """The list with ``more`` (an item or a list) appended."""
    return terminate(items) + terminate(more)


@on_texts("listRange")
def items_range(items: str, low: float, high: float) -> str:
    """The items from ``low`` to ``high`` (excluded), a list ended with ``;``."""
    total = size(items)
    if low >= high or low >= total:
        return ""
    end = len(items) if high >= total else find(items, ";", high - 1) + 1
    start = 0 if low <= 0 else find(items, ";", low - 1) + 1
    return terminate(substring(items, start, end))


@on_texts("listIndex")
def index_of(items: str, search: str) -> int:
    """The index of the first item ``search`` matches, -1 when none does.

    Matching runs on the text, as ``ce.lib`` does: ``*x*`` finds ``x`` anywhere, ``*x`` finds ``x;``,
    ``x*`` finds ``;x``, an exact search ``;x;`` (the list read with a ``;`` before it); the index is the
    number of ``;`` before the match. An empty list has no item to match (that CGA finds ``""`` and
    ``"*"`` at 0 in it, and its ``listCount`` never ends)."""
    if not items:
        return -1
    lead, trail = find(search, "*", 0) == 0, find_last(search, "*") == len(search) - 1
    if lead and trail and count(items, search[1:-1]) > 0:
        return count(prefix(items, search[1:-1]), ";")
    if lead and count(items, search[1:] + ";") > 0:
        return count(prefix(items, search[1:] + ";"), ";")
    if trail and count(";" + items, ";" + search[:-1]) > 0:
        return count(prefix(";" + items, ";" + search[:-1]), ";")
    if count(";" + items, ";" + search + ";") > 0:
        return count(prefix(";" + items, ";" + search + ";"), ";")
    return -1


def _matches(items: str, search: str):
    """(the items before each match, the matched item) for each item ``search`` matches, in order."""
    while (at := index_of(items, search)) >= 0:
        yield items_range(items, 0, at), item(items, at)
        items = items_range(items, at + 1, size(items))


@on_texts("listCount")
def count_matches(items: str, search: str) -> int:
    """The number of items ``search`` matches."""
    return sum(1 for _ in _matches(items, search))


@on_texts("listRemove")
def remove(items: str, search: str) -> str:
    """The list without the first item ``search`` matches (the list itself when none does)."""
    at = index_of(items, search)
    return items_range(items, 0, at) + items_range(items, at + 1, size(items)) if at >= 0 else items


@on_texts("listRemoveAll")
def remove_all(items: str, search: str) -> str:
    """The list without the items ``search`` matches."""
    kept, rest = [], items
    while (at := index_of(rest, search)) >= 0:
        kept.append(items_range(rest, 0, at))
        rest = items_range(rest, at + 1, size(rest))
    return "".join(kept) + rest


@on_texts("listRetainAll")
def retain_all(items: str, search: str) -> str:
    """The list of the items ``search`` matches."""
    return "".join(found + ";" for _, found in _matches(items, search))


@function("listRandom")
def list_random(call, args, env: Env):
    """``listRandom(list)``: an item drawn per shape (index ``floor(u * (size - SHY))``, "" of an empty
    list), from the shape's stream at the call's site as ``rand`` draws. Each distinct list is cut into its
    items once; the items are gathered per shape by the drawn index."""
    strings, known = env.plan.strings, texts(env)
    u = draw(env.plan.sequential_random, env.shapes.key, call.site)
    lists, which = np.unique(np.broadcast_to(args[0], u.shape), return_inverse=True)
    items = [[strings.intern(item(known[text], k)) for k in range(size(known[text]))] for text in lists.tolist()]
    sizes = np.array([len(i) for i in items], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    # every item, then "" for the draws of an empty list (index -1)
    flat = np.array([i for each in items for i in each] + [strings.intern("")], dtype=np.int32)
    index = np.floor(u * (sizes[which] - SHY)).astype(np.int64)
    return flat[np.where(index >= 0, starts[which] + index, len(flat) - 1)]
