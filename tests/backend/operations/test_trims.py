"""backend/operations/trims.py in derivations: trim() cuts the shape's own geometry at its trim planes."""

from __future__ import annotations

import numpy as np
import pytest
from derivations import mesh_faces, rect, run, totals

LEDGE = ("Lot --> extrude(10) {set}comp(f){{ side : Facade }}\n"
         "Facade --> split(y){{ 1 : Ledge | ~1 : NIL }}\n"
         "Ledge --> s('1.2, '1, 0.5) center(x) {trim}report(\"v\", geometry.volume) report(\"a\", geometry.area) X.\n")


def test_trim_mitres_a_ledge_at_the_corners_and_closes_it(write):
    """A ledge 1.2 times its facade's width and 0.5 deep, trimmed, is a closed solid mitred at 45 degrees:
    at depth w it runs from -w to the facade's width + w, so its volume is 0.5 (width + 0.5) per facade;
    its mitre faces are sqrt(0.5) by 1. Without trim() it is the whole box."""
    trimmed = totals(run(write, LEDGE.format(set="", trim="trim() "), [rect(12, 8)]))
    assert trimmed["v_sum"] == pytest.approx(2 * 0.5 * (12.5 + 8.5))
    front = 13 + 12 + 2 * 0.5 * 12.5 + 2 * np.sqrt(0.5)
    assert trimmed["a_max"] == pytest.approx(front)
    whole = totals(run(write, LEDGE.format(set="", trim=""), [rect(12, 8)]))
    assert whole["v_sum"] == pytest.approx(2 * 0.5 * (14.4 + 9.6))


def test_trim_keeps_what_the_inserted_cube_keeps(write):
    """trim() then a leaf gives the faces whose corners are those of the same box inserted as a cube and
    trimmed as it is placed."""
    faces = mesh_faces(run(write, LEDGE.format(set="", trim="trim() "), [rect(12, 8)]))
    cube = run(write, LEDGE.format(set="", trim="primitiveCube() "), [rect(12, 8)])
    corners = np.unique(np.round(np.concatenate([r for f in faces for r in f]), 6), axis=0)
    cut = np.unique(np.round(cube["mesh"].vertices.astype(float), 4), axis=0)
    assert all((np.abs(cut - c).max(axis=1) < 1e-3).any() for c in np.round(corners, 4))
    assert all(len(f) == 1 for f in faces)


def test_trim_without_planes_or_turned_off_changes_nothing(write):
    """No comp(f), or ``set(trim.vertical, false)``: trim() leaves the box a box (a cube instance)."""
    off = run(write, LEDGE.format(set="set(trim.vertical, false) ", trim="trim() "), [rect(12, 8)])
    assert len(off["mesh"].lot) == 0 and len(off["asset"]) == 4
    plain = run(write, "Lot --> extrude(3) trim() X.\n", [rect(12, 8)])
    assert len(plain["mesh"].lot) == 0 and len(plain["asset"]) == 1


def test_a_trimmed_solid_splits_and_splits_into_faces(write):
    """The Roman rule sets' pattern: a wall extruded 1 from a facade 10 high, widened, trimmed, then split
    or split into faces: the pieces of the mitred solid, (width + 1) 10 in volume, six faces each (the
    widened box reaches past both mitres: its ends are cut away)."""
    text = ("Lot --> extrude(10) comp(f){{ side : Wall }}\n"
            "Wall --> extrude(1) s('1.3, '1, '1) center(x) trim {then}\n")
    pieces = totals(run(write, text.format(then='split(x){ ~2 : report("v", geometry.volume) A. }*'),
                        [rect(12, 8)]))
    assert pieces["v_sum"] == pytest.approx(2 * 10 * (13 + 9))
    faces = totals(run(write, text.format(then='comp(f){ all : report("a", geometry.area) F. }'), [rect(12, 8)]))
    mitre = 2 * 10 * np.sqrt(2)
    assert faces["a_n"] == 24
    assert faces["a_sum"] == pytest.approx(2 * sum(10 * (w + w + 2) + 2 * (w + 1) + mitre for w in (12, 8)))


def test_horizontal_trim_planes_mitre_a_ledge_at_the_top_and_a_roof_face_at_its_ridge(write):
    """``set(trim.horizontal, true)``: a ledge 1.5 high at the top 1 of a facade, 0.5 deep, is cut by the
    plane bisecting the wall and the flat roof, y <= 10 + depth: 0.625 of its 1.2 widths without the
    corners' mitres, 0.625 width + 1/3 with them (the facades are 12, 12, 8 and 8 wide). A hip roof's face,
    enlarged and extruded 0.5 as in the reference's example, reaches past the ridge (4 m on an 8 m wide lot)
    only up to the vertical mitre there, 0.5 sqrt(2) above it; without horizontal planes it runs on."""
    text = ("Lot --> extrude(10) {set}comp(f){{ side : Facade | top : T. }}\n"
            "Facade --> split(y){{ ~1 : NIL | 1 : Ledge }}\n"
            "Ledge --> s('1.2, '1.5, 0.5) center(x) trim() report(\"v\", geometry.volume) X.\n")
    for switch, volume in [("", 1.5 * 21), ("set(trim.horizontal, true) set(trim.vertical, false) ", 0.625 * 48),
                           ("set(trim.horizontal, true) ", 0.625 * 40 + 4 / 3)]:
        assert totals(run(write, text.format(set=switch), [rect(12, 8)]))["v_sum"] == pytest.approx(volume)
    roof = ("Lot --> roofHip(45) {set}comp(f){{ 1 : Face }}\n"
            "Face --> s('2, '2, '1) center(x) extrude(0.5) trim() X.\n")
    heights = [np.concatenate([r for f in mesh_faces(run(write, roof.format(set=s), [rect(12, 8)])) for r in f])[:, 1].max()
               for s in ("", "set(trim.horizontal, true) ")]
    assert heights[0] > 6 and heights[1] == pytest.approx(4 + 0.5 * np.sqrt(2), abs=1e-5)
