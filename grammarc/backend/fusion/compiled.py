"""A region's generated module, written to the user's cache folder and imported from there, so that numba's
``cache=True`` keeps its machine code between runs.

The file is named by a digest of its text (the text is a function of the region's IR, so the digest is
the region's key): an unchanged grammar finds its kernels compiled; a changed one writes a new file. A file
is imported only if it is the user's own, writable by nobody else, and holds exactly the text expected
(``frontend.user_cache``); its code object is kept beside it (``code``), so that a run does not compile
it from its text again where Python writes no bytecode. Where the cache folder cannot be used, the module
goes to a private temporary folder of this process, removed when it exits, and is compiled again in the
next.
"""

from __future__ import annotations

import hashlib
import importlib.util
import marshal
import os
import shutil
import sys
import tempfile
import types
from contextlib import contextmanager
from functools import cache
from multiprocessing.util import Finalize
from pathlib import Path

import numpy as np

try:
    import fcntl
except ImportError:  # Windows: no forked workers to wait for
    fcntl = None

from grammarc.atomic import remove_stale
from grammarc.frontend import user_cache


def digest(text: str) -> str:
    """The key of a region's source ``text``."""
    return hashlib.sha256(text.encode()).hexdigest()[:24]


#: The prefix of the generated modules' names (``server.load_cached_kernels`` looks for it).
MODULE_PREFIX = "grammarc_fused_"
#: The kernels compiled or loaded in this process, by source text.
_KERNELS: dict[str, object] = {}


def kernel(text: str, columns: int):
    """The compiled kernel (``derive``) of a region's source ``text`` whose parameters and attributes are
    ``columns`` arrays, once per process.

    It is compiled (or its machine code loaded from numba's cache) here, on empty arrays of the types the
    runner passes, holding a lock beside the file: forked workers that start on the same grammar wait for
    the first one's compilation and load its machine code, instead of each compiling the same kernel. A
    mark beside the file then says it is compiled (``ready``).
    """
    if text in _KERNELS:
        return _KERNELS[text]
    module, path = load(text)
    rows = [np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0, np.uint64),
            np.zeros(0, np.int32), np.zeros((1, 3, 3)), *(np.zeros(0) for _ in range(columns)), np.zeros((0, 3)),
            np.zeros(0), 0.0, False, np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.bool_),
            np.zeros((0, 3, 4), np.float32), np.zeros(0, np.int32), np.zeros(0, np.int64), np.zeros((0, 0)),
            np.zeros(0, np.int64), handed_columns(0, 0)]
    with _locked(path.with_suffix(".lock")):
        module.derive(*rows)
    user_cache.store(path.with_suffix(".compiled"), lambda f: None)
    _KERNELS[text] = module.derive
    return module.derive


def import_compiled() -> int:
    """Import the module of every kernel that a build compiled into the cache folder (its mark beside it),
    as a warm server does before it serves (``server.load_cached_kernels`` then loads their machine
    code): a command forked from it finds them ready, without reading, importing or loading them
    itself. Returns how many."""
    folder = user_cache.cache_folder("fusion")
    if folder is None:
        return 0
    imported = 0
    for mark in sorted(folder.glob("region_*.compiled")):
        text = user_cache.load(mark.with_suffix(".py"), lambda f: f.read().decode())
        if text is None or text in _KERNELS or not user_cache.load(mark, lambda f: True) \
                or mark.stem != f"region_{digest(text)}":
            continue
        module, _ = load(text)
        _KERNELS[text] = module.derive
        imported += 1
    return imported


#: Shapes this process derived without the kernel of a source text, because it was not compiled yet.
_WAITED: dict[str, int] = {}


def ready(text: str, shapes: int, compile_at: int) -> bool:
    """Whether to derive ``shapes`` more shapes with the kernel of ``text``: it is compiled (in this process,
    or by an earlier one into the cache folder: its mark is there, whence numba loads its machine code), or
    this process has now met ``compile_at`` shapes for it, enough to pay for compiling it."""
    if text in _KERNELS or compiled_before(text):
        return True
    _WAITED[text] = _WAITED.get(text, 0) + shapes
    return _WAITED[text] >= compile_at


def compiled_before(text: str) -> bool:
    """Whether a process compiled the kernel of ``text`` into the cache folder (its mark is there, whence
    numba loads its machine code instead of compiling it)."""
    folder = user_cache.cache_folder("fusion")
    return folder is not None and bool(user_cache.load(folder / f"region_{digest(text)}.compiled", lambda f: True))


def handed_columns(rows: int, params: int, carries: bool = False, written: int = 0) -> tuple:
    """The columns of ``rows`` shapes a kernel hands off (``codegen._Writer.handoff``): origin, size, frame,
    lot, key, depth, ``params`` parameters (params, rows), the rows of the roots they come from where
    the kernel ``carries`` per-shape columns (else none), and the values of the ``written`` columns the
    region writes (written, rows)."""
    return (np.empty((rows, 3)), np.empty((rows, 3)), np.empty(rows, np.int32), np.empty(rows, np.int32),
            np.empty(rows, np.uint64), np.empty(rows, np.int32), np.empty((params, rows)),
            np.empty(rows if carries else 0, np.int64), np.empty((written, rows)))


@contextmanager
def _locked(path: Path):
    """An exclusive lock on the file at ``path`` (none where files cannot be locked or made)."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o600)
    except OSError:
        yield
        return
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def load(text: str):
    """The module of ``text`` and the file it was imported from."""
    key = digest(text)
    folder = user_cache.cache_folder("fusion") or _private_folder()
    path = folder / f"region_{key}.py"
    if user_cache.load(path, lambda f: f.read().decode()) != text:
        user_cache.store(path, lambda f: f.write(text.encode()))
        if user_cache.load(path, lambda f: f.read().decode()) != text:  # a folder that cannot be written
            path = _private_folder() / path.name
            path.write_text(text)
    name = f"{MODULE_PREFIX}{key}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache finds the functions' globals by the module's name
    exec(code(text, path), module.__dict__)  # noqa: S102 - the module's own code, run as its loader would
    return module, path


def code(text: str, path: Path) -> types.CodeType:
    """The code object of ``text``, the source of the module at ``path``, from the file beside it that
    keeps it (``region_<key>.<Python's cache tag>.code``) or compiled and kept there.

    Python keeps its own compiled modules in ``__pycache__`` only where it may write bytecode, which
    containers and CI runs often forbid (``PYTHONDONTWRITEBYTECODE``): then each run would compile every
    region's module again (``examples/pompeii`` has 84). The kept file starts
    with Python's magic number and the text's full digest, and its code must name ``path`` as its file
    (numba's cache finds a kernel's machine code by its function's file and line): a file of another
    Python, of another text, from a moved cache folder, or a damaged one, is compiled again and replaced.
    """
    tag = sys.implementation.cache_tag
    if tag is None:  # this Python keeps no compiled modules
        return compile(text, str(path), "exec", dont_inherit=True)
    kept = path.with_name(f"{path.stem}.{tag}.code")
    header = importlib.util.MAGIC_NUMBER + hashlib.sha256(text.encode()).digest()

    def read(file):
        if file.read(len(header)) != header:
            raise ValueError("another Python's or another text's code")
        found = marshal.load(file)
        if not isinstance(found, types.CodeType) or found.co_filename != str(path):
            raise ValueError("not the code of this file")
        return found

    found = user_cache.load(kept, read)
    if found is not None:
        return found
    made = compile(text, str(path), "exec", dont_inherit=True)  # as Python's import compiles a module
    user_cache.store(kept, lambda file: file.write(header + marshal.dumps(made)))
    return made


#: The prefix of the private folders of modules that the cache folder could not take.
_PRIVATE_PREFIX = "grammarc-fusion-"


@cache
def _private_folder() -> Path:
    """This process's folder of modules that the cache folder could not take, removed when the process
    exits: at the interpreter's exit, or a forked worker's (``multiprocessing``'s finalizers run in both;
    a fork that inherits the folder leaves it to its maker). Those of processes that were killed are
    removed by the next process that makes one (``atomic.remove_stale``)."""
    temp = Path(tempfile.gettempdir())
    remove_stale(temp, _PRIVATE_PREFIX)
    folder = Path(tempfile.mkdtemp(prefix=f"{_PRIVATE_PREFIX}{os.getpid()}-", dir=temp))
    Finalize(None, _remove, args=(folder, os.getpid()), exitpriority=0)
    return folder


def _remove(folder: Path, maker: int) -> None:
    if os.getpid() == maker:
        shutil.rmtree(folder, ignore_errors=True)
