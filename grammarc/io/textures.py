"""Texture files that an output names by path: an OBJ's material library, USD's ``UsdUVTexture`` shaders.

An output names a texture by its path relative to the output, where the grammar's folders hold it. A rule
package's folders are different: the build extracts the package into the user's cache, which removes it
once unused (``io.kept_packages``), or into a temporary folder removed when the build ends (``io.rpk``), so
a path into it would name nothing for long. A texture found
there is copied into the output's own files instead (the OBJ's ``city.obj.textures`` folder, the USD tile
folder's ``textures``), at its path inside the package, as PRT's OBJ encoder writes a package's textures
beside its OBJ. The other formats embed their textures (GLB, 3D Tiles) or name none (npz, PLY, STL).

A record's ``meta`` says where its textures come from (``build.record_meta``): a build of a ``.rpk`` names
the package as its grammar and only the user's own asset folders in ``asset_roots``; every other folder of
the writer's roots is the package's extraction.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping, Sequence
from pathlib import Path, PurePosixPath

__all__ = ["PackagedTextures", "package_folder"]


def package_folder(meta: Mapping, roots: Sequence[str | os.PathLike]) -> Path | None:
    """The folder a rule package was extracted to, when ``meta`` is of a build of one: the folder that holds
    every root of the writer's ``roots`` that is not one of the user's (``meta["asset_roots"]``). None for a
    grammar on disk, or without such roots."""
    if not str(meta.get("grammar", "")).lower().endswith(".rpk"):
        return None
    own = {Path(r).resolve() for r in meta.get("asset_roots", ())}
    extracted = [str(Path(r).resolve()) for r in roots if Path(r).resolve() not in own]
    if not extracted:
        return None
    folder = Path(os.path.commonpath(extracted))
    return folder if folder != Path(folder.anchor) else None


class PackagedTextures:
    """Copies of a rule package's textures in a folder an output stages (module docstring).

    Parameters
    ----------
    meta : mapping
        The record's meta (``package_folder``).
    roots : sequence of path-like
        The folders the writer finds textures in.
    into : Path
        The staged folder the copies go to; made when the first texture is copied.
    """

    def __init__(self, meta: Mapping, roots: Sequence[str | os.PathLike], into: Path):
        self._package = package_folder(meta, roots)
        self.into = Path(into)
        self._copied: set[PurePosixPath] = set()

    @property
    def copied(self) -> bool:
        """Whether any texture was copied."""
        return bool(self._copied)

    def copy(self, file: Path) -> PurePosixPath | None:
        """The copy of texture ``file`` (a resolved path, as ``locate`` finds it), relative to ``into``, when
        the file lies in the rule package (copied the first time it is asked for); None for any other file,
        which the output names where it is."""
        if self._package is None or os.path.commonpath([file, self._package]) != str(self._package):
            return None
        relative = PurePosixPath(file.relative_to(self._package).as_posix())
        if relative not in self._copied:
            target = self.into / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(file, target)
            self._copied.add(relative)
        return relative

    def named(self, file: Path, folder: str, base: Path) -> str:
        """How an output at ``base`` names texture ``file`` (a resolved path): its copy, under ``folder``
        (the output's name for ``into``), where the file lies in the rule package; else its path relative to
        ``base``, where the grammar's folders hold it."""
        copied = self.copy(file)
        return f"{folder}/{copied}" if copied is not None else os.path.relpath(file, base)
