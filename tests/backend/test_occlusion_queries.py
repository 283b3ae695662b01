"""CityEngine's occlusion queries in derivations: no window where a mass meets another (intra), where a
building meets its neighbour (inter, the same whatever the chunking), and labelled occluders."""

from __future__ import annotations

import numpy as np
from conftest import in_world
from operations.derivations import names, of_symbol, rect, run

MASSES = """
Lot --> [ s('0.6, '1, '1) Mass ] t('0.4, 0, 0) s('0.6, '1, '1) Mass
Mass --> extrude(10) comp(f){ side : Facade }
Facade --> split(x){ ~2 : Tile }*
Tile --> case {query} : Wall. else : Window.
"""


def count(record, name):
    return int((np.array(names(record)) == name).sum())


def test_no_window_where_two_masses_of_a_lot_meet(write):
    """Two 18 x 20 m masses overlapping by 6 m: the tiles of a front or back in the other's face, and
    the sides inside the other mass, are walls; 2 x (6 + 6 + 10) windows are left."""
    r = run(write, MASSES.replace("{query}", "touches(intra)"), [rect(30, 20)])
    assert r["bad"] == ()
    assert count(r, "Window") == 44 and count(r, "Wall") == 2 * (3 + 3 + 10)
    # overlaps: only the sides inside the other mass; inside: those and the coplanar front tiles
    assert count(run(write, MASSES.replace("{query}", "overlaps(intra)"), [rect(30, 20)]), "Wall") == 20
    assert count(run(write, MASSES.replace("{query}", "inside(intra)"), [rect(30, 20)]), "Wall") == 32


NEIGHBOURS = """
Lot --> extrude(10) comp(f){ side : Facade }
Facade --> split(x){ ~2 : Tile }*
Tile --> case touches() : Wall. else : Window.
"""


def test_no_window_on_a_wall_shared_with_the_neighbour_whatever_the_chunking(write):
    lots = [rect(20, 20), [np.array([[20, 0], [40, 0], [40, 20], [20, 20]], float)],
            [np.array([[100, 0], [120, 0], [120, 20], [100, 20]], float)]]
    r = run(write, NEIGHBOURS, lots)
    walls = np.array(names(r)) == "Wall"
    # the two touching lots lose their shared side's 10 tiles each; the lot far away loses none
    assert np.bincount(r["lot"][walls], minlength=3).tolist() == [10, 10, 0]
    again = run(write, NEIGHBOURS, lots, chunk_size=1)
    np.testing.assert_array_equal(r["xform"], again["xform"])
    assert names(r) == names(again)
    # intra only: a lot does not see its neighbour
    assert count(run(write, NEIGHBOURS.replace("touches()", "touches(intra)"), lots), "Wall") == 0


def test_a_labelled_occluder_is_seen_by_its_label_only(write):
    text = """
Lot --> [ s(4, 3, 4) t(2, 0, 2) primitiveCube() label("kiosk") ] extrude(10) comp(f){ bottom : Floor }
Floor --> split(x){ ~2 : Cell }*
Cell --> case overlaps(all, "kiosk") : Taken. case touches(all, "tree") : Shaded. else : Free.
"""
    r = run(write, text, [rect(20, 20)])
    # the floor's 2 m strips at x 2..6 (two of them) run under the kiosk's 4 x 4 m base
    assert count(r, "Taken") == 0 and count(r, "Shaded") == 0  # a face on the base touches, not overlaps
    r = run(write, text.replace("overlaps(all", "touches(all"), [rect(20, 20)])
    assert count(r, "Taken") == 2 and count(r, "Free") == 8


def test_targets_and_labels_computed_per_lot(write):
    """``label(variable)`` and ``touches(sel(variable), variable)``, as ESRI.lib's fences write them: each lot
    labels its kiosk and seeks its own label, in the targets its attribute names."""
    text = """
attr mark = "kiosk"
attr seek = "kiosk"
attr where = "all"
Lot --> [ s(4, 3, 4) t(2, 0, 2) primitiveCube() label(mark) ] extrude(10) comp(f){ bottom : Floor }
Floor --> split(x){ ~2 : Cell }*
Cell --> case touches(sel(where), seek) : Taken. else : Free.
"""
    lots = [[np.array([[x, 0], [x + 20, 0], [x + 20, 20], [x, 20]], float)] for x in (0, 100, 200, 300, 400)]
    attrs = {"mark": ["kiosk", "kiosk", "kiosk", "kiosk", "tree"], "seek": ["kiosk", "tree", "kiosk", "kiosk", "tree"],
             "where": ["all", "all", "inter", "intra", "sel"]}
    r = run(write, text, lots, lot_attrs=attrs)
    taken = np.array(names(r)) == "Taken"
    # the lots far apart see only their own kiosk: where they seek it, with its label, in their own lot
    assert np.bincount(r["lot"][taken], minlength=5).tolist() == [2, 0, 0, 2, 2]


FIG13 = """
lot ~> S(1r, 10, 1r) facades
facades ~> Comp("sidefaces"){ facade }
facade ~> Repeat("X", 2){ tile }
tile : Shape.occ("noparent") == "none" ~> window
tile : Shape.occ("noparent") == "part" ~> wall
tile ~> ε
"""


def test_fig13_no_window_where_a_building_meets_its_neighbours(write):
    """Three buildings on touching 20 x 20 m lots (the paper's Fig. 13): the tiles of the walls they
    share lie on the neighbour's surface ("full") and go; the ends keep three facades, the middle two."""
    lots = [[np.array([[x, 0], [x + 20, 0], [x + 20, 20], [x, 20]], float)] for x in (0, 20, 40)]
    r = run(write, FIG13, lots, version=False)
    windows = np.array(names(r)) == "window"
    assert np.bincount(r["lot"][windows], minlength=3).tolist() == [30, 20, 30]
    assert count(r, "wall") == 0
    # "all" counts the building's own mass: every tile is fully occluded by its parent
    assert count(run(write, FIG13.replace('"noparent"', '"all"'), lots, version=False), "window") == 0


def test_an_enlarged_scope_finds_a_neighbour_a_little_away(write):
    """Shape.occ("noparent", "distance", d): buildings 1 m apart; with d = 1.5 the facing sides' tiles
    (10 each) and the end tiles of the fronts and backs next to the gap (4) reach the neighbour ("part");
    with d = 0.5 none do."""
    lots = [[np.array([[x, 0], [x + 20, 0], [x + 20, 20], [x, 20]], float)] for x in (0, 21)]
    near = FIG13.replace('Shape.occ("noparent")', 'Shape.occ("noparent", "distance", 1.5)')
    r = run(write, near, lots, version=False)
    assert count(r, "wall") == 24 and count(r, "window") == 80 - 24
    far = FIG13.replace('Shape.occ("noparent")', 'Shape.occ("noparent", "distance", 0.5)')
    r = run(write, far, lots, version=False)
    assert count(r, "wall") == 0 and count(r, "window") == 80


def test_only_the_facades_that_see_the_street_see_it(write):
    """Section 4 rule 3: Shape.visible("street"). A 20 x 15 m lot whose street is its first (south) edge:
    the south facade faces the street; the north one looks through its own building; the two side ones,
    on the lot's boundary, have no street ahead of them (a party wall of a row must not get the door).
    Set back 2 m from the sides, the side facades see the street obliquely."""
    text = """
lot ~> S(1r, 10, 1r) facades
facades ~> Comp("sidefaces"){ facade }
facade : Shape.visible("street") ~> seen
facade ~> hidden
"""
    lot = [np.array([[0, 0], [20, 0], [20, 15], [0, 15]], float)]
    for street in ([8, 0, 0, 0], None):  # marked, or the lot's first edge by default
        from grammarc.build import BuildOptions, derive
        from grammarc.compiler import compile_grammar
        from grammarc.io.lots import lots_from_polygons

        r = in_world(derive(compile_grammar(write("v.cga", text)), lots_from_polygons([lot], street=[street]),
                            BuildOptions()))
        seen = r["xform"][np.array(names(r)) == "seen"].astype(float)
        assert len(seen) == 1 and count(r, "hidden") == 3
        np.testing.assert_allclose(seen[0, 2, 3], 0)  # the south facade (map y = 0: world z = 0)
        inset = text.replace("S(1r, 10, 1r)", "S(1r, 10, 1r) T(2, 0, 0) S(Scope.sx - 4, 10, 1r)")
        r = derive(compile_grammar(write("w.cga", inset)), lots_from_polygons([lot], street=[street]),
                   BuildOptions())
        assert count(r, "seen") == 3 and count(r, "hidden") == 1


def test_section5_compares_visibility_with_zero(write):
    """Section 5 rule 5 writes ``Shape.visible("Street") == 0``: a truth value compares as 1 or 0."""
    text = """
lot ~> S(1r, 10, 1r) facades
facades ~> Comp("sidefaces"){ facade }
facade : Shape.visible("Street") == 0 ~> hidden
facade ~> seen
"""
    r = run(write, text, [[np.array([[0, 0], [20, 0], [20, 15], [0, 15]], float)]], version=False)
    assert count(r, "hidden") == 3 and count(r, "seen") == 1  # the back, and the sides on the boundary


def test_section6_trees_keep_their_distance_from_the_house(write):
    """Section 6: trees are kept at a distance from the house. The paper names a shape by its symbol, so
    Shape.occ("house", "distance", 2.5) sees the house only: of a row of ten 2 m trees across the house's
    10 m front, the two end ones, more than 2.5 m from it, stay."""
    text = """
lot ~> S(1r, 0, 1r) [ T(5, 0, 6) S(10, 6, 8) house ] trees
trees ~> Subdiv("Z", 9, 2, 1r){ ε | row | ε }
row ~> Repeat("X", 2){ tree }
tree : Shape.occ("house", "distance", 2.5) == "none" ~> S(1r, 4, 1r) I("tree.obj")
tree ~> ε
"""
    r = run(write, text, [rect(20, 20)], version=False)
    x = np.sort(r["xform"][np.array(names(r)) == "tree"][:, 0, 3].astype(float))
    assert len(x) == 2 and count(r, "house") == 1
    # any other label sees nothing: every tree stays
    assert count(run(write, text.replace('"house"', '"garage"'), [rect(20, 20)], version=False), "tree") == 10


def test_section6_the_driveway_takes_the_sidewalk_where_they_cross(write):
    """Section 6 lays the sidewalk and the driveway as overlapping shapes and resolves the conflict later
    with an occlusion query: the driveway (priority 1) crosses the 2 m sidewalk at x 11.5..15.5, and the
    sidewalk's slabs (priority 2) that it covers are dropped, so no slab lies under the driveway."""
    text = """
PRIORITY 1:
lot ~> S(1r, 0, 1r) [ T(11.5, 0, 0) S(4, 0.1, 8) driveway ] Subdiv("Z", 2, 1r){ sidewalk | yard }
PRIORITY 2:
sidewalk ~> Repeat("X", 1.4){ slab }
slab : Shape.occ("driveway") == "none" ~> S(1r, 0.1, 1r) I("slab.obj")
slab ~> ε
"""
    r = run(write, text, [rect(20, 20)], version=False)
    slabs = np.array(names(r)) == "slab"
    left = r["xform"][slabs][:, 0, 3].astype(float)
    right = left + r["xform"][slabs][:, 0, 0].astype(float)
    # 15 slabs of 4/3 m; the four between x 10.67 and 16 run under the driveway
    assert slabs.sum() == 11 and count(r, "driveway") == 1
    assert np.all((right <= 11.5) | (left >= 15.5))
    # without the driveway the sidewalk is whole
    assert count(run(write, text.replace("driveway ]", "ramp ]"), [rect(20, 20)], version=False), "slab") == 15


def test_a_mass_split_by_two_component_splits_is_one_occluder(write):
    """Two Comp()s of one mass: their faces (opposite sides of the box) do not see the mass as another
    shape, as they would if each split registered it again."""
    text = """
lot ~> S(10, 6, 10) Comp("sideface", 0){ a } Comp("sideface", 2){ a }
a : Scope.occ("noparent") != "none" ~> hit
a ~> free
"""
    r = run(write, text, [rect(20, 20)], version=False)
    assert count(r, "free") == 2 and count(r, "hit") == 0


SPREAD = """
Lot --> split(x){ ~2 : Strip(split.index) }*
Strip(i) --> split(z){ ~2 : Cell(i, split.index) }*
Cell(i, j) --> [ case i == 2 && j == 2 : label("centre") else : NIL ] Rise(minimumDistance(intra, "centre"))
Rise(d) --> case d < 5 : extrude(5 - d) Block. else : NIL
"""


def test_minimum_distance_raises_the_cells_near_a_labelled_one(write):
    """The reference's example: a grid of 2 m cells, the one at (2, 2) labelled (a face: its scope counts),
    each cell extruded by 5 minus its distance to it, the gap between their rectangles."""
    r = run(write, SPREAD, [rect(30, 20)])
    blocks = of_symbol(r, "Block")
    xform = r["xform"][blocks]
    i, j = np.rint(xform[:, 0, 3] / 2).astype(int), np.rint((xform[:, 2, 3] + 20) / 2).astype(int)
    gap = np.hypot(2 * np.maximum(np.abs(i - 2) - 1, 0), 2 * np.maximum(np.abs(j - 2) - 1, 0))
    np.testing.assert_allclose(xform[:, 1, 1], 5 - gap)  # the cell and its neighbours (gap 0) rise 5 m
    assert sorted(set(np.round(5 - gap, 3))) == [0.528, 1.0, 2.172, 3.0, 5.0]
    assert blocks.sum() == 35 and count(r, "Cell") == 1  # the labelled face is a leaf of its own


TOWERS = """
attr mark = "tower"
Lot --> [ s(4, 0, 4) center(xz) extrude(30) label(mark) Tower. ] split(x){ ~5 : Plot }*
Plot --> Post(minimumDistance({target}, "tower"))
Post(d) --> case isinf(d) : Far. else : s(1, d, 1) Post.
"""


def test_minimum_distance_to_the_labels_of_other_lots_whatever_the_chunking(write):
    """Two 20 m lots 10 m apart, a tower labelled at the centre of the first (x 8..12) only: the plots
    of the second (x 30..50) measure the distance to it with ``inter``, their own lot's with ``intra``."""
    lots = [rect(20, 20), [np.array([[30, 0], [50, 0], [50, 20], [30, 20]], float)]]
    attrs = {"mark": ["tower", "none"]}
    r = run(write, TOWERS.replace("{target}", "inter"), lots, lot_attrs=attrs)
    posts = of_symbol(r, "Post")
    assert (r["lot"][posts] == 1).all() and count(r, "Far") == 4  # the first lot sees no other tower
    np.testing.assert_allclose(sorted(r["xform"][posts][:, 1, 1]), [18, 23, 28, 33])
    again = run(write, TOWERS.replace("{target}", "inter"), lots, lot_attrs=attrs, chunk_size=1)
    np.testing.assert_array_equal(r["xform"], again["xform"])
    r = run(write, TOWERS.replace("{target}", "intra"), lots, lot_attrs=attrs)
    posts = of_symbol(r, "Post")
    # the first lot's plots: x 0..5 and 15..20 are 3 m from the tower, 5..10 and 10..15 under it
    assert (r["lot"][posts] == 0).all() and count(r, "Far") == 4
    np.testing.assert_allclose(sorted(r["xform"][posts][:, 1, 1]), [0, 0, 3, 3])
    r = run(write, TOWERS.replace("{target}", "all").replace('"tower")', '"")'), lots, lot_attrs=attrs)
    assert count(r, "Far") == 8  # an empty label finds nothing: infinity


def test_context_count_counts_every_label_of_the_target(write):
    """The reference's example: a lot cut into 1 m tiles, each labelled, then sized by how many tiles
    are labelled; every label() counts, a tile's own included, ``inter`` the other lots' only."""
    text = """
Lot --> split(x){ ~1 : Strip }*
Strip --> split(z){ ~1 : Tile }*
Tile --> label("Tile") Count
Count --> s(contextCount({target}, "Tile"), '1, '1) Counted.
"""
    lots = [rect(3, 3), [np.array([[10, 0], [12, 0], [12, 2], [10, 2]], float)]]  # 9 tiles and 4
    for target, first, second in (("intra", 9, 4), ("inter", 4, 9), ("all", 13, 13)):
        r = run(write, text.replace("{target}", target), lots)
        assert r["bad"] == () and count(r, "Counted") == 13
        np.testing.assert_array_equal(r["xform"][:, 0, 1], np.where(r["lot"] == 0, first, second))  # a quad: x
    assert (run(write, text.replace("{target}", "all").replace('"Tile")', '"")'), lots)["xform"][:, 0, 1] == 0).all()
