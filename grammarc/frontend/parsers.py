"""The lark parsers of the dialects' grammars, built once per process and kept between processes in the
user's own cache folder (``user_cache``).

Building an LALR parser from ``grammars/*.lark`` takes several times longer than loading its tables, and
every ``grammarc`` command starts by it. lark's own cache (``cache=True``) is a pickle in the shared temp
folder, loaded whoever wrote it: anyone who can write ``/tmp`` could make grammarc run code.
"""

from __future__ import annotations

import hashlib
from functools import cache
from importlib import resources
from pathlib import Path

import lark
from lark import Lark

from grammarc.frontend.user_cache import cache_folder, load, store

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
    parser = load(path, Lark.load)
    if parser is None:
        parser = _build(grammar_file)
        store(path, parser.save)
    return parser


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
