"""grammarc.backend.random bit for bit against a plain-numpy SplitMix64 reference, plus sanity of the draws."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend.random import child_keys, lot_keys, mix, uniform

GOLDEN = np.uint64(0x9E3779B97F4A7C15)
M1 = np.uint64(0xBF58476D1CE4E5B9)
M2 = np.uint64(0x94D049BB133111EB)
SIZES = [0, 1, 2, 1000]


def ref_mix(key, value):
    """SplitMix64's finalizer of key ^ ((value + 1) * golden), uint64 arrays wrapping."""
    key = np.asarray(key, dtype=np.uint64)
    value = np.broadcast_to(np.asarray(value, dtype=np.int64), key.shape).astype(np.uint64)
    with np.errstate(over="ignore"):
        z = key ^ ((value + np.uint64(1)) * GOLDEN)
        z = (z ^ (z >> np.uint64(30))) * M1
        z = (z ^ (z >> np.uint64(27))) * M2
    return z ^ (z >> np.uint64(31))


def ref_uniform(key, site):
    return (ref_mix(key, site) >> np.uint64(11)).astype(np.float64) * 2.0**-53


def random_keys(rng, n):
    return rng.integers(0, 2**64, n, dtype=np.uint64, endpoint=False)


def test_reference_is_splitmix64():
    """The reference itself: SplitMix64 seeded with 0 gives 0xE220A8397B1DCDAF first (Vigna's splitmix64.c)."""
    assert ref_mix(np.zeros(1, np.uint64), 0)[0] == np.uint64(0xE220A8397B1DCDAF)


@pytest.mark.parametrize("n", SIZES)
def test_mix_bit_for_bit(n):
    rng = np.random.default_rng(n)
    key = random_keys(rng, n)
    value = rng.integers(-(2**40), 2**40, n)
    out = mix(key, value)
    assert out.dtype == np.uint64
    assert np.array_equal(out, ref_mix(key, value))
    assert np.array_equal(mix(key, 12345), ref_mix(key, 12345))


@pytest.mark.parametrize("n", SIZES)
def test_child_keys_bit_for_bit(n):
    rng = np.random.default_rng(n)
    key = random_keys(rng, n)
    index = rng.integers(0, 100, n)
    assert np.array_equal(child_keys(key, 17, index), ref_mix(ref_mix(key, 17), index))
    assert np.array_equal(child_keys(key, 3), ref_mix(ref_mix(key, 3), 0))


@pytest.mark.parametrize("n", SIZES)
def test_uniform_bit_for_bit_and_in_unit_interval(n):
    key = random_keys(np.random.default_rng(n), n)
    u = uniform(key, 5)
    assert u.dtype == np.float64
    assert np.array_equal(u, ref_uniform(key, 5))
    assert np.all((u >= 0.0) & (u < 1.0))


def test_uniform_extremes_stay_below_one():
    """The largest 53-bit value maps to 1 - 2**-53, never 1."""
    top = np.uint64(2**64 - 1) >> np.uint64(11)
    assert float(top) * 2.0**-53 < 1.0


@pytest.mark.parametrize("seed", [0, 1, 2**64 - 1, -1, 2**70 + 5])
def test_lot_keys_bit_for_bit(seed):
    index = np.arange(20)
    base = ref_mix(np.array([seed & (2**64 - 1)], np.uint64), 0x5EED)[0]
    want = ref_mix(np.full(20, base, np.uint64), index)
    assert np.array_equal(lot_keys(seed, index), want)


def test_lot_keys_depend_only_on_the_lot():
    """A lot's key is the same alone, in any chunk and any order (docs/architecture.md, invariant 2)."""
    index = np.arange(50)
    everything = lot_keys(42, index)
    rng = np.random.default_rng(0)
    for _ in range(5):
        sel = rng.permutation(50)[: rng.integers(1, 50)]
        assert np.array_equal(lot_keys(42, index[sel]), everything[sel])
    assert lot_keys(42, index[3:4])[0] == everything[3]
    assert len(np.unique(everything)) == 50
    assert not np.array_equal(lot_keys(43, index), everything)
    assert len(lot_keys(42, np.zeros(0, np.int64))) == 0


def test_keys_differ_by_site_and_index():
    key = lot_keys(7, np.arange(100))
    a, b = child_keys(key, 1, 0), child_keys(key, 2, 0)
    c = child_keys(key, 1, 1)
    assert not np.any(a == b) and not np.any(a == c)
    assert len(np.unique(np.concatenate([a, b, c, key]))) == 400


def test_uniform_chi_square():
    """10^5 draws in 100 bins: chi-square with 99 dof has mean 99, sd 14; 99 + 6 sd is far out."""
    key = lot_keys(2024, np.arange(100_000))
    counts = np.bincount((uniform(key, 3) * 100).astype(np.int64), minlength=100)
    expected = 1000.0
    chi2 = ((counts - expected) ** 2 / expected).sum()
    assert chi2 < 99 + 6 * 14


def test_uniform_sites_are_uncorrelated():
    key = lot_keys(1, np.arange(100_000))
    u, v = uniform(key, 1), uniform(key, 2)
    assert abs(np.corrcoef(u, v)[0, 1]) < 0.02
    assert abs(u.mean() - 0.5) < 0.01
