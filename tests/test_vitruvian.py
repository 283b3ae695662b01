"""The Vitruvian example (examples/vitruvian): Noghani's Vitruvian town (MPhil thesis, 2015) as a grammar.

The tests measure the thesis's numbers on what the grammar makes, from the instance transforms (column j
of ``xform`` is scope axis j times size j, column 3 the origin): the temple's podium 1:2, its columns'
diameter one seventh of their height, the top diameter three quarters of the foot, the eustyle
intercolumniation of 2.25 diameters, an odd number of steps twice as deep as high; the forum 2:3; the
theatre's 240-degree cavea and its stage; the amphitheatre's ovals 1.2:1 and 1.5:1; the villa's
triclinium 2:1 and peristyle 4:3; the towers a bowshot (182 m) apart. Its records keep a digest, as the
other examples do; a change that alters them says why and updates it with:

    python tests/test_vitruvian.py    # prints the digest; copy it to examples/vitruvian/records.sha256

The town (799 lots) derives in about a second, so the tests build it whole, once per module.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import example_script, in_world
from test_examples import record_digest

from grammarc.build import build
from grammarc.cli import main
from grammarc.io.npz import read_instances

ROOT = Path(__file__).resolve().parents[1]
VITRUVIAN = ROOT / "examples" / "vitruvian"
GRAMMAR = VITRUVIAN / "vitruvian.cga"


def _script(name: str):
    return example_script(VITRUVIAN, name)


@pytest.fixture(scope="module")
def town(tmp_path_factory):
    """The example built whole: the build result, the record's path, its instances and the lots."""
    out = tmp_path_factory.mktemp("vitruvian") / "vitruvian.npz"
    result = build(GRAMMAR, out)
    record = in_world(read_instances(out))
    mesh_lot = record["mesh_lot"]
    features = json.loads((VITRUVIAN / "lots.geojson").read_text())["features"]
    return result, out, record, mesh_lot, features


def _parts(record, features, lot_id: str, symbol: str) -> np.ndarray:
    """The (n, 3, 4) transforms of one lot's terminals of ``symbol``."""
    lot = [f["id"] for f in features].index(lot_id)
    code = list(record["symbols"]).index(symbol)
    return np.asarray(record["xform"], dtype=np.float64)[(record["lot"] == lot) & (record["symbol"] == code)]


def _sizes(xform: np.ndarray) -> np.ndarray:
    """(n, 3) scope sizes: the lengths of the transforms' first three columns."""
    return np.linalg.norm(xform[:, :, :3], axis=1)


def _frame(xform: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The unit x and z axes of the first transform (a temple's parts share its frame)."""
    return xform[0, :, 0] / np.linalg.norm(xform[0, :, 0]), xform[0, :, 2] / np.linalg.norm(xform[0, :, 2])


def _temples(features) -> list[dict]:
    return [f for f in features if f["properties"]["kind"] == "temple"]


def _on_podium(record, features, temple: dict) -> np.ndarray:
    """The shafts of a temple's own columns: those standing on its podium (its precinct's porticoes
    stand on the ground)."""
    shafts = _parts(record, features, temple["id"], "col_shaft")
    return shafts[shafts[:, 1, 3] > temple["properties"]["podium_h"]]


def _axes(xform: np.ndarray) -> np.ndarray:
    """(n, 2) the horizontal centres (x, z) of boxes: a column's parts share their axis."""
    return xform[:, [0, 2], 3] + 0.5 * (xform[:, [0, 2], 0] + xform[:, [0, 2], 2])


def _matching(parts: np.ndarray, shafts: np.ndarray) -> np.ndarray:
    """The part of each shaft's column among ``parts``: the one on the shaft's axis."""
    return parts[np.argmin(np.linalg.norm(_axes(shafts)[:, None] - _axes(parts)[None], axis=2), axis=1)]


def test_check_reports_no_warnings(capsys):
    assert main(["check", str(GRAMMAR)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    assert "rules:" in out


def test_every_lot_is_derived_and_makes_something(town):
    result, _, record, mesh_lot, features = town
    assert result.bad == ()
    assert result.derived == len(features) > 700
    made = np.bincount(record["lot"], minlength=len(features)) + np.bincount(mesh_lot, minlength=len(features))
    kinds = np.array([f["properties"]["kind"] for f in features])
    assert set(kinds) >= {"temple", "forum", "theatre", "amphitheatre", "basilica", "government", "villa",
                          "house", "shop", "garden", "street", "crossing", "wall", "tower", "gate"}
    assert made.min() > 0, f"lots without terminals: {sorted(set(kinds[made == 0]))}"


def test_temple_podium_is_twice_as_long_as_wide(town):
    _, _, record, _, features = town
    for temple in _temples(features):
        body = _parts(record, features, temple["id"], "podium_body")
        ux, uz = _frame(body)
        corners = np.concatenate([body[:, :, 3] + a * body[:, :, 0] + c * body[:, :, 2]
                                  for a in (0, 1) for c in (0, 1)])
        width, length = np.ptp(corners @ ux), np.ptp(corners @ uz)
        assert width == pytest.approx(temple["properties"]["temple_w"], rel=1e-4)
        assert length / width == pytest.approx(2.0, rel=1e-4), temple["id"]


def test_temple_columns_are_ionic_one_to_seven_tapering_to_three_quarters(town):
    _, _, record, _, features = town
    for temple in _temples(features):
        shafts = _on_podium(record, features, temple)
        base, neck, capital = (_matching(_parts(record, features, temple["id"], s), shafts)
                               for s in ("col_base", "col_neck", "col_capital"))
        d = _sizes(shafts)[:, 0]
        n = int(temple["properties"]["columns"])
        assert len(shafts) >= n and np.ptp(d) < 1e-4 * d[0]
        assert _sizes(neck)[:, 0] / d == pytest.approx(np.full(len(d), 0.75), rel=1e-4)
        # each column from the foot of its base to the top of its capital
        height = capital[:, 1, 3] + capital[:, 1, 1] - base[:, 1, 3]
        assert height / d == pytest.approx(np.full(len(d), 7.0), rel=1e-4), temple["id"]


def test_the_shaft_asset_tapers_to_three_quarters():
    lines = (VITRUVIAN / "assets" / "ionic_shaft.obj").read_text().splitlines()
    v = np.array([[float(t) for t in line.split()[1:]] for line in lines if line.startswith("v ")])
    foot, top = v[v[:, 1] == 0.0], v[v[:, 1] == 1.0]
    assert np.ptp(top[:, 0]) / np.ptp(foot[:, 0]) == pytest.approx(0.75, abs=2e-4)


def test_temple_fronts_stand_eustyle_with_their_number_of_columns(town):
    _, _, record, _, features = town
    for temple in _temples(features):
        shafts = _on_podium(record, features, temple)
        ux, uz = _frame(shafts)
        d = _sizes(shafts)[0, 0]
        along, depth = shafts[:, :, 3] @ ux, shafts[:, :, 3] @ uz
        # ranks: shafts at one depth (float32 world coordinates: a rank's depths agree to ~1e-4 m)
        order = np.argsort(depth)
        ranks = [np.sort(along[r]) for r in np.split(order, np.flatnonzero(np.diff(depth[order]) > 0.1 * d) + 1)]
        fronts = [r for r in ranks if len(r) > 2]
        n = int(temple["properties"]["columns"])
        assert 1 <= len(fronts) <= 2 and all(len(r) == n for r in fronts), temple["id"]
        for r in fronts:
            assert (np.diff(r) - d) / d == pytest.approx(np.full(n - 1, 2.25), rel=1e-3)


def test_temple_steps_are_odd_and_twice_as_deep_as_high(town):
    _, _, record, _, features = town
    for temple in _temples(features):
        steps = _sizes(_parts(record, features, temple["id"], "step"))
        assert len(steps) % 2 == 1
        assert steps[:, 2] / steps[:, 1] == pytest.approx(np.full(len(steps), 2.0), rel=1e-4)
        assert steps[:, 1].sum() == pytest.approx(temple["properties"]["podium_h"], rel=1e-4)


def test_forum_is_two_thirds_as_wide_as_long(town):
    _, _, record, _, features = town
    paving = _parts(record, features, "forum", "forum_paving")
    ux, uz = _frame(paving)
    corners = np.concatenate([paving[:, :, 3], paving[:, :, 3] + paving[:, :, 0] + paving[:, :, 2]])
    assert np.ptp(corners @ uz) / np.ptp(corners @ ux) == pytest.approx(2 / 3, rel=1e-4)


def test_theatre_cavea_spans_240_degrees_and_its_stage_follows_the_orchestra(town):
    _, _, record, _, features = town
    seats = _parts(record, features, "theatre", "seat")
    orchestra = _parts(record, features, "theatre", "orchestra")
    centre = orchestra[0, :, 3] + 0.5 * (orchestra[0, :, 0] + orchestra[0, :, 2])
    # a seat row's inner corners (its origin and origin + x) lie on the wedge's sides
    corners = np.concatenate([seats[:, :, 3], seats[:, :, 3] + seats[:, :, 0]]) - centre
    middle = (seats[:, :, 3] - centre).mean(axis=0)
    angle = np.degrees(np.arctan2(corners[:, 0], corners[:, 2]) - np.arctan2(middle[0], middle[2]))
    angle = (angle + 180) % 360 - 180
    assert np.ptp(angle) == pytest.approx(240.0, abs=0.01)
    diameter = _sizes(orchestra)[0, 0]
    stage = _sizes(_parts(record, features, "theatre", "pulpitum"))[0]
    assert stage[0] == pytest.approx(2 * diameter, rel=1e-4)        # the scene: twice the orchestra
    assert stage[1] == pytest.approx(diameter / 12, rel=1e-4)       # its podium: a twelfth of it


def test_amphitheatre_ovals(town):
    _, _, record, _, features = town
    for symbol, ratio in (("amphi_ground", 1.2), ("arena", 1.5)):
        size = _sizes(_parts(record, features, "amphitheatre", symbol))[0]
        assert size[0] / size[2] == pytest.approx(ratio, rel=1e-4)


def test_villa_rooms_keep_vitruvius_proportions(town):
    _, _, record, _, features = town
    villa = next(f["id"] for f in features if f["properties"]["kind"] == "villa")
    triclinium = _sizes(_parts(record, features, villa, "triclinium_room"))[0]
    peristyle = _sizes(_parts(record, features, villa, "peristyle_garden"))[0]
    assert triclinium[0] / triclinium[2] == pytest.approx(2.0, rel=1e-4)
    assert peristyle[0] / peristyle[2] == pytest.approx(4 / 3, rel=1e-4)


def test_towers_stand_a_bowshot_apart(town):
    record = town[2]
    code = list(record["symbols"]).index("tower_body")
    towers = np.asarray(record["xform"], dtype=np.float64)[record["symbol"] == code]
    centres = (towers[:, :, 3] + 0.5 * (towers[:, :, 0] + towers[:, :, 2]))[:, [0, 2]]
    assert len(centres) == 15
    around = centres - centres.mean(axis=0)
    ring = centres[np.argsort(np.arctan2(around[:, 1], around[:, 0]))]
    spacing = np.linalg.norm(ring - np.roll(ring, 1, axis=0), axis=1)
    # corner towers stand out along the corner's bisector, so their neighbours are up to 1% further
    assert spacing == pytest.approx(np.full(15, 182.0), rel=0.012)


def test_lots_and_assets_are_made_by_the_scripts():
    town = _script("make_town").lots()
    assert json.loads(json.dumps(town)) == json.loads((VITRUVIAN / "lots.geojson").read_text())
    made = _script("make_assets").obj_files()
    assert sorted(made) == sorted(p.name for p in (VITRUVIAN / "assets").glob("*.obj"))
    for name, (text, triangles) in made.items():
        assert (VITRUVIAN / "assets" / name).read_text() == text, f"{name} differs from make_assets.py's"
        assert triangles <= 400


def test_the_build_is_deterministic_and_its_records_unchanged(town, tmp_path):
    _, first, _, _, _ = town
    build(GRAMMAR, tmp_path / "again.npz")
    assert (tmp_path / "again.npz").read_bytes() == first.read_bytes()
    assert record_digest(first) == (VITRUVIAN / "records.sha256").read_text().split()[0]


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        build(GRAMMAR, Path(folder) / "vitruvian.npz")
        sys.stdout.write(record_digest(Path(folder) / "vitruvian.npz") + "\n")
