"""The differential harness: lot records, judging a batch against PRT's figures, the table, and (with
PyPRT's side environment) a live run."""

import json
from dataclasses import replace

import numpy as np
import pytest
from conftest import PRT_KIT as KIT
from conftest import needs_kit

from grammarc.build import derive
from grammarc.conform import measure, prt_python
from grammarc.conform.cases import make_case, write_lots
from grammarc.conform.fuzz import (
    distributions,
    fuzz,
    judge_batch,
    lot_record,
    open_packages,
    read_results,
    same_lot_records,
    table,
)
from grammarc.io.bake import bake
from grammarc.io.lots import read_lots

needs_prt = pytest.mark.skipif(prt_python() is None or not KIT.is_dir(),
                               reason="PyPRT's side environment (.prt-venv or GRAMMARC_PRT_PYTHON) absent")


@pytest.fixture(scope="module")
def massing():
    with open_packages(["massing"], KIT) as packages:
        yield packages["massing"]


def _batch(package, tmp_path, kinds=("convex", "courtyard", "L")):
    cases = [make_case(package.name, package.grammar.module, kind, seed) for seed, kind in enumerate(kinds)]
    lots = tmp_path / "lots.geojson"
    write_lots(lots, cases, 2000)
    return cases, lots


def _as_prt(package, lots):
    """PRT's figures as grammarc itself measures its lots: what a perfect match looks like."""
    record = derive(package.grammar, read_lots(lots), package.options)
    out = {}
    for lot, feature in enumerate(json.loads(lots.read_text())["features"]):
        mesh = bake(lot_record(record, lot), package.options.asset_roots)
        figures = measure(mesh)
        figures["triangles"] = np.asarray(mesh.triangles)
        figures["report"] = record["reports"].table(record["reports"].lots.get(lot, {}))
        out[feature["properties"]["name"]] = figures
    return out


@needs_kit
def test_lot_records_split_a_record_by_lot_and_do_not_depend_on_chunking(massing, tmp_path):
    _, lots = _batch(massing, tmp_path)
    whole = derive(massing.grammar, read_lots(lots), massing.options)
    single = derive(massing.grammar, read_lots(lots), replace(massing.options, chunk_size=1))
    parts = [lot_record(whole, lot) for lot in range(3)]
    assert sum(len(p["asset"]) for p in parts) == len(whole["asset"])
    assert sum(len(p["mesh"].lot) for p in parts) == len(whole["mesh"].lot)
    assert all((p["lot"] == lot).all() and (p["mesh"].lot == lot).all() for lot, p in enumerate(parts))
    assert all(same_lot_records(p, lot_record(single, lot)) for lot, p in enumerate(parts))
    assert not same_lot_records(parts[0], parts[1])
    recoloured = dict(parts[0], mesh=replace(parts[0]["mesh"], color=parts[0]["mesh"].colors() // 2))
    assert not same_lot_records(parts[0], recoloured)
    assert same_lot_records(parts[0], recoloured, geometry_only=True)


@needs_kit
def test_judging_a_batch_names_each_failed_check(massing, tmp_path):
    cases, lots = _batch(massing, tmp_path)
    prt = _as_prt(massing, lots)
    results = judge_batch(massing, cases, lots, prt)
    assert [r["failed"] for r in results] == [[], [], []] and not any(r.get("random") for r in results)
    assert all(r["distance"] < 1e-3 and r["area_rel"] < 1e-9 for r in results)

    names = [c.name for c in cases]
    prt[names[0]] = dict(prt[names[0]], surface_area=prt[names[0]]["surface_area"] * 1.02)
    prt[names[1]] = dict(prt[names[1]], bbox_max=[x + 0.05 for x in prt[names[1]]["bbox_max"]],
                         report={"extra_n": 1.0})
    prt[names[2]] = {"error": "PRT generated no model"}
    first, second, third = judge_batch(massing, cases, lots, prt)
    assert first["failed"] == ["area"] and "area" in first["detail"]
    assert second["failed"] == ["bbox", "reports"] and "extra_n" in second["detail"]
    assert third["failed"] == [] and third["prt_error"] == "PRT generated no model"


@needs_kit
def test_random_lots_are_compared_where_grammarc_draws_prts_numbers(tmp_path):
    """extrusion_rule extrudes by ``rand(min, max)`` in a rule: grammarc draws PRT's number from the lot's
    seed (``backend.streams``), so its random lots are compared value for value, and a height PRT did not
    draw is a mismatch."""
    with open_packages(["extrusion_rule"], KIT) as packages:
        package = packages["extrusion_rule"]
        cases, lots = _batch(package, tmp_path)
        prt = _as_prt(package, lots)
        assert all(r["failed"] == [] and not r.get("random") for r in judge_batch(package, cases, lots, prt))
        for name in prt:  # PRT drew other heights
            prt[name]["bbox_max"] = [prt[name]["bbox_max"][0], 99.0, prt[name]["bbox_max"][2]]
        results = judge_batch(package, cases, lots, prt)
    assert all(r["failed"] == ["bbox"] and not r.get("random") for r in results)


@needs_kit
def test_lots_whose_attribute_defaults_draw_are_kept_for_the_distributions(tmp_path):
    """reporting's attribute defaults draw (``floorHeight = rand(4, 5)``) from streams grammarc does not
    match: its random lots are judged on what does not depend on the draws, and their figures (height,
    surface over footprint) are kept for the distributions, not compared with PRT's value for value."""
    with open_packages(["reporting"], KIT) as packages:
        package = packages["reporting"]
        cases, lots = _batch(package, tmp_path, kinds=("convex", "L", "T", "U", "Z", "H"))
        prt = _as_prt(package, lots)
        for name in prt:  # PRT drew other heights
            prt[name]["bbox_max"] = [prt[name]["bbox_max"][0], 99.0, prt[name]["bbox_max"][2]]
        results = judge_batch(package, cases, lots, prt)
    random = [r for r in results if r.get("random")]
    assert random and all(r["failed"] == [] and r["prt_height"] == 99 for r in random)
    assert all(0 <= r["ours_height"] <= 75 and r["ours_surface_ratio"] > 0.9 for r in random)


def test_table_counts_matches_and_failures_per_package_and_class():
    results = [
        {"package": "massing", "kind": "L", "failed": [], "distance": 0.001},
        {"package": "massing", "kind": "L", "failed": ["area"], "distance": 0.5},
        {"package": "massing", "kind": "convex", "failed": ["skipped"]},
        {"package": "candler", "kind": "L", "failed": ["bbox", "chunking"], "distance": 0.1},
        {"package": "candler", "kind": "L", "failed": [], "random": True},
    ]
    lines = table(results).splitlines()
    assert lines[0].startswith("| package | footprints | cases | match | skipped | bbox | area | reports | chunking"
                               " | random |")
    assert lines[2] == "| candler | L | 2 | 50.0 % |  | 1 |  |  | 1 | 1 | 0.1 |"
    assert lines[3] == "| massing | convex | 1 | 0.0 % | 1 |  |  |  |  |  | - |"  # classes in their order
    assert lines[4] == "| massing | L | 2 | 50.0 % |  |  | 1 |  |  |  | 0.251 |"
    assert "| **massing** | all | 3 | 33.3 % |" in lines[-1]


def test_distributions_of_random_lots():
    rng = np.random.default_rng(0)
    same = [{"package": "reporting", "random": True, "ours_height": a, "prt_height": b, "ours_surface_ratio": 1.0,
             "prt_surface_ratio": 1.0} for a, b in rng.uniform(10, 30, (200, 2))]
    shifted = [dict(r, package="extrusion_rule", prt_height=r["prt_height"] + 5) for r in same]
    lines = distributions(same + shifted).splitlines()
    assert lines[2].startswith("| extrusion_rule | 200 |") and lines[3].startswith("| reporting | 200 |")
    p_shifted, p_same = (float(line.split("|")[4]) for line in lines[2:4])
    assert p_shifted < 1e-6 and p_same > 0.01


@needs_prt
def test_a_live_run_against_prt(tmp_path):
    results = fuzz(4, tmp_path, packages=["extrude_color"], kinds=["convex", "courtyard"], batch=2,
                   progress=lambda line: None)
    assert len(results) == 4 and all(not r["failed"] for r in results), results
    assert [r["name"] for r in read_results(tmp_path)] == [r["name"] for r in results]


@needs_kit
def test_a_far_lot_changes_nothing_of_another_lot_in_its_chunk(tmp_path):
    """The harness's first candler run found records that differed with the chunking: tolerances scaled
    by the largest coordinate of a whole batch (trim planes' corner matching, ridge cuts) let a lot at
    national-grid coordinates coarsen those of a small lot derived in the same chunk (its pipes)."""
    with open_packages(["candler"], KIT) as packages:
        candler = packages["candler"]
        cases = [make_case("candler", candler.grammar.module, kind, seed) for kind, seed in (("tiny", 9), ("far", 13))]
        write_lots(tmp_path / "lots.geojson", cases, 2000)
        lots = read_lots(tmp_path / "lots.geojson")
        together = derive(candler.grammar, lots, candler.options)
        alone = derive(candler.grammar, lots.take(np.array([0])), candler.options)
        assert same_lot_records(lot_record(together, 0), lot_record(alone, 0))
