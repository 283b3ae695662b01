"""The example cities keep the digest of their records: a refactor leaves them byte-identical.

A change that alters the example's records must say why, and update the digest file with:

    python tests/test_examples.py    # prints the digest of examples/city; copy it to examples/city/records.sha256

The digest covers every array of the record except ``meta`` (which names paths and versions).
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np

from grammarc.build import BuildOptions, build

ROOT = Path(__file__).resolve().parents[1]
CITY = ROOT / "examples" / "city"


def record_digest(path: Path) -> str:
    digest = hashlib.sha256()
    with np.load(path) as record:
        for key in sorted(record.files):
            if key != "meta":
                array = record[key]
                digest.update(f"{key}:{array.dtype.str}:{array.shape}".encode())
                digest.update(np.ascontiguousarray(array).tobytes())
    return digest.hexdigest()


def test_example_city_records_are_unchanged(tmp_path):
    out = tmp_path / "city.npz"
    result = build(CITY / "city.cga", out)
    assert not result.bad and result.derived == 432
    assert record_digest(out) == (CITY / "records.sha256").read_text().split()[0]


def test_example_city_is_the_same_in_small_chunks_and_in_workers(tmp_path):
    build(CITY / "city.cga", tmp_path / "a.npz")
    build(CITY / "city.cga", tmp_path / "b.npz", options=BuildOptions(chunk_size=5))
    build(CITY / "city.cga", tmp_path / "c.npz", options=BuildOptions(chunk_size=7, workers=3))
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "b.npz").read_bytes()
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "c.npz").read_bytes()


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        build(CITY / "city.cga", Path(folder) / "city.npz")
        sys.stdout.write(record_digest(Path(folder) / "city.npz") + "\n")
