"""Lots in, assets, instance records out.

Output formats register here by extension, one module per format (as trimesh's ``exchange/``); the build
asks ``writer_for`` for the writer of ``--emit PATH``:

* ``.npz``: the instance record (``io/npz.py``);
* ``.usda``, ``.usdc``, ``.usd``: instanced USD, one PointInstancer per tile (``io/usd.py``);
* ``.glb``: glTF with GPU instancing (``io/gltf.py``), or baked with ``--bake``;
* ``.obj``, ``.ply``, ``.stl``: the record baked into one mesh (``io/bake.py``), as a .glb with ``--bake``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

from grammarc.errors import UsageError

_BAKED = ("grammarc.io.bake", "BakedWriter", ("lod", "max_triangles", "asset_roots"))
#: Output extension -> (module, writer class, the ``OutputOptions`` fields it takes).
WRITERS = {
    ".npz": ("grammarc.io.npz", "InstanceWriter", ()),
    ".usda": ("grammarc.io.usd", "UsdWriter", ("lod", "tile_size", "asset_roots")),
    ".usdc": ("grammarc.io.usd", "UsdWriter", ("lod", "tile_size", "asset_roots")),
    ".usd": ("grammarc.io.usd", "UsdWriter", ("lod", "tile_size", "asset_roots")),
    ".glb": ("grammarc.io.gltf", "GltfWriter", ("lod", "tile_size", "asset_roots")),
    ".obj": _BAKED,
    ".ply": _BAKED,
    ".stl": _BAKED,
}
#: Formats ``--bake`` applies to: always baked but for .glb, which is instanced without it.
BAKEABLE = (".obj", ".ply", ".stl", ".glb")


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
    the level of detail of assets (``io.bake.load_asset``), the tile edge of the instanced formats
    (``io.instancing``), the folders assets are loaded from (the build gives the grammar's, a rule
    package's while it is extracted, and ``--assets``). None: the writer's default."""

    bake: bool = False
    lod: str | None = None
    tile_size: float | None = None
    max_triangles: int | None = None
    asset_roots: tuple | None = None


def writer_for(path: str | Path, options: OutputOptions = OutputOptions()):
    """The writer factory for an output path: ``factory(path, assets=, symbols=, meta=)``; a UsageError
    names the supported extensions."""
    suffix = Path(path).suffix.lower()
    if suffix not in WRITERS:
        supported = ", ".join(WRITERS)
        raise UsageError(f"cannot write `{path}`: output format `{suffix or '(none)'}` is not supported "
                         f"(supported: {supported})")
    if options.bake and suffix not in BAKEABLE:
        raise UsageError(f"--bake writes meshes ({', '.join(BAKEABLE)}), not `{suffix}`")
    module, name, takes = _BAKED if options.bake else WRITERS[suffix]
    from importlib import import_module

    writer = getattr(import_module(module), name)
    given = {field: getattr(options, field) for field in takes if getattr(options, field) is not None}
    return functools.partial(writer, **given) if given else writer
