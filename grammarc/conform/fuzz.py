"""The differential harness: grammarc against PRT on random footprints, case by case.

For each rule package of the kit, batches of cases (``cases``: a footprint class, a seed, attributes sampled
from the package's annotated ranges) are written as one lots file, spread on a grid 2 km apart so that no
lot sees another. PRT derives the batch in its side environment (``prt_batch``), while grammarc derives it
twice, with the default chunking and one lot per chunk. Each case is then judged on what the issue asks:

- ``skipped``: grammarc made the lot bad where PRT built it (a lot grammarc cannot build is a mismatch);
- ``bbox``: a bounding box coordinate more than 2 cm off; ``area``: surface area more than 1 % off;
- ``reports``: a report key missing or of another value (numbers to a relative 1e-9);
- ``chunking``: the lot's records differ between the two chunkings (they must be byte-identical);

and the symmetric mean surface distance between the two meshes is measured (``measure.surface_distance``).
A case that fails a check is saved as ``OUT/cases/NAME.geojson``, the lot alone with its attributes and
both engines' figures under the foreign member ``grammarc_conform``; ``--case FILE`` runs it again. Every
result is appended to ``OUT/results.jsonl``, so that a run of hours accumulates and ``--table OUT``
tabulates it per package and footprint class.
"""

from __future__ import annotations

import contextlib
import functools
import json
import math
import subprocess
import sys
import tempfile
import time
import zlib
from array import array
from collections import defaultdict
from collections.abc import Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from grammarc.conform.cases import Case, cases_from_file, make_case, write_lots
from grammarc.conform.footprints import CLASSES
from grammarc.conform.kit import kit_dir, prt_python
from grammarc.conform.measure import compare, compare_reports, measure, surface_distance
from grammarc.conform.processes import Processes
from grammarc.errors import UsageError

__all__ = ["PACKAGES", "distributions", "fuzz", "judge_batch", "lot_record", "read_results", "rerun_case", "same_lot_records", "table"]

#: The kit's rule packages, in the issue's order.
PACKAGES = ("candler", "massing", "complexpatterns", "extrude_color", "extrusion_rule", "translateModel",
            "genattrs", "reporting")
#: The issue's criteria: bounding box within 2 cm, surface area within 1 %.
BBOX_TOL, AREA_TOL = 0.02, 0.01
#: Points sampled on each surface for the distance: enough for a mean to ~1 mm on a building.
DISTANCE_SAMPLES = 2000
#: Lots of a batch lie on a grid this far apart (metres): beyond any rule's reach.
SPACING = 2000.0
#: The checks, in the order a case's failures are listed.
CHECKS = ("skipped", "bbox", "area", "reports", "chunking")


@dataclass
class Package:
    """A kit rule package compiled once for the whole run."""

    name: str
    rpk: Path
    grammar: object
    options: object  # the resolved BuildOptions (asset roots of the extracted package)


@contextlib.contextmanager
def open_packages(names: Iterable[str], kit: Path) -> Iterator[dict[str, Package]]:
    """The packages ``names`` compiled, their archives extracted for as long as the block runs."""
    from grammarc.build import BuildOptions, grammar_source
    from grammarc.compiler import compile_grammar

    with contextlib.ExitStack() as stack:
        packages = {}
        for name in names:
            rpk = kit / "rpk" / f"{name}.rpk"
            if not rpk.is_file():
                raise UsageError(f"no rule package `{name}` in {kit / 'rpk'}")
            source, display, resolved = stack.enter_context(grammar_source(rpk, BuildOptions()))
            grammar = compile_grammar(source, start=resolved.start, asset_roots=resolved.asset_roots,
                                      display=display)
            packages[name] = Package(name, rpk, grammar, resolved)
        yield packages


# ------------------------------------------------------------------------------------------ PRT's side


def run_prt(python: Path, kit: Path, rpk: Path, lots: Path, folder: Path, timeout: float = 900,
            processes: Processes | None = None) -> dict:
    """PRT's records of the lots of ``lots``: {case name: record}, each with ``triangles`` an (n, 3, 3)
    array. A batch whose PRT process dies is run again in halves, so that one lot that crashes PRT costs
    only itself (its record then says so). PRT runs through ``processes`` (``conform.processes``), which
    the caller can stop."""
    with open(lots, encoding="utf-8") as file:
        features = json.load(file)["features"]
    return _prt_records(python, kit, rpk, features, folder, timeout, processes or Processes())


def _prt_records(python, kit, rpk, features, folder, timeout, processes: Processes) -> dict:
    path = folder / f"prt-{features[0]['properties']['name']}-{len(features)}"
    with open(path.with_suffix(".geojson"), "w", encoding="utf-8") as file:
        json.dump({"type": "FeatureCollection", "features": features}, file)
    command = [str(python), str(Path(__file__).with_name("prt_batch.py")), str(kit), str(rpk),
               str(path.with_suffix(".geojson")), str(path)]
    try:
        status, stderr = processes.run(command, timeout)
        failure = status != 0 and (stderr.strip().splitlines() or [f"exit {status}"])[-1]
    except subprocess.TimeoutExpired:
        failure = f"PRT took more than {timeout:g} s"
    if failure:
        if len(features) == 1:
            return {features[0]["properties"]["name"]: {"error": f"PRT failed: {failure}"}}
        half = len(features) // 2
        return {**_prt_records(python, kit, rpk, features[:half], folder, timeout, processes),
                **_prt_records(python, kit, rpk, features[half:], folder, timeout, processes)}
    with open(str(path) + ".json", encoding="utf-8") as file:
        records = json.load(file)["lots"]
    corners = array("d")
    with open(str(path) + ".tri", "rb") as file:
        corners.frombytes(file.read())
    if sys.byteorder != "little":
        corners.byteswap()
    corners = np.frombuffer(corners, dtype=np.float64).reshape(-1, 3, 3)
    for record in records.values():
        first, count = record.pop("triangles", (0, 0))
        record["triangles"] = corners[first:first + count]
    return records


# ------------------------------------------------------------------------------------- grammarc's side


def lot_record(record: dict, lot: int) -> dict:
    """The rows of lot number ``lot`` in a record of ``build.derive``: its instances and mesh faces."""
    rows = np.flatnonzero(record["lot"] == lot)
    part = {name: record[name][rows] for name in ("asset", "xform", "lot", "symbol", "uv") if name in record}
    origin = np.full((lot + 1, 3), np.nan)  # the record's lot_origin table, this lot's row alone
    origin[lot] = record["lot_origin"][lot]
    part.update(assets=record["assets"], symbols=record["symbols"], lot_origin=origin,
                mesh=record["mesh"].take(np.flatnonzero(record["mesh"].lot == lot)))
    return part


def same_lot_records(a: dict, b: dict, geometry_only: bool = False) -> bool:
    """Byte-identical lot records: instances, their uv, and the mesh table's arrays; with
    ``geometry_only``, the assets, transforms and polygons alone (not colours, textures or uv)."""
    instance_fields = ("lot_origin", "asset", "xform") + (() if geometry_only else ("symbol", "uv"))
    for name in instance_fields:
        if (name in a) != (name in b) or (name in a and a[name].tobytes() != b[name].tobytes()):
            return False
    ma, mb = a["mesh"], b["mesh"]
    mesh_fields = ("vertices", "ring_offsets", "face_offsets")
    if not geometry_only:
        mesh_fields += ("symbol", "color", "uv")
    arrays = [(getattr(ma, name), getattr(mb, name)) for name in mesh_fields]
    if not geometry_only:
        # ``derive`` joins the chunks' material tables: compare the faces' textures, not their row numbers
        arrays.append(tuple(None if m.material is None else m.materials[m.material] for m in (ma, mb)))
    return all((x is None) == (y is None) and (x is None or np.asarray(x).tobytes() == np.asarray(y).tobytes())
               for x, y in arrays)


def _triangles_mesh(triangles: np.ndarray):
    import trimesh

    return trimesh.Trimesh(triangles.reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3), process=False)


# --------------------------------------------------------------------------------------------- judging


def judge_batch(package: Package, cases: list[Case], lots: Path, prt: dict) -> list[dict]:
    """Derive ``lots`` (the cases' lots file) with grammarc and judge each case against ``prt``.

    The lots are derived with the default chunking, with one lot per chunk (the records must be the
    same), and with other seeds (``_random_lots``). A lot whose records change with the seed draws random
    numbers. grammarc draws PRT's numbers for CityEngine's rules (``backend.streams``) but not in an
    attribute's default (README, "Conformance with PRT"): a random lot whose case leaves such a default
    to be drawn is judged on what does not depend on the draws (skipped, chunking) and its figures are
    kept for the comparison of distributions (``distributions``); the others are compared value for value.
    """
    from dataclasses import replace

    from grammarc.build import derive
    from grammarc.io.lots import read_lots

    lots_read = read_lots(lots)
    # a seed per batch: its lots are numbered from 0 as every batch's are, and would draw the same numbers
    package = replace(package, options=replace(package.options, seed=zlib.crc32(cases[0].name.encode())))
    record = derive(package.grammar, lots_read, package.options)
    one_by_one = derive(package.grammar, lots_read, replace(package.options, chunk_size=1))
    random = _random_lots(package, lots_read, record, len(cases))
    drawn_defaults = _drawn_defaults(package.grammar.module)
    bad = {b.index: b.reason for b in record["bad"]}
    reports = record["reports"]
    results = []
    for lot, case in enumerate(cases):
        theirs = prt.get(case.name, {"error": "no PRT record"})
        result = {"name": case.name, "package": case.package, "kind": case.kind, "seed": case.seed,
                  "attrs": case.attrs, "failed": [], "detail": ""}
        failed, details = set(), []
        ours = lot_record(record, lot)
        if not same_lot_records(ours, lot_record(one_by_one, lot)):
            failed.add("chunking")
        if "error" in theirs:  # not grammarc's to match; a lot both refuse is no mismatch
            result["prt_error"] = theirs["error"]
        elif lot in bad:
            failed.add("skipped")
            details.append(bad[lot])
        elif random[lot] and not drawn_defaults <= set(case.attrs):
            result["random"] = True
            _random_figures(package, case, ours, theirs, result)
        else:
            _judge_geometry(package, case, ours, theirs, result, failed, details)
            same, differences = compare_reports(reports.table(reports.lots.get(lot, {})), theirs.get("report") or {})
            if not same:
                failed.add("reports")
                details.append("; ".join(differences[:3]))
        result["failed"] = [check for check in CHECKS if check in failed]
        result["detail"] = " | ".join(details)
        results.append(result)
    return results


def _drawn_defaults(module) -> set[str]:
    """The attributes whose defaults draw random numbers: grammarc draws other numbers there than PRT,
    whose attribute streams start at a hash of the name that is not identified (``backend.prt_random``)."""
    from grammarc.backend.streams import draws

    return {a.name for a in module.attrs if draws(a.default)}


def _random_lots(package: Package, lots, record: dict, n: int) -> np.ndarray:
    """(n,) bool: the lots whose geometry changes with the seed (candler draws its texture tiles at random,
    which the compared figures do not show: its lots are judged on their geometry), both the build's and
    the lots' own (CityEngine's rules draw from the latter). One other seed tells a package that draws no
    random number; where one does, six more catch the lots that drew the same choices every time (a lot
    that takes a 30 % case's empty branch for seven seeds: one in 4,500)."""
    from dataclasses import replace

    from grammarc.build import derive

    random = np.zeros(n, bool)
    for step in range(1, 8):
        # far apart: PRT's streams of near seeds start a few steps apart and draw almost the same numbers
        moved = lots if "seed" not in lots.attrs else replace(
            lots, attrs={**lots.attrs, "seed": lots.attrs["seed"] + step * 100_003})
        other = derive(package.grammar, moved, replace(package.options, seed=package.options.seed + step))
        random |= [not same_lot_records(lot_record(record, lot), lot_record(other, lot), geometry_only=True)
                   for lot in range(n)]
        if not random.any():
            break
    return random


def _random_figures(package: Package, case: Case, ours: dict, theirs: dict, result: dict) -> None:
    """A random lot's figures, for the distributions: its height and its surface over its footprint's area
    (so that lots of different sizes compare), grammarc's and PRT's."""
    from grammarc.io.bake import bake

    measured = measure(bake(ours, package.options.asset_roots))
    for who, figures in (("ours", measured), ("prt", theirs)):
        low, high = figures.get("bbox_min"), figures.get("bbox_max")
        height = high[1] - low[1] if low is not None and math.isfinite(low[1]) else 0.0
        result[f"{who}_height"] = height
        result[f"{who}_surface_ratio"] = figures.get("surface_area", 0.0) / case.polygon.area


def _judge_geometry(package: Package, case: Case, ours: dict, theirs: dict, result: dict, failed: set,
                    details: list) -> None:
    """Bounding box, area and surface distance of one lot against PRT's record of it."""
    from grammarc.io.bake import bake

    mesh = bake(ours, package.options.asset_roots)
    measured = measure(mesh)
    if theirs.get("bbox_min") is None or not len(mesh.faces):  # no geometry from one of them, or both
        if theirs.get("bbox_min") is not None or len(mesh.faces):
            failed.add("bbox")
            details.append("no geometry from " + ("PRT" if theirs.get("bbox_min") is None else "grammarc"))
        return
    verdict = compare(measured, theirs, bbox_tol=BBOX_TOL, area_rel_tol=AREA_TOL)
    result.update(bbox=verdict.bbox_deviation, area_rel=verdict.area_rel_error, area=measured["surface_area"],
                  prt_area=theirs["surface_area"], faces=[measured["n_faces"], theirs.get("n_faces")])
    if not (verdict.bbox_ok and verdict.area_ok):
        failed.update(name for name, ok in (("bbox", verdict.bbox_ok), ("area", verdict.area_ok)) if not ok)
        details.append(verdict.summary)
    if mesh.area > 0 and len(theirs["triangles"]):
        result["distance"] = surface_distance(mesh, _triangles_mesh(theirs["triangles"]), n=DISTANCE_SAMPLES,
                                              seed=case.seed)


def save_case(folder: Path, case: Case, result: dict, prt_record: dict) -> Path:
    """Write a mismatch as a case file: the lot alone, at its own coordinates, and both engines' figures."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{case.name}.geojson"
    write_lots(path, [case])
    with open(path, encoding="utf-8") as file:
        collection = json.load(file)
    prt_figures = {k: v for k, v in prt_record.items() if k != "triangles"}
    collection["grammarc_conform"] = {"package": case.package, "kind": case.kind, "seed": case.seed,
                                      "result": result, "prt": prt_figures}
    with open(path, "w", encoding="utf-8") as file:
        json.dump(collection, file, indent=1, default=float)
    return path


# ----------------------------------------------------------------------------------------------- runs


def fuzz(n: int, out: Path, *, packages: Iterable[str] = PACKAGES, kinds: Iterable[str] = tuple(CLASSES),
         seed: int = 0, batch: int = 64, footprints: Path | None = None, progress=print) -> list[dict]:
    """Run ``n`` cases per package, classes in turn, seeds from ``seed`` (or the first ``n`` lots of the
    file ``footprints``, from the ``seed``-th on); results appended to ``out/results.jsonl``, mismatches
    saved under ``out/cases``. Returns this run's results."""
    python, kit = prt_python(), kit_dir()
    if python is None or not kit.is_dir():
        raise UsageError("the differential harness needs the PRT kit (../shared/prt, or GRAMMARC_PRT_KIT) "
                         "and PyPRT's side environment (.prt-venv, or GRAMMARC_PRT_PYTHON): see the kit's README")
    kinds = list(kinds)
    unknown = sorted(set(kinds) - set(CLASSES))
    if unknown:
        raise UsageError(f"unknown footprint class {', '.join(unknown)} (classes: {', '.join(CLASSES)})")
    out.mkdir(parents=True, exist_ok=True)
    results: list[dict] = []
    with open_packages(packages, kit) as compiled, tempfile.TemporaryDirectory(prefix="grammarc-fuzz-") as tmp, \
            ThreadPoolExecutor(1) as prt_pool, open(out / "results.jsonl", "a", encoding="utf-8") as log:
        jobs = []
        for package in compiled.values():
            if footprints is not None:
                given = cases_from_file(package.name, package.grammar.module, footprints)[seed:seed + n]
            else:
                given = [make_case(package.name, package.grammar.module, kinds[k % len(kinds)], seed + k)
                         for k in range(n)]
            for start in range(0, len(given), batch):
                cases = given[start:start + batch]
                lots = Path(tmp) / f"{package.name}-{start}.geojson"
                write_lots(lots, cases, SPACING)
                jobs.append((package, cases, lots))
        # PRT runs one batch ahead, in its own process, while grammarc derives and judges the one before.
        processes = Processes()
        prt_batch = functools.partial(run_prt, python, kit, folder=Path(tmp), processes=processes)
        pending = [prt_pool.submit(prt_batch, p.rpk, lots) for p, _, lots in jobs[:1]]
        begun = time.perf_counter()
        try:
            for i, (package, cases, lots) in enumerate(jobs):
                if i + 1 < len(jobs):
                    pending.append(prt_pool.submit(prt_batch, jobs[i + 1][0].rpk, jobs[i + 1][2]))
                prt = pending[i].result()
                for case, result in zip(cases, judge_batch(package, cases, lots, prt)):
                    if result["failed"]:
                        result["case_file"] = str(save_case(out / "cases", case, result,
                                                            prt.get(case.name, {})))
                    log.write(json.dumps(result, default=float) + "\n")
                    results.append(result)
                log.flush()
                matched = sum(not r["failed"] for r in results)
                progress(f"{package.name}: {len(results)} cases, {matched} match "
                         f"({time.perf_counter() - begun:.0f} s)")
        except BaseException:  # a stop, or a failure: PRT's process goes with the harness
            processes.stop()
            raise
    return results


def rerun_case(path: Path) -> dict:
    """Run a saved case file again, on both engines; returns the new result.

    The lot and its attributes are read from the file, not regenerated from its class and seed, so that a
    case stays what it was when the footprint classes change."""
    from shapely.geometry import shape

    with open(path, encoding="utf-8") as file:
        collection = json.load(file)
    saved, (feature,) = collection["grammarc_conform"], collection["features"]
    attrs = {k: v for k, v in feature["properties"].items() if k not in ("name", "seed")}
    python, kit = prt_python(), kit_dir()
    if python is None:
        raise UsageError("--case needs PyPRT's side environment (.prt-venv, or GRAMMARC_PRT_PYTHON)")
    with open_packages([saved["package"]], kit) as compiled, \
            tempfile.TemporaryDirectory(prefix="grammarc-case-") as tmp:
        package = compiled[saved["package"]]
        case = Case(package.name, saved["kind"], saved["seed"], attrs, shape(feature["geometry"]))
        lots = Path(tmp) / "case.geojson"
        write_lots(lots, [case])
        prt = run_prt(python, kit, package.rpk, lots, Path(tmp))
        return judge_batch(package, [case], lots, prt)[0]


def read_results(folder: Path) -> list[dict]:
    """The results of every run into ``folder`` (the last result of a case wins)."""
    latest = {}
    with open(folder / "results.jsonl", encoding="utf-8") as file:
        for line in file:
            result = json.loads(line)
            latest[result["name"]] = result
    return list(latest.values())


def table(results: list[dict]) -> str:
    """Markdown: per package and footprint class, the cases, the share that match, each check's failures,
    the random lots (judged on skipping and chunking only, see ``judge_batch``) and the median surface
    distance."""
    groups = defaultdict(list)
    for r in results:
        groups[(r["package"], r["kind"])].append(r)
    order = {k: i for i, k in enumerate(CLASSES)}
    lines = ["| package | footprints | cases | match | " + " | ".join(CHECKS) + " | random | median distance (m) |",
             "|---|---|---:|---:|" + "---:|" * len(CHECKS) + "---:|---:|"]
    totals = defaultdict(list)
    for (package, kind) in sorted(groups, key=lambda g: (_package_order(g[0]), order.get(g[1], 99))):
        rows = groups[(package, kind)]
        totals[package] += rows
        lines.append(_row(package, kind, rows))
    for package, rows in totals.items():
        lines.append(_row(f"**{package}**", "all", rows))
    return "\n".join(lines)


def distributions(results: list[dict]) -> str:
    """Markdown: per package, its random lots' heights and surface ratios, grammarc's against PRT's, with
    the two-sample Kolmogorov-Smirnov test's p-value (a small one: the distributions differ); "" when no
    lot is random."""
    from scipy.stats import ks_2samp

    if not any(r.get("random") for r in results):
        return ""
    lines = ["| package | random lots | height: median ours / PRT | p | surface / footprint: median ours / PRT | p |",
             "|---|---:|---|---:|---|---:|"]
    for package in sorted({r["package"] for r in results if r.get("random")}, key=_package_order):
        rows = [r for r in results if r.get("random") and r["package"] == package]
        cells = []
        for figure in ("height", "surface_ratio"):
            ours, theirs = [r[f"ours_{figure}"] for r in rows], [r[f"prt_{figure}"] for r in rows]
            cells.append(f"{np.median(ours):.3g} / {np.median(theirs):.3g} | {ks_2samp(ours, theirs).pvalue:.2g}")
        lines.append(f"| {package} | {len(rows)} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _package_order(package: str) -> int:
    return PACKAGES.index(package) if package in PACKAGES else len(PACKAGES)


def _row(package: str, kind: str, rows: list[dict]) -> str:
    match = sum(not r["failed"] for r in rows)
    counts = [sum(check in r["failed"] for r in rows) for check in CHECKS]
    distances = [r["distance"] for r in rows if "distance" in r and math.isfinite(r["distance"])]
    distance = f"{np.median(distances):.3g}" if distances else "-"
    random = sum(bool(r.get("random")) for r in rows)
    return (f"| {package} | {kind} | {len(rows)} | {100 * match / len(rows):.1f} % | "
            + " | ".join(str(c) if c else "" for c in counts) + f" | {random or ''} | {distance} |")
