"""The command line: every error kind gets its message and exit code, and a failed build writes nothing."""

from __future__ import annotations

import contextlib
import ctypes
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from grammarc.cli import main
from grammarc.errors import Stopped, raise_stopped
from grammarc.io.npz import read_instances

GOOD = 'attr height = 9\nlot ~> S(1r, height, 1r) Comp("sidefaces"){ wall }\n'


def geojson(path, polygons, props=None):
    features = [
        {"type": "Feature", "id": f"lot{i}", "properties": (props or [{}] * len(polygons))[i],
         "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]] for ring in rings]}}
        for i, rings in enumerate(polygons)
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


SQUARE = [[[0, 0], [10, 0], [10, 10], [0, 10]]]
BOWTIE = [[[0, 0], [10, 10], [10, 0], [0, 10]]]
FLAT = [[[0, 0], [10, 0], [20, 0]]]


def test_build_writes_the_record(write, tmp_path, capsys):
    grammar = write("g.cga", GOOD)
    lots = geojson(tmp_path / "lots.geojson", [SQUARE, SQUARE])
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--lots", str(lots), "--emit", str(out)]) == 0
    record = read_instances(out)
    assert len(record["asset"]) == 8 and list(np.unique(record["lot"])) == [0, 1]
    np.testing.assert_allclose(record["xform"][:, 1, 1], 9)
    assert "8 instances" in capsys.readouterr().err


def test_build_uses_lots_beside_the_grammar_and_attr_override(write, tmp_path):
    grammar = write("city.cga", GOOD)
    geojson(tmp_path / "city.geojson", [SQUARE])
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out), "--attr", "height=4", "--quiet"]) == 0
    record = read_instances(out)
    np.testing.assert_allclose(record["xform"][:, 1, 1], 4)
    assert record["meta"]["attrs"] == {"height": 4.0}


def test_syntax_errors_all_reported_with_caret_exit_2(write, tmp_path, capsys):
    grammar = write("bad.cga", "a ~> S(1, 2, 3 b\nc ~> T(1, 2, 3)\nd ~> Subdv(\"X\", 1){ e }\n")
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{grammar}:1:16: error: unexpected `b`" in err
    assert f"{grammar}:3:6: error: unknown operation `Subdv` (did you mean `Subdiv`?)" in err
    assert " 3 | d ~> Subdv" in err and "   |      ^^^^^" in err
    assert "2 errors; nothing was written" in err
    assert not out.exists()


@pytest.mark.parametrize("text, message", [
    ("lot ~> S(1r, heigth, 1r) x\n", "unknown identifier `heigth`"),
    ("lot ~> f(1, 2)\nf(a) ~> x\n", "`f` takes 1 argument, got 2"),
    ("lot ~> a : 0.5\n    ~> b : 0.4\n", "probabilities of `lot` sum to 0.9"),
    ("lot ~> Shape.occ(\"all\")\n", "unexpected"),
    ("lot : Shape.visible(\"river\") ~> x\n", "`Shape.visible` takes \"street\" (the lot's street edges) or \"front\""),
])
def test_grammar_errors_exit_2(write, tmp_path, capsys, text, message):
    out = tmp_path / "out.npz"
    assert main(["build", str(write("g.cga", text)), "--emit", str(out)]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_bad_lots_reported_and_skipped(write, tmp_path, capsys):
    lots = geojson(tmp_path / "lots.geojson", [SQUARE, BOWTIE, SQUARE, FLAT])
    out = tmp_path / "out.npz"
    assert main(["build", str(write("g.cga", GOOD)), "--lots", str(lots), "--emit", str(out)]) == 0
    err = capsys.readouterr().err
    assert "lot lot1 (#1) skipped: self-intersection" in err
    assert "lot lot3 (#3) skipped" in err
    assert list(np.unique(read_instances(out)["lot"])) == [0, 2]


def test_a_build_says_how_many_lots_were_bad_and_exit_codes_tell_the_truth(write, tmp_path, capsys):
    grammar = str(write("g.cga", GOOD))
    some = geojson(tmp_path / "some.geojson", [SQUARE, BOWTIE])
    assert main(["build", grammar, "--lots", str(some), "--emit", str(tmp_path / "a.npz"), "--quiet"]) == 0
    assert capsys.readouterr().err == "grammarc: 1 of 2 lots skipped\n"
    assert main(["build", grammar, "--lots", str(some), "--emit", str(tmp_path / "b.npz"), "--quiet",
                 "--strict"]) == 1
    capsys.readouterr()
    none = geojson(tmp_path / "none.geojson", [BOWTIE, FLAT, BOWTIE])
    assert main(["build", grammar, "--lots", str(none), "--emit", str(tmp_path / "a.npz"), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err == ("grammarc: none of the 3 lots could be built (2 self-intersection at (5.0, 5.0); 1 zero area); "
                   "nothing was written\n")
    assert set(read_instances(tmp_path / "a.npz")["lot"].tolist()) == {0}  # the failed build left the older city


def test_a_build_without_lots_says_which_it_built_even_when_quiet(write, tmp_path, capsys):
    grammar = write("g.cga", GOOD)
    assert main(["build", str(grammar), "--emit", str(tmp_path / "a.npz"), "--quiet"]) == 0
    assert capsys.readouterr().err == "grammarc: no --lots: built one built-in 30 x 20 m lot\n"
    own = geojson(tmp_path / "g.geojson", [SQUARE])
    assert main(["build", str(grammar), "--emit", str(tmp_path / "b.npz"), "--quiet"]) == 0
    assert capsys.readouterr().err == f"grammarc: no --lots: built {own}\n"


def test_id_field_names_the_lots_and_repeated_ids_warn(write, tmp_path, capsys):
    lots = geojson(tmp_path / "osm.geojson", [SQUARE, SQUARE, SQUARE],
                   [{"osm_id": 11, "name": "Mill"}, {"osm_id": 12, "name": "Mill"}, {"osm_id": 13}])
    for path in lots.parent.glob("osm.geojson"):
        text = json.loads(path.read_text())
        for feature in text["features"]:
            del feature["id"]
        path.write_text(json.dumps(text))
    grammar = str(write("g.cga", GOOD))
    assert main(["build", grammar, "--lots", str(lots), "--emit", str(tmp_path / "a.npz")]) == 0
    assert ("warning: 1 lot ids belong to more than one lot ('Mill'): --id-field names the field of unique ids"
            in capsys.readouterr().err)
    assert main(["build", grammar, "--lots", str(lots), "--emit", str(tmp_path / "b.npz"), "--id-field",
                 "osm_id", "--select", "12,13"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert list(np.unique(read_instances(tmp_path / "b.npz")["lot"])) == [1, 2]


def test_min_area_makes_slivers_bad_lots(write, tmp_path, capsys):
    sliver = [[[0, 0], [10, 0], [10, 0.002], [0, 0.002]]]  # 2 mm wide
    lots = geojson(tmp_path / "lots.geojson", [SQUARE, sliver])
    out = tmp_path / "out.npz"
    assert main(["build", str(write("g.cga", GOOD)), "--lots", str(lots), "--emit", str(out), "--min-area",
                 "1"]) == 0
    assert "lot lot1 (#1) skipped: area 0.02 m2 under --min-area 1" in capsys.readouterr().err
    assert list(np.unique(read_instances(out)["lot"])) == [0]


def test_negative_size_lot_skipped_by_id(write, tmp_path, capsys):
    grammar = write("g.cga", "lot ~> S(Scope.sx - 10.5, 3, 1r) I(\"cube\")\n")
    lots = geojson(tmp_path / "lots.geojson", [SQUARE, [[[0, 0], [12, 0], [12, 5], [0, 5]]]])
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--lots", str(lots), "--emit", str(out)]) == 0
    assert "lot lot0 (#0) skipped: `S` gives a negative or NaN size" in capsys.readouterr().err
    assert list(read_instances(out)["lot"]) == [1]


def test_a_runaway_lot_is_skipped_by_name_and_the_others_built(write, tmp_path, capsys):
    """--max-shapes and --max-depth are limits per lot: the lot over one is a bad lot named with the rule
    and its place, the good ones are written, exit 0; where every lot runs away, exit 1 with the reason."""
    out = tmp_path / "out.npz"
    grammar = write("g.cga", "attr n = 0\nlot : n > 0 ~> grow\nlot ~> I(\"cube\")\n"
                             "grow ~> T(0, 1, 0) grow grow\n")
    lots = geojson(tmp_path / "city.geojson", [SQUARE] * 3, [{"n": 0}, {"n": 1}, {"n": 0}])
    assert main(["build", str(grammar), "--lots", str(lots), "--emit", str(out), "--max-shapes", "100000"]) == 0
    err = capsys.readouterr().err
    assert re.search(r"grammarc: lot lot1 \(#1\) skipped: more than 100,000 shapes \(131,071\) in rule `grow` at "
                     r"\S*g\.cga:4:\d+: a runaway grammar\? Raise the limit with --max-shapes N\.\n", err)
    assert err.endswith("grammarc: 1 of 3 lots skipped\n")
    assert list(read_instances(out)["lot"]) == [0, 2]
    assert main(["build", str(grammar), "--emit", str(out), "--attr", "n=1", "--max-depth", "10"]) == 1
    assert "none of the 1 lots could be built (1 reached --max-depth 10 in rule `grow`" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["city.geojson", "g.cga", "out.npz"]


def test_a_lot_grammarc_fails_on_is_named_with_the_fault_and_the_others_written(write, tmp_path, capsys,
                                                                              monkeypatch):
    """A fault of grammarc's that one lot's geometry meets (an exception that is none of its errors) does not
    lose the city: the chunk is halved until the lot is found, which is skipped and named with the fault and
    where it was raised; the other lots' records are those they have without it. The tests' strict mode
    raises the fault instead."""
    import grammarc.build

    derive_chunk = grammarc.build.derive_chunk

    def faulty(plan, lots, **kwargs):
        if "lot2" in lots.ids.tolist():
            raise ValueError("too many values to unpack (expected 2)")
        return derive_chunk(plan, lots, **kwargs)

    grammar = write("g.cga", GOOD)
    lots = geojson(tmp_path / "city.geojson", [SQUARE] * 4)
    expected = tmp_path / "expected.npz"
    assert main(["build", str(grammar), "--lots", str(lots), "--emit", str(expected), "--quiet"]) == 0
    monkeypatch.setattr(grammarc.build, "derive_chunk", faulty)
    out = tmp_path / "out.npz"
    with pytest.raises(ValueError):
        main(["build", str(grammar), "--lots", str(lots), "--emit", str(out), "--quiet"])
    monkeypatch.setattr(grammarc.build, "STRICT", False)
    assert main(["build", str(grammar), "--lots", str(lots), "--emit", str(out)]) == 0
    err = capsys.readouterr().err
    assert re.search(r"grammarc: lot lot2 \(#2\) skipped: grammarc failed on this lot \(ValueError at "
                     r"test_cli\.py:\d+: too many values to unpack \(expected 2\)\); this is a fault of "
                     r"grammarc's, not of the lot: please report it with the lot\n", err)
    assert err.endswith("grammarc: 1 of 4 lots skipped\n")
    got, want = read_instances(out), read_instances(expected)
    keep = want["lot"] != 2
    assert got["lot"].tolist() == want["lot"][keep].tolist()
    assert np.array_equal(got["xform"], want["xform"][keep])


def test_bad_lots_of_the_derivation_are_named_and_the_good_ones_written(write, tmp_path, capsys):
    """One lot of a facade's tile 1e-9 m wide (3e10 tiles), one of a height of 1e308 (no float32 holds it:
    the extrude fails it), one of ``height: true`` (a boolean for a number): each is named on stderr with
    why, the good lots are written, exit 0."""
    grammar = write("g.cga", 'version "2022.0"\nattr height = 9\nattr tile_w = 3\n@StartRule\n'
                             'Lot --> extrude(height) comp(f){ side : Facade }\n'
                             'Facade --> split(x){ tile_w : Tile }*\nTile --> i("builtin:cube")\n')
    lots = geojson(tmp_path / "city.geojson", [SQUARE] * 5,
                   [{}, {"tile_w": 1e-9}, {"height": 1e308}, {"height": True}, {"tile_w": 2}])
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--lots", str(lots), "--emit", str(out)]) == 0
    err = capsys.readouterr().err
    assert re.search(r"lot lot1 \(#1\) skipped: more than 2,000,000 shapes \(\d[\d,]*\) in rule `Facade` at "
                     r"\S*g\.cga:6:12: a runaway grammar\? Raise the limit with --max-shapes N\.\n", err)
    assert re.search(r"lot lot2 \(#2\) skipped: a scope sized or placed beyond any coordinate \(1e\+308\) "
                     r"in rule `Lot` at \S*g\.cga:5:9\n", err)
    assert 'lot lot3 (#3) skipped: attribute `height` is "true", not a num\n' in err
    assert err.endswith("grammarc: 3 of 5 lots skipped\n")
    assert np.unique(read_instances(out)["lot"]).tolist() == [0, 4]


def test_depth_limit_can_be_raised(write, tmp_path):
    grammar = write("g.cga", "lot ~> S(1r, 1, 1r) grow(300)\ngrow(n) : n > 0 ~> T(0, 1, 0) grow(n - 1)\n"
                             "grow(n) ~> I(\"cube\")\n")
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out), "--quiet"]) == 1
    assert main(["build", str(grammar), "--emit", str(out), "--quiet", "--max-depth", "400"]) == 0
    np.testing.assert_allclose(read_instances(out)["xform"][0, 1, 3], 300)


@pytest.mark.parametrize("content, message", [
    (None, "lots file not found"),
    ("{not json", "lots.geojson"),
    ('{"type": "FeatureCollection", "features": []}', "no polygon"),
])
def test_unreadable_lots_exit_1(write, tmp_path, capsys, content, message):
    lots = tmp_path / "lots.geojson"
    if content is not None:
        lots.write_text(content)
    out = tmp_path / "out.npz"
    assert main(["build", str(write("g.cga", GOOD)), "--lots", str(lots), "--emit", str(out)]) == 1
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_the_grammars_errors_and_the_options_come_before_those_of_the_lots_read_meanwhile(write, tmp_path, capsys):
    """The lots are read in a thread while the grammar compiles (``io.lots_reading``); their error is said
    only where it was before, once the grammar and the options are found good."""
    missing = str(tmp_path / "missing.geojson")
    out = str(tmp_path / "out.npz")
    assert main(["build", str(write("g.cga", GOOD)), "--lots", missing, "--emit", out, "--attr", "nope=1"]) == 2
    assert "declares no attribute `nope`" in (err := capsys.readouterr().err) and "not found" not in err
    assert main(["build", str(write("bad.cga", "lot ~> S(1, 2\n")), "--lots", missing, "--emit", out]) == 2
    assert "not found" not in capsys.readouterr().err


@pytest.mark.parametrize("args, message", [
    (["--emit", "out.fbx"], "output format `.fbx` is not supported"),
    (["--emit", "out.npz", "--attr", "nope=1"], "declares no attribute `nope`"),
    (["--emit", "out.npz", "--attr", "height=tall"], "`height` is a num, not a str"),
    (["--emit", "out.npz", "--start", "missing"], "start symbol `missing` has no rule"),
])
def test_usage_errors_exit_2(write, tmp_path, capsys, args, message):
    args = [a if not a.startswith("out.") else str(tmp_path / a) for a in args]
    assert main(["build", str(write("g.cga", GOOD)), *args]) == 2
    assert message in capsys.readouterr().err


def test_workspace_option_of_check_and_build(write, capsys, tmp_path):
    from pathlib import Path

    workspace = Path(__file__).parent / "frontend" / "grammars" / "cityengine" / "workspace"
    grammar = write("g.cga", 'version "2019.0"\nimport h : "/Houses/rules/house.cga"\n@StartRule\nLot --> h.Lot\n')
    assert main(["check", str(grammar)]) == 2
    assert "is in no CityEngine workspace" in capsys.readouterr().err
    assert main(["check", "--workspace", str(workspace), str(grammar)]) == 0
    assert "assets:    builtin:cube, builtin:quad, chimney.obj, Houses/assets/window.obj" in capsys.readouterr().out
    out = tmp_path / "o.npz"
    assert main(["build", "--workspace", str(workspace), str(grammar), "--emit", str(out), "--quiet"]) == 0
    assert "Houses/assets/window.obj" in list(read_instances(out)["assets"])


CITYENGINE_START = 'version "2022.0"\n@StartRule\nLot(h, floors) --> extrude(h) split(y){ ~floors : Floor }*\n'


def test_build_calls_a_start_rule_with_the_arguments_of_start(write, tmp_path, capsys):
    grammar = write("g.cga", CITYENGINE_START)
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out), "--start", "Lot(12, 3)", "--quiet"]) == 0
    record = read_instances(out)
    assert len(record["asset"]) == 4  # 12 m in floors of about 3
    np.testing.assert_allclose(record["xform"][:, 1, 1], 3)
    assert main(["check", str(grammar), "--start", "Lot(12, 3)"]) == 0
    assert "start:     Lot(12, 3)" in capsys.readouterr().out


def test_a_start_rule_with_parameters_checks_with_a_warning_and_does_not_build_without_them(write, tmp_path,
                                                                                           capsys):
    grammar = write("g.cga", CITYENGINE_START)
    assert main(["check", str(grammar)]) == 0
    assert "warning: the start rule `Lot` takes parameters (h, floors)" in capsys.readouterr().err
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out)]) == 2
    assert "build it with --start 'Lot(...)' giving their values" in capsys.readouterr().err
    assert main(["build", str(grammar), "--emit", str(out), "--start", "Lot(12)"]) == 2
    assert "--start calls `Lot` with 1 argument; it takes 2 (h, floors)" in capsys.readouterr().err
    assert not out.exists()


def test_a_cityengine_file_of_constants_only_checks_with_a_warning_and_does_not_build(write, tmp_path, capsys):
    grammar = write("config.cga", 'version "2023.1"\nconst storey = 3.2\nattr coverage = 0.7\n'
                                  "getHeight(n) = n * storey\n")
    assert main(["check", str(grammar)]) == 0
    captured = capsys.readouterr()
    assert "warning: the grammar has no rules: a file of attributes, constants and functions to import" \
        in captured.err
    assert "start:     -" in captured.out and "attrs:     storey, coverage" in captured.out
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out)]) == 2
    assert "error: the grammar has no rules" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("command", ["check", "build"])
def test_warnings_as_errors_exit_2(write, tmp_path, capsys, command):
    grammar = write("g.cga", 'version "2022.0"\n@StartRule\nLot --> extrude(3) comp(f){ side : Facdae }\n'
                             "Facade --> X\n")
    args = [command, str(grammar)] + (["--emit", str(tmp_path / "out.npz")] if command == "build" else [])
    assert main(args + ["--warnings-as-errors"]) == 2
    err = capsys.readouterr().err
    assert "error: `Facdae` has no rule, so it is a leaf (did you mean `Facade`?)" in err
    assert "2 errors; nothing was written" in err  # and the unreachable rule
    assert not (tmp_path / "out.npz").exists()
    assert main(args + ["--quiet"] * (command == "build")) == 0


def test_a_cycle_of_attributes_is_an_error_not_a_crash(write, tmp_path, capsys):
    grammar = write("g.cga", 'version "2022.0"\nattr a = b\nattr b = a\n@StartRule\nLot --> extrude(a) X\n')
    assert main(["build", str(grammar), "--emit", str(tmp_path / "out.npz")]) == 2
    assert "attribute `a` has no value: its default uses itself (attr a -> b -> a)" in capsys.readouterr().err


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_stop_a_build_as_ctrl_c_does(tmp_path, signum):
    """What `timeout`, docker, systemd and Slurm send: the build unwinds, exits 128 + the signal, and leaves
    no output, no temporary folder, no shared memory and no worker process behind."""
    with _a_build_under_way(tmp_path) as build:
        build.send_signal(signum)
        _, err = build.communicate(timeout=120)
    assert build.returncode == 128 + signum
    assert err.endswith(f"grammarc: {signal.Signals(signum).name}: stopped; nothing was written\n")


def test_a_stop_while_the_writer_makes_its_temporary_folder_leaves_none(write, tmp_path, capsys, monkeypatch):
    """SIGTERM just after the output's temporary folder is made, before the writer exists to remove it (a
    served build stopped by its client's death left the folder so, once in a loaded test run): the signal
    waits until the writer is set up, then the build stops and its abort removes the folder."""
    import grammarc.io.npz

    made = grammarc.io.npz.private_folder

    def made_then_stopped(path):
        folder = made(path)
        os.kill(os.getpid(), signal.SIGTERM)
        return folder

    monkeypatch.setattr(grammarc.io.npz, "private_folder", made_then_stopped)
    grammar = write("g.cga", "Lot --> extrude(3)\n")
    assert main(["build", str(grammar), "--emit", str(tmp_path / "out.npz"), "--quiet"]) == 128 + signal.SIGTERM
    assert capsys.readouterr().err == "grammarc: SIGTERM: stopped; nothing was written\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.cga"]


def test_a_signal_raised_inside_numbas_callback_still_stops_the_build(write, tmp_path, capsys, monkeypatch):
    """A handler that raises while compiled code calls back into Python surfaces as a SystemError caused by
    the signal (a served build caught it so): it is said and exits as the signal, not as a traceback."""
    def derive_chunk(*args, **kwargs):
        try:
            raise Stopped(signal.SIGTERM)
        except Stopped as stop:
            raise SystemError("CPUDispatcher(group_by) returned a result with an exception set") from stop

    monkeypatch.setattr("grammarc.build.derive_chunk", derive_chunk)
    grammar = write("g.cga", "Lot --> extrude(3)\n")
    assert main(["build", str(grammar), "--emit", str(tmp_path / "out.npz"), "--quiet"]) == 128 + signal.SIGTERM
    assert capsys.readouterr().err == "grammarc: SIGTERM: stopped; nothing was written\n"
    assert not (tmp_path / "out.npz").exists()


def test_a_signal_whose_raise_a_c_callback_swallows_still_stops_the_build(write, tmp_path, capsys,
                                                                           monkeypatch):
    """llvmlite's ctypes callbacks (while numba compiles) drop what a handler raises in them: the stop is
    kept, and the derivation's next round stops the build, which writes nothing and prints no traceback."""
    from grammarc import build

    swallowing = ctypes.CFUNCTYPE(None)(lambda: raise_stopped(signal.SIGTERM, None))
    derive_chunk = build.derive_chunk

    def derive_chunk_after_a_signal(*args, **kwargs):
        swallowing()  # "Exception ignored on calling ctypes callback function"
        return derive_chunk(*args, **kwargs)

    monkeypatch.setattr("grammarc.build.derive_chunk", derive_chunk_after_a_signal)
    grammar = write("g.cga", "Lot --> extrude(3) A\nA --> split(y) { 1 : B }*\n")
    assert main(["build", str(grammar), "--emit", str(tmp_path / "out.npz"), "--quiet"]) == 128 + signal.SIGTERM
    assert capsys.readouterr().err == "grammarc: SIGTERM: stopped; nothing was written\n"
    assert not (tmp_path / "out.npz").exists()


def test_a_worker_killed_by_sigkill_fails_the_build_cleanly(tmp_path):
    """What the out-of-memory killer does to a worker: one line, exit 1, and nothing left behind."""
    with _a_build_under_way(tmp_path) as build:
        workers = Path(f"/proc/{build.pid}/task/{build.pid}/children").read_text().split()
        assert workers, "the build has no worker process"
        os.kill(int(workers[0]), signal.SIGKILL)
        _, err = build.communicate(timeout=120)
    assert build.returncode == 1
    assert re.fullmatch(r"grammarc: error: a worker process was killed while deriving lots #\d+-#\d+ "
                        r"\(out of memory\?\); nothing was written: rerun with fewer --workers or a smaller "
                        r"--chunk-size\n", err)


@contextlib.contextmanager
def _a_build_under_way(tmp_path):
    """A two-worker build of 24,000 lots in a subprocess, caught in its derivation once its workers
    run (the parent derives the first chunk before it starts them): the process. After the caller has
    stopped it, nothing may be left: no output, no temporary folder, no shared memory, no process."""
    lots = [[[[x * 25, y * 25], [x * 25 + 20, y * 25], [x * 25 + 20, y * 25 + 15], [x * 25, y * 25 + 15]]]
            for x in range(120) for y in range(200)]
    geojson(tmp_path / "lots.geojson", lots)
    out = tmp_path / "out" / "city.npz"
    out.parent.mkdir()
    grammar = Path(__file__).resolve().parents[1] / "benchmarks" / "facade.cga"
    build = subprocess.Popen([sys.executable, "-m", "grammarc.cli", "build", str(grammar), "--lots",
                              str(tmp_path / "lots.geojson"), "--emit", str(out), "--workers", "2", "--quiet"],
                             stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(out.parent.glob(".city.npz.tmp*")) and build.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    children = Path(f"/proc/{build.pid}/task/{build.pid}/children")
    while build.poll() is None and not children.read_text().split() and time.monotonic() < deadline:
        time.sleep(0.02)
    assert build.poll() is None, "the build ended before it could be stopped"
    time.sleep(0.1)  # into the workers' derivation
    yield build
    assert list(out.parent.iterdir()) == []
    assert list(Path("/dev/shm").glob(f"grammarc-records-{build.pid}-*")) == []  # named by their process
    left = [p for p in Path("/proc").glob("[0-9]*") if _cmdline(p).find(str(out)) >= 0]
    assert left == []


def _cmdline(process: Path) -> str:
    try:
        return (process / "cmdline").read_bytes().decode(errors="replace")
    except OSError:  # gone meanwhile
        return ""


def test_a_bake_origin_that_is_not_three_numbers_is_refused(write, tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["build", str(write("g.cga", GOOD)), "--emit", str(tmp_path / "c.ply"), "--bake-origin", "1,2"])
    assert stop.value.code == 2
    assert "--bake-origin: must be three numbers X,Y,Z, got `1,2`" in capsys.readouterr().err
    assert not (tmp_path / "c.ply").exists()


@pytest.mark.parametrize("paths, reason", [
    (["--emit", "out.npz"], "it is a folder"),
    (["--emit", "file/out.npz"], "is a file, not a folder"),
    (["--emit", "x" * 250 + ".usdc"], "longer than the 255 a file name may have"),  # legal; its tile folder's is not
    (["--emit", "city.npz", "--reports", "out.npz"], "it is a folder"),
])
def test_an_output_path_that_cannot_be_written_is_one_line_exit_2_before_deriving(write, tmp_path, capsys,
                                                                                   monkeypatch, paths, reason):
    grammar = write("g.cga", GOOD)
    (tmp_path / "out.npz").mkdir()
    (tmp_path / "file").write_text("x")
    monkeypatch.setattr("grammarc.build.derive_all", lambda *a, **k: pytest.fail("derived before the check"))
    assert main(["build", str(grammar), *(p if p.startswith("--") else str(tmp_path / p) for p in paths)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("grammarc: error: cannot write `") and reason in err


def test_an_output_of_the_longest_legal_name_is_written(write, tmp_path):
    out = tmp_path / ("x" * 251 + ".npz")  # 255 bytes: its temporary folder's name must be shorter
    assert main(["build", str(write("g.cga", GOOD)), "--emit", str(out), "--quiet"]) == 0
    assert len(read_instances(out)["asset"]) == 4 and sorted(p.name for p in tmp_path.iterdir()) == ["g.cga", out.name]


def test_a_disk_that_fills_during_a_build_is_one_line_exit_1(write, tmp_path, capsys, monkeypatch):
    import errno

    import grammarc.io.npz

    def full(path):
        raise OSError(errno.ENOSPC, "No space left on device", path)

    monkeypatch.setattr(grammarc.io.npz, "_create", full)
    out = tmp_path / "out.npz"
    assert main(["build", str(write("g.cga", GOOD)), "--emit", str(out), "--quiet", "--workers", "1"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "No space left on device; nothing was written" in err
    assert [p.name for p in tmp_path.iterdir()] == ["g.cga"]


REPORTING = 'Lot --> report("area", geometry.area()) extrude(6) comp(f){ side : Wall. }\n'


def test_a_build_whose_reports_cannot_be_written_leaves_no_new_output(write, tmp_path, capsys, monkeypatch):
    import errno

    import grammarc.io.reports

    grammar = write("g.cga", REPORTING)
    out = tmp_path / "out.npz"
    assert main(["build", str(grammar), "--emit", str(out), "--quiet", "--workers", "1"]) == 0
    before = out.read_bytes(), (tmp_path / "out.reports.json").read_text()

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(grammarc.io.reports.json, "dumps", full)
    assert main(["build", str(grammar), "--emit", str(out), "--quiet", "--workers", "1", "--seed", "2"]) == 1
    assert "No space left on device" in capsys.readouterr().err
    assert (out.read_bytes(), (tmp_path / "out.reports.json").read_text()) == before


def test_the_libraries_warnings_do_not_reach_the_user(write, tmp_path):
    """numpy's overflow in an attribute's arithmetic (which it warns of) is not shown beside grammarc's
    messages; Python's -W still shows it to whom asks."""
    grammar = write("g.cga", 'version "2023.0"\nattr z = 0\n@StartRule\nLot --> report("big", 1e308 * (10 + z)) X.\n')
    command = ["-m", "grammarc.cli", "build", str(grammar), "--emit", str(tmp_path / "c.npz"), "--workers", "1"]
    err = subprocess.run([sys.executable, *command], capture_output=True, text=True, check=False).stderr
    assert "Warning" not in err and all(line.startswith(("grammarc:", str(tmp_path))) for line in err.splitlines())
    asked = subprocess.run([sys.executable, "-W", "always::RuntimeWarning", *command], capture_output=True, text=True,
                           check=False)
    assert "RuntimeWarning: overflow" in asked.stderr
