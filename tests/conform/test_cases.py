"""Cases of the differential harness: attributes sampled from their annotations, lots files."""

import json

import numpy as np

from grammarc.compiler import compile_grammar
from grammarc.conform.cases import make_case, sample_attrs, write_lots

GRAMMAR = '''version "2023.0"
@Range(min=2, max=4)
attr height = 3
@Range(min=1, max=4, stepsize=1, restricted=false)
attr floors = 2
@Range(0, 8)
attr offset = 3
@Range(0, 90, 180, 270)
attr orientation = 0
@Range("shapeR", "shapeL")
attr shape = "shapeR"
@Range(true, false)
attr build = true
@Enum("a", "b", "c")
attr kind = "a"
attr plain = 5
const fixed = 1
@Range(min=0, max=1)
attr Style$height = 1

@StartRule
Lot --> extrude(height) X.
'''


def test_attributes_are_sampled_from_their_annotations():
    module = compile_grammar("g.cga", text=GRAMMAR).module
    samples = [sample_attrs(module, np.random.default_rng(seed)) for seed in range(200)]
    assert all(set(s) == {"height", "floors", "offset", "orientation", "shape", "build", "kind"} for s in samples)
    heights = np.array([s["height"] for s in samples])
    assert 2 <= heights.min() < 2.2 and 3.8 < heights.max() <= 4
    assert {s["floors"] for s in samples} == {1, 2, 3, 4}
    assert all(0 <= s["offset"] <= 8 for s in samples)
    assert {s["orientation"] for s in samples} == {0, 90, 180, 270}
    assert {s["shape"] for s in samples} == {"shapeR", "shapeL"}
    assert {s["build"] for s in samples} == {True, False}
    assert {s["kind"] for s in samples} == {"a", "b", "c"}
    assert all(round(s["height"], 3) == s["height"] for s in samples)


def test_a_case_is_a_function_of_package_class_and_seed():
    module = compile_grammar("g.cga", text=GRAMMAR).module
    a, b = make_case("p", module, "L", 3), make_case("p", module, "L", 3)
    assert a.attrs == b.attrs and a.polygon.equals_exact(b.polygon, 0) and a.name == "p.L.3"
    assert make_case("q", module, "L", 3).attrs != a.attrs or make_case("p", module, "L", 4).attrs != a.attrs


def test_lots_file_names_each_case_and_spreads_them(tmp_path):
    module = compile_grammar("g.cga", text=GRAMMAR).module
    cases = [make_case("p", module, kind, seed) for seed, kind in enumerate(["convex", "courtyard", "tiny"])]
    write_lots(tmp_path / "lots.geojson", cases, spacing=1000)
    features = json.loads((tmp_path / "lots.geojson").read_text())["features"]
    assert [f["properties"]["name"] for f in features] == [c.name for c in cases]
    assert features[1]["properties"]["height"] == cases[1].attrs["height"]
    assert len(features[1]["geometry"]["coordinates"]) == 2  # the courtyard's hole
    first = np.array(features[1]["geometry"]["coordinates"][0])
    np.testing.assert_allclose(first - np.asarray(cases[1].polygon.exterior.coords), [[1000, 0]] * len(first))


def test_cases_from_a_file_of_real_lots(tmp_path):
    from grammarc.conform.cases import cases_from_file

    module = compile_grammar("g.cga", text=GRAMMAR).module
    square = [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
    far = [[[x + 100, y] for x, y in square]]
    collection = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "a"}, "geometry": {"type": "Polygon", "coordinates": [square]}},
        {"type": "Feature", "properties": {}, "geometry": {"type": "MultiPolygon", "coordinates": [[square], far]}},
    ]}
    path = tmp_path / "pompeii.geojson"
    path.write_text(json.dumps(collection))
    cases = cases_from_file("p", module, path)
    assert [c.name for c in cases] == ["p.pompeii.0", "p.pompeii.1", "p.pompeii.2"]
    assert cases[2].polygon.bounds == (100, 0, 110, 10) and cases[0].attrs != cases[1].attrs
