"""Shapes.take: every column gathered alike, whatever the index."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend.shapes import COLUMNS, Shapes


def batch(n: int) -> Shapes:
    rng = np.random.default_rng(n)
    return Shapes(rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.integers(0, 9, n).astype(np.int32),
                  rng.integers(-3, 9, n).astype(np.int32), rng.integers(0, 4, n).astype(np.int32),
                  rng.integers(0, 2**63, n).astype(np.uint64), rng.integers(0, 5, n).astype(np.int32),
                  (rng.normal(size=n),), (rng.normal(size=n), rng.integers(0, 7, n).astype(np.int32),
                                          rng.random(n) < 0.5))


def columns(shapes: Shapes) -> list[np.ndarray]:
    return [getattr(shapes, f) for f in COLUMNS[:-2]] + list(shapes.params) + list(shapes.dynamic)


@pytest.mark.parametrize("n", [0, 1, 7])
@pytest.mark.parametrize("kind", ["rows", "list", "mask", "slice"])
def test_take_gathers_each_column_as_indexing_does(n, kind):
    shapes = batch(n)
    rng = np.random.default_rng(n + 1)
    index = {"rows": rng.permutation(n)[: n - n // 3], "list": [n - 1] * 2 if n else [],
             "mask": rng.random(n) < 0.5, "slice": slice(1, None)}[kind]
    got = shapes.take(index)
    for mine, theirs in zip(columns(got), columns(shapes)):
        assert mine.dtype == theirs.dtype and np.array_equal(mine, theirs[index])


def test_a_mask_keeping_every_shape_gives_the_batch_itself():
    shapes = batch(5)
    assert shapes.take(np.ones(5, dtype=bool)) is shapes
