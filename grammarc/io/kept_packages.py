"""Rule packages extracted once and kept in the user's cache folder, so that a package built again is not
extracted again (nor py7zr imported): that was much of a one-lot build of candler.rpk (README, "Figures").

An entry is ``<cache>/rpk/<digest>/`` (``frontend.user_cache.cache_folder``, private to the user), named by
the SHA-256 of the archive's bytes, so a package exported again under the same name is a new entry. It holds
``package/``, the extracted files, and ``files.json``, each file's size and modification time at extraction
and their total bytes. An entry is made whole in a temporary folder of the cache (``grammarc-rpk-<pid>-...``,
removed by the next extraction if its process died) and renamed into place: two builds that extract the same
package at once both finish, and one entry stays. An entry is used only if its files are still the ones
listed; one whose files changed is replaced. An entry unused for ``UNUSED_DAYS`` days goes when a package is
next extracted. The limits of an extraction (``io.rpk``'s budget) hold for a kept package too: one larger
than this build allows is extracted again, which refuses it.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from grammarc.atomic import remove_stale
from grammarc.frontend.user_cache import cache_folder

__all__ = ["UNUSED_DAYS", "entry_of", "keep", "kept"]

#: An entry not used for this many days is removed when a package is next extracted.
UNUSED_DAYS = 30
#: The prefix of the temporary folders an entry is made in (and of one set aside to be removed).
_MAKING = "grammarc-rpk-"
_PACKAGE = "package"
_MANIFEST = "files.json"
#: The bytes of an archive read at a time to take its digest.
_BLOCK = 1 << 20


def entry_of(archive: Path) -> Path | None:
    """Where the cache keeps the package ``archive`` (which may not be there yet); None without a usable
    cache folder."""
    folder = cache_folder("rpk")
    if folder is None:
        return None
    digest = hashlib.sha256()
    with open(archive, "rb") as file:  # in blocks: a package of textures may hold gigabytes
        for block in iter(lambda: file.read(_BLOCK), b""):
            digest.update(block)
    return folder / digest.hexdigest()[:32]


def kept(entry: Path, limit: int) -> Path | None:
    """The package's folder in ``entry``, if the entry is whole, its files unchanged and no larger than
    ``limit`` bytes; else None. Marks the entry used."""
    try:
        manifest = json.loads((entry / _MANIFEST).read_text(encoding="utf-8"))
        if manifest["bytes"] > limit or _files(entry / _PACKAGE) != manifest["files"]:
            return None
        os.utime(entry / _MANIFEST)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return entry / _PACKAGE


def keep(entry: Path, extract: Callable[[Path], None], limit: int) -> Path | None:
    """The package's folder in ``entry`` after ``extract(folder)`` made it there (or another process did
    at the same time); None if the cache cannot take it (the caller extracts it elsewhere). Errors of
    ``extract`` but OSError are raised, and nothing is left of the attempt."""
    cache = entry.parent
    remove_stale(cache, _MAKING)
    _remove_unused(cache)
    try:
        work = Path(tempfile.mkdtemp(prefix=f"{_MAKING}{os.getpid()}-", dir=cache))
    except OSError:
        return None
    try:
        extract(work / _PACKAGE)
        files = _files(work / _PACKAGE)
        (work / _MANIFEST).write_text(json.dumps({"files": files, "bytes": sum(s for s, _ in files.values())}),
                                      encoding="utf-8")
        try:
            os.rename(work, entry)
        except OSError:  # an entry is there: made by another process meanwhile, or changed since
            if kept(entry, limit) is not None:
                shutil.rmtree(work, ignore_errors=True)
                return entry / _PACKAGE
            aside = cache / f"{_MAKING}{os.getpid()}-replaced-{entry.name}"
            os.rename(entry, aside)
            shutil.rmtree(aside, ignore_errors=True)
            os.rename(work, entry)
        return entry / _PACKAGE
    except OSError:
        shutil.rmtree(work, ignore_errors=True)
        return None
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise


def _files(folder: Path) -> dict[str, list[int]]:
    """Each file under ``folder`` by its POSIX path there: its size and modification time (ns)."""
    files = {}
    for top, _, names in os.walk(folder):
        for name in names:
            path = os.path.join(top, name)
            info = os.stat(path)
            files[Path(os.path.relpath(path, folder)).as_posix()] = [info.st_size, info.st_mtime_ns]
    return files


def _remove_unused(cache: Path) -> None:
    """Remove the entries of ``cache`` not used for ``UNUSED_DAYS`` days (or without a manifest for as long)."""
    oldest = time.time() - UNUSED_DAYS * 86400
    for entry in cache.iterdir():
        if entry.name.startswith(_MAKING) or not entry.is_dir():
            continue
        marker = entry / _MANIFEST if (entry / _MANIFEST).exists() else entry
        try:
            if marker.stat().st_mtime < oldest:
                shutil.rmtree(entry, ignore_errors=True)
        except OSError:
            continue
