"""The Xkipche example (examples/xkipche): the Puuc rules of Mueller et al. 2006 on the site's groups.

The tests hold the derived site to the paper's numbers, measured on the instance record rather than read
back from the grammar: the facade bands of Figure 4 (rule 3) and the members of every molding (Figure 7,
rule 13) have the heights the lot's control parameters give; doors are 100-120 cm wide (section 3.2)
between jambs leaning in by jamb_a (rule 9); colonettes stand 1.2 diameters apart with one colonette,
not two, at each corner (rule 18). The grammar checks clean, every lot derives, and the records keep a
digest (a change that alters them says why and updates it):

    python tests/test_xkipche.py    # prints the digest; copy it to examples/xkipche/records.sha256

A scope's axes are the columns of an instance's ``xform``: column 0 is its x axis times its width,
column 1 its y axis times its height, column 2 its z axis times its depth, column 3 its origin.
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
from grammarc.compiler import compile_grammar
from grammarc.io.npz import read_instances

ROOT = Path(__file__).resolve().parents[1]
XKIPCHE = ROOT / "examples" / "xkipche"
GRAMMAR = XKIPCHE / "xkipche.cga"
#: Lengths in the record are float32: a millimetre covers their rounding on a 200 m site.
TOL = 1e-3


def _script(name: str):
    return example_script(XKIPCHE, name)


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The example built whole: the build result, the record's path, the record and the lots."""
    out = tmp_path_factory.mktemp("xkipche") / "xkipche.npz"
    result = build(GRAMMAR, out)
    features = json.loads((XKIPCHE / "lots.geojson").read_text())["features"]
    return result, out, in_world(read_instances(out)), features


def buildings(site):
    """Per building: its lot number, properties, its instances' symbol names and xforms (float64),
    and its GeoJSON feature."""
    _, _, record, features = site
    names = record["symbols"][record["symbol"]]
    for lot, feature in enumerate(features):
        props = feature["properties"]
        if props["type"] != "plaza":
            mine = record["lot"] == lot
            yield lot, props, names[mine], record["xform"][mine].astype(np.float64), feature


def test_check_reports_no_warnings(capsys):
    assert main(["check", str(GRAMMAR)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    assert "ok" in out


def test_rules_1_to_21_are_all_there():
    labels = [rule.label for rule in compile_grammar(GRAMMAR).module.rules if rule.label]
    assert labels == [str(i) for i in range(1, 22)]


def test_every_lot_is_derived(site):
    result, _, _, features = site
    assert result.bad == ()
    assert result.derived == len(features) >= 30


def test_18_building_types_with_doors_of_100_to_120_cm():
    features = json.loads((XKIPCHE / "lots.geojson").read_text())["features"]
    kinds = [f["properties"] for f in features if f["properties"]["type"] != "plaza"]
    assert len({p["type"] for p in kinds}) == 18
    assert all(1.0 <= p["door_w"] <= 1.2 for p in kinds)


def test_facade_bands_have_the_heights_of_the_parameters(site):
    """Rule 3's five bands, bottom to top from the platform: every wall lies in one band, every band
    boundary is a wall's foot or top, the frieze wall is frieze_h tall; in each molding the members'
    walls cut it at apron_h, apron_h + deco_h and its height less reverse_apron_h, and its aprons and
    reverse aprons are as tall as their parameters."""
    for _, p, names, xform, _ in buildings(site):
        y0 = p["platform_h"]
        heights = {"base": p["base_molding_h"], "lower": 0.0, "medial": p["medial_molding_h"],
                   "frieze": p["frieze_h"], "cornice": p["cornice_molding_h"]}
        heights["lower"] = p["building_h"] - sum(heights.values())     # rule 3's 1r
        cuts = y0 + np.concatenate([[0.0], np.cumsum(list(heights.values()))])
        assert cuts[-1] == pytest.approx(y0 + p["building_h"])
        walls = xform[names == "wall"]
        foot, top = walls[:, 1, 3], walls[:, 1, 3] + walls[:, 1, 1]
        band = np.searchsorted(cuts, foot + TOL) - 1
        assert (band >= 0).all() and (band < 5).all()
        assert (top <= cuts[band + 1] + TOL).all(), f"{p['type']}: a wall crosses a band boundary"
        ends = np.concatenate([foot, top])
        for cut in cuts:
            assert np.abs(ends - cut).min() < TOL, f"{p['type']}: no wall ends at the band boundary {cut}"
        assert top.max() == pytest.approx(y0 + p["building_h"], abs=TOL)
        frieze = band == 3
        assert np.abs(walls[frieze, 1, 1] - p["frieze_h"]).min() < TOL
        for k, molding in ((0, "base"), (2, "medial"), (4, "cornice")):
            h, apron, deco, revap = (p[f"{molding}_{key}"] for key in ("molding_h", "apron_h", "deco_h",
                                                                       "reverse_apron_h"))
            inside = band == k
            seen = np.unique(np.round(np.concatenate([foot[inside], top[inside]]) - cuts[k], 3))
            expected = np.unique(np.round([0.0, apron, apron + deco, h - revap, h], 3))
            np.testing.assert_allclose(seen, expected, atol=TOL, err_msg=f"{p['type']} {molding} molding")
            for symbol, height in (("apron", apron), ("revap", revap)):
                pieces = xform[names == symbol]
                mine = pieces[(pieces[:, 1, 3] > cuts[k] - TOL) & (pieces[:, 1, 3] < cuts[k + 1] - TOL)]
                if height:
                    assert len(mine) >= 4, f"{p['type']} {molding}: {len(mine)} {symbol} pieces"
                    np.testing.assert_allclose(mine[:, 1, 1], height, atol=TOL)
                else:
                    assert len(mine) == 0, f"{p['type']} {molding}: a {symbol} of height 0"


def test_doors_are_100_to_120_cm_wide_between_jambs_leaning_in(site):
    """Rule 7: each door is an opening door_w wide between two jambs under one lintel (rule 8); section
    3.2: 100-120 cm. Rule 9 turns the jambs by -jamb_a and +jamb_a about the facade's normal: each leans
    into the opening by jamb_a (doors framed by columns stand upright)."""
    doors = 0
    for _, p, names, xform, _ in buildings(site):
        lintels, jambs = xform[names == "lintel"], xform[names == "jamb"]
        assert len(lintels) == p["doors"] + p["back_doors"] and len(jambs) == 2 * len(lintels)
        lean = 0.0 if p["door_frame"] == "columns" else p["jamb_a"]
        for lintel in lintels:
            width = np.linalg.norm(lintel[:, 0])
            u = lintel[:, 0] / width
            # the jambs standing under this lintel: their feet lie on its facade, within its span
            offset = (jambs[:, :, 3] - lintel[:, 3]) * [1.0, 0.0, 1.0]
            along = offset @ u
            off_plane = np.linalg.norm(offset - along[:, None] * u, axis=1)
            under = np.flatnonzero((along > -TOL) & (along < width) & (off_plane < TOL))
            assert len(under) == 2
            left, right = jambs[under[np.argsort(along[under])]]
            opening = (right[:, 3] - (left[:, 3] + left[:, 0])) @ u
            assert 1.0 - TOL <= opening <= 1.2 + TOL
            assert opening == pytest.approx(p["door_w"], abs=2e-3)
            assert width == pytest.approx(p["door_w"] + 2 * p["door_frame_w"], abs=TOL)
            for jamb, inward in ((left, 1.0), (right, -1.0)):
                up = jamb[:, 1] / np.linalg.norm(jamb[:, 1])
                assert np.degrees(np.arcsin(inward * up @ u)) == pytest.approx(lean, abs=0.01)
            doors += 1
    assert doors >= 80


def _rows(names, xform, d):
    """Colonettes of diameter ``d`` grouped into rows by band height and direction along the wall: on a
    rectangular footprint, one row per facade and band (facing facades run in opposite directions)."""
    cols = xform[(names == "colonette") & (np.abs(np.linalg.norm(xform[:, :, 0], axis=1) - d) < TOL)]
    keys = np.round(np.column_stack([cols[:, 1, 3], cols[:, :, 0] / d]), 2)
    return [cols[(keys == key).all(axis=1)] for key in np.unique(keys, axis=0)]


def test_colonettes_stand_one_point_two_diameters_apart(site):
    """Rule 18: Repeat("X", d * 1.2) lays ceil(length / 1.2 d) equal elements, one colonette of
    diameter d at the start of each: along a facade the colonettes of a row are evenly spaced, at most
    1.2 d and within 5 % of it. Checked on the rule-21 friezes (no masks cut them) and the decorated
    molding members (rule 15)."""
    rows = 0
    for _, p, names, xform, _ in buildings(site):
        diameters = [p["molding_colonette_diameter"]] if any(
            p[f"{m}_deco_h"] > 0 for m in ("base", "medial", "cornice")) else []
        if p["frieze_decoration"] == "colonettes" and not p["front_mask_w"] and not p["edge_mask_w"]:
            diameters.append(p["frieze_colonette_diameter"])
        for d in diameters:
            for row in _rows(names, xform, d):
                gaps = np.diff(np.sort(row[:, :, 3] @ (row[0, :, 0] / d)))
                assert len(gaps) >= 10
                assert np.ptp(gaps) < TOL, f"{p['type']}: uneven colonettes"
                assert 0.95 * 1.2 * d <= gaps[0] <= 1.2 * d + TOL
                rows += 1
    assert rows >= 60


def test_each_corner_has_one_colonette_not_two(site):
    """Rule 18's empty last element: of the two facades at a corner, one starts its row of colonettes
    at the corner and the other ends it 1.2 d or more before it, so that every corner of a rule-21
    frieze has one colonette, not two."""
    checked = 0
    for _, p, names, xform, feature in buildings(site):
        if p["frieze_decoration"] != "colonettes" or p["front_mask_w"] or p["edge_mask_w"]:
            continue
        d = p["frieze_colonette_diameter"]
        ring = np.array(feature["geometry"]["coordinates"][0][:-1], np.float64)
        corners = np.column_stack([ring[:, 0], -ring[:, 1]])   # world x, z of the footprint's corners
        touched = []
        for row in _rows(names, xform, d):                     # one facade's frieze colonettes
            u = row[0, [0, 2], 0] / d
            normal = np.array([-u[1], u[0]])
            feet = row[:, [0, 2], 3]                           # world x, z of each colonette's origin
            for k, corner in enumerate(corners):
                if np.abs((feet - corner) @ normal).max() > p["frieze_p"] + d:
                    continue                                   # not a corner of this facade
                # each colonette spans [along, along + d] on its facade, from this corner
                along = (feet - corner) @ u
                gap = np.abs(np.concatenate([along, along + d])).min()
                assert gap < TOL or gap >= 1.2 * d - TOL, f"{p['type']}: a colonette {gap:.3f} from a corner"
                if gap < TOL:
                    touched.append(k)
        assert sorted(touched) == list(range(len(corners))), f"{p['type']}: colonettes at corners {touched}"
        checked += 1
    assert checked >= 5


def test_assets_and_lots_are_made_by_the_scripts():
    made = _script("make_assets").obj_files()
    assert sorted(made) == sorted(p.name for p in (XKIPCHE / "assets").glob("*.obj"))
    for name, (text, triangles) in made.items():
        assert (XKIPCHE / "assets" / name).read_text() == text, f"{name} differs from make_assets.py's"
        assert 8 <= triangles <= 400
    assert _script("make_lots").lots() == json.loads((XKIPCHE / "lots.geojson").read_text())


def test_records_are_unchanged(site):
    _, out, _, _ = site
    assert record_digest(out) == (XKIPCHE / "records.sha256").read_text().split()[0]


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        build(GRAMMAR, Path(folder) / "xkipche.npz")
        sys.stdout.write(record_digest(Path(folder) / "xkipche.npz") + "\n")
