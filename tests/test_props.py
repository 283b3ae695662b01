"""The props example (examples/props): wind turbines, trees and fences inserted from GLB assets.

The record is held to what each insert mode promises, measured on the instances: towers fitted to a box
of their asset's footprint (``assetInfo``) as tall as the lot says, nacelles at their own 3 x 3 x 10 m centred on the tower top, rotors (a
z-up export) at their own size with their hub, the asset's origin, 1.5 m above the tower, trees at their
own proportions standing on the ground, fence posts as tall as the lot's fence. The assets and lots are
what the scripts make, ``render`` draws the GLB meshes (no box stands in), and the records keep a digest
(a change that alters them says why and updates it):

    python tests/test_props.py    # prints the digest; copy it to examples/props/records.sha256

A scope's axes are the columns of an instance's ``xform`` (column 3 its origin); an asset's unit box maps
onto them, so an instance's column lengths are the asset's extents along its own axes.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from conftest import example_script, in_world
from test_examples import record_digest

from grammarc.build import build
from grammarc.io.npz import read_instances
from grammarc.model.assets import load_asset
from grammarc.render.picture import render

ROOT = Path(__file__).resolve().parents[1]
PROPS = ROOT / "examples" / "props"
GRAMMAR = PROPS / "props.cga"
TOL = 1e-3  # float32 lengths on a 300 m site


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("props") / "props.npz"
    result = build(GRAMMAR, out)
    features = json.loads((PROPS / "props.geojson").read_text())["features"]
    return result, out, in_world(read_instances(out)), features


def instances(record, symbol):
    """The xforms (float64) and lots of the instances of ``symbol``."""
    mine = record["symbols"][record["symbol"]] == symbol
    return record["xform"][mine].astype(np.float64), record["lot"][mine]


def extents(asset: str) -> np.ndarray:
    bounds = load_asset(asset, [PROPS]).bounds
    return bounds[1] - bounds[0]


def test_every_lot_is_derived_with_its_assets(site):
    result, _, record, features = site
    assert not result.bad and result.derived == len(features) == 11
    used = set(record["assets"][np.unique(record["asset"])])
    assert {f"assets/{name}" for name in example_script(PROPS, "make_assets").ASSETS} <= used


def test_towers_are_fitted_and_nacelles_keep_their_size_on_top(site):
    _, _, record, features = site
    tower, lots = instances(record, "Tower")
    heights = np.array([features[lot]["properties"]["turbineHeight"] for lot in lots])
    width, _, depth = extents("assets/turbine/tower.glb")  # the box is the asset's footprint (assetInfo)
    np.testing.assert_allclose(np.linalg.norm(tower[:, :, :3], axis=1),
                               np.stack([np.full(len(lots), width), heights, np.full(len(lots), depth)], 1), atol=TOL)
    nacelle, _ = instances(record, "Nacelle")
    np.testing.assert_allclose(np.linalg.norm(nacelle[:, :, :3], axis=1), [[3, 3, 10]] * len(lots), atol=TOL)
    # the nacelle's bottom centre is the tower's top centre
    top = tower[:, :, 3] + (tower[:, :, 0] + tower[:, :, 2]) / 2 + tower[:, :, 1]
    np.testing.assert_allclose(nacelle[:, :, 3] + (nacelle[:, :, 0] + nacelle[:, :, 2]) / 2, top, atol=TOL)


def test_rotors_keep_their_size_and_turn_about_their_hub(site):
    _, _, record, features = site
    rotor, lots = instances(record, "Rotor")
    size = extents("assets/turbine/rotor.glb")
    np.testing.assert_allclose(np.linalg.norm(rotor[:, :, :3], axis=1), [size] * len(lots), atol=TOL)
    # zUp: the asset's y, the blades' thickness, is horizontal (its z turns with the rotor about it)
    assert (np.abs(rotor[:, 1, 1]) < TOL).all()
    # the hub, the asset's origin, lies 1.5 m above the tower
    low = load_asset("assets/turbine/rotor.glb", [PROPS]).bounds[0]
    hub = rotor[:, :, 3] + np.einsum("nij,j->ni", rotor[:, :, :3], -low / size)
    heights = [features[lot]["properties"]["turbineHeight"] for lot in lots]
    np.testing.assert_allclose(hub[:, 1], np.array(heights) + 1.5, atol=TOL)


def test_trees_keep_their_proportions_and_stand_on_the_ground(site):
    """Both trees of the folder are drawn (``fileRandom``), with the leaf colours of the list."""
    _, _, record, _ = site
    tree, _ = instances(record, "TreeModel")
    names = record["assets"][record["asset"][record["symbols"][record["symbol"]] == "TreeModel"]]
    assert set(names) == {"assets/trees/broadleaf.glb", "assets/trees/conifer.glb"}
    lengths = np.linalg.norm(tree[:, :, :3], axis=1)
    own = np.array([extents(str(name)) for name in names])
    scale = lengths / own
    np.testing.assert_allclose(scale, scale[:, :1].repeat(3, axis=1), atol=TOL)
    assert ((0.75 - TOL < scale[:, 0]) & (scale[:, 0] < 1.3 + TOL)).all()
    assert np.abs(tree[:, 1, 3]).max() < TOL  # every tree's bottom on y = 0
    colours = record["color"][record["symbols"][record["symbol"]] == "TreeModel"][:, :3]
    leaves = {(0x5D, 0x8F, 0x3E), (0x2F, 0x6A, 0x44), (0x6B, 0x9A, 0x45), (0x3F, 0x7A, 0x4F)}
    assert {tuple(c) for c in colours.tolist()} == leaves


def test_fence_posts_are_as_tall_as_the_lot_says(site):
    _, _, record, features = site
    post, lots = instances(record, "FencePost")
    heights = np.array([features[lot]["properties"]["fenceHeight"] for lot in lots])
    np.testing.assert_allclose(np.linalg.norm(post[:, :, 1], axis=1), heights, atol=TOL)


def test_render_draws_the_glb_meshes(site, tmp_path):
    _, _, record, _ = site
    drawn = render(dict(record), tmp_path / "props.png", size=(320, 200))
    assert drawn["asset_problems"] == [] and drawn["meshes"] > 0


def test_assets_and_lots_are_made_by_the_scripts():
    made = example_script(PROPS, "make_assets").ASSETS
    assert sorted(made) == sorted(p.relative_to(PROPS / "assets").as_posix() for p in PROPS.glob("assets/*/*.glb"))
    for name, make in made.items():
        committed = trimesh.load(PROPS / "assets" / name, force="mesh", process=False)
        fresh = make().to_geometry()
        np.testing.assert_allclose(*(np.unique(m.vertices.round(5), axis=0) for m in (committed, fresh)),
                                   err_msg=name)
        assert len(committed.faces) == len(fresh.faces)
        assert (PROPS / "assets" / name).stat().st_size < 8000
    assert example_script(PROPS, "make_lots").lots() == json.loads((PROPS / "props.geojson").read_text())["features"]


def test_records_are_unchanged(site):
    _, out, _, _ = site
    assert record_digest(out) == (PROPS / "records.sha256").read_text().split()[0]


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        build(GRAMMAR, Path(folder) / "props.npz")
        sys.stdout.write(record_digest(Path(folder) / "props.npz") + "\n")
