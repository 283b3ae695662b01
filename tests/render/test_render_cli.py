"""``grammarc render``: writes the PNG and exits 0; a bad record exits 2 and writes nothing."""

from PIL import Image
from render_records import box_xform, write_record

from grammarc.cli import main


def test_render_writes_the_picture(tmp_path, capsys):
    xforms = [box_xform([0, 0, -4], [4, 9, 4]), box_xform([10, 0, -4], [4, 3, 4])]
    record = write_record(tmp_path / "r.npz", xforms)
    out = tmp_path / "city.png"
    assert main(["render", str(record), "-o", str(out), "--size", "120x80", "--view", "top",
                 "--color", "symbol"]) == 0
    assert Image.open(out).size == (120, 80)
    assert "2 instances" in capsys.readouterr().err


def test_a_missing_asset_is_reported(tmp_path, capsys):
    record = write_record(tmp_path / "r.npz", [box_xform([0, 0, -4], [4, 9, 4])], assets=["w.obj"])
    assert main(["render", str(record), "-o", str(tmp_path / "a.png"), "--assets", str(tmp_path)]) == 0
    assert "asset `w.obj` not found" in capsys.readouterr().err


def test_a_bad_record_exits_2(tmp_path, capsys):
    assert main(["render", str(tmp_path / "none.npz"), "-o", str(tmp_path / "out.png")]) == 2
    assert "grammarc: error: record" in capsys.readouterr().err
    assert not (tmp_path / "out.png").exists()
