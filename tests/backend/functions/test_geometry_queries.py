"""backend/functions/geometry.py: CityEngine's geometry queries through compiled grammars, on footprints,
concave and holed lots, their masses, their faces and their roofs.

The values are the geometry's own, computed by hand: a 12 x 8 lot (its first edge the south one, along
world +x), the 30 x 20 L of the zoo (area 400, perimeter 100) and the 40 x 40 courtyard with its 20 x 20
hole. The selectors, the angles' compass and the edge counts are the reference's ("geometry functions").
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from backend.operations.derivations import per_lot, rect, run
from conftest import LOT_ZOO

SOUTH_EDGE_FIRST = rect(12, 8)


def values(write, text, lots):
    """Per lot, each reported key's sum (bools reported as 0/1)."""
    r = run(write, text, lots)
    return [{k[:-4]: float(v) for k, v in t.items() if k.endswith("_sum")} for t in per_lot(r).values()]


def query(write, expression, lots, prefix=""):
    """Per lot, the value of ``expression`` on the lot's shape after ``prefix`` operations."""
    return [t["q"] for t in values(write, f'Lot --> {prefix} report("q", float({expression}))\n', lots)]


# ------------------------------------------------------------------------------------------------ areas

AREAS = {  # a 12 x 8 lot extruded 10: its faces by scope, lot, world and compass
    "top": 96, "bottom": 96, "front": 120, "back": 120, "left": 80, "right": 80, "side": 400, "all": 592,
    "surface": 592, "object.top": 96, "object.front": 120, "object.side": 400, "world.up": 96,
    "world.down": 96, "world.south": 120, "world.north": 120, "world.east": 80, "world.west": 80,
    "world.side": 400,
}


@pytest.mark.parametrize("selector", sorted(AREAS))
def test_area_of_the_faces_a_selector_takes(write, selector):
    assert query(write, f"geometry.area({selector})", [SOUTH_EDGE_FIRST], "extrude(10)") == [
        pytest.approx(AREAS[selector])]


def test_area_by_floor_as_the_public_files_report_it(write):
    """``geometry.area(bottom)`` of each floor of a split mass is the floor's area, also of a concave
    mass; its top faces up, its bottom down, in the world."""
    text = ('Lot --> extrude(9) split(y){ 3 : Floor }*\n'
            'Floor --> report("b", geometry.area(bottom)) report("up", geometry.area(world.up))\n')
    got = values(write, text, [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]])
    assert [(t["b"], t["up"]) for t in got] == [pytest.approx((1200, 1200)), pytest.approx((3600, 3600))]


def test_a_flat_lot_is_its_top_face(write):
    got = values(write, 'Lot --> report("top", geometry.area(top)) report("bottom", geometry.area(bottom))\n'
                        '    report("all", geometry.area(all))\n', [LOT_ZOO["courtyard"]])
    assert got == [{"top": pytest.approx(1200), "bottom": 0, "all": pytest.approx(1200)}]


def test_is_oriented_finds_the_facades_facing_each_way(write):
    """Each facade of the L faces one way: two face north, one south, two east, one west."""
    text = ('Lot --> extrude(10) comp(f){ side : F }\n'
            'F --> ' + " ".join(f'report("{d}", float(geometry.isOriented(world.{d})))'
                                for d in ("north", "south", "east", "west", "up", "side")) + '\n')
    got, = values(write, text, [LOT_ZOO["concave_L"]])
    assert got == {"north": 2, "south": 1, "east": 2, "west": 1, "up": 0, "side": 6}


def test_is_oriented_on_a_mass_has_any_face_facing_so(write):
    assert query(write, "geometry.isOriented(object.top)", [SOUTH_EDGE_FIRST], "extrude(3)") == [1]
    assert query(write, "geometry.isOriented(left)", [SOUTH_EDGE_FIRST]) == [0]


# ----------------------------------------------------------------------------------------------- angles


def test_angles_of_hip_roof_planes(write):
    """The reference's example colours each roof face by its slope and azimuth: the planes of a 30 degree
    hip roof slope 30 degrees (zenith 60) and face south, east, north and west, in the lot's edge order."""
    text = ('Lot --> roofHip(30) comp(f){ aslant : Plane }\n'
            'Plane --> report("slope", geometry.angle(maxSlope)) report("zenith", geometry.angle(zenith))\n'
            '    report("az" + str(comp.index), geometry.angle(azimuth))\n')
    got, = values(write, text, [SOUTH_EDGE_FIRST])
    assert got["slope"] == pytest.approx(4 * 30) and got["zenith"] == pytest.approx(4 * 60)
    assert sorted(round(v, 9) for k, v in got.items() if k.startswith("az")) == [0, 90, 180, 270]


def test_a_level_lot_has_no_slope_and_a_mass_is_as_steep_as_its_walls(write):
    assert query(write, "geometry.angle(maxSlope)", [SOUTH_EDGE_FIRST]) == [0]
    assert query(write, "geometry.angle(azimuth)", [SOUTH_EDGE_FIRST]) == [0]
    assert query(write, "geometry.angle(maxSlope)", [SOUTH_EDGE_FIRST], "extrude(3)") == [pytest.approx(90)]


def test_azimuth_of_a_turned_facade(write):
    """A lot turned 30 degrees counter-clockwise on the map: its first facade faces south turned 30
    degrees east, azimuth 150."""
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    lot = [np.array([[0, 0], [10, 0], [10, 4], [0, 4]], float) @ np.array([[c, s], [-s, c]])]
    text = 'Lot --> extrude(5) comp(f){ side : F }\nF --> report("a" + str(comp.index), geometry.angle(azimuth))\n'
    got, = values(write, text, [lot])
    assert [got[f"a{i}"] for i in range(4)] == pytest.approx([150, 60, 330, 240])


# -------------------------------------------------------------------------------------------- the faces


@pytest.mark.parametrize("prefix, concave, holes", [
    ("", [0, 1, 1], [0, 0, 1]),
    ("extrude(4)", [0, 1, 1], [0, 0, 2]),  # a prism's bottom and top have the lot's holes
])
def test_concave_faces_and_holes(write, prefix, concave, holes):
    lots = [SOUTH_EDGE_FIRST, LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]]
    assert query(write, "geometry.isConcave", lots, prefix) == concave
    assert query(write, "geometry.nHoles", lots, prefix) == holes


def test_concave_lots_subdivided_as_a_public_file_does(write):
    """``case geometry.isConcave : split`` until no part is concave: the L's two arms are convex."""
    text = ('Lot --> Part\nPart --> case geometry.isConcave : split(x){ 10 : Part | ~1 : Part }\n'
            '    else : report("parts", 1) report("area", geometry.area)\n')
    got, = values(write, text, [LOT_ZOO["concave_L"]])
    assert got == {"parts": 2, "area": pytest.approx(400)}


def test_planar_faces(write):
    lots = [SOUTH_EDGE_FIRST, LOT_ZOO["courtyard"]]
    for prefix in ("", "extrude(3)", "roofHip(30)", "roofGable(45)"):
        assert query(write, "geometry.isPlanar(0.25)", lots, prefix) == [1, 1], prefix
    # an edge is no face
    assert query(write, "geometry.isPlanar(0.25)", [SOUTH_EDGE_FIRST], "comp(e){ all : E }\nE -->") == [0]


@pytest.mark.parametrize("prefix, edges, boundary, closed", [
    ("", [4, 6, 8], [40, 100, 240], [0, 0, 0]),
    ("extrude(4)", [12, 18, 24], [0, 0, 0], [1, 1, 1]),
    ("roofHip(30)", [9, 14, None], [0, 0, None], [1, 1, None]),  # base, hips and valleys, ridges
])
def test_edges_shared_by_faces(write, prefix, edges, boundary, closed):
    lots = [SOUTH_EDGE_FIRST, LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]]
    got = values(write, f'Lot --> {prefix} report("e", geometry.nEdges) report("b", geometry.boundaryLength)\n'
                        '    report("c", float(geometry.isClosedSurface))\n', lots)
    for want, key in ((edges, "e"), (boundary, "b"), (closed, "c")):
        assert [t[key] for t, w in zip(got, want) if w is not None] == pytest.approx(
            [w for w in want if w is not None]), key


def test_a_facade_is_an_open_rectangle(write):
    text = 'Lot --> extrude(10) comp(f){ front : F }\nF --> report("e", geometry.nEdges) report("b", geometry.boundaryLength)\n'
    assert values(write, text, [SOUTH_EDGE_FIRST]) == [{"e": 4, "b": pytest.approx(44)}]


def test_height_in_the_world(write):
    """A mass is as high as it is extruded, a flat lot 0, a hip roof on 8 m of depth 4 tan 30 and a
    facade 10 m, also after its scope alone is turned about its normal; the face turned with it (``r``)
    stands 12 m."""
    lots = [SOUTH_EDGE_FIRST]
    assert query(write, "geometry.height", lots, "extrude(10)") == [pytest.approx(10)]
    assert query(write, "geometry.height()", lots) == [0]
    assert query(write, "geometry.height", lots, "roofHip(30)") == [pytest.approx(4 * math.tan(math.radians(30)))]
    facade = "extrude(10) comp(f){ front : F }\nF --> "
    assert query(write, "geometry.height", lots, facade + "rotateScope(0, 0, 90)") == [pytest.approx(10)]
    assert query(write, "geometry.height", lots, facade + "r(0, 0, 90)") == [pytest.approx(12)]


def test_is_instanced_after_an_insert(write):
    write("box.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nf 1 2 3\nf 1 3 4\n")
    assert query(write, "geometry.isInstanced", [SOUTH_EDGE_FIRST], 'extrude(2) i("box.obj")') == [1]
    assert query(write, "geometry.isInstanced", [SOUTH_EDGE_FIRST], "extrude(2)") == [0]


# ------------------------------------------------------------------------------------- batches, errors


def test_a_batch_gives_each_lot_what_it_gets_alone(write):
    """Every query on a mixed batch of lots (rectangles of many sizes, L's, courtyards; their masses,
    facades and roofs) equals the query on each lot derived alone."""
    rng = np.random.default_rng(7)
    lots = [rect(*rng.uniform(3, 30, 2)) for _ in range(12)] + [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]] * 3
    queries = ("geometry.area(top)", "geometry.area(world.south)", "geometry.angle(azimuth)", "geometry.isConcave",
               "geometry.nHoles", "geometry.nEdges", "geometry.boundaryLength", "geometry.isClosedSurface",
               "geometry.isPlanar(1)", "geometry.height", "geometry.isOriented(object.left)")
    report = " ".join(f'report("{k}{{0}}", float({q}))' for k, q in enumerate(queries))
    text = (f'Lot --> {report.format("lot")} extrude(2 + scope.sx / 3) {report.format("mass")} R\n'
            f'R --> comp(f){{ side : F | top : roofHip(25) G }}\n'
            f'F --> {report.format("facade")}\nG --> {report.format("roof")}\n')
    together = values(write, text, lots)
    alone = [values(write, text, [lot])[0] for lot in lots[::5]]
    assert [t for t in together[::5]] == alone


@pytest.mark.parametrize("prefix, want", [
    # convexify: the L's arm that keeps the cut's end as a fifth corner is not a rectangle (as in PRT)
    ("", [1, 0]), ("extrude(3)", [1, 0]), ("convexify()", [1, 0]),
    ("roofHip(30)", [0, 0]), ("extrude(3) comp(e){ all : E }\nE -->", [0, 0]),  # an edge has no face
    ('extrude(3) i("box.obj")', [0, 0]),  # an asset's faces are not known
])
def test_rectangular_when_every_face_is(write, prefix, want):
    write("box.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    assert query(write, "geometry.isRectangular(1)", [SOUTH_EDGE_FIRST, LOT_ZOO["concave_L"]], prefix) == want
