"""The CGA shape paper's own buildings (examples/cga2006): sections 4, 5, 6 and Fig. 6 of "Procedural
Modeling of Buildings" (Mueller et al. 2006), each a grammar with its own lots.

Each grammar checks clean and derives every lot; the tests then hold it to what its section says. Their
records keep digests in examples/cga2006/records.sha256; a change that alters them says why and updates
the file with:

    python tests/test_cga2006.py    # prints the digests; copy them to examples/cga2006/records.sha256
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import in_world
from test_examples import record_digest

from grammarc.build import build
from grammarc.cli import main
from grammarc.io.npz import read_instances

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cga2006"
GRAMMARS = ("simple_building", "office", "suburb", "petronas")


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """Every grammar built once: name -> (build result, record path, record)."""
    folder = tmp_path_factory.mktemp("cga2006")
    out = {}
    for name in GRAMMARS:
        path = folder / f"{name}.npz"
        out[name] = (build(EXAMPLE / f"{name}.cga", path), path, in_world(read_instances(path)))
    return out


def _names(record) -> np.ndarray:
    return record["symbols"][record["symbol"]]


def _features(name: str) -> list[dict]:
    return json.loads((EXAMPLE / f"{name}.geojson").read_text())["features"]


@pytest.mark.parametrize("name", GRAMMARS)
def test_each_grammar_checks_without_warnings(name, capsys):
    assert main(["check", str(EXAMPLE / f"{name}.cga")]) == 0
    _, err = capsys.readouterr()
    assert err == ""


@pytest.mark.parametrize("name", GRAMMARS)
def test_every_lot_is_derived(records, name):
    result, _, record = records[name]
    assert result.bad == ()
    assert result.derived == len(_features(name))
    assert np.bincount(record["lot"], minlength=result.derived).min() > 0


def test_lots_are_made_by_the_script():
    spec = importlib.util.spec_from_file_location("cga2006_make_lots", EXAMPLE / "make_lots.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for file, collection in module.collections().items():
        assert collection == json.loads((EXAMPLE / file).read_text()), file


def test_section4_facade_tiles_split_as_written(records):
    """Rule 5 repeats tiles of window_spacing (3 m, stretched); rule 6 puts a 1.2 m window in the middle
    of each, at 2/3 of the height the 1.4 m window leaves (Fig. 4's split of a facade)."""
    _, _, record = records["simple_building"]
    windows = record["xform"][_names(record) == "window"].astype(float)
    assert len(windows) > 50
    width = np.linalg.norm(windows[:, :, 0], axis=1)
    height = np.linalg.norm(windows[:, :, 1], axis=1)
    np.testing.assert_allclose(width, 1.2, atol=1e-4)
    np.testing.assert_allclose(height, 1.4, atol=1e-4)
    # the window's base: 2r of the (storey - 1.4) under it, so (h - 1.4) * 2/3 over a facade of h
    lot_height = np.array([f["properties"]["building_height"] for f in _features("simple_building")])
    lots = record["lot"][_names(record) == "window"]
    np.testing.assert_allclose(windows[:, 1, 3], (lot_height[lots] - 1.4) * 2 / 3, atol=1e-4)


def test_section4_no_window_against_a_neighbour_and_doors_face_a_street(records):
    _, _, record = records["simple_building"]
    names = _names(record)
    xform = record["xform"].astype(float)
    features = _features("simple_building")
    boxes = []
    for f in features:      # each mass: x and map-y extent, height (world z = -map y)
        ring = np.array(f["geometry"]["coordinates"][0])
        boxes.append((*ring.min(0), *ring.max(0), f["properties"]["building_height"]))
    # rule 7: no window's centre on a wall the neighbour's mass covers
    for lot, x in zip(record["lot"][names == "window"], xform[names == "window"]):
        centre = x[:, 3] + x[:, 0] / 2 + x[:, 1] / 2
        for other, (x0, y0, x1, y1, h) in enumerate(boxes):
            if other != lot:
                inside = (x0 - 1e-6 <= centre[0] <= x1 + 1e-6 and y0 - 1e-6 <= -centre[2] <= y1 + 1e-6
                          and centre[1] <= h)
                assert not inside, f"a window of lot {lot} on lot {other}'s mass"
    # rule 3: every door faces one of its lot's street edges (outward normal along the edge's)
    doors = xform[names == "door"]
    assert len(doors) == 16     # 12 fronts and the 4 corner lots' side streets
    for lot, x in zip(record["lot"][names == "door"], doors):
        normal = x[:, 2] / np.linalg.norm(x[:, 2])
        ring = np.array(features[lot]["geometry"]["coordinates"][0])
        streets = features[lot]["properties"]["streetWidth"]
        outward = []
        for (ax, ay), (bx, by), width in zip(ring[:-1], ring[1:], streets):
            if width > 0:       # counter-clockwise ring: outward is (dy, -dx) on the map, z = -y
                d = np.array([by - ay, 0.0, bx - ax])
                outward.append(d / np.linalg.norm(d))
        assert any(normal @ o > 0.99 for o in outward), f"a door of lot {lot} faces no street"


def test_section5_floors_of_all_solids_meet_at_common_levels(records):
    """Snapping (rules 8, 9): the tile walls that span a whole storey start at the storeys' levels; over
    all solids of a building those levels are the same, so no two differ by less than a metre (the
    2.5 m top floors, which each solid puts under its own top, are left out)."""
    _, _, record = records["office"]
    names = _names(record)
    xform = record["xform"].astype(float)
    walls = names == "wall"
    height = np.linalg.norm(xform[:, :, 1], axis=1)
    assert (names == "escapestairs").sum() > 0
    for lot in np.unique(record["lot"]):
        storey = walls & (record["lot"] == lot) & (height > 2.6)
        levels = np.unique(np.round(xform[storey, 1, 3], 3))
        assert len(levels) >= 6
        assert np.diff(levels).min() > 1.0, f"lot {lot}: floors at {levels}"


def _footprint(x: np.ndarray) -> tuple[float, float, float, float]:
    """The x-z bounding rectangle of an instance (xform (3, 4))."""
    corners = x[:, 3] + np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)]) @ x[:, :3].T
    return corners[:, 0].min(), corners[:, 2].min(), corners[:, 0].max(), corners[:, 2].max()


def _gap(a, b) -> float:
    dx = max(a[0] - b[2], b[0] - a[2], 0.0)
    dz = max(a[1] - b[3], b[1] - a[3], 0.0)
    return float(np.hypot(dx, dz))


def test_section6_no_slab_under_a_driveway_and_trees_keep_their_distance(records):
    _, _, record = records["suburb"]
    names = _names(record)
    xform = record["xform"].astype(float)
    lots = record["lot"]
    assert (names == "slab").sum() > 0 and (names == "driveway").sum() == len(_features("suburb"))
    assert 0 < (names == "treespot").sum()
    for lot in np.unique(lots):
        drive = [_footprint(x) for x in xform[(lots == lot) & (names == "driveway")]]
        for x in xform[(lots == lot) & (names == "slab")]:
            slab = _footprint(x)
            overlap = [min(slab[2], d[2]) - max(slab[0], d[0]) for d in drive]
            assert max(overlap) < 1e-6, f"lot {lot}: a slab under the driveway"
        house = [_footprint(x) for x in xform[(lots == lot) & np.isin(names, ["wall", "window", "door"])]]
        for x in xform[(lots == lot) & (names == "treespot")]:
            tree = _footprint(x)
            assert min(_gap(tree, h) for h in house) >= 4.0 - 1e-6, f"lot {lot}: a tree by the house"


def test_petronas_has_rotated_boxes_and_cylinders(records):
    _, _, record = records["petronas"]
    assets = record["assets"][record["asset"]]
    assert (assets == "builtin:cylinder16").sum() == 5 * 8 + 1
    walls = record["xform"][_names(record) == "wall"].astype(float)
    along = walls[:, :, 0] / np.linalg.norm(walls[:, :, 0], axis=1, keepdims=True)
    diagonal = np.isclose(np.abs(along[:, 0]), np.sqrt(0.5), atol=1e-3)
    assert diagonal.sum() > 0 and (~diagonal).sum() > 0    # facades on both squares of the star


def test_records_are_unchanged(records):
    digests = dict(line.split()[::-1] for line in (EXAMPLE / "records.sha256").read_text().splitlines())
    for name in GRAMMARS:
        assert record_digest(records[name][1]) == digests[name], name


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        for name in GRAMMARS:
            build(EXAMPLE / f"{name}.cga", Path(folder) / f"{name}.npz")
            sys.stdout.write(f"{record_digest(Path(folder) / f'{name}.npz')}  {name}\n")
