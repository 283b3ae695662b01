"""The Pompeii example (examples/pompeii): a Roman town in the paper's notation and the speed benchmark.

It must stay what the benchmark measures: a grammar that checks clean, derives every lot of its town,
makes 50 or more terminals per building from its own ~36 assets (all of them used), and gives the same
bytes every time. Its records keep a digest, as the example city's do (tests/test_examples.py); a change
that alters them says why and updates the digest with:

    python tests/test_pompeii.py    # prints the digest; copy it to examples/pompeii/records.sha256

The whole town (2,505 lots) derives in about a second, so the tests build it whole, once per module.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import example_script
from test_examples import record_digest

from grammarc.build import build
from grammarc.cli import main

ROOT = Path(__file__).resolve().parents[1]
POMPEII = ROOT / "examples" / "pompeii"
GRAMMAR = POMPEII / "pompeii.cga"
#: Lot kinds that are not buildings: they count as lots, not in the terminals per building.
NOT_BUILDINGS = ("street", "crossing", "wall", "tower")


def _script(name: str):
    return example_script(POMPEII, name)


@pytest.fixture(scope="module")
def town(tmp_path_factory):
    """The example built whole: the build result, the record's path and its per-lot columns."""
    out = tmp_path_factory.mktemp("pompeii") / "pompeii.npz"
    result = build(GRAMMAR, out)
    with np.load(out) as record:
        columns = {key: record[key] for key in ("assets", "asset", "lot")}
    features = json.loads((POMPEII / "lots.geojson").read_text())["features"]
    kinds = np.array([f["properties"]["kind"] for f in features])
    per_lot = np.bincount(columns["lot"], minlength=len(kinds))
    return result, out, columns, kinds, per_lot


def test_check_reports_no_warnings_and_over_100_rules(capsys):
    assert main(["check", str(GRAMMAR)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    assert int(re.search(r"rules:\s+(\d+)", out).group(1)) >= 100


def test_every_lot_is_derived(town):
    result, _, _, kinds, _ = town
    assert result.bad == ()
    assert result.derived == len(kinds) > 2000


def test_every_kind_makes_terminals(town):
    _, _, _, kinds, per_lot = town
    assert set(kinds) >= {"domus", "taberna", "casa", "garden", "temple", "forum", "basilica", "baths",
                          "macellum", "street", "crossing", "wall", "tower"}
    for kind in sorted(set(kinds)):
        least = per_lot[kinds == kind].min()
        assert least >= (1 if kind in NOT_BUILDINGS else 20), f"a {kind} lot makes {least} terminals"


def test_buildings_make_50_or_more_terminals_on_average(town):
    _, _, _, kinds, per_lot = town
    buildings = ~np.isin(kinds, NOT_BUILDINGS)
    assert per_lot[buildings].mean() >= 50


def test_about_36_small_assets_all_used_and_made_by_the_script(town):
    _, _, columns, _, _ = town
    files = sorted(p.name for p in (POMPEII / "assets").glob("*.obj"))
    assert 30 <= len(files) <= 40
    used = set(columns["assets"][np.unique(columns["asset"])].tolist())
    assert {f"assets/{name}" for name in files} <= used
    made = _script("make_assets").obj_files()
    assert sorted(made) == files
    for name, (text, triangles) in made.items():
        assert (POMPEII / "assets" / name).read_text() == text, f"{name} differs from make_assets.py's"
        assert 8 <= triangles <= 400


def test_lots_are_made_by_the_script_and_tile_with_unique_ids():
    make_lots = _script("make_lots")
    assert make_lots.lots() == json.loads((POMPEII / "lots.geojson").read_text())
    one, three = len(make_lots.lots()["features"]), make_lots.lots(scale=3)["features"]
    ids = [f["id"] for f in three]
    assert len(ids) == 3 * one == len(set(ids))


def test_the_build_is_deterministic(town, tmp_path):
    _, first, _, _, _ = town
    build(GRAMMAR, tmp_path / "again.npz")
    assert (tmp_path / "again.npz").read_bytes() == first.read_bytes()


def test_records_are_unchanged(town):
    _, out, _, _, _ = town
    assert record_digest(out) == (POMPEII / "records.sha256").read_text().split()[0]


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        build(GRAMMAR, Path(folder) / "pompeii.npz")
        sys.stdout.write(record_digest(Path(folder) / "pompeii.npz") + "\n")
