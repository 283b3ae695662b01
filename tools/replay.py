"""Replay before you refactor: one digest per build of every example, benchmark grammar and PRT rule package.

A change that should not alter any record (a refactor) is checked by running this before and after it::

    python tools/replay.py > before.txt        # on the commit before
    python tools/replay.py --check before.txt  # on the commit after: lists every build that changed

Each line is ``name digest``: the digest covers every array of the record but ``meta`` (as the examples'
``records.sha256``), the reports and the bad lots with their messages. The builds: the examples on their
own lots; the benchmark grammars on 200 grid lots and 200 concave lots (some with courtyards); the
paper-notation and CityEngine grammars of the tests; every rule package of the PRT kit (``../shared/prt``,
skipped when absent) on the kit's footprints and on 60 concave ones, with the attribute variants of the
kit's ``reference.json`` and two seeds.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]  # this checkout's grammarc, whichever one is installed


def _benchmark_lots():
    """The benchmarks' lot makers (their ``conftest``, loaded by path: under pytest, ``conftest`` is the
    tests' own)."""
    spec = importlib.util.spec_from_file_location("benchmark_lots", ROOT / "benchmarks" / "conftest.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.concave_lots, module.grid_lots


concave_lots, grid_lots = _benchmark_lots()

from test_examples import record_digest

from grammarc.build import BuildOptions, build
from grammarc.conform import kit_dir

#: Attribute variants of rule packages, as the kit's reference.json has them.
VARIANTS = {
    "candler": [{"BuildingHeight": 40.0, "FloorHeight": 3.2, "TileWidth": 3.0}],
    "extrusion_rule": [{"minBuildingHeight": 17.0, "maxBuildingHeight": 17.0}],
    "complexpatterns": [{"buildingH": 20.0}],
}


def cases(lots: Path):
    """``(name, grammar, lots or None, options)`` of every build."""
    for grammar in sorted((ROOT / "examples").glob("*/*.cga")):
        yield f"examples/{grammar.parent.name}/{grammar.name}", grammar, None, BuildOptions()
    grid, concave = grid_lots(lots / "grid.geojson", 200), concave_lots(lots / "concave.geojson", 200)
    for grammar in sorted((ROOT / "benchmarks").glob("*.cga")):
        for name, path in (("grid", grid), ("concave", concave)):
            yield f"benchmarks/{grammar.name}@{name}", grammar, path, BuildOptions()
    for grammar in sorted((ROOT / "tests" / "frontend" / "grammars").rglob("*.cga")):
        if grammar.stem not in ("syntax_errors", "unsupported"):
            for name, path in (("one", None), ("concave", concave)):
                yield f"tests/{grammar.relative_to(ROOT / 'tests').as_posix()}@{name}", grammar, path, \
                    BuildOptions()
    kit = kit_dir()
    if not kit.is_dir():
        print("# no PRT kit at", kit, file=sys.stderr)
        return
    kit_lots = kit / "footprints" / "all.geojson"
    few = concave_lots(lots / "concave60.geojson", 60, seed=11)
    for package in sorted((kit / "rpk").glob("*.rpk")):
        for attrs in [{}, *VARIANTS.get(package.stem, [])]:
            for seed in (0, 5):
                for name, path in (("kit", kit_lots), ("concave", few)):
                    label = ",".join(f"{k}={v:g}" for k, v in attrs.items())
                    yield (f"prt/{package.name}[{label}]@{name}#seed{seed}", package, path,
                           BuildOptions(attrs=attrs, seed=seed))


def digest(grammar: Path, lots: Path | None, options: BuildOptions, folder: Path) -> str:
    out = folder / "out.npz"
    reports = folder / "out.reports.json"
    reports.unlink(missing_ok=True)
    out.unlink(missing_ok=True)
    try:
        result = build(grammar, out, lots_path=lots, options=options, reports_to=reports)
    except Exception as error:  # noqa: BLE001 - a build that fails is a result to compare too
        return "error:" + hashlib.sha256(f"{type(error).__name__}: {error}".encode()).hexdigest()[:16]
    # a build where no lot could be built writes nothing: its bad lots are the result
    h = hashlib.sha256(record_digest(out).encode() if result.written else b"nothing written")
    if reports.exists():
        h.update(reports.read_bytes())
    # a reason may name the grammar by its path: the checkout's folder is left out of the digest
    reasons = [(b.index, b.id, b.reason.replace(str(ROOT), "<root>")) for b in result.bad]
    h.update(json.dumps(reasons).encode())
    return h.hexdigest()[:32]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", type=Path, help="compare with an earlier run's output")
    parser.add_argument("-k", default="", help="only the builds whose name contains this")
    args = parser.parse_args()
    expected = {}
    if args.check:
        expected = dict(line.split() for line in args.check.read_text().splitlines() if line and line[0] != "#")
    changed = 0
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name, grammar, lots, options in cases(folder):
            if args.k not in name:
                continue
            value = digest(grammar, lots, options, folder)
            if args.check:
                if expected.get(name) != value:
                    changed += 1
                    print(f"CHANGED {name}: {expected.get(name)} -> {value}", flush=True)
            else:
                print(name, value, flush=True)
    if args.check:
        print(f"{changed} changed of {len(expected)}" if changed else f"all {len(expected)} unchanged")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
