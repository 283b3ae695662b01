"""What a server loads before serving (``commands/serving.py``, ``warm``): a served command is a fork of it, so
whatever it would import on its way is what every command of its kind pays again."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: What ``warm`` changed in the environment, and after it, builds of GeoParquet lots with a coordinate system to
#: USD, a baked mesh, glTF, 3D Tiles and npz: the modules of the libraries in ``LIBRARIES`` they import
#: (printed as JSON).
BUILDS = """
import json, os, sys
from grammarc.cli import main
from grammarc.commands.serving import LIBRARIES, warm
tops = {name.split(".")[0] for name in LIBRARIES}
environment = dict(os.environ)
warm()
changed = sorted(k for k in {*environment, *os.environ} if environment.get(k) != os.environ.get(k))
before = set(sys.modules)
for emit in ("o.usda", "o.obj", "o.glb", "o.3dtiles", "o.npz"):
    assert main(["build", "g.cga", "--lots", "lots.parquet", "--emit", emit, "--quiet"]) == 0
imported = sorted(m for m in set(sys.modules) - before if m.split(".")[0] in tops)
print(json.dumps({"changed": changed, "imported": imported}))
"""


def test_a_warm_server_has_imported_the_libraries_its_commands_read_and_write_with(georeferenced_lots):
    """... and left the environment as it was: a served command takes its client's, so a setting made by an
    import (pyogrio's certificate bundles) would be the server's alone."""
    pytest.importorskip("pxr")
    folder = georeferenced_lots.parent
    (folder / "g.cga").write_text("Lot --> extrude(3) X.\n")
    assert json.loads(_fresh_python(BUILDS, folder)) == {"changed": [], "imported": []}


def test_a_library_that_fails_to_import_leaves_the_server_warm_without_it(tmp_path):
    """pyproj without its data raises an error of its own when imported: the server starts, and the command
    that needs the library meets the error itself."""
    (tmp_path / "broken_library.py").write_text("raise RuntimeError('no data here')\n")
    warming = ("from grammarc.commands import serving\n"
               "serving.LIBRARIES = ('broken_library',)\n"
               "serving.warm()\n"
               "print('warm')\n")
    assert _fresh_python(warming, tmp_path).split() == ["warm"]


def _fresh_python(code: str, folder: Path) -> str:
    """What ``code`` prints, run by a Python of its own in ``folder`` (whose modules it may import), as a
    server warms up: in a process that has imported nothing of grammarc's yet."""
    env = {**os.environ, "GRAMMARC_SERVER": "off", "PYTHONPATH": os.pathsep.join((str(ROOT), str(folder)))}
    done = subprocess.run([sys.executable, "-c", code], cwd=folder, env=env, capture_output=True, text=True,
                          timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout
