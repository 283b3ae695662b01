"""Asset names: built-in primitives and OBJ files, resolved inside the asset roots.

``I("cube")`` and ``I("builtin:cube")`` name the built-in unit cube (built-ins: ``cube``, ``quad``,
``cylinder`` and ``cylinderN`` with N sides, ``coneN``, ``sphereNxM`` (CityEngine's primitives), and the
paper's mass-model blocks ``L``, ``H``, ``U``, ``T``; CityEngine's ``builtin:cube:notex``, a cube without
texture coordinates, is the cube: records carry none); ``I("facade/window.obj")`` names a file relative to
an asset root (the grammar's folder first, then any ``--assets`` folders). The record keeps a canonical name: ``builtin:NAME`` or the POSIX path
relative to the root that holds it. A drive path (``C:/x.obj``) or a name that climbs out of every root
(``../../etc/passwd``) is refused: grammars are shared, and a rule file must not read outside the folders
its user gave; a workspace path ``/Project/...`` is looked up inside them only.

It is part of the IR because compiling resolves the names (``passes.assets``); the writers and the
baker that load the files ask it too.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

BUILTINS = ("cube", "quad", "cylinder", "L", "H", "U", "T")
#: Built-ins with segment counts, and how many: ``cylinderN`` and ``coneN`` (N sides), ``sphereNxM`` (N
#: sides around, M divisions from pole to pole); ``cylinder`` is ``cylinder16``.
SEGMENTED = {"cylinder": 1, "cone": 1, "sphere": 2}
#: The segment counts a built-in may have.
SEGMENTS_RANGE = range(3, 257)


def builtin_name(bare: str) -> bool:
    """Whether ``bare`` (without ``builtin:``) names a built-in: one of ``BUILTINS``, or one of
    ``SEGMENTED`` with its segment counts."""
    return bare in BUILTINS or builtin_segments(bare) is not None


def builtin_segments(bare: str) -> tuple[str, tuple[int, ...]] | None:
    """The kind and segment counts of a segmented built-in (``"sphere8x4"`` -> ``("sphere", (8, 4))``),
    or None when ``bare`` names none."""
    for kind, count in SEGMENTED.items():
        digits = bare.removeprefix(kind).split("x")
        if bare.startswith(kind) and len(digits) == count and all(d.isdigit() for d in digits):
            numbers = tuple(int(d) for d in digits)
            if all(n in SEGMENTS_RANGE for n in numbers):
                return kind, numbers
    return None


def primitive_asset(kind: str, counts: tuple[int, ...]) -> str | None:
    """The built-in asset of a CityEngine primitive of ``kind`` with segment ``counts``
    (``segment_counts``), or None for those that are no asset (cube, quad, disk)."""
    if kind not in SEGMENTED:
        return None
    return f"builtin:{kind}{'x'.join(str(n) for n in counts)}"


def segment_counts(values) -> tuple[int, ...]:
    """Segment counts from a primitive's segment arguments: rounded (half up) to whole numbers and kept within
    ``SEGMENTS_RANGE`` (CityEngine asks for at least 3; 256 sides are round to the eye)."""
    return tuple(min(max(math.floor(float(v) + 0.5), SEGMENTS_RANGE.start), SEGMENTS_RANGE.stop - 1) for v in values)


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
    """Resolve one ``I()`` name against ``roots`` (searched in order).

    A workspace path ``/Project/assets/x.obj`` (CityEngine's absolute paths, which start at the
    workspace) is looked up as ``Project/assets/x.obj`` in the roots (one of them may be a workspace, a
    folder of projects), else, when no root holds a folder ``Project``, as ``assets/x.obj`` (a rule package
    or a lone project is the project its paths name); when no root holds it, it is missing, as a relative
    name is. A drive path ``C:/...`` (the host's, never the workspace's) is refused, as is a name that
    climbs out of every root or holds a NUL byte.
    """
    bare = name.removeprefix("builtin:")
    if name == "builtin:cube:notex":
        bare = "cube"
    if builtin_name(bare):
        return ResolvedAsset(f"builtin:{bare}", None)
    if name.startswith("builtin:"):
        return ResolvedAsset(name, None, problem=f"unknown built-in asset `{name}` (built-ins: "
                             + ", ".join(BUILTINS) + ", cylinderN and coneN for N sides, sphereNxM)")
    if "\0" in name:
        shown = name.replace("\0", "\\0")
        return ResolvedAsset(shown, None, problem=f"asset path `{shown}` holds a NUL byte")
    pure = PurePosixPath(name.replace("\\", "/"))
    if len(name) > 1 and name[1] == ":":
        return ResolvedAsset(name, None, problem=f"asset path `{name}` is absolute; give it relative "
                             "to the grammar's folder or an --assets folder")
    found = locate(name, roots)
    if found is not None:
        root, path = found
        return ResolvedAsset(path.relative_to(root).as_posix(), path)
    if pure.is_absolute():
        # a workspace path that no root holds is missing, as in CityEngine, which inserts nothing for it;
        # only the roots were searched, so nothing outside them was read
        return ResolvedAsset(pure.as_posix(), None, missing=True)
    if not any(_inside((r.resolve() / pure).resolve(), r.resolve()) for r in roots):
        return ResolvedAsset(name, None, problem=f"asset path `{name}` leaves the asset folders "
                             f"({', '.join(str(r) for r in roots)})")
    return ResolvedAsset(pure.as_posix(), None, missing=True)


def locate(name: str, roots) -> tuple[Path, Path] | None:
    """The first root holding the file ``name`` and the file (resolved), or None.

    ``name`` is relative to a root, or a workspace path ``/Project/rest`` (see ``resolve_asset``). A
    candidate that leaves its root (``..``, or a link pointing out of it) is skipped: what a grammar reads
    stays inside the folders its user gave.
    """
    pure = PurePosixPath(name.replace("\\", "/"))
    relatives = [pure]
    if pure.is_absolute():
        inner = PurePosixPath(*pure.parts[1:])
        relatives = [inner]
        if len(inner.parts) > 1 and not any((Path(r) / inner.parts[0]).is_dir() for r in roots):
            relatives.append(PurePosixPath(*inner.parts[1:]))
    for relative in relatives:
        for root in roots:
            root = Path(root).resolve()
            candidate = (root / relative).resolve()
            if _inside(candidate, root) and candidate.is_file():
                return root, candidate
    return None


def _inside(path: Path, root: Path) -> bool:
    return os.path.commonpath([path, root]) == str(root)


#: Asset formats read only through an optional package: file ending -> (the format's name, the module).
OPTIONAL_FORMATS = {".fbx": ("FBX", "assimp_py"), ".3ds": ("3DS", "assimp_py")}


def unsupported_format(path: str | os.PathLike) -> str:
    """Why an asset file cannot be read here, or "": its format needs a package that is not installed
    (the compiler says so at the insert; the loader when it is asked for the file)."""
    import importlib.util

    entry = OPTIONAL_FORMATS.get(Path(path).suffix.lower())
    if entry is None:
        return ""
    try:
        if importlib.util.find_spec(entry[1]) is not None:
            return ""
    except ValueError:  # set to None in sys.modules: importing it fails
        pass
    return f"unsupported asset format: {entry[0]} (`{Path(path).name}`; pip install 'grammarc[fbx]' reads FBX and 3DS)"
