"""Lots in, assets, instance records out.

Output formats register here by extension, one module per format (as trimesh's ``exchange/``); the build
asks ``writer_for`` for the writer of ``--emit PATH``.
"""

from __future__ import annotations

from pathlib import Path

from grammarc.errors import UsageError

#: Output extension -> writer class name in its module. Later formats (USD, glTF, OBJ) add a line each.
WRITERS = {".npz": ("grammarc.io.npz", "InstanceWriter")}
WRITERS[".obj"] = ("grammarc.io.bake", "BakedWriter")  # meshes: the record baked on close (io/bake.py)
WRITERS[".ply"] = ("grammarc.io.bake", "BakedWriter")
WRITERS[".stl"] = ("grammarc.io.bake", "BakedWriter")
WRITERS[".glb"] = ("grammarc.io.bake", "BakedWriter")


def writer_for(path: str | Path):
    """The writer class for an output path, or a UsageError naming the supported extensions."""
    suffix = Path(path).suffix.lower()
    if suffix not in WRITERS:
        supported = ", ".join(WRITERS)
        raise UsageError(f"cannot write `{path}`: output format `{suffix or '(none)'}` is not supported "
                         f"(supported: {supported})")
    module, name = WRITERS[suffix]
    from importlib import import_module

    return getattr(import_module(module), name)
