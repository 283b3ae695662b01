"""Benchmark helpers: lots written outside the timed region, the whole command timed as a process.

Run with ``python -m pytest benchmarks`` (add ``-k 1e5`` for one size). Each benchmark reports terminals
per second and the child's peak RSS in ``extra_info`` (shown by ``--benchmark-json`` and in the table's
name column); times are wall-clock for the whole ``grammarc build`` process, start-up included.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely

HERE = Path(__file__).parent


def grid_lots(path: Path, n: int, width: float = 20.0, depth: float = 15.0, crs: str | None = None,
              at: tuple[float, float] = (0.0, 0.0)) -> Path:
    """n rectangular lots on a grid from ``at``, as GeoJSON (deterministic), in the coordinate system ``crs``
    (a ``crs`` member, as GDAL writes it) or none."""
    side = int(n ** 0.5 + 0.999)
    features = []
    for i in range(n):
        x, y = at[0] + (i % side) * (width + 10), at[1] + (i // side) * (depth + 10)
        ring = [[x, y], [x + width, y], [x + width, y + depth], [x, y + depth], [x, y]]
        features.append({"type": "Feature", "id": f"lot{i}", "properties": {},
                         "geometry": {"type": "Polygon", "coordinates": [ring]}})
    named = {"crs": {"type": "name", "properties": {"name": crs}}} if crs else {}
    path.write_text(json.dumps({"type": "FeatureCollection", **named, "features": features}))
    return path


def concave_lots(path: Path, n: int, seed: int = 7) -> Path:
    """n random concave footprints of 8 to 40 vertices (star-shaped, radius 6 to 12 m), every fifth with
    a round courtyard where it fits, on a 30 m grid, as GeoJSON (deterministic)."""
    rng = np.random.default_rng(seed)
    side = int(n ** 0.5 + 0.999)
    features = []
    for i in range(n):
        k = int(rng.integers(8, 41))
        angles = np.sort(rng.uniform(0, 2 * np.pi, k))
        angles += (np.arange(k) * 2 * np.pi / k - angles) * 0.5  # spread out: no needle wedges
        radius = rng.uniform(6, 12, k)
        centre = np.array([(i % side) * 30.0, (i // side) * 30.0])
        outer = centre + np.stack([np.cos(angles), np.sin(angles)], axis=1) * radius[:, None]
        rings = [[*outer.tolist(), outer[0].tolist()]]
        hole = centre + np.stack([np.cos(-np.arange(12) * np.pi / 6), np.sin(-np.arange(12) * np.pi / 6)],
                                 axis=1) * 2.5
        if i % 5 == 0 and shapely.Polygon(outer).contains(shapely.Polygon(hole).buffer(0.5)):
            rings.append([*hole.tolist(), hole[0].tolist()])
        features.append({"type": "Feature", "id": f"lot{i}", "properties": {},
                         "geometry": {"type": "Polygon", "coordinates": rings}})
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def run_build(args: list[str], env: dict | None = None, entry: str = "grammarc.cli") -> dict:
    """Run ``grammarc build`` in a child process; returns its stderr and its own peak RSS (KiB)."""
    return run_command("build", args, env, entry)


def run_command(command: str, args: list[str], env: dict | None = None, entry: str = "grammarc.cli") -> dict:
    """Run ``grammarc COMMAND`` in a child process; returns its stderr and its own peak RSS (KiB).

    ``entry`` is the module run: ``grammarc.cli`` runs the command in the child itself, ``grammarc.client``
    as the ``grammarc`` command does (in a fork of a warm server where one is up: the RSS is then the
    client's). ``os.wait4`` gives the child's own resource usage (RUSAGE_CHILDREN would be the maximum
    over every child the benchmark session ever waited for).
    """
    proc = subprocess.Popen([sys.executable, "-m", entry, command, *args],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, **(env or {})})
    stderr = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(stderr)
    return {"stderr": stderr, "peak_rss_kib": usage.ru_maxrss}


@pytest.fixture(scope="session")
def lots_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("lots")


@pytest.fixture(scope="session")
def served_env(tmp_path_factory):
    """The environment of commands that a server (started here as a user starts one, stopped at the end)
    runs."""
    folder = tmp_path_factory.mktemp("run")
    folder.chmod(0o700)
    env = {**os.environ, "XDG_RUNTIME_DIR": str(folder)}
    command = [sys.executable, "-m", "grammarc.client", "server"]
    subprocess.run([*command, "start", "--idle-timeout", "30"], env=env, check=True, capture_output=True)
    yield env
    subprocess.run([*command, "stop"], env=env, check=True, capture_output=True)
