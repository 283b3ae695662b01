"""Asset names: built-in primitives and OBJ files, resolved inside the asset roots.

``I("cube")`` and ``I("builtin:cube")`` name the built-in unit cube (built-ins: ``cube``, ``quad``,
``cylinder`` and ``cylinderN`` with N sides, and the paper's mass-model blocks ``L``, ``H``, ``U``,
``T``); ``I("facade/window.obj")`` names a file relative to an asset root (the grammar's folder first,
then any ``--assets`` folders). The record keeps a canonical name: ``builtin:NAME`` or the POSIX path
relative to the root that holds it. A name that is absolute or climbs out of every root
(``../../etc/passwd``) is refused: grammars are shared, and a rule file must not read outside the folders
its user gave.

It is part of the IR because compiling resolves the names (``passes.assets``); the writers and the
baker that load the files ask it too.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

BUILTINS = ("cube", "quad", "cylinder", "L", "H", "U", "T")
#: ``cylinderN``: a cylinder of N sides (``cylinder`` has 16).
CYLINDER_SIDES_RANGE = range(3, 257)


def builtin_name(bare: str) -> bool:
    """Whether ``bare`` (without ``builtin:``) names a built-in: one of ``BUILTINS`` or ``cylinderN``."""
    if bare in BUILTINS:
        return True
    digits = bare.removeprefix("cylinder")
    return digits != bare and digits.isdigit() and int(digits) in CYLINDER_SIDES_RANGE


#: Assets every record can use for leaves: volumes are cubes, faces are quads.
LEAF_CUBE = "builtin:cube"
LEAF_QUAD = "builtin:quad"


@dataclass(frozen=True)
class ResolvedAsset:
    name: str               # canonical name written to the record
    path: Path | None       # the file, for OBJ assets that exist
    problem: str = ""       # why it is refused (escapes the roots) - empty when fine
    missing: bool = False   # a file name that no root holds


def resolve_asset(name: str, roots: list[Path]) -> ResolvedAsset:
    """Resolve one ``I()`` name against ``roots`` (searched in order)."""
    bare = name.removeprefix("builtin:")
    if builtin_name(bare):
        return ResolvedAsset(f"builtin:{bare}", None)
    if name.startswith("builtin:"):
        return ResolvedAsset(name, None, problem=f"unknown built-in asset `{name}` (built-ins: "
                             + ", ".join(BUILTINS) + ", cylinderN for N sides)")
    pure = PurePosixPath(name.replace("\\", "/"))
    if pure.is_absolute() or (len(name) > 1 and name[1] == ":"):
        return ResolvedAsset(name, None, problem=f"asset path `{name}` is absolute; give it relative "
                             "to the grammar's folder or an --assets folder")
    for root in roots:
        root = root.resolve()
        candidate = (root / pure).resolve()
        if not _inside(candidate, root):
            continue
        if candidate.is_file():
            return ResolvedAsset(candidate.relative_to(root).as_posix(), candidate)
    if not any(_inside((r.resolve() / pure).resolve(), r.resolve()) for r in roots):
        return ResolvedAsset(name, None, problem=f"asset path `{name}` leaves the asset folders "
                             f"({', '.join(str(r) for r in roots)})")
    return ResolvedAsset(pure.as_posix(), None, missing=True)


def _inside(path: Path, root: Path) -> bool:
    return os.path.commonpath([path, root]) == str(root)
