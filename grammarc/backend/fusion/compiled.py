"""A region's generated module, written to the user's cache folder and imported from there, so that numba's
``cache=True`` keeps its machine code between runs.

The file is named by a digest of its text (the text is a function of the region's IR, so the digest is
the region's key): an unchanged grammar finds its kernels compiled; a changed one writes a new file. A file
is imported only if it is the user's own, writable by nobody else, and holds exactly the text expected
(``frontend.user_cache``); where the cache folder cannot be used, the module goes to a private temporary
folder of this process, and is compiled again in the next.
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
import tempfile
from functools import cache
from pathlib import Path

from grammarc.frontend import user_cache


def digest(text: str) -> str:
    """The key of a region's source ``text``."""
    return hashlib.sha256(text.encode()).hexdigest()[:24]


@cache
def load(text: str):
    """The module of ``text`` (its kernel, ``derive``), once per process."""
    key = digest(text)
    folder = user_cache.cache_folder("fusion") or _private_folder()
    path = folder / f"region_{key}.py"
    if user_cache.load(path, lambda f: f.read().decode()) != text:
        user_cache.store(path, lambda f: f.write(text.encode()))
        if user_cache.load(path, lambda f: f.read().decode()) != text:  # a folder that cannot be written
            path = _private_folder() / path.name
            path.write_text(text)
    name = f"grammarc_fused_{key}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache finds the functions' globals by the module's name
    spec.loader.exec_module(module)
    return module


@cache
def _private_folder() -> Path:
    return Path(tempfile.mkdtemp(prefix="grammarc-fusion-"))
