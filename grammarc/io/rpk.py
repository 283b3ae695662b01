"""CityEngine rule packages (``.rpk``): the CGA sources, the start rule and the assets of a package.

A rule package is a 7-zip archive as CityEngine exports it::

    rules/Candler Building.cga      CGA sources (may be absent: a package needs only its compiled rules)
    bin/Candler Building.cgb        compiled rules; the main one carries the start rule
    assets/facade/windows/x.obj     assets and textures (absent in packages without any)
    .resolvemap.xml                 workspace path -> path in the package
    .ws/ESRI.lib/rules/x.cga        files of other projects of the workspace (in some packages)

``open_rpk`` extracts the archive once into the user's cache folder, where it is kept for the next builds
of the same package (``io.kept_packages``), so rule files and assets are plain paths the compiler and the
baker read as they read any other. Asked to (``tmpdir``), or without a usable cache folder, it extracts to a
temporary directory instead, which lives as long as the returned ``RulePackage`` (use it as a context
manager, or call ``close()``). That directory's name holds the process id
(``grammarc-rpk-<pid>-<package>-<random>``): one a process left behind as it died (a SIGKILL, a power cut)
goes when a package is next opened in the same temporary folder.

An archive is untrusted input: a few kilobytes may decompress to gigabytes (a "zip bomb"). Extraction
counts the bytes as they are decompressed, not as the archive's headers claim, and stops at the first of
two limits: ``max_size`` bytes in all (``--max-package-size``, default ``MAX_PACKAGE_SIZE``, 2 GiB), and
``MAX_RATIO`` times the archive's own size (packages of textures and rules compress a few times; a
thousandfold is a bomb). Each member goes straight to its file, so memory stays small whatever the sizes.

Assets are resolved as CityEngine resolves a relative ``i("facade/windows/x.obj")`` of a rule file: first
in the ``assets`` folder of the project the rule file is in, then in that project's root
(CityEngine manual, "Asset and texture search"). ``RulePackage.asset_roots`` lists those folders in that
order; a package is one project. Workspace paths (``/Project/assets/x.obj``, ``import x :
"/ESRI.lib/rules/y.cga"``) are looked up in its ``.ws`` folder, else in the package itself (an export
keeps a project's files at the package's root): ``RulePackage.workspace``, and ``frontend.imports``.

py7zr is an optional dependency (the ``rpk`` extra), imported when a package is extracted.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
import weakref
from collections.abc import Iterator, Mapping
from pathlib import Path, PurePosixPath
from typing import TYPE_CHECKING

from grammarc.atomic import remove_stale
from grammarc.errors import UsageError
from grammarc.frontend.source import read_grammar_text
from grammarc.io import kept_packages
from grammarc.model.assets import record_roots

if TYPE_CHECKING:
    from typing_extensions import Self

__all__ = ["MAX_PACKAGE_SIZE", "MAX_RATIO", "RulePackage", "open_rpk", "record_asset_roots", "start_rule_of"]

#: The most bytes a package may extract to (``--max-package-size``).
MAX_PACKAGE_SIZE = 2 << 30
#: The most bytes a package may extract to per byte of the archive.
MAX_RATIO = 1000
#: The bytes py7zr decompresses at a time (``_small_blocks``).
_BLOCK = 4 << 20

#: The names of extraction folders begin so, then the process id (module docstring).
_EXTRACTED = "grammarc-rpk-"

_INSTALL_HINT = "pip install 'grammarc[rpk]' (or pip install py7zr)"

# A string literal (group 1) or a comment; _strip_comments blanks the one and drops the other, so a "//"
# inside a string is not taken for a comment.
_STRING_OR_COMMENT = re.compile(r'("(?:[^"\\\n]|\\.)*"|\'(?:[^\'\\\n]|\\.)*\')|//[^\n]*|/\*.*?\*/', re.DOTALL)
# @StartRule, then any further annotations (@Hidden, @Description("...")), then the rule's name. Strings
# inside annotation arguments are blanked by _strip_comments, so `[^)]*` cannot stop inside one.
_START_RULE = re.compile(r"@StartRule\b\s*(?:@\w+\s*(?:\([^)]*\))?\s*)*([A-Za-z_][\w.]*)")


class RulePackage:
    """An extracted rule package; its files exist until ``close()`` (or the end of a ``with`` block) at least:
    a temporary extraction's are removed then, a kept one's stay in the cache.

    Attributes
    ----------
    path : Path
        The ``.rpk`` file.
    root : Path
        The directory holding the extracted package: a kept one in the user's cache, or a temporary one.
    rules : dict of str to Path
        Every CGA source, by its POSIX path in the package (``"rules/Candler Building.cga"``), sorted.
    compiled : list of str
        The compiled rule files (``"bin/Candler Building.cgb"``), sorted.
    assets_root : Path
        The package's ``assets`` folder, or ``root`` when it has none: where ``i("facade/x.obj")``
        is looked up first.
    main_rule_file : Path or None
        The CGA source of the compiled main rule file: the ``.cga`` named as a ``bin/*.cgb``, else the
        only ``.cga``, else the one with a ``@StartRule``; None for a package without sources.
    start_rule : str or None
        The rule after ``@StartRule`` in ``main_rule_file`` (``"Footprint"``); None if it has none.
        PRT names it with its style, ``"Default$Footprint"``.

    Examples
    --------
    >>> with open_rpk("candler.rpk") as rpk:                                      # doctest: +SKIP
    ...     rpk.start_rule, rpk.main_rule_file.name
    ('Footprint', 'Candler Building.cga')
    """

    def __init__(self, path: Path, root: Path, temporary: bool = True):
        self.path = path
        self.root = root
        self._closed = False
        # A temporary extraction's files go on close(), or when the package is dropped unclosed.
        self._cleanup = weakref.finalize(self, shutil.rmtree, str(root), ignore_errors=True) if temporary \
            else None
        files = sorted(p for p in root.rglob("*") if p.is_file())
        relative = {p.relative_to(root).as_posix(): p for p in files}
        self.rules = {name: p for name, p in relative.items() if name.lower().endswith(".cga")}
        self.compiled = [name for name in relative if name.lower().endswith(".cgb")]
        self.assets_root = root / "assets" if (root / "assets").is_dir() else root
        self.main_rule_file = _main_rule_file(self.rules, self.compiled)
        self.start_rule = start_rule_of(self.main_rule_file) if self.main_rule_file is not None else None

    @property
    def asset_roots(self) -> tuple[Path, ...]:
        """Folders to resolve asset names in, in CityEngine's order: ``assets``, then the package root."""
        return (self.assets_root,) if self.assets_root == self.root else (self.assets_root, self.root)

    @property
    def workspace(self) -> Path:
        """The package's workspace, its ``.ws`` folder (which may not exist): workspace paths are looked up
        there and in the package, never in the folders around the extracted package."""
        return self.root / ".ws"

    @property
    def closed(self) -> bool:
        """True once closed."""
        return self._closed

    def close(self) -> None:
        """Remove the extracted files of a temporary extraction; the paths of this package are not to be used
        afterwards. Idempotent."""
        self._closed = True
        if self._cleanup is not None:
            self._cleanup()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self.closed else str(self.root)
        main = self.main_rule_file.relative_to(self.root).as_posix() if self.main_rule_file else None
        return f"RulePackage({self.path.name!r}, main={main!r}, start={self.start_rule!r}, {state})"


def open_rpk(path: str | os.PathLike, *, tmpdir: str | os.PathLike | None = None,
             max_size: int = MAX_PACKAGE_SIZE) -> RulePackage:
    """Extract a CityEngine rule package and describe it.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.rpk`` file (a 7-zip archive).
    tmpdir : str or os.PathLike, optional
        Where to create a temporary extraction directory, removed on ``close()``. By default the package
        is extracted once into the user's cache folder and kept there (``io.kept_packages``), or, where
        there is no usable cache folder, into the system's temporary folder.
    max_size : int
        The most bytes the package may extract to (module docstring: this and ``MAX_RATIO``).

    Returns
    -------
    RulePackage
        Its files live until ``close()`` at least; use it as a context manager.

    Raises
    ------
    UsageError
        If py7zr is missing (naming the ``rpk`` extra), the file is missing or not a 7-zip archive, a
        member's path is absolute, leaves the package or is a link, or the package extracts to more than
        its limits.
    """
    path = Path(path)
    if not path.is_file():
        raise UsageError(f"rule package `{path}` does not exist")
    limit = min(max_size, MAX_RATIO * path.stat().st_size)
    if tmpdir is None and (entry := kept_packages.entry_of(path)) is not None:
        root = kept_packages.kept(entry, limit) or kept_packages.keep(
            entry, lambda folder: _extract(path, folder, limit), limit)
        if root is not None:
            return RulePackage(path, root, temporary=False)
    folder = Path(tmpdir) if tmpdir is not None else Path(tempfile.gettempdir())
    remove_stale(folder, _EXTRACTED)
    root = Path(tempfile.mkdtemp(prefix=f"{_EXTRACTED}{os.getpid()}-{path.stem}-", dir=folder))
    try:
        _extract(path, root, limit)
    except BaseException:
        shutil.rmtree(root, ignore_errors=True)
        raise
    return RulePackage(path, root)


def _extract(path: Path, root: Path, limit: int) -> None:
    """Extract the archive ``path`` into the folder ``root`` (made if missing), at most ``limit`` bytes."""
    try:
        import py7zr
    except ImportError as error:
        raise UsageError(f"reading rule packages (.rpk) needs py7zr: {_INSTALL_HINT}") from error
    root.mkdir(exist_ok=True)
    try:
        # an open file, not its path: py7zr then extracts in this thread (with a path, it extracts an
        # archive's blocks in threads that each open the file and leave it open)
        with open(path, "rb") as file, py7zr.SevenZipFile(file, mode="r") as archive:
            for info in archive.list():
                _check_member(path, info)
                folder = root / info.filename if info.is_directory else (root / info.filename).parent
                folder.mkdir(parents=True, exist_ok=True)
            extracted = _Extracted(root, _Budget(path, limit))
            try:
                with _small_blocks(py7zr):
                    archive.extractall(factory=extracted)
            finally:
                extracted.close()
    except (py7zr.exceptions.ArchiveError, EOFError) as error:
        raise UsageError(f"cannot read rule package `{path}`: {error}") from error


def start_rule_of(cga: str | os.PathLike) -> str | None:
    """The name of the rule after the first ``@StartRule`` annotation of a CGA file, or None.

    Comments are ignored (a commented-out ``// @StartRule`` does not count); further annotations between
    ``@StartRule`` and the rule are skipped. The file is read as the compiler reads it (UTF-8 with or
    without a BOM, else Windows-1252).
    """
    text, _ = read_grammar_text(cga)
    match = _START_RULE.search(_strip_comments(text))
    return match.group(1) if match else None


def _strip_comments(text: str) -> str:
    """CGA text without comments, and string literals blanked to ``""`` (their quotes kept)."""

    def keep(match: re.Match) -> str:
        string = match.group(1)
        if string is None:
            return " "
        return string[0] * 2  # "" or '': an annotation's argument, not text to search

    return _STRING_OR_COMMENT.sub(keep, text)


def _check_member(archive: Path, info) -> None:
    """Refuse members that would land outside the extraction directory (absolute, ``..``, links)."""
    name = info.filename.replace("\\", "/")
    pure = PurePosixPath(name)
    if pure.is_absolute() or ".." in pure.parts or (len(name) > 1 and name[1] == ":"):
        raise UsageError(f"rule package `{archive}`: member `{info.filename}` leaves the package")
    if getattr(info, "is_symlink", False):
        raise UsageError(f"rule package `{archive}`: member `{info.filename}` is a link")


@contextlib.contextmanager
def _small_blocks(py7zr):
    """py7zr decompressed in blocks of ``_BLOCK`` bytes: its own are up to 128 MB (a quarter of the free
    memory), each held twice before a byte of it is written, so a bomb would take that much memory before
    the budget sees it. Its block size is a function of its module, set back when the block ends."""
    module = py7zr.py7zr
    own = module.get_memory_limit
    module.get_memory_limit = lambda: _BLOCK
    try:
        yield
    finally:
        module.get_memory_limit = own


class _Budget:
    """The bytes a package may still extract to; ``take`` refuses the bytes past it."""

    def __init__(self, archive: Path, limit: int):
        self.archive = archive
        self.limit = self.left = limit

    def take(self, member: str, size: int) -> None:
        self.left -= size
        if self.left < 0:
            raise UsageError(f"rule package `{self.archive}` extracts to more than {self.limit:,} bytes (at "
                             f"`{member}`): at most {MAX_RATIO} times its size and --max-package-size")


class _Extracted:
    """py7zr's ``WriterFactory``: each member written to its file under ``root`` as it is decompressed,
    its bytes taken from the package's budget."""

    def __init__(self, root: Path, budget: _Budget):
        self.root = root
        self.budget = budget
        self.files: list[_MemberFile] = []

    def create(self, filename: str):
        self.files.append(_MemberFile(self.root / filename, filename, self.budget))
        return self.files[-1]

    def close(self) -> None:
        """Close every member's file (py7zr closes those it finished, not one a refusal stopped)."""
        for member in self.files:
            member.close()


class _MemberFile:
    """One member's file, as py7zr's ``Py7zIO`` (which it duck-types: py7zr is imported when a package is
    opened, not with this module)."""

    def __init__(self, path: Path, name: str, budget: _Budget):
        self.name = name
        self.budget = budget
        self.file = open(path, "wb")  # noqa: SIM115 - closed by py7zr through close()
        self.written = 0

    def write(self, data) -> int:
        self.budget.take(self.name, len(data))
        self.written += len(data)
        return self.file.write(data)

    def read(self, size: int | None = None) -> bytes:
        return b""

    def seek(self, offset: int, whence: int = 0) -> int:
        return self.file.seek(offset, whence)

    def flush(self) -> None:
        self.file.flush()

    def size(self) -> int:
        return self.written

    def close(self) -> None:
        self.file.close()


def _main_rule_file(rules: dict[str, Path], compiled: list[str]) -> Path | None:
    """The CGA source of the main compiled rule file (see ``RulePackage.main_rule_file``)."""
    if not rules:
        return None
    compiled_stems = {PurePosixPath(name).stem for name in compiled}
    matching = [p for p in rules.values() if p.stem in compiled_stems]
    if len(matching) == 1:
        return matching[0]
    candidates = matching or list(rules.values())
    if len(candidates) == 1:
        return candidates[0]
    with_start = [p for p in candidates if start_rule_of(p) is not None]
    return with_start[0] if with_start else candidates[0]


@contextlib.contextmanager
def record_asset_roots(meta: Mapping | None, asset_roots=None) -> Iterator[list[Path] | None]:
    """The folders a record's assets load from, for ``render`` and ``info`` after the build: a record built
    from a rule package names the ``.rpk`` as its grammar (not the folder it was extracted to), so while
    the block runs the package is opened again (``open_rpk``) and its ``asset_roots`` come first, then
    ``asset_roots`` or the record's own (``model.assets.record_roots``). Any other record, or a package no
    longer where the record says: ``asset_roots`` as given (None: the record's own)."""
    grammar = meta.get("grammar") if isinstance(meta, Mapping) else None
    if not (grammar and str(grammar).lower().endswith(".rpk") and Path(grammar).is_file()):
        yield asset_roots
        return
    with open_rpk(grammar) as package:
        yield [*package.asset_roots, *record_roots({"meta": meta}, asset_roots)]
