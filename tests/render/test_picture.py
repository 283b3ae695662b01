"""``render``: same record same bytes, buildings where the camera puts them, colourings, errors, atomicity."""

import json

import numpy as np
import pytest
from PIL import Image
from render_records import SKY, box_xform, write_record

from grammarc.build import build
from grammarc.errors import UsageError
from grammarc.io.npz import read_instances
from grammarc.render import render
from grammarc.render.camera import AMBIENT, DIFFUSE, MARGIN, SUN, fit_camera
from grammarc.render.picture import palette, parse_size

RED = [220, 40, 40, 255]
GREY = [200, 200, 200, 255]


def pixels(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def background(image) -> np.ndarray:
    return (image == SKY).all(axis=2)


@pytest.fixture
def block_city(tmp_path):
    """A 6 x 6 grid of 8 x 8 x 6 m grey blocks 20 m apart, and one red tower 40 m high at x 45, z -45."""
    xforms = [box_xform([20 * i, 0, -20 * j - 8], [8, 6, 8]) for i in range(6) for j in range(6)]
    xforms.append(box_xform([42, 0, -48], [6, 40, 6]))
    colors = [GREY] * 36 + [RED]
    record = read_instances(write_record(tmp_path / "city.npz", xforms, colors=colors))
    return record, np.array([45.0, 40.0, -45.0])


def test_same_record_same_bytes(block_city, tmp_path):
    record, _ = block_city
    render(record, tmp_path / "a.png", size=(320, 200))
    render(dict(record), tmp_path / "b.png", size=(320, 200))
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png", "city.npz"]  # no temporaries


def test_the_tower_is_where_the_oblique_camera_puts_it(block_city, tmp_path):
    record, roof = block_city
    size = (320, 200)
    result = render(record, tmp_path / "city.png", size=size)
    image = pixels(tmp_path / "city.png")
    assert image.shape == (200, 320, 3)
    assert result["instances"] == 37 and (~background(image)).sum() > 0.05 * image[:, :, 0].size
    # The camera fits the record's bounding box, so it can be made again from it.
    camera = fit_camera([0, 0, -108], [108, 40, 0], size, "oblique")
    x, y, _ = camera.project([roof])[0]
    r, g, b = image[int(y), int(x)].astype(int)
    assert r > 100 and r > 2 * g and r > 2 * b  # the red tower's roof, shaded
    assert background(image)[2, 2] and background(image)[-3, -3]  # the margins stay sky


def test_top_view_puts_a_unit_cube_in_its_pixel_rectangle(tmp_path):
    record = read_instances(write_record(tmp_path / "cube.npz", [box_xform([7, 3, -12], [1, 1, 1])]))
    render(record, tmp_path / "cube.png", size=(200, 100), view="top")
    image = pixels(tmp_path / "cube.png")
    # The cube fills the height less the margins, centred: 92 px a metre, columns 54-146, rows 4-96.
    scale = 100 * (1 - 2 * MARGIN)
    left, top = 100 - scale / 2, 50 - scale / 2
    inside = np.zeros(image.shape[:2], bool)
    inside[int(top) + 1 : int(top + scale) - 1, int(left) + 1 : int(left + scale) - 1] = True
    outside = np.ones(image.shape[:2], bool)
    outside[int(top) - 1 : int(top + scale) + 2, int(left) - 1 : int(left + scale) + 2] = False
    assert not background(image)[inside].any() and background(image)[outside].all()
    # The roof, white, shaded by Lambert with the sun's height.
    sun = np.asarray(SUN) / np.linalg.norm(SUN)
    assert image[50, 100].tolist() == [round(255 * (AMBIENT + DIFFUSE * sun[1]))] * 3


def test_colourings_by_symbol_and_asset_use_the_palette(tmp_path):
    xforms = [box_xform([0, 0, -10], [10, 10, 10]), box_xform([20, 0, -10], [10, 10, 10])]
    record = read_instances(write_record(tmp_path / "two.npz", xforms, asset=[0, 1],
                                         assets=["builtin:cube", "builtin:cylinder"]))
    render(record, tmp_path / "asset.png", size=(200, 100), view="top", color="asset")
    render(record, tmp_path / "symbol.png", size=(200, 100), view="top", color="symbol")
    by_asset, by_symbol = pixels(tmp_path / "asset.png"), pixels(tmp_path / "symbol.png")
    camera = fit_camera([0, 0, -10], [30, 10, 0], (200, 100), "top")
    (x0, y0), (x1, y1) = camera.project([[5, 10, -5], [25, 10, -5]])[:, :2].astype(int)
    shade = AMBIENT + DIFFUSE * SUN[1] / np.linalg.norm(SUN)
    expected = np.round(palette(2).astype(float) * shade)
    assert by_asset[y0, x0].tolist() == expected[0].tolist()
    assert by_asset[y1, x1].tolist() == expected[1].tolist()
    assert by_symbol[y0, x0].tolist() == by_symbol[y1, x1].tolist() == expected[0].tolist()


def test_a_derived_city_with_mesh_faces(write, tmp_path):
    grammar = write("g.cga", 'lot ~> S(1r, 9, 1r) Comp("sidefaces"){ wall } Comp("top"){ roof }\n')
    # An L, whose roof is a concave polygon (a mesh face), and a square.
    rings = [[[0, 0], [30, 0], [30, 10], [10, 10], [10, 20], [0, 20], [0, 0]],
             [[40, 0], [50, 0], [50, 10], [40, 10], [40, 0]]]
    lots = tmp_path / "lots.geojson"
    lots.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{i}", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [r]}}
        for i, r in enumerate(rings)]}))
    build(grammar, tmp_path / "city.npz", lots_path=lots)
    record = read_instances(tmp_path / "city.npz")
    assert record["meta"]["counts"]["mesh_faces"] > 0
    result = render(record, tmp_path / "top.png", size=(250, 100), view="top", color="symbol")
    image = pixels(tmp_path / "top.png")
    camera = fit_camera([0, 0, -20], [50, 9, 0], (250, 100), "top")
    x, y, _ = camera.project([[5, 9, -15]])[0]  # on the L's roof, a mesh face
    roof = list(record["symbols"]).index("roof")
    shade = AMBIENT + DIFFUSE * SUN[1] / np.linalg.norm(SUN)
    assert image[int(y), int(x)].tolist() == np.round(palette(roof + 1)[roof] * shade).tolist()
    assert result["mesh_faces"] == record["meta"]["counts"]["mesh_faces"]
    x, y, _ = camera.project([[20, 0, -15]])[0]  # in the L's notch
    assert background(image)[int(y), int(x)]


def test_a_missing_file_asset_is_drawn_as_boxes(tmp_path):
    record = read_instances(write_record(tmp_path / "r.npz", [box_xform([0, 0, -1], [1, 1, 1])],
                                         assets=["gone/window.obj"], meta={"grammar": str(tmp_path / "g.cga")}))
    result = render(record, tmp_path / "r.png", size=(40, 40), view="top")
    assert result["missing_assets"] == ["gone/window.obj"] and result["boxes"] == 1
    assert result["asset_problems"] == [
        f"asset `gone/window.obj` not found in {tmp_path} (--lod builtin puts a cube in its place)"]
    assert not background(pixels(tmp_path / "r.png"))[20, 20]


def test_an_asset_of_a_format_without_its_reader_says_so(tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "assimp_py", None)  # as if it were not installed
    (tmp_path / "mill.fbx").write_text("; FBX 7.4.0 project file\n")
    record = read_instances(write_record(tmp_path / "r.npz", [box_xform([0, 0, -1], [1, 1, 1])],
                                         assets=["mill.fbx"], meta={"grammar": str(tmp_path / "g.cga")}))
    result = render(record, tmp_path / "r.png", size=(40, 40), view="top")
    assert result["boxes"] == 1 and result["asset_problems"][0].startswith("unsupported asset format: FBX")


def test_an_empty_record_gives_the_sky(tmp_path):
    record = read_instances(write_record(tmp_path / "empty.npz", np.zeros((0, 3, 4))))
    render(record, tmp_path / "empty.png", size=(30, 20))
    assert background(pixels(tmp_path / "empty.png")).all()


@pytest.mark.parametrize(("columns", "message"), [
    ({"assets": ["builtin:cube"]}, "no asset, xform"),
    ({"assets": ["builtin:cube"], "asset": [0], "xform": np.zeros((2, 3, 4))}, r"xform is \(2, 3, 4\)"),
    ({"assets": ["builtin:cube"], "asset": [1], "xform": np.zeros((1, 3, 4))}, "asset index out of range"),
])
def test_columns_that_are_no_record_are_a_usage_error(tmp_path, columns, message):
    with pytest.raises(UsageError, match=f"not an instance record: {message}"):
        render(columns, tmp_path / "out.png")
    assert not (tmp_path / "out.png").exists()
    with pytest.raises(TypeError, match="a mapping"):
        render(tmp_path / "city.npz", tmp_path / "out.png")  # files are read by io.npz.load_record


@pytest.mark.parametrize(("options", "message"), [
    ({"view": "side"}, "view must be one of oblique, top"),
    ({"color": "height"}, "color must be one of material, symbol, asset"),
    ({"size": (0, 10)}, "size must be 1 to"),
])
def test_bad_options_are_usage_errors(block_city, tmp_path, options, message):
    with pytest.raises(UsageError, match=message):
        render(block_city[0], tmp_path / "out.png", **options)


def test_the_output_must_be_a_png_in_an_existing_folder(block_city, tmp_path):
    with pytest.raises(UsageError, match="name it `.png`"):
        render(block_city[0], tmp_path / "out.jpg")
    with pytest.raises(UsageError, match="does not exist"):
        render(block_city[0], tmp_path / "no" / "out.png")


def test_parse_size():
    assert parse_size("320x200") == (320, 200)
    for bad in ("320", "x200", "320x-2", "axb", "0x10"):
        with pytest.raises(UsageError):
            parse_size(bad)


def test_a_search_records_solutions_are_drawn_side_by_side(tmp_path):
    from grammarc.render.picture import _side_by_side

    # three solutions of one 4 x 6 lot, one over the other: laid out on a grid of two columns
    xform = np.stack([box_xform((0, 0, 0), (4, 0, 6))] * 3).astype(np.float64)
    record = {"lot": np.array([0, 1, 2]), "meta": {"search": {}}}
    moved, _ = _side_by_side(record, xform, np.zeros((0, 3)))
    np.testing.assert_allclose(moved[:, :, 3], [[0, 0, 0], [4.8, 0, 0], [0, 0, 7.2]])
    np.testing.assert_array_equal(moved[:, :, :3], xform[:, :, :3])
