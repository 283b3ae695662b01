"""Batched expression evaluation: ``elementwise`` against numpy/math, ``evaluate`` semantics on a small Env."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import LOT_ZOO, make_lots
from operations.derivations import per_lot, rect, run, totals

from grammarc.backend.derive import initial_chunk
from grammarc.backend.evaluate import Env, evaluate, evaluate_array
from grammarc.backend.functions.math import _MATH, elementwise
from grammarc.backend.plan import Strings
from grammarc.backend.random import mix
from grammarc.ir import nodes as ir

ZOO = ("square", "rect_12x8", "concave_L", "courtyard", "sliver")
N = 2000

# ------------------------------------------------------------------------------------------- elementwise

#: Plain numpy references, angles in degrees.
REFERENCES = {
    "sin": lambda x: np.sin(np.radians(x)),
    "cos": lambda x: np.cos(np.radians(x)),
    "tan": lambda x: np.tan(np.radians(x)),
    "asin": lambda x: np.degrees(np.arcsin(x)),
    "acos": lambda x: np.degrees(np.arccos(x)),
    "atan": lambda x: np.degrees(np.arctan(x)),
    "exp": np.exp,
    "log": np.log,
    "sqrt": np.sqrt,
}


def sample(rng, n):
    """Values spanning the domains, edge points included."""
    if n < 2:
        return rng.uniform(-400, 400, n)
    return np.concatenate([rng.uniform(-400, 400, n), rng.uniform(-1.2, 1.2, n),
                           [0.0, -0.0, 1.0, -1.0, 90.0, 180.0, 30.0, 45.0, 1e-300, -5.0, 700.0]])


@pytest.mark.parametrize("name", sorted(_MATH))
@pytest.mark.parametrize("n", [0, 1, 500])
def test_elementwise_matches_numpy(name, n):
    x = sample(np.random.default_rng(n), n)
    with np.errstate(all="ignore"):
        want = REFERENCES[name](x)
    out = elementwise(_MATH[name], np.ascontiguousarray(x))
    assert out.shape == x.shape and out.dtype == np.float64
    np.testing.assert_allclose(out, want, rtol=1e-12, atol=1e-12, equal_nan=True)


@pytest.mark.parametrize("name, x, want", [
    ("sin", 90.0, 1.0), ("sin", 30.0, 0.5), ("cos", 60.0, 0.5), ("tan", 45.0, 1.0),
    ("asin", 1.0, 90.0), ("acos", 0.0, 90.0), ("atan", 1.0, 45.0),
    ("log", 0.0, -math.inf), ("exp", 0.0, 1.0), ("sqrt", 16.0, 4.0),
])
def test_elementwise_degrees(name, x, want):
    assert elementwise(_MATH[name], np.array([x]))[0] == pytest.approx(want, rel=1e-14)


@pytest.mark.parametrize("name, x", [("log", -1.0), ("sqrt", -4.0), ("asin", 1.5), ("acos", -2.0)])
def test_elementwise_out_of_domain_is_nan(name, x):
    assert np.isnan(elementwise(_MATH[name], np.array([x]))[0])


@pytest.mark.parametrize("name", sorted(_MATH))
def test_elementwise_value_does_not_depend_on_batch_position(name):
    x = sample(np.random.default_rng(1), 64)
    whole = elementwise(_MATH[name], x)
    for i in range(0, len(x), 7):
        single = elementwise(_MATH[name], x[i:i + 1])
        assert np.array_equal(single, whole[i:i + 1], equal_nan=True)


# ---------------------------------------------------------------------------------------------- evaluate


@pytest.fixture(scope="module")
def env():
    """N shapes over the five zoo lots, distinct keys, one parameter, a per-lot attribute ``h``."""
    chunk, shapes = initial_chunk(make_lots(*ZOO), seed=9)
    lot = np.arange(N) % len(ZOO)
    shapes = shapes.take(lot)
    rng = np.random.default_rng(0)
    shapes = replace(shapes, key=mix(shapes.key, np.arange(N)), params=(rng.uniform(-10, 10, N),))
    chunk.attrs = {"h": np.array([1.0, 2.0, 3.0, 4.0, 5.0])}
    strings = Strings()
    strings.intern("a")
    strings.intern("b")
    return Env(shapes, chunk, SimpleNamespace(strings=strings, dynamic={}, pivot_slot=None, sequential_random=False))


def num(v):
    return ir.Num(float(v))


P0 = ir.Param(0, "p")


def call(func, *args, site=0):
    return ir.Call(func, tuple(args), site=site)


def test_constants_stay_scalars(env):
    assert evaluate(num(3), env) == 3.0
    assert evaluate(ir.Bool(True), env) is True
    assert evaluate(ir.Str("b"), env) == 1
    assert evaluate(ir.Binary("+", num(1), num(2)), env) == 3.0
    out = evaluate_array(num(2.5), env)
    assert out.shape == (N,) and np.all(out == 2.5)


def test_param_and_attribute(env):
    p = env.shapes.params[0]
    assert np.array_equal(evaluate(P0, env), p)
    assert np.array_equal(evaluate(ir.AttrRef("h"), env), env.shapes.lot + 1.0)


@pytest.mark.parametrize("op, ref", [
    ("+", np.add), ("-", np.subtract), ("*", np.multiply), ("/", np.divide), ("%", np.fmod),
])
def test_arithmetic(env, op, ref):
    p = env.shapes.params[0]
    h = env.shapes.lot + 1.0
    out = evaluate(ir.Binary(op, P0, ir.AttrRef("h")), env)
    assert np.array_equal(out, ref(p, h))
    out = evaluate(ir.Binary(op, num(7), P0), env)
    with np.errstate(all="ignore"):
        assert np.array_equal(out, ref(7.0, p))


def test_division_by_zero_is_inf_silently(env):
    with np.errstate(all="raise"):
        out = evaluate(ir.Binary("/", P0, num(0)), env)
    assert np.all(np.isinf(out))


def test_modulo_follows_the_dividend():
    assert evaluate(ir.Binary("%", num(-7), num(3)), None) == math.fmod(-7, 3)


def test_unary(env):
    p = env.shapes.params[0]
    assert np.array_equal(evaluate(ir.Unary("-", P0), env), -p)
    assert np.array_equal(evaluate(ir.Unary("!", ir.Binary(">", P0, num(0))), env), p <= 0)


@pytest.mark.parametrize("op, ref", [
    ("<", np.less), ("<=", np.less_equal), (">", np.greater), (">=", np.greater_equal),
    ("==", np.equal), ("!=", np.not_equal),
])
def test_comparisons(env, op, ref):
    h = env.shapes.lot + 1.0
    out = evaluate(ir.Binary(op, ir.AttrRef("h"), num(3)), env)
    assert out.dtype == np.bool_
    assert np.array_equal(out, ref(h, 3.0))


def test_logic(env):
    p = env.shapes.params[0]
    big, pos = ir.Binary(">", ir.AttrRef("h"), num(2)), ir.Binary(">", P0, num(0))
    h = env.shapes.lot + 1.0
    assert np.array_equal(evaluate(ir.Binary("&&", big, pos), env), (h > 2) & (p > 0))
    assert np.array_equal(evaluate(ir.Binary("||", big, pos), env), (h > 2) | (p > 0))
    assert evaluate(ir.Binary("&&", ir.Bool(True), ir.Bool(False)), env) == False


def test_string_equality(env):
    assert evaluate(ir.Binary("==", ir.Str("b"), ir.Str("b")), env) == True
    assert evaluate(ir.Binary("==", ir.Str("a"), ir.Str("b")), env) == False


@pytest.mark.parametrize("args, low, high", [((), 0, 1), ((5,), 0, 5), ((2, 7), 2, 7), ((-3, -1), -3, -1)])
def test_rand_range(env, args, low, high):
    out = evaluate(call("rand", *map(num, args), site=4), env)
    assert out.shape == (N,)
    assert np.all((out >= low) & (out < high))
    # spread over the whole range, not a corner of it
    assert out.min() < low + 0.05 * (high - low) and out.max() > high - 0.05 * (high - low)


def test_rand_with_per_shape_bounds(env):
    p = np.abs(env.shapes.params[0]) + 1
    out = evaluate(call("rand", num(1), ir.Binary("+", ir.Call("abs", (P0,)), num(2)), site=1), env)
    assert np.all((out >= 1) & (out < p + 1))


def test_rand_sites_are_independent(env):
    a = evaluate(call("rand", site=1), env)
    b = evaluate(call("rand", site=2), env)
    assert np.array_equal(a, evaluate(call("rand", site=1), env))  # same site, same numbers
    assert not np.any(a == b)
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.1
    # shapes of one lot draw different numbers
    assert len(np.unique(a[env.shapes.lot == 0])) == np.count_nonzero(env.shapes.lot == 0)


def test_rand_does_not_depend_on_batch(env):
    """A shape draws the same number alone or in a batch (docs/architecture.md, invariant 2)."""
    whole = evaluate(call("rand", num(2), num(9), site=3), env)
    sel = np.random.default_rng(0).permutation(N)[:50]
    part = Env(env.shapes.take(sel), env.chunk, env.plan)
    assert np.array_equal(evaluate(call("rand", num(2), num(9), site=3), part), whole[sel])


@pytest.mark.parametrize("func, ref", [
    ("floor", np.floor), ("ceil", np.ceil), ("abs", np.abs),
    ("sqrt", lambda x: np.where(x >= 0, np.sqrt(np.abs(x)), np.nan)),
    ("sin", lambda x: np.sin(np.radians(x))),
    ("round", lambda x: np.array([math.copysign(math.floor(abs(v) + 0.5), v) for v in x])),
])
def test_unary_functions(env, func, ref):
    p = env.shapes.params[0]
    out = evaluate(call(func, P0), env)
    np.testing.assert_allclose(out, ref(p), rtol=1e-12, atol=1e-12, equal_nan=True)


def test_functions_of_constants_are_scalars(env):
    assert evaluate(call("sin", num(30)), env) == pytest.approx(0.5)
    assert isinstance(evaluate(call("sqrt", num(9)), env), float)
    assert evaluate(call("round", num(2.5)), env) == 3.0
    assert evaluate(call("round", num(-2.5)), env) == -3.0
    assert evaluate(call("atan2", num(1), num(1)), env) == pytest.approx(45.0)
    assert evaluate(call("atan2", num(1), num(-1)), env) == pytest.approx(135.0)
    assert evaluate(call("pow", num(2), num(10)), env) == 1024.0


def test_binary_functions(env):
    p = env.shapes.params[0]
    h = env.shapes.lot + 1.0
    args = (P0, ir.AttrRef("h"))
    assert np.array_equal(evaluate(call("min", *args), env), np.minimum(p, h))
    assert np.array_equal(evaluate(call("max", *args), env), np.maximum(p, h))
    with np.errstate(invalid="ignore"):
        np.testing.assert_allclose(evaluate(call("pow", *args), env), np.power(p, h), rtol=1e-14)
    np.testing.assert_allclose(evaluate(call("atan2", *args), env), np.degrees(np.arctan2(p, h)),
                               rtol=1e-12, atol=1e-12)
    assert evaluate(call("atan2", P0, num(1)), env).shape == (N,)


def test_scope_fields(env):
    shapes = env.shapes
    assert np.array_equal(evaluate(ir.ScopeRef("sx"), env), shapes.size[:, 0])
    assert np.array_equal(evaluate(ir.ScopeRef("sz"), env), shapes.size[:, 2])
    # A lot's own scope is at translation 0; moving by d world units reads d along the lot's axes.
    for field in ("tx", "ty", "tz"):
        assert np.allclose(evaluate(ir.ScopeRef(field), env), 0.0)
    d = np.random.default_rng(2).normal(size=(N, 3))
    moved = Env(replace(shapes, origin=shapes.origin + d), env.chunk, env.plan)
    axes = env.chunk.lot_axes[shapes.lot]
    for k, field in enumerate(("tx", "ty", "tz")):
        np.testing.assert_allclose(evaluate(ir.ScopeRef(field), moved), np.einsum("nj,nj->n", d, axes[:, k]),
                                   atol=1e-12)


def test_empty_batch(env):
    empty = Env(env.shapes.take(np.zeros(0, np.int64)), env.chunk, env.plan)
    for expr in (call("rand", site=1), call("sin", P0), ir.Binary("*", P0, num(2)), ir.ScopeRef("tx")):
        assert evaluate(expr, empty).shape == (0,)
    assert evaluate_array(num(1), empty).shape == (0,)


# --------------------------------------------------------------------------------- in derivations


def test_geometry_area_of_a_lot_and_volume_after_extrude(write):
    r = run(write, 'Lot --> report("area", geometry.area) extrude(10) report("volume", geometry.volume)\n'
                   '    report("surface", geometry.area)\n', [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]])
    lots = per_lot(r)
    assert (lots[0]["area_sum"], lots[0]["volume_sum"], lots[0]["surface_sum"]) == pytest.approx(
        (400, 4000, 1800))
    assert (lots[1]["area_sum"], lots[1]["volume_sum"]) == pytest.approx((1200, 12000))


def test_a_function_with_rand_draws_at_each_use(write):
    """Each use of `h = rand()` draws anew from the shape's stream, as CityEngine evaluates a function at each
    use (``backend.streams``: a draw moves the state on, whatever its call's site)."""
    r = run(write, 'h = rand(0, 100)\nLot --> report("d", h - h)\n', [rect(1, 1)] * 20)
    assert totals(r)["d_max"] > 0


def test_shape_queries(write):
    r = run(write, 'Lot --> report("nv", geometry.nVertices) report("nf", geometry.nFaces) extrude(3) A\n'
                   'A --> report("nv3", geometry.nVertices) report("nf3", geometry.nFaces) r(0, 30, 0) '
                   'report("ry", scope.ry) report("ox", initialShape.origin.px) report("len", len("abcd")) X.\n',
          [LOT_ZOO["concave_L"]])
    t = totals(r)
    assert (t["nv_sum"], t["nf_sum"], t["nv3_sum"], t["nf3_sum"]) == (6, 1, 12, 8)
    assert t["ry_sum"] == pytest.approx(30) and t["len_sum"] == 4 and t["ox_sum"] == 0


def test_n_vertices_counts_each_polygons_own_rings(write):
    """Regression: a polygon's count summed the counts of the rings numbered like the store's polygons,
    wrong for every polygon after one with a hole (the L after the courtyard counted 4)."""
    r = run(write, 'Lot --> report("nv", geometry.nVertices)\n', [LOT_ZOO["courtyard"], LOT_ZOO["concave_L"]])
    assert [t["nv_sum"] for t in per_lot(r).values()] == [8, 6]

