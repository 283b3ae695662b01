"""A rule package's textures travel with the outputs that name them (OBJ, USD): the package's extraction is
gone once the build returns."""

import json
from pathlib import Path

import pytest
import trimesh
from writers_city import PNG, TEXTURED

from grammarc.build import build
from grammarc.io.textures import PackagedTextures, package_folder

py7zr = pytest.importorskip("py7zr")


def textured_package(tmp_path: Path) -> tuple[Path, Path]:
    """A rule package of ``TEXTURED`` with its texture in ``assets/tex/wall.png``, and a lot."""
    package = tmp_path / "textured.rpk"
    with py7zr.SevenZipFile(package, "w") as archive:
        archive.writestr(("@StartRule\n" + TEXTURED.split("\n", 1)[1]).encode(), "rules/main.cga")
        archive.writestr(PNG, "assets/tex/wall.png")
    lots = tmp_path / "lots.geojson"
    lots.write_text(json.dumps({"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {},
        "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [12, 0], [12, 9], [0, 9], [0, 0]]]}}]}))
    return package, lots


def test_the_package_folder_holds_every_root_but_the_users(tmp_path):
    extracted, own = tmp_path / "grammarc-rpk-x", tmp_path / "mine"
    roots = [extracted / "rules", extracted / "assets", extracted, extracted / ".ws", own]
    assert package_folder({"grammar": "a/city.rpk", "asset_roots": [str(own)]}, roots) == extracted.resolve()
    assert package_folder({"grammar": "a/city.cga", "asset_roots": [str(own)]}, roots) is None
    assert package_folder({"grammar": "a/city.RPK", "asset_roots": [str(own)]}, [own]) is None


def test_only_a_packages_files_are_copied_each_once(tmp_path):
    extracted, own = tmp_path / "pkg", tmp_path / "mine"
    (extracted / "assets" / "tex").mkdir(parents=True)
    own.mkdir()
    (extracted / "assets" / "tex" / "a.png").write_bytes(PNG)
    (own / "b.png").write_bytes(PNG)
    textures = PackagedTextures({"grammar": "p.rpk", "asset_roots": [str(own)]},
                                [extracted / "assets", extracted, own], tmp_path / "out" / "textures")
    assert not textures.copied
    assert textures.copy((own / "b.png").resolve()) is None
    assert str(textures.copy((extracted / "assets" / "tex" / "a.png").resolve())) == "assets/tex/a.png"
    assert str(textures.copy((extracted / "assets" / "tex" / "a.png").resolve())) == "assets/tex/a.png"
    assert textures.copied
    assert [p.name for p in (tmp_path / "out").rglob("*") if p.is_file()] == ["a.png"]


def test_an_obj_of_a_package_names_copies_of_its_textures(tmp_path):
    package, lots = textured_package(tmp_path)
    out = tmp_path / "out" / "city.obj"
    build(package, out, lots_path=lots)
    maps = [line.split(None, 1)[1] for line in (out.parent / "city.mtl").read_text().splitlines()
            if line.startswith("map_Kd")]
    assert maps == ["city.obj.textures/assets/tex/wall.png"]
    assert (out.parent / maps[0]).read_bytes() == PNG
    images = [g.visual.material.image for g in trimesh.load(out).geometry.values()]
    assert sum(image is not None for image in images) == 1
    build(package, out, lots_path=lots)  # again, onto the first build's folder
    assert sorted(p.name for p in out.parent.iterdir()) == ["city.mtl", "city.obj", "city.obj.textures"]
    assert (out.parent / maps[0]).read_bytes() == PNG


def test_an_obj_without_a_packages_textures_leaves_no_texture_folder(tmp_path):
    package, lots = textured_package(tmp_path)
    out = tmp_path / "city.obj"
    build(package, out, lots_path=lots)
    (tmp_path / "g.cga").write_text(TEXTURED.replace('texture("tex/wall.png") ', ""))
    build(tmp_path / "g.cga", out, lots_path=lots)
    assert not (tmp_path / "city.obj.textures").exists()
    assert "map_Kd" not in (tmp_path / "city.mtl").read_text()


def test_a_usd_of_a_package_binds_copies_of_its_textures(tmp_path):
    pxr = pytest.importorskip("pxr")
    package, lots = textured_package(tmp_path)
    out = tmp_path / "city.usda"
    build(package, out, lots_path=lots)
    stage = pxr.Usd.Stage.Open(str(out))
    files = [pxr.UsdShade.Shader(p).GetInput("file").Get() for p in stage.Traverse()
             if pxr.UsdShade.Shader(p) and pxr.UsdShade.Shader(p).GetIdAttr().Get() == "UsdUVTexture"]
    assert files and {f.path for f in files} == {"./textures/assets/tex/wall.png"}
    assert all(Path(f.resolvedPath).read_bytes() == PNG for f in files)
