"""Text files and CSV tables of the grammar's folders: ``readTextFile``, ``readStringTable``, ``readFloatTable``.

A path is looked up as an asset name is (``ir.asset_names.locate``: the grammar's folder, its project,
the ``--assets`` folders, a workspace path ``/Project/...``), never outside those folders, and a file of more
than ``MAX_FILE_BYTES`` is refused before it is read. A file is read and parsed once per process (cached by
its path, modification time and size, so that an edited file is read again), and its cells are interned
once per string table; the functions run once per distinct path of a batch, not per shape.

As the reference says: the text is ASCII, UTF-8 or UTF-16 (with its byte-order mark), line endings become
``"\\n"`` and the other control characters but tabs ``"?"``; a file that is none of these is read as
Windows-1252, as grammars are (``frontend.source``). A table's delimiter is found in its text (below),
cells in double quotes may hold it, cells are trimmed of surrounding blanks, blank lines are skipped, and a
row shorter than the longest is filled with ``""`` (NaN in a float table). ``readFloatTable`` is
``readStringTable`` with each cell read as a number, NaN where it is none (the reference's ``floatArray``).

Where the reference is silent: a path that names no file of the grammar's folders, a larger file, or a
table of more than ``arrays.MAX_ELEMENTS`` cells (CityEngine's array limit) fail the lots that read it, with
the reason, as a bad lot is reported (``LotFailure``), rather than giving an empty value that would build
something else without a word.
"""

from __future__ import annotations

import codecs
import csv
import io
import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING
from weakref import WeakKeyDictionary

import numpy as np

from grammarc.backend import arrays
from grammarc.backend.arrays import Arrays
from grammarc.backend.functions.table import function
from grammarc.errors import LotFailure
from grammarc.frontend.source import decode_grammar
from grammarc.ir.asset_names import locate

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: The largest text or table file read (bytes): a table of CityEngine's 100,000 cells is well below it.
MAX_FILE_BYTES = 16 * 2**20
#: Delimiters in the order they are preferred when several fit a table (``_delimiter``): a semicolon table
#: may write decimal commas, a comma table may hold ``;`` string lists.
DELIMITERS = ("\t", ";", ",", " ")
#: Control characters the text keeps; the others become "?".
_UNPRINTABLE = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")


@dataclass(frozen=True, eq=False)
class Table:
    """A parsed CSV file: ``rows`` x ``columns`` cells, row by row, as text and as numbers (NaN if none)."""

    rows: int
    columns: int
    cells: tuple[str, ...]
    numbers: np.ndarray


@function("readTextFile")
def read_text_file(call, args, env: Env):
    strings = env.plan.strings
    return _per_path(call, args[0], env, lambda path: np.array([strings.intern(_text(*_stamp(path)))],
                                                               dtype=np.int32), np.int32)


@function("readStringTable", "readFloatTable")
def read_table(call, args, env: Env):
    if call.func == "readFloatTable":
        return _per_path(call, args[0], env, lambda path: _table(*_stamp(path)), np.float64)
    interned = _interned.setdefault(env.plan.strings, {})

    def cells(path: Path) -> Table:
        stamp = _stamp(path)
        if stamp not in interned:
            table = _table(*stamp)
            ids = np.fromiter((env.plan.strings.intern(c) for c in table.cells), np.int32, len(table.cells))
            interned[stamp] = Table(table.rows, table.columns, table.cells, ids)
        return interned[stamp]
    return _per_path(call, args[0], env, cells, np.int32)


#: The interned cells of each string table, per table of interned strings (a plan's; ids are per table).
_interned: WeakKeyDictionary = WeakKeyDictionary()


def _per_path(call, path, env: Env, load, dtype):
    """The value of each shape's file: ``load(file)`` once per distinct path, gathered per shape.

    ``load`` returns a ``Table`` (its ``numbers`` are the elements: ids or floats), or a 1-element array (a
    text file's id); tables give ``Arrays``, texts an (n,) column, or a scalar for a constant path.
    """
    n = len(env.shapes)
    texts, inverse = np.unique(np.atleast_1d(path), return_inverse=True)
    which = inverse.reshape(-1) if np.ndim(path) else np.zeros(n, dtype=np.int64)
    names = list(env.plan.strings.ids)
    loaded = []
    for i, text in enumerate(texts):
        found, reason = _find(names[text], env.plan.grammar.asset_roots)
        value = None if found is None else load(found)
        if isinstance(value, Table) and value.rows * value.columns > arrays.MAX_ELEMENTS:
            reason = f"`{names[text]}` has more than {arrays.MAX_ELEMENTS:,} cells"
        if reason is not None:
            raise LotFailure(f"`{call.func}` at {call.span}: {reason}", np.unique(env.shapes.lot[which == i]))
        loaded.append(value)
    if not isinstance(loaded[0], Table):
        column = np.concatenate(loaded)[inverse.reshape(-1)]
        return column if np.ndim(path) else column[0].item()
    sizes = np.array([t.rows * t.columns for t in loaded], dtype=np.int64)
    starts = np.cumsum(sizes) - sizes
    pool = np.concatenate([t.numbers for t in loaded]).astype(dtype)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(sizes[which], out=offsets[1:])
    owner = np.repeat(np.arange(n), sizes[which])
    position = np.arange(offsets[-1]) - offsets[:-1][owner]
    columns = np.array([t.columns for t in loaded], dtype=np.int64)[which]
    return Arrays(pool[starts[which][owner] + position], offsets, columns)


def _find(name: str, roots) -> tuple[Path | None, str | None]:
    """The file ``name`` names in the grammar's folders ``roots``, or None and why it cannot be read."""
    found = locate(name, roots) if name and "\0" not in name else None
    if found is None:
        return None, f"`{name}` is not a file of the grammar's folders"
    if found[1].stat().st_size > MAX_FILE_BYTES:
        return None, f"`{name}` is larger than {MAX_FILE_BYTES // 2**20} MiB"
    return found[1], None


def _stamp(path: Path) -> tuple[Path, int, int]:
    """The file, its modification time and size: the cache key, so that an edited file is read again."""
    status = path.stat()
    return path, status.st_mtime_ns, status.st_size


@lru_cache(maxsize=64)
def _text(path: Path, mtime: int, size: int) -> str:
    """The text of a file: its encoding found, line endings ``\\n``, control characters ``?``."""
    with path.open("rb") as handle:
        data = handle.read(MAX_FILE_BYTES + 1)[:MAX_FILE_BYTES]
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        text = data.decode("utf-16", errors="replace")
    else:
        text = decode_grammar(data)[0]
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    return _UNPRINTABLE.sub("?", text)


@lru_cache(maxsize=64)
def _table(path: Path, mtime: int, size: int) -> Table:
    """The file's table (see the module's docstring)."""
    lines = [line for line in _text(path, mtime, size).split("\n") if line.strip()]
    delimiter = _delimiter(lines)
    if delimiter == " ":
        lines = [line.strip() for line in lines]
    reader = csv.reader(io.StringIO("\n".join(lines)), delimiter=delimiter or ",",
                        skipinitialspace=delimiter == " ")
    rows = [[cell.strip() for cell in row] for row in reader]
    columns = max((len(r) for r in rows), default=0)
    cells = tuple(c for row in rows for c in row + [""] * (columns - len(row)))
    return Table(len(rows), columns if rows else 0, cells, np.array([_number(c) for c in cells]))


def _delimiter(lines: list[str]) -> str | None:
    """The table's delimiter: of ``DELIMITERS``, the first that every line holds as often (outside quotes),
    else the one that most lines hold; None when no line holds any (one column)."""
    bare = [re.sub(r'"[^"]*"', "", line).strip() for line in lines]
    counts = {d: [len(re.findall(" +" if d == " " else re.escape(d), line)) for line in bare] for d in DELIMITERS}
    steady = [d for d in DELIMITERS if counts[d] and counts[d][0] > 0 and len(set(counts[d])) == 1]
    if steady:
        return steady[0]
    held = {d: sum(c > 0 for c in counts[d]) for d in DELIMITERS}
    best = max(DELIMITERS, key=lambda d: held[d])
    return best if held[best] else None


def _number(cell: str) -> float:
    """A cell as a number, NaN when it is none: decimals with a point, as CityEngine's ``float()`` reads them."""
    return float(cell) if _NUMBER.fullmatch(cell) else np.nan


#: A decimal number: an optional sign, digits with an optional point, an optional exponent.
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
