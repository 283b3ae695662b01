"""CityEngine's file search queries (``fileSearch``, ``fileRandom``, the asset and image choosers), answered
inside the asset roots.

A query (CGA reference, "fileSearch / filesSearch") is one or more terms separated by whitespace, all of
which a file must match:

* a path with wildcards: ``*`` stands for any characters, ``/`` included (``"*.png"`` finds the PNG files
  of every folder), ``?`` for one character; ``**/`` for any folders or none (``"assets/**/*.obj"``, a
  glob habit CityEngine does not document); every other character stands for itself;
* a regular expression after ``$`` (``"$textures/[12].png"``, Python's ``re``, matched whole);
* a file property: ``Name=`` (the file name), ``Ext=`` (its extension without the dot), ``Path=`` (a
  path as above) or ``Project=`` (a folder the file's root is, or lies in, or the path's first folder:
  the project of a project's root, of its ``assets`` or of a workspace's file), each with wildcards.

A path is matched against the file's path relative to each root, in the roots' order (the grammar's
folder, its project's ``assets`` and root, ``--assets`` folders, the workspace: ``Module.roots``), as
CityEngine matches a query relative to the project's ``assets``, the project and the workspace. A
workspace path ``/Project/x/*.obj`` is matched as ``Project/x/*.obj``, and as ``x/*.obj`` when no root
holds a folder ``Project`` (a rule package, a lone project: ``asset_names.locate`` resolves it alike).

What a search returns is a name per file: its path relative to the first root where it matches, the
name ``asset_names.resolve_asset`` resolves back to that very file (a name found in an earlier root wins,
and a file found under two roots keeps its first name). CityEngine returns workspace paths
(``/Project/assets/x.obj``); grammarc returns the root-relative ones because a grammar need not lie in a
project or workspace, and both name the same file for ``i()``, ``assetInfo`` and ``fileName``. The names
are sorted, never in the file system's order. Matching is case-sensitive.

Nothing outside the roots is listed: a folder is walked only inside its root, links to folders are not
followed and links to files outside their root are skipped, and names beginning with ``.`` are hidden (a
rule package's ``.ws`` is a root of its own). A query climbing out of the roots (``"../*"``) or naming
a host path (``"/etc/*"``) finds nothing there. A search lists at most ``MAX_LISTED`` files of a root.

A process answers a query once (the compiler, then the derivation of every chunk ask the same): files
added to the roots during a build are not seen by it.
"""

from __future__ import annotations

import os
import re
from functools import lru_cache
from pathlib import Path, PurePosixPath

from grammarc.errors import AssetError
from grammarc.ir.asset_names import locate

__all__ = ["ASSET_SUFFIXES", "MAX_LISTED", "constant_folder", "search"]

#: File endings of the geometry assets ``i()`` inserts.
ASSET_SUFFIXES = (".obj", ".glb", ".gltf", ".dae", ".fbx", ".3ds")
#: The most files listed under one root for one search.
MAX_LISTED = 200_000
_PROPERTIES = ("name", "ext", "path", "project")


def search(query: str, roots: tuple[Path, ...]) -> tuple[str, ...]:
    """The sorted names of the files matching ``query`` in ``roots`` (see the module docstring).

    Raises
    ------
    AssetError
        If a root holds more than ``MAX_LISTED`` files where the query looks, or a ``$`` regular
        expression does not compile.
    """
    return _search(query, tuple(Path(r) for r in roots))


@lru_cache(maxsize=512)
def _search(query: str, roots: tuple[Path, ...]) -> tuple[str, ...]:
    if "\0" in query:
        return ()
    terms = [_term(t, query) for t in query.split()]
    if not terms:
        return ()
    globs = [text for kind, text in terms if kind == "glob"]
    compiled = [(kind, _glob(value.lstrip("/")) if kind == "glob" else value) for kind, value in terms]
    found: dict[Path, str] = {}
    for root in roots:
        for prefix, folder in _walks(globs[0] if globs else "", roots):
            for name, file in _listing(root.resolve(), folder):
                if file not in found and all(_matches(kind, pattern, prefix + name, name, root)
                                             for kind, pattern in compiled):
                    found[file] = name
    return tuple(sorted({_canonical(file, name, roots) for file, name in found.items()}))


def _canonical(file: Path, name: str, roots: tuple[Path, ...]) -> str:
    """The name of ``file`` whatever query found it: its path relative to the first root that holds it
    under a name ``locate`` resolves back to it (``name``, as found, otherwise)."""
    for root in roots:
        root = root.resolve()
        if root in file.parents:
            relative = file.relative_to(root).as_posix()
            if (locate(relative, roots) or (None, None))[1] == file:
                return relative
    return name


def constant_folder(prefix: str) -> str:
    """The folder a query beginning with the constant text ``prefix`` looks in: the prefix up to its last
    ``/`` before any wildcard, "" for none (a computed query such as ``"assets/" + kind + "/*.obj"``
    looks in ``assets/``)."""
    if prefix.startswith("$") or not prefix.split() or "=" in prefix.split()[0]:
        return ""
    head = prefix.split()[0]
    head = head[:min((head.index(c) for c in "*?" if c in head), default=len(head))]
    return head[:head.rfind("/") + 1]


def _term(text: str, query: str) -> tuple[str, object]:
    """One whitespace-separated term: ("glob", text), ("regex", compiled) or (property, compiled)."""
    if text.startswith("$"):
        try:
            return "regex", re.compile(text[1:])
        except re.error as error:
            raise AssetError(f"the file search `{query}` holds a bad regular expression: {error}") from None
    key, sep, value = text.partition("=")
    if sep and key.lower() in _PROPERTIES:
        return key.lower(), _glob(value.lstrip("/"))
    return "glob", text


def _glob(pattern: str) -> re.Pattern:
    """A wildcard pattern as a regular expression matched whole: ``*`` any characters, ``?`` one,
    ``**/`` any folders or none."""
    out = []
    i = 0
    while i < len(pattern):
        if pattern.startswith("**/", i):
            out.append("(?:.*/)?")
            i += 3
            continue
        out.append({"*": ".*", "?": "."}.get(pattern[i]) or re.escape(pattern[i]))
        i += 1
    return re.compile("".join(out), re.DOTALL)


def _folder(pattern: str) -> PurePosixPath:
    """The constant folder of a relative wildcard path: its folders before the first wildcard."""
    constant = []
    for part in PurePosixPath(pattern).parts[:-1]:
        if "*" in part or "?" in part:
            break
        constant.append(part)
    return PurePosixPath(*constant)


def _walks(glob: str, roots) -> list[tuple[str, PurePosixPath]]:
    """Where a search walks in each root: (prefix put before a listed name to match it, folder).

    A relative path is matched as written under its constant folder; a workspace path ``/Project/rest``
    as ``Project/rest``, and, when no root holds a folder ``Project`` and ``rest`` begins with a folder, as
    ``rest`` with ``Project/`` put back before the names found (``/etc/*`` is not ``*``)."""
    if not glob.startswith("/"):
        return [("", _folder(glob))]
    inner = PurePosixPath(glob.lstrip("/"))
    walks = [("", _folder(inner.as_posix()))]
    head = inner.parts[0] if inner.parts else ""
    rest = PurePosixPath(*inner.parts[1:])
    if _folder(rest.as_posix()).parts and not any(c in head for c in "*?") and not any(
            (Path(r) / head).is_dir() for r in roots):
        walks.append((head + "/", _folder(rest.as_posix())))
    return walks


def _matches(kind: str, pattern: re.Pattern, shown: str, name: str, root: Path) -> bool:
    """Whether the file ``name`` (relative to ``root``; ``shown`` as a workspace path is matched) matches
    one term."""
    if kind in ("glob", "regex"):
        return pattern.fullmatch(shown) is not None
    if kind == "path":
        return pattern.fullmatch(name) is not None
    base = name.rsplit("/", 1)[-1]
    if kind == "name":
        return pattern.fullmatch(base) is not None
    if kind == "ext":
        return "." in base and pattern.fullmatch(base.rsplit(".", 1)[1]) is not None
    folders = (root.name, root.parent.name, name.split("/", 1)[0] if "/" in name else "")
    return any(pattern.fullmatch(f) for f in folders if f)  # project


@lru_cache(maxsize=256)
def _listing(root: Path, folder: PurePosixPath) -> tuple[tuple[str, Path], ...]:
    """(name relative to ``root``, resolved file) of the files under ``root / folder``, sorted; nothing
    outside ``root`` (see the module docstring)."""
    top = (root / folder).resolve()
    if not (top == root or root in top.parents) or not top.is_dir():
        return ()
    out = []
    for here, dirs, names in os.walk(top, followlinks=False):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        for name in sorted(names):
            path = Path(here) / name
            file = path.resolve()
            if name.startswith(".") or root not in file.parents or not file.is_file():
                continue
            out.append((path.relative_to(root).as_posix(), file))
            if len(out) > MAX_LISTED:
                raise AssetError(f"a file search lists more than {MAX_LISTED} files under {top}; give it a "
                                 "folder (\"assets/trees/*.obj\") rather than a bare wildcard")
    return tuple(sorted(out))
