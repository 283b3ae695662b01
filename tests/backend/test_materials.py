"""backend/materials.py: a shape's colour, opacity and texture channels, read and set by the grammar and
carried into the record."""

from __future__ import annotations

import numpy as np
import pytest
from operations.derivations import VERSION, names, rect, run, totals

from grammarc.backend import materials
from grammarc.backend.derive import derive_chunk
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS
from grammarc.io.lots import lots_from_polygons

OPTIONS = {"seed": 0, "limits": LIMITS, "overrides": {}, "chunk_budget": 10**9}


def test_packed_colours_keep_their_opacity_apart():
    """Opaque colours are the numbers they always were; an opacity sits above them and survives a new colour."""
    red = np.array([float(0xFF0000)])
    assert materials.rgba(red).tolist() == [[255, 0, 0, 255]]
    faded = materials.with_opacity(red, np.array([0.25]))
    assert materials.rgba(faded).tolist() == [[255, 0, 0, 64]]
    assert materials.channel("material.opacity", faded) == pytest.approx(64 / 255)
    blue = materials.with_transparency_of(np.array([float(0x0000FF)]), faded)
    assert materials.rgba(blue).tolist() == [[0, 0, 255, 64]]
    assert materials.channel("material.color.b", blue) == 1.0
    assert materials.channel("material.color.r", None) == 1.0  # no colour set: white and opaque


def test_rgba_takes_each_channel_from_its_byte_of_the_packed_colour():
    rng = np.random.default_rng(3)
    packed = np.r_[0.0, 0xFFFFFF, 0xFF000000, 0xFFFFFFFF, rng.integers(0, 2**32, 50)].astype(np.float64)
    value = packed.astype(np.int64)
    want = [[v >> 16 & 255, v >> 8 & 255, v & 255, 255 - (v >> 24 & 255)] for v in value.tolist()]
    got = materials.rgba(packed)
    assert got.dtype == np.uint8 and got.tolist() == want
    assert materials.rgba(packed[:0]).shape == (0, 4)


def test_colour_components_and_opacity_are_read_and_set(write):
    r = run(write, 'Lot --> report("r0", material.color.r) report("o0", material.opacity) color(1, 0.5, 0)\n'
                   '    set(material.opacity, 0.25) set(material.color.b, material.color.g / 2)\n'
                   '    report("g", material.color.g) report("b", material.color.b) report("o", material.opacity)\n'
                   '    color("#00ff00") report("o2", material.opacity) X.\n', [rect(2, 2)])
    t = totals(r)
    assert (t["r0_sum"], t["o0_sum"]) == (1.0, 1.0)
    assert (t["g_sum"], t["b_sum"]) == pytest.approx((128 / 255, 64 / 255))
    assert t["o_sum"] == t["o2_sum"] == pytest.approx(64 / 255)  # color() keeps the opacity


def test_texture_channels_are_read_by_expressions(write):
    r = run(write, 'Lot --> extrude(3) comp(f){ top : texture("roof.jpg") Part | side : Part }\n'
                   'Part --> case material.colormap == "roof.jpg" : Roof.\n'
                   '    case material.colormap == "" && material.bumpmap == "" : Side.\n    else : Other.\n',
            [rect(2, 2)])
    assert sorted(names(r)) == ["Roof"] + ["Side"] * 4


def test_records_carry_a_table_of_materials_and_a_row_per_instance_and_face(write):
    """Texture paths are kept as written; rows without a texture take the material of none."""
    text = ('Lot --> extrude(3) comp(f){ top : texture("roof.jpg") set(material.normalmap, "n.png") Top\n'
            '    | side : set(material.colormap, "wall" + ".jpg") primitiveCube() | bottom : Bottom. }\n'
            'Top --> setback(0.5){ all : Rim. | remainder : Inner. }\n')
    grammar = compile_grammar(write("g.cga", VERSION + text))
    chunk, _ = derive_chunk(make_plan(grammar), lots_from_polygons([rect(4, 4)]), **OPTIONS)
    table = [tuple(row) for row in chunk.materials]
    none, wall, roof = ("",) * 10, ("wall.jpg",) + ("",) * 9, ("roof.jpg",) + ("",) * 4 + ("n.png",) + ("",) * 4
    assert sorted(table) == sorted([none, wall, roof])
    assert chunk.mesh.materials is chunk.materials
    rows = [table[m] for m in chunk.material] + [table[m] for m in chunk.mesh.material]
    # the four side walls, the bottom, the roof's inner quad and its rim (a face with a hole)
    assert sorted(rows) == sorted([wall] * 4 + [none] + [roof] * 2)
    assert table[chunk.mesh.material[0]] == roof


def test_a_grammar_without_textures_records_no_materials(write):
    grammar = compile_grammar(write("g.cga", VERSION + 'Lot --> color(1, 0, 0) extrude(3) Mass.\n'))
    plan = make_plan(grammar)
    assert plan.material_slots == ()
    chunk, _ = derive_chunk(plan, lots_from_polygons([rect(4, 4)]), **OPTIONS)
    assert chunk.materials is None and chunk.material is None and chunk.mesh.material is None


@pytest.mark.parametrize("names", [7, 100_000])  # keys as ids in base 7; rows, past 2^62
def test_the_table_of_materials_is_that_of_every_row_though_only_runs_are_sorted(names):
    class Plan:  # what collect_materials reads of a plan
        strings = type("Strings", (), {"ids": {f"s{k}": k for k in range(names)}})()
        material_slots = ((0, 10), (1, 11), (2, 12), (3, 13))

    rng = np.random.default_rng(5)
    runs = rng.integers(0, names, (300, 4)).astype(np.int32)
    ids = np.repeat(runs, rng.integers(1, 6, len(runs)), axis=0)  # runs of one to five equal rows
    table, material = materials.collect_materials(Plan, ids)
    assert len(table) == len(np.unique(ids, axis=0))  # each distinct row once
    assert table[material, :4].tolist() == [[f"s{i}" for i in row] for row in ids]  # each row its own
    empty_table, empty = materials.collect_materials(Plan, ids[:0])
    assert empty_table.shape[0] == 0 and empty.shape == (0,)
