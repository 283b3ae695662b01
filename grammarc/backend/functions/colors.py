"""Colour functions: ``colorRamp``, and conversions between hexadecimal colour strings, RGB and HSV.

A colour string is CityEngine's ``"#rrggbb"``, or ``"#rrggbboo"`` with an opacity; the functions write
upper-case digits, as CityEngine does (``colorRGBToHex(0, 0.5, 1)`` is ``"#0080FF"``). The numbers are
computed with numpy over the batch and rounded to 8-bit channels (half away from zero); only the distinct
colours are then written as strings and interned (``table.distinct``), and a colour string is read once per
distinct string. Components are clamped to [0, 1] and hues taken modulo 360, as the reference says; a NaN
component counts as 0. Reading a colour string, a digit that is not hexadecimal counts as 0 and a missing
pair (an opacity of ``"#rrggbb"``) is 0.
"""

from __future__ import annotations

import colorsys
import string
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.table import distinct, function

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: The ramps of ``colorRamp``: each is 36 colours, ``(index, 0xRRGGBB)`` stops and the colours between two
#: stops interpolated linearly per channel, rounded down (``_ramp_colour``), which gives CityEngine's colours.
RAMPS = {
    "whiteToBlack": ((0, 0xFFFFFF), (35, 0x000000)),
    "greenToRed": ((0, 0x3BA800), (17, 0xFFFF00), (35, 0xFF0000)),
    "yellowToRed": ((0, 0xF5F500), (35, 0xF50000)),
    "redToBlue": ((0, 0xC44539), (17, 0xFAFCBB), (35, 0x3661CF)),
    "orangeToBlue": ((0, 0xFFC800), (8, 0xFF730F), (17, 0xFF0051), (26, 0xE800A2), (35, 0x0000FF)),
    "brownToBlue": ((0, 0x9C5621), (17, 0xFFFFBF), (35, 0x218291)),
    "spectrum": ((0, 0xB952A4), (5, 0x3C53A3), (10, 0x39BFEF), (13, 0x6BBF45), (15, 0xA8D036),
                 (20, 0xFBEE24), (25, 0xF16D20), (30, 0xEF3624), (35, 0xED2726)),
}
#: Colours per ramp: a value v in [0, 1) takes colour floor(36 v), 1 and above the last.
RAMP_STEPS = 36


@function("colorRamp")
def color_ramp(call, args, env: Env):
    """``colorRamp(ramp, value)``: "" for a ramp that is not one of ``RAMPS`` or a NaN value."""
    value = np.asarray(args[1], dtype=np.float64)
    with np.errstate(invalid="ignore"):
        step = np.where(np.isnan(value), -1.0, np.clip(np.floor(RAMP_STEPS * value), 0, RAMP_STEPS - 1))
    strings = env.plan.strings
    names = list(strings.ids)

    def colour(ramp: int, k: float) -> int:
        stops = RAMPS.get(names[ramp])
        return strings.intern(_ramp_colour(stops, int(k)) if stops is not None and k >= 0 else "")
    return distinct(colour, args[0], step, dtype=np.int32)


def _ramp_colour(stops, k: int) -> str:
    """Colour ``k`` of a ramp as ``"#RRGGBB"``."""
    (i0, a), (i1, b) = next((s, t) for s, t in pairwise(stops) if k <= t[0])
    channels = [(a >> shift & 0xFF) + ((b >> shift & 0xFF) - (a >> shift & 0xFF)) * (k - i0) // (i1 - i0)
                for shift in (16, 8, 0)]
    return "#" + "".join(f"{c:02X}" for c in channels)


@function("colorRGBToHex", "colorRGBOToHex")
def rgb_to_hex(call, args, env: Env):
    """``colorRGBToHex(r, g, b)``, ``colorRGBOToHex(r, g, b, o)``: components in [0, 1]."""
    return _hex(env, *args)


@function("colorHSVToHex", "colorHSVOToHex")
def hsv_to_hex(call, args, env: Env):
    """``colorHSVToHex(h, s, v)``, ``colorHSVOToHex(h, s, v, o)``: hue in degrees, the rest in [0, 1]."""
    with np.errstate(invalid="ignore"):
        sector = np.nan_to_num(np.mod(np.asarray(args[0], dtype=np.float64), 360.0)) / 60.0
    saturation, value = _unit(args[1]), _unit(args[2])
    # channel n (red 5, green 3, blue 1) is v - v s clamp(min(k, 4 - k), 0, 1) with k = (n + h / 60) mod 6
    rgb = []
    for n in (5.0, 3.0, 1.0):
        k = np.mod(n + sector, 6.0)
        rgb.append(value - value * saturation * np.clip(np.minimum(k, 4.0 - k), 0.0, 1.0))
    return _hex(env, *rgb, *args[3:])


@function("colorHexToR", "colorHexToG", "colorHexToB", "colorHexToO", "colorHexToH", "colorHexToS",
          "colorHexToV")
def hex_to_component(call, args, env: Env):
    """``colorHexToR(hex)`` ...: a channel in [0, 1], or the hue in degrees, saturation or value."""
    component = call.func[-1]
    names = list(env.plan.strings.ids)
    return distinct(lambda text: _component(names[text], component), args[0])


def _unit(value) -> np.ndarray:
    """A component clamped to [0, 1], NaN as 0."""
    return np.clip(np.nan_to_num(np.asarray(value, dtype=np.float64)), 0.0, 1.0)


def _hex(env: Env, *components):
    """Components in [0, 1] (3 or 4, scalars or (n,)) as interned ``"#rrggbb"`` / ``"#rrggbboo"`` ids."""
    code = 0
    for c in components:  # 8 bits a channel, packed in one integer per shape: one string per distinct colour
        code = code * 256 + np.floor(_unit(c) * 255.0 + 0.5)
    digits = 2 * len(components)
    strings = env.plan.strings
    return distinct(lambda k: strings.intern(f"#{int(k):0{digits}X}"), code, dtype=np.int32)


def _component(text: str, component: str) -> float:
    red, green, blue, opacity = (_channel(text[i:i + 2]) / 255.0 for i in (1, 3, 5, 7))
    if component in "RGBO":
        return {"R": red, "G": green, "B": blue, "O": opacity}[component]
    hue, saturation, value = colorsys.rgb_to_hsv(red, green, blue)
    return {"H": hue * 360.0, "S": saturation, "V": value}[component]


def _channel(digits: str) -> int:
    """A pair of hexadecimal digits as a number; a digit that is not hexadecimal is 0."""
    value = 0
    for d in digits:
        value = 16 * value + (int(d, 16) if d in string.hexdigits else 0)
    return value
