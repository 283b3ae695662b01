"""Lots in, instance records out: the readers and writers, leaves above the model.

Output formats register by extension, one module per format, as trimesh's ``exchange/`` modules declare
their exporters: each writer module has ``WRITERS``, the extensions it writes -> its writer class, and
``writers()`` collects them. The build asks ``writer_for`` for the writer of ``--emit PATH``:

* ``.npz``: the instance record (``io/npz.py``);
* ``.usda``, ``.usdc``, ``.usd``: instanced USD, one PointInstancer per tile (``io/usd.py``);
* ``.glb``: glTF with GPU instancing (``io/gltf.py``), or baked with ``--bake``;
* ``.3dtiles``: a folder of 3D Tiles 1.1, instanced GLB tiles under a quadtree of coarser ones
  (``io/tiles3d.py``), which ``grammarc view`` shows in a browser;
* ``.obj``, ``.ply``, ``.stl``: the record baked into one mesh (``io/bake.py``), as a .glb with ``--bake``;
* ``.json`` (``city.city.json``): CityJSON 2.0, a Building per lot (``io/cityjson.py``).

A writer class whose ``bakes`` is true writes baked meshes: ``--bake`` asks for it, and an extension that
no other writer takes is written baked anyway. A writer takes the ``OutputOptions`` its constructor names.
The writer modules are imported when a lookup reaches them, not with this package: importing grammarc loads
none of them, nor usd-core or trimesh (which they import when they write), and an .npz build only the npz
writer.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import TYPE_CHECKING

from grammarc.errors import UsageError

if TYPE_CHECKING:
    from grammarc.model.lots import Lots

#: The modules that declare ``WRITERS``, in the order ``writer_for``'s messages list their extensions.
WRITER_MODULES = ("grammarc.io.npz", "grammarc.io.usd", "grammarc.io.gltf", "grammarc.io.tiles3d", "grammarc.io.bake",
                  "grammarc.io.cityjson")


class WriterBlock:
    """``with writer:`` for writers with ``close``, ``abort`` and a ``_state``: closed when the block
    ends, aborted when it raises; a writer closed or aborted inside the block is left as it is."""

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is not None:
            self.abort()
        elif self._state == "open":
            self.close()


@dataclass(frozen=True)
class OutputOptions:
    """How a record is written, beyond its rows: ``bake`` instances into meshes (at most ``max_triangles``),
    the level of detail of assets (``model.assets.load_asset``), the tile edge of the instanced formats
    (``io.instancing``), the folders assets are loaded from (the build gives the grammar's, a rule
    package's while it is extracted, and ``--assets``), the world point baked meshes are relative to
    (``io.bake.BakedWriter``), the build's lots (``io.cityjson``: Buildings' ids and attributes;
    ``io.tiles3d``: the features' ids and attributes). None: the writer's default."""

    bake: bool = False
    lod: str | None = None
    tile_size: float | None = None
    max_triangles: int | None = None
    asset_roots: tuple | None = None
    bake_origin: tuple | None = None
    lots: Lots | None = None


def _declared():
    """``((extension, bakes), writer class)`` of each writer module's ``WRITERS``, in order; a module is
    imported when the walk reaches it, so that looking up ``.npz`` imports no other writer."""
    for name in WRITER_MODULES:
        for suffix, writer in import_module(name).WRITERS.items():
            yield (suffix, bool(getattr(writer, "bakes", False))), writer


@functools.cache
def writers() -> dict[tuple[str, bool], type]:
    """``(extension, bakes) -> writer class`` of every writer module, in declaration order."""
    return dict(_declared())


def writer_for(path: str | Path, options: OutputOptions = OutputOptions()):
    """The writer factory for an output path: ``factory(path, assets=, symbols=, meta=)``, with the
    options its constructor takes; a UsageError names the supported extensions."""
    writer = _writer_class(path, options)
    given = _taken(writer, options)
    return functools.partial(writer, **given) if given else writer


def written_paths(path: str | Path, options: OutputOptions = OutputOptions()) -> tuple[list[Path], list[Path]]:
    """The files and the folders that writing ``path`` makes: the output, and what its writer class puts
    beside it (its ``beside(path)``: ``(files, folders)``, the longest names they may have), for
    ``io.output_paths.check_writable`` to check before a build derives anything. A writer class whose
    ``folder`` is true writes the output as a folder."""
    path = Path(path)
    writer = _writer_class(path, options)
    if getattr(writer, "folder", False):
        return [], [path]
    beside = getattr(writer, "beside", None)
    files, folders = beside(path) if beside is not None else ([], [])
    return [path, *files], list(folders)


def _writer_class(path: str | Path, options: OutputOptions) -> type:
    """The writer class of ``path``'s extension (and ``options.bake``); a UsageError names the supported
    extensions."""
    suffix = Path(path).suffix.lower()
    # --bake: the extension's baked writer; else its instanced writer, or the baked one if it has none.
    writer = _first((suffix, options.bake)) or (None if options.bake else _first((suffix, True)))
    if writer is None:
        table = writers()
        if (suffix, False) not in table and (suffix, True) not in table:
            supported = ", ".join(dict.fromkeys(s for s, _ in table))
            raise UsageError(f"cannot write `{path}`: output format `{suffix or '(none)'}` is not supported "
                             f"(supported: {supported})")
        bakeable = ", ".join(s for s, bakes in table if bakes)
        raise UsageError(f"--bake writes meshes ({bakeable}), not `{suffix}`")
    return writer


def _first(key: tuple[str, bool]) -> type | None:
    """The writer declared for ``key``, walking the modules only as far as its declaration."""
    return next((writer for found, writer in _declared() if found == key), None)


def _taken(writer: type, options: OutputOptions) -> dict:
    """The options that are set and that ``writer``'s constructor takes, by the name of its keyword."""
    keywords = inspect.signature(writer).parameters
    return {field.name: getattr(options, field.name) for field in dataclasses.fields(options)
            if field.name in keywords and getattr(options, field.name) is not None}
