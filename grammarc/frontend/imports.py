"""CityEngine ``import``: where an imported rule file is, whether it may be read, and its text.

A grammar is shared: a downloaded rule file or rule package must not read the host's files. So an import
is confined, as assets are, to the grammar's roots (``Roots``): the main grammar's folder, the CityEngine
project around it, the workspace (a folder of projects: ``--workspace``, or the folder holding the
project), and in a rule package the package itself. Only ``.cga`` files are read, at most
``MAX_GRAMMAR_BYTES`` of them (a larger file, or a device such as ``/dev/zero`` behind a link, is
refused after reading one byte more than that), and a file that is not text (it holds NUL bytes) is
refused without its contents ever reaching a message.

Paths are resolved as CityEngine resolves them (CGA reference, "import" and "Asset search"):

* ``"facade.cga"``, ``facade.cga`` (unquoted) or ``"sub/facade.cga"``: relative to the importing file's
  folder, else to the root of its project (``"rules/facade.cga"``);
* ``"/Project/rules/facade.cga"``: a workspace path, looked up in the workspace; in a rule package, whose
  export flattens the workspace, in the package (``.ws/Project/...`` or the package's own files, see
  ``grammarc.ir.asset_names.locate``).

A project is a folder with a ``.project`` file (CityEngine's own mark), the folder whose ``rules/`` holds
the grammar, or a rule package's root (it has a ``.resolvemap.xml``); the workspace is the folder that holds
the project.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.source import decode_grammar, encoding_warning
from grammarc.ir.asset_names import locate

__all__ = ["MAX_GRAMMAR_BYTES", "ImportRefused", "Roots", "find_roots", "load_import", "read_import",
           "resolve_import"]

#: The largest grammar file read (bytes).
MAX_GRAMMAR_BYTES = 16 * 2**20
#: How far above the grammar a project is looked for.
_PROJECT_DEPTH = 8


class ImportRefused(Exception):
    """An import that cannot or may not be read; the message names the path as written, never the text."""


@dataclass(frozen=True)
class Roots:
    """The folders a grammar's imports and assets come from.

    Attributes
    ----------
    home : Path
        The main grammar's folder.
    project : Path or None
        The CityEngine project (or rule package) around the grammar.
    workspaces : tuple of Path
        Folders of projects, where workspace paths ``/Project/...`` are looked up.
    imported_projects : dict of Path to None
        The projects of the imported files, in the order met (filled by ``load_import``).
    """

    home: Path
    project: Path | None = None
    workspaces: tuple[Path, ...] = ()
    imported_projects: dict[Path, None] = field(default_factory=dict)

    @property
    def folders(self) -> tuple[Path, ...]:
        """Every folder an import may come from."""
        return tuple(dict.fromkeys((self.home, *filter(None, (self.project,)), *self.workspaces)))

    def asset_roots(self, given: tuple[Path, ...] = ()) -> tuple[Path, ...]:
        """Where assets are resolved, in order: the grammar's folder (as grammarc always did), then as
        CityEngine does, the project's ``assets`` and its root, then the ``given`` folders (``--assets``,
        a package's), then the projects of imported files, then the workspaces.

        CityEngine looks an asset up from the project of the rule file that inserts it; grammarc resolves
        the names of a module at once, so an imported file's project comes after the grammar's own."""
        own = () if self.project is None else (self.project / "assets", self.project)
        imported = [folder for p in self.imported_projects for folder in (p / "assets", p)]
        found = [p for p in (*own, *given, *imported, *self.workspaces) if p.is_dir()]
        seen = {self.home.resolve()}
        return (self.home, *[p for p in found if not (p.resolve() in seen or seen.add(p.resolve()))])


def find_roots(grammar: Path, workspace: Path | None = None) -> Roots:
    """The roots of the grammar file ``grammar``; ``workspace`` (``--workspace``) adds a folder of projects.

    Without ``workspace``, the folder that holds the grammar's project is its workspace; a rule package's
    ``.ws`` folder is one too.
    """
    home = grammar.parent
    project = _project_of(home.resolve())
    workspaces = [] if workspace is None else [Path(workspace).resolve()]
    if project is not None:
        if (project / ".resolvemap.xml").is_file():
            if (project / ".ws").is_dir():
                workspaces.append(project / ".ws")
        elif workspace is None:
            workspaces.append(project.parent)
    return Roots(home, project, tuple(dict.fromkeys(workspaces)))


def _is_project(folder: Path) -> bool:
    return (folder / ".project").is_file() or (folder / "rules").is_dir() or (folder / "assets").is_dir()


def _project_of(folder: Path) -> Path | None:
    for depth, candidate in enumerate((folder, *folder.parents)):
        if depth > _PROJECT_DEPTH:
            break
        if (candidate / ".project").is_file() or (candidate / ".resolvemap.xml").is_file():
            return candidate
        if candidate.name == "rules" and candidate.parent != candidate:
            return candidate.parent
    return None


def resolve_import(name: str, importing: Path, roots: Roots) -> Path:
    """The file an ``import`` names, from the file ``importing``; raise ``ImportRefused`` if it is not a
    ``.cga`` file inside the roots."""
    if "\0" in name:
        shown = name.replace("\0", "\\0")
        raise ImportRefused(f"imported path `{shown}` holds a NUL byte")
    pure = PurePosixPath(name.replace("\\", "/"))
    if pure.suffix.lower() != ".cga":
        raise ImportRefused(f"`{name}` is not a CGA rule file (.cga): only rule files are imported")
    if len(name) > 1 and name[1] == ":":
        raise ImportRefused(f"`{name}` is a path of the host: give it relative to the rule file or as a "
                            "workspace path /Project/rules/...")
    if pure.is_absolute():
        searched = roots.folders
        named = [w / pure.parts[1] for w in roots.workspaces if len(pure.parts) > 2]
        if any(p.is_dir() and not _is_project(p) for p in named):
            raise ImportRefused(f"`{name}`: `/{pure.parts[1]}` is not a CityEngine project of the workspace")
    else:  # the importing file's folder, then its project's root
        project = _project_of(importing.parent.resolve()) or roots.project
        searched = (importing.parent, *filter(None, (project,)))
    # each candidate is resolved (links followed) and kept only inside its own folder, and that folder is
    # one of the roots
    allowed = tuple(r.resolve() for r in roots.folders)
    searched = [s for s in searched if any(_inside(s.resolve(), r) for r in allowed)]
    found = locate(name, searched)
    if found is not None:
        return found[1]
    if pure.is_absolute():
        if not roots.workspaces:
            raise ImportRefused(f"`{name}` is a workspace path and the grammar is in no CityEngine workspace "
                                "(give the folder of its projects with --workspace)")
        raise ImportRefused(f"`{name}` is not found in the workspace ({', '.join(map(str, roots.workspaces))})")
    where = ", ".join(str(r) for r in searched)
    if not any(_inside((s.resolve() / pure).resolve(), s.resolve()) for s in searched):
        raise ImportRefused(f"`{name}` leaves the grammar's folders ({where})")
    raise ImportRefused(f"`{name}` is not found in {where}")


def read_import(path: Path) -> tuple[str, str | None]:
    """The text of an imported rule file and the encoding it fell back to (see ``source``); raise
    ``ImportRefused`` for a file that is not a regular file, too large, or not text."""
    if not path.is_file():
        raise ImportRefused("it is not a regular file")
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_GRAMMAR_BYTES + 1)
    except OSError as error:
        raise ImportRefused(error.strerror or type(error).__name__) from None
    if len(data) > MAX_GRAMMAR_BYTES:
        raise ImportRefused(f"it is larger than {MAX_GRAMMAR_BYTES // 2**20} MiB")
    if b"\0" in data:
        raise ImportRefused("it is not a text file")
    return decode_grammar(data)


def _inside(path: Path, root: Path) -> bool:
    return path == root or root in path.parents


def load_import(statement, file: str, path: Path | None, roots: Roots, importing: tuple[Path, ...],
                diags: Diagnostics) -> tuple[str, str, Path] | None:
    """The name in diagnostics, the text and the file of what the ``Import`` ``statement`` of the file
    ``path`` (named ``file``) imports; None after reporting why it cannot be imported.

    ``importing`` are the files whose imports led here: a file that imports itself through them is an
    error, not an endless recursion.
    """
    if path is None:
        diags.error("import", "`import` needs the grammar's folder (the text was given without a file)",
                    statement.span)
        return None
    try:
        target = resolve_import(statement.path, path, roots)
    except ImportRefused as refused:
        diags.error("import", f"cannot import: {refused}", statement.span)
        return None
    if target in importing or target == path.resolve():
        diags.error("import", f"`{statement.path}` imports itself (through {len(importing)} files)",
                    statement.span)
        return None
    try:
        text, fallback = read_import(target)
    except ImportRefused as refused:
        diags.error("import", f"cannot import `{statement.path}`: {refused}", statement.span)
        return None
    project = _project_of(target.parent)
    if project is not None:
        roots.imported_projects[project] = None
    pure = PurePosixPath(statement.path.replace("\\", "/"))
    display = statement.path if pure.is_absolute() else (PurePosixPath(file).parent / pure).as_posix()
    if fallback is not None and not any(d.message == encoding_warning(display) for d in diags):
        diags.warning("encoding", encoding_warning(display), statement.span)
    return display, text, target
