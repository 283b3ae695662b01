"""The writer registry of ``grammarc.io``: extensions to writers, ``--bake``, options, messages, laziness."""

import functools
import subprocess
import sys
from collections import Counter

import pytest

from grammarc.errors import UsageError
from grammarc.io import WRITER_MODULES, OutputOptions, _declared, writer_for, writers
from grammarc.io.bake import BakedWriter
from grammarc.io.gltf import GltfWriter
from grammarc.io.npz import InstanceWriter
from grammarc.io.usd import UsdWriter

EVERY = OutputOptions(lod="low", tile_size=3.0, max_triangles=5, asset_roots=("assets",))


def made(path, options=EVERY):
    """The writer class ``writer_for`` gives, and the keywords it binds."""
    writer = writer_for(path, options)
    return (writer.func, writer.keywords) if isinstance(writer, functools.partial) else (writer, {})


@pytest.mark.parametrize(("path", "bake", "writer", "keywords"), [
    ("city.npz", False, InstanceWriter, set()),
    ("city.usda", False, UsdWriter, {"lod", "tile_size", "asset_roots"}),
    ("city.usdc", False, UsdWriter, {"lod", "tile_size", "asset_roots"}),
    ("CITY.USD", False, UsdWriter, {"lod", "tile_size", "asset_roots"}),
    ("city.glb", False, GltfWriter, {"lod", "tile_size", "asset_roots"}),
    ("city.glb", True, BakedWriter, {"lod", "max_triangles", "asset_roots"}),
    ("city.obj", False, BakedWriter, {"lod", "max_triangles", "asset_roots"}),
    ("city.ply", True, BakedWriter, {"lod", "max_triangles", "asset_roots"}),
    ("city.stl", False, BakedWriter, {"lod", "max_triangles", "asset_roots"}),
])
def test_each_extension_has_its_writer_with_the_options_its_constructor_takes(path, bake, writer, keywords):
    got, given = made(path, OutputOptions(**{**vars(EVERY), "bake": bake}))
    assert got is writer and set(given) == keywords
    assert all(value == getattr(EVERY, key) for key, value in given.items())


def test_options_left_unset_are_not_passed():
    assert writer_for("city.stl") is BakedWriter
    assert made("city.usdc", OutputOptions(lod="low")) == (UsdWriter, {"lod": "low"})


SUPPORTED = "(supported: .npz, .usda, .usdc, .usd, .glb, .3dtiles, .obj, .ply, .stl, .json)"


@pytest.mark.parametrize(("path", "bake", "message"), [
    ("city.fbx", False, f"cannot write `city.fbx`: output format `.fbx` is not supported {SUPPORTED}"),
    ("city", True, f"cannot write `city`: output format `(none)` is not supported {SUPPORTED}"),
    ("city.npz", True, "--bake writes meshes (.obj, .ply, .stl, .glb, .json), not `.npz`"),
    ("city.usdc", True, "--bake writes meshes (.obj, .ply, .stl, .glb, .json), not `.usdc`"),
])
def test_a_format_nothing_writes_names_those_that_are(path, bake, message):
    with pytest.raises(UsageError) as error:
        writer_for(path, OutputOptions(bake=bake))
    assert str(error.value) == message


def test_each_extension_is_declared_once_baked_and_once_not():
    declared = Counter(key for key, _ in _declared())
    assert declared and max(declared.values()) == 1
    assert list(writers()) == list(dict(_declared()))  # the table keeps the declaration order
    assert [key for key in writers() if key[1]] == [(s, True) for s in (".obj", ".ply", ".stl", ".glb", ".json")]


def test_importing_grammarc_loads_no_writer_and_an_npz_lookup_only_its_own():
    heavy = ("pxr", "trimesh", "pygltflib", *WRITER_MODULES)
    script = f"""
import sys
import grammarc, grammarc.cli, grammarc.io
loaded = [m for m in {heavy!r} if m in sys.modules]
grammarc.io.writer_for("city.npz")
print(loaded, [m for m in {heavy!r} if m in sys.modules])
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["[]", "['grammarc.io.npz']"]
