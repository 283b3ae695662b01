"""The lark parsers of the dialects' grammars, built once per process and kept between processes in the
user's own cache folder.

Building an LALR parser from ``grammars/*.lark`` takes several times longer than loading its tables, and
every ``grammarc`` command starts by it. lark's own cache (``cache=True``) is a pickle in the shared temp
folder, loaded whoever wrote it: anyone who can write ``/tmp`` could make grammarc run code. So the tables
are kept in ``$XDG_CACHE_HOME/grammarc`` (by default ``~/.cache/grammarc``), a folder created ``0700``;
a cached file is loaded only if that folder and the file belong to the user and nobody else can write
them, and it is written atomically (a temporary file renamed over it), so that a reader never sees half a
file. A cache that cannot be used is no error: the parser is built instead.
"""

from __future__ import annotations

import hashlib
import os
import stat
import tempfile
from functools import cache
from importlib import resources
from pathlib import Path

import lark
from lark import Lark

#: How every grammar is read: LALR, positions on (for spans), ``None`` for an optional part left out.
OPTIONS = {"start": "statement", "parser": "lalr", "propagate_positions": True, "maybe_placeholders": True}


@cache
def parser_for(grammar_file: str) -> Lark:
    """The parser of ``grammar_file`` (a path in ``grammarc.frontend``, e.g. ``grammars/cityengine.lark``):
    loaded from the cache folder when a file there was built from the same grammars by the same lark,
    else built (and stored there)."""
    folder = cache_folder()
    if folder is None:
        return _build(grammar_file)
    path = folder / f"{Path(grammar_file).stem}-{_key(grammar_file)}.lark"
    parser = _load(path)
    if parser is None:
        parser = _build(grammar_file)
        _store(parser, path)
    return parser


def cache_folder() -> Path | None:
    """``$XDG_CACHE_HOME/grammarc`` or ``~/.cache/grammarc``, created ``0700``; ``None`` if it cannot be
    made, is not a folder of the user's own (a link, another owner), or others may write into it."""
    base = os.environ.get("XDG_CACHE_HOME", "")
    if not os.path.isabs(base):  # the XDG rule: a relative path is ignored
        base = os.path.join(os.path.expanduser("~"), ".cache")
    folder = Path(base) / "grammarc"
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        info = os.lstat(folder)
    except OSError:
        return None
    return folder if stat.S_ISDIR(info.st_mode) and _private(info) else None


def _private(info: os.stat_result) -> bool:
    """Owned by the user, writable by nobody else."""
    return info.st_uid == os.getuid() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def _key(grammar_file: str) -> str:
    """What the tables depend on: lark's version, the options, and the text of every grammar of the
    package (a dialect's grammar imports ``expressions.lark``)."""
    digest = hashlib.sha256(f"{lark.__version__} {sorted(OPTIONS.items())} {grammar_file}".encode())
    for grammar in sorted(resources.files("grammarc.frontend").joinpath("grammars").iterdir(),
                          key=lambda p: p.name):
        if grammar.name.endswith(".lark"):
            digest.update(grammar.name.encode() + b"\0" + grammar.read_bytes())
    return digest.hexdigest()[:24]


def _build(grammar_file: str) -> Lark:
    # from the package, so that `%import .expressions` finds its file beside the dialect's
    return Lark.open_from_package("grammarc.frontend", grammar_file, **OPTIONS)


def _load(path: Path) -> Lark | None:
    """The parser stored at ``path``, if the file is the user's own, writable by nobody else."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return None
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(f.fileno())
        if not stat.S_ISREG(info.st_mode) or not _private(info):
            return None
        try:
            return Lark.load(f)
        except Exception:  # noqa: BLE001 - a stale or truncated file of the user's own raises anything
            return None


def _store(parser: Lark, path: Path) -> None:
    """Write ``parser`` to ``path`` through a temporary file of the same folder (mode 0600) renamed over
    it; a folder that cannot be written leaves the cache empty."""
    try:
        fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(fd, "wb") as f:
            parser.save(f)
        os.replace(temporary, path)
    except OSError:
        os.unlink(temporary)
