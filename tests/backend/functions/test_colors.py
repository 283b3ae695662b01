"""backend/functions/colors.py: ``colorRamp`` and the colour conversions, on whole batches. The expected
values are the examples of the CGA reference pages (colorRGBToHex, colorRGBOToHex, colorHSVToHex,
colorHSVOToHex, colorHexToR/G/B/O/H/S/V)."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from backend.operations.derivations import per_lot, rect, run

from grammarc.backend.functions.colors import RAMP_STEPS, RAMPS, _ramp_colour


def reported(write, expr: str, lots=1, attrs=None):
    """The value of ``expr`` reported by each of ``lots`` lots."""
    r = run(write, f'attr v = 0\nLot --> report("k", {expr}) X\n', [rect(2, 2)] * lots, lot_attrs=attrs)
    return [table["k_sum"] for table in per_lot(r).values()]


@pytest.mark.parametrize("expr, want", [
    ("colorRGBToHex(0, 0.5, 1)", "#0080FF"),
    ("colorRGBOToHex(0, 0.5, 1, 0.5)", "#0080FF80"),
    ("colorHSVToHex(90, 0.5, 0.5)", "#608040"),
    ("colorHSVOToHex(90, 0.5, 0.5, 0.5)", "#60804080"),
    # hues are taken modulo 360, the other components clamped to [0, 1]
    ("colorHSVToHex(450, 0.5, 0.5)", "#608040"),
    ("colorHSVToHex(-270, 0.5, 0.5)", "#608040"),
    ("colorRGBToHex(-1, 2, 0.2)", "#00FF33"),
    ("colorHSVToHex(0, 1, 1)", "#FF0000"),
    ("colorHSVToHex(240, 1, 1)", "#0000FF"),
])
def test_colours_to_hex(write, expr, want):
    assert reported(write, expr) == [want]


@pytest.mark.parametrize("expr, want", [
    ('colorHexToR("#4080BF")', 0.2509803921568628), ('colorHexToR("#4080BF80")', 0.2509803921568628),
    ('colorHexToG("#4080BF")', 0.5019607843137256), ('colorHexToG("#4080BF80")', 0.5019607843137256),
    ('colorHexToB("#4080BF")', 0.7490196078431374), ('colorHexToB("#4080BF80")', 0.7490196078431374),
    ('colorHexToO("#4080BF80")', 0.5019607843137256), ('colorHexToO("#4080BF")', 0.0),
    ('colorHexToH("#608040")', 90.0), ('colorHexToH("#60804080")', 90.0),
    ('colorHexToS("#608040")', 0.5), ('colorHexToS("#60804080")', 0.5),
    ('colorHexToV("#608040")', 0.5019607843137256), ('colorHexToV("#60804080")', 0.5019607843137256),
    # lower-case digits read as upper-case ones; a digit that is not hexadecimal is 0
    ('colorHexToR("#ff0000")', 1.0), ('colorHexToR("#G00000")', 0.0),
])
def test_hex_to_components(write, expr, want):
    assert reported(write, expr) == [pytest.approx(want, abs=1e-12)]


def test_a_colour_goes_round_through_hsv(write):
    got = reported(write, 'colorHSVToHex(colorHexToH("#3A93D0"), colorHexToS("#3A93D0"), colorHexToV("#3A93D0"))')
    assert got == ["#3A93D0"]


def test_ramps_end_at_their_stops_and_clamp_out_of_range_values(write):
    assert reported(write, 'colorRamp("whiteToBlack", 0)') == ["#FFFFFF"]
    assert reported(write, 'colorRamp("whiteToBlack", 1)') == ["#000000"]
    assert reported(write, 'colorRamp("greenToRed", -3)') == ["#3BA800"]
    assert reported(write, 'colorRamp("greenToRed", 7)') == ["#FF0000"]
    # value 0.5 is step 18 of 36: the reference's example calls it orange
    assert reported(write, 'colorRamp("yellowToRed", 0.5)') == ["#F57700"]
    assert reported(write, 'colorRamp("noSuchRamp", 0.5)') == [""]
    assert reported(write, 'colorRamp("spectrum", log(v - 1))') == [""]


def test_ramp_steps_interpolate_between_stops_rounding_down():
    """Each ramp is 36 colours; between two stops every channel moves linearly and is rounded down."""
    for stops in RAMPS.values():
        assert stops[0][0] == 0 and stops[-1][0] == RAMP_STEPS - 1
        for (i, a), (j, b) in pairwise(stops):
            assert _ramp_colour(stops, i) == f"#{a:06X}" and _ramp_colour(stops, j) == f"#{b:06X}"
    assert _ramp_colour(RAMPS["whiteToBlack"], 1) == "#F7F7F7"  # 255 - 255 / 35 = 247.7
    assert _ramp_colour(RAMPS["greenToRed"], 18) == "#FFF000"   # 255 - 255 / 18 = 240.8


def test_colours_per_shape_follow_their_values(write):
    values = [0.0, 0.25, 0.5, 0.999, 1.0]
    got = reported(write, 'colorRamp("whiteToBlack", v) + " " + colorRGBToHex(v, v, v)', lots=len(values),
                   attrs={"v": np.array(values)})
    ramp = [_ramp_colour(RAMPS["whiteToBlack"], min(int(36 * v), 35)) for v in values]
    grey = ["#" + f"{int(np.floor(255 * v + 0.5)):02X}" * 3 for v in values]
    assert got == [f"{r} {g}" for r, g in zip(ramp, grey)]
