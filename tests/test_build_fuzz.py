"""The whole build under fuzzing: random grammars of both dialects on random lots.

Whatever the grammar and the lots, `grammarc build` ends in one of four ways, each clean:
- a grammar error: exit 2, every message `file:line:col: error:`, nothing written;
- a build: exit 0, every value of the output finite, and every skipped lot named on stderr with its reason;
- no lot built: exit 1, said in one line, nothing written;
- a refused input (lots that cannot be read at all): exit 1 or 2, one line.
Never a traceback, never a warning that is not grammarc's own, never more memory than the bound.

The grammars are drawn from a small generator of CityEngine CGA and of the paper's notation whose numbers
come from a list of hostile values (zero, negative, 1e-9, 1e308, a division by zero) beside ordinary ones;
the lots from rectangles of extreme sizes and places, random polygons (self-intersecting, degenerate),
holes, and attributes of the wrong type. In CI the default profile runs a few hundred examples; run it long
with `pytest tests/test_build_fuzz.py --hypothesis-profile long`.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import resource
import tempfile
import warnings
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from grammarc.cli import main
from grammarc.io.npz import read_instances

#: How much more address space than at its start a fuzzed build may take.
MEMORY_BOUND = 2 << 30
#: Shapes per lot: low, so that a shape explosion is caught quickly (the limit is the same code).
MAX_SHAPES = 50_000

#: The values of the attributes and the literals of expressions.
LITERALS = ["0", "1", "-1", "0.5", "3", "12", "1e-9", "1e-18", "1e9", "1e308", "-1e308"]
#: Numbers in expressions: literals, attributes, and a division by an attribute that may be 0 (a division
#: by a constant 0 is a grammar error).
NUMBERS = [*LITERALS, "h", "w", "(h / w)"]
FLOATS = [0.0, 1.0, 3.0, 10.0, -2.0, 1e-9, 1e9, 1e308]


@st.composite
def numbers(draw) -> str:
    """An expression of a number: a hostile or ordinary literal, an attribute, or a little arithmetic."""
    first = draw(st.sampled_from(NUMBERS))
    if draw(st.booleans()):
        return first
    return f"{first} {draw(st.sampled_from(['+', '-', '*']))} {draw(st.sampled_from(NUMBERS))}"


@st.composite
def cityengine_grammars(draw) -> str:
    """A CityEngine CGA file of a few rules, each naming only later rules (and, sometimes, itself)."""
    n = draw(st.integers(1, 5))
    names = ["Lot"] + [f"R{i}" for i in range(1, n)]
    lines = ['version "2022.0"', f"attr h = {draw(st.sampled_from(LITERALS))}",
             f"attr w = {draw(st.sampled_from(LITERALS))}"]
    for k, name in enumerate(names):
        later = names[k + 1:] + ["X.", 'i("builtin:cube")', "NIL"] + [name] * draw(st.integers(0, 1))

        def successor(later=later) -> str:
            return draw(st.sampled_from(later))

        def size() -> str:
            return draw(st.sampled_from(["", "~", "'"])) + draw(numbers())

        ops = draw(st.lists(st.sampled_from([
            "extrude", "split", "repeat", "comp", "setback", "offset", "roof", "transform", "insert", "color",
        ]), min_size=1, max_size=3))
        body = []
        for op in ops:
            if op == "extrude":
                body.append(f"extrude({draw(numbers())})")
            elif op == "split":
                parts = " | ".join(f"{size()} : {successor()}" for _ in range(draw(st.integers(1, 3))))
                body.append(f"split({draw(st.sampled_from('xyz'))}){{ {parts} }}")
            elif op == "repeat":
                body.append(f"split({draw(st.sampled_from('xyz'))}){{ {size()} : {successor()} }}*")
            elif op == "comp":
                body.append(f"comp(f){{ top : {successor()} | side : {successor()} | bottom : {successor()} }}")
            elif op == "setback":
                body.append(f"setback({draw(numbers())}){{ front : {successor()} | remainder : {successor()} }}")
            elif op == "offset":
                body.append(f"offset({draw(numbers())}, {draw(st.sampled_from(['inside', 'border', 'all']))})")
            elif op == "roof":
                kind = draw(st.sampled_from(["roofHip", "roofGable", "roofShed", "roofPyramid"]))
                body.append(f"{kind}({draw(numbers())})")
            elif op == "transform":
                kind = draw(st.sampled_from(["t", "s", "r"]))
                body.append(f"{kind}({draw(numbers())}, {draw(numbers())}, {draw(numbers())})")
            elif op == "insert":
                body.append('i("builtin:cube")')
            else:
                body.append('color("#ff8000")')
        tail = "" if body[-1].endswith("}") or body[-1].endswith("}*") else f" {successor()}"
        rule = f"{name} --> {' '.join(body)}{tail}"
        if draw(st.booleans()):
            rule = f"{name} -->\n    case {draw(numbers())} > {draw(numbers())} : {' '.join(body)}{tail}\n    else : {successor()}"
        lines.append(("@StartRule\n" if k == 0 else "") + rule)
    return "\n".join(lines) + "\n"


@st.composite
def paper_grammars(draw) -> str:
    """A grammar in the CGA paper's notation: scope, subdivisions, repeats, components, roofs."""
    n = draw(st.integers(1, 5))
    names = ["lot"] + [f"r{i}" for i in range(1, n)]
    lines = [f"attr h = {draw(st.sampled_from(LITERALS))}", f"attr w = {draw(st.sampled_from(LITERALS))}"]
    for k, name in enumerate(names):
        later = names[k + 1:] + ['I("cube")', "ε"] + [name] * draw(st.integers(0, 1))

        def successor(later=later) -> str:
            return draw(st.sampled_from(later))

        def size() -> str:
            return draw(numbers()) + draw(st.sampled_from(["", "r"])) if draw(st.booleans()) else "1r"

        op = draw(st.sampled_from(["S", "T", "Subdiv", "Repeat", "Comp", "Roof"]))
        if op in "ST":
            body = f"{op}({size() if op == 'S' else draw(numbers())}, {draw(numbers())}, {draw(numbers())}) {successor()}"
        elif op == "Subdiv":
            sizes = [size() for _ in range(draw(st.integers(1, 3)))]
            body = f'Subdiv("{draw(st.sampled_from("XYZ"))}", {", ".join(sizes)}){{ ' \
                   + " | ".join(successor() for _ in sizes) + " }"
        elif op == "Repeat":
            body = f'Repeat("{draw(st.sampled_from("XY"))}", {draw(numbers())}){{ {successor()} }}'
        elif op == "Comp":
            body = f'Comp("{draw(st.sampled_from(["sidefaces", "top", "faces"]))}"){{ {successor()} }}'
        else:
            body = f'Roof("{draw(st.sampled_from(["hipped", "gable"]))}", {draw(numbers())}){{ {successor()} }}'
        lines.append(f"{name} ~> {body}")
    return "\n".join(lines) + "\n"


@st.composite
def lots(draw) -> dict:
    """A GeoJSON feature collection of one to four lots: rectangles of extreme sizes and places, random
    polygons, holes, and a property `h` of any JSON type."""
    features = []
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["rectangle", "polygon", "courtyard"]))
        x0, y0 = draw(st.sampled_from([0.0, 1e3, 5e5, 6e6])), draw(st.sampled_from([0.0, -1e3, 5e6]))
        if kind == "polygon":
            points = draw(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=0, max_size=9))
            rings = [[[x0 + x, y0 + y] for x, y in points]]
        else:
            sx, sy = draw(st.sampled_from(FLOATS[1:])), draw(st.sampled_from(FLOATS[1:]))
            rings = [[[x0, y0], [x0 + sx, y0], [x0 + sx, y0 + sy], [x0, y0 + sy]]]
            if kind == "courtyard":
                rings.append([[x0 + sx / 4, y0 + sy / 4], [x0 + sx / 4, y0 + 3 * sy / 4],
                              [x0 + 3 * sx / 4, y0 + 3 * sy / 4], [x0 + 3 * sx / 4, y0 + sy / 4]])
        for ring in rings:
            if ring:
                ring.append(ring[0])
        properties = {}
        if draw(st.booleans()):
            properties["h"] = draw(st.one_of(st.sampled_from(FLOATS), st.booleans(), st.text(max_size=3),
                                             st.none()))
        features.append({"type": "Feature", "properties": properties,
                         "geometry": {"type": "Polygon", "coordinates": rings}})
    return {"type": "FeatureCollection", "features": features}


@contextlib.contextmanager
def _memory_bound(extra: int):
    """Address space limited to what the process has now plus ``extra`` bytes: an allocation beyond it
    raises MemoryError (a crash, as the test sees it) instead of swapping the machine."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    in_use = int(Path("/proc/self/statm").read_text().split()[0]) * resource.getpagesize()
    resource.setrlimit(resource.RLIMIT_AS, (in_use + extra, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _build_and_check(grammar: str, lot_collection: dict) -> None:
    """``grammarc build`` in this process, in a folder of its own, and its ending checked."""
    with tempfile.TemporaryDirectory(prefix="grammarc-fuzz-") as folder:
        _check(grammar, *_build(Path(folder), grammar, lot_collection), len(lot_collection["features"]))


def _build(folder: Path, grammar: str, lot_collection: dict) -> tuple[int, str, Path]:
    """``grammarc build`` in this process: exit code, stderr and the output path."""
    (folder / "g.cga").write_text(grammar, encoding="utf-8")
    (folder / "lots.geojson").write_text(json.dumps(lot_collection), encoding="utf-8")
    out = folder / "out" / "city.npz"
    out.parent.mkdir()
    err = io.StringIO()
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = lambda message, category, filename, lineno, file=None, line=None: err.write(
            warnings.formatwarning(message, category, filename, lineno, line))
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()), _memory_bound(MEMORY_BOUND):
            try:
                code = main(["build", str(folder / "g.cga"), "--lots", str(folder / "lots.geojson"),
                             "--emit", str(out), "--workers", "1", "--max-shapes", str(MAX_SHAPES)])
            except SystemExit as stop:  # argparse
                code = stop.code
    return code, err.getvalue(), out


def _check(grammar: str, code: int, err: str, out: Path, n_lots: int) -> None:
    """The four clean endings of the module's docstring; the grammar in the message of any failure."""
    where = f"\n--- grammar ---\n{grammar}--- stderr ---\n{err}"
    assert "Traceback" not in err and "Warning:" not in err, where
    written = sorted(p.name for p in out.parent.iterdir())
    if code == 2:
        assert written == [], where
        assert re.search(r"\d+ errors?; nothing was written\n$|^grammarc: error: ", err), where
        return
    if code == 1:
        assert written == [], where
        assert re.search(r"^grammarc: (error: |none of the )", err, re.MULTILINE), where
        return
    assert code == 0, where
    assert written == ["city.npz"], where
    record = read_instances(out)
    # a lot without rows has no origin: NaN (the record's layout)
    assert np.isfinite(record["xform"]).all() and np.isfinite(record["lot_origin"][record["lot"]]).all(), where
    if "mesh" in record:
        assert np.isfinite(record["mesh"].vertices).all(), where
    assert (record["lot"] < n_lots).all(), where
    named = re.findall(r"^grammarc: lot .* \(#(\d+)\) skipped: .+$", err, re.MULTILINE)
    said = re.search(r"^grammarc: ([\d,]+) of ([\d,]+) lots skipped$", err, re.MULTILINE)
    assert len(named) == (int(said.group(1).replace(",", "")) if said else 0), where
    assert not set(map(int, named)) & set(np.unique(record["lot"]).tolist()), where


FUZZ = settings(suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large], deadline=None)


@FUZZ
@given(grammar=cityengine_grammars(), lot_collection=lots())
def test_cityengine_grammars_on_any_lots_end_cleanly(grammar, lot_collection):
    _build_and_check(grammar, lot_collection)


@FUZZ
@given(grammar=paper_grammars(), lot_collection=lots())
def test_paper_grammars_on_any_lots_end_cleanly(grammar, lot_collection):
    _build_and_check(grammar, lot_collection)
