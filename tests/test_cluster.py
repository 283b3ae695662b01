"""A build on a Dask cluster of two worker processes gives the records of a one-process build: shard by
shard in order, after a worker is killed mid-run, and when a run resumes from the shards of an earlier one."""

import json
import os
import signal
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("dask.distributed")

from grammarc.build import BuildOptions, build
from grammarc.cli import main
from grammarc.cluster import build_on_dask
from grammarc.io.npz import read_instances
from grammarc.io.shards import manifest_path, read_manifest, shard_outputs, shards_folder
from grammarc.io.summary import summarize

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CITY = EXAMPLES / "city" / "city.cga"
COLUMNS = ("asset", "xform", "lot", "symbol", "mesh_vertices", "mesh_ring_offsets", "mesh_face_offsets")


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        yield cluster.scheduler_address, client


@pytest.fixture(scope="module")
def city_lots(tmp_path_factory):
    """The example city's lots as a GeoJSON sequence, the form a cluster reads in partitions."""
    features = json.loads((EXAMPLES / "city" / "city.geojson").read_text())["features"]
    path = tmp_path_factory.mktemp("lots") / "city.geojsonl"
    path.write_text("".join(json.dumps(f) + "\n" for f in features))
    return path


def one_process(grammar, lots, tmp_path) -> dict:
    out = tmp_path / "single.npz"
    build(grammar, out, lots_path=lots, options=BuildOptions(workers=1))
    return read_instances(out)


def assert_same_records(single: dict, manifest: Path) -> None:
    shards = [read_instances(p) for p in shard_outputs(manifest)]
    for column in ("asset", "xform", "lot", "symbol", "mesh_vertices"):
        np.testing.assert_array_equal(np.concatenate([s[column] for s in shards]), single[column], err_msg=column)


def test_shards_in_order_hold_the_records_of_one_process(cluster, city_lots, tmp_path):
    address, _ = cluster
    result = build_on_dask(CITY, tmp_path / "out" / "city.npz", dask=address, lots_path=city_lots,
                           partition_size=100)
    assert result.output == tmp_path / "out" / "city.manifest.json"
    manifest = read_manifest(result.output)
    assert manifest["partitions"] == 5 and len(manifest["shards"]) == 5
    single = one_process(CITY, city_lots, tmp_path)
    assert_same_records(single, result.output)
    assert manifest["counts"]["instances"] == len(single["asset"]) == result.counts["instances"]
    # info reads the manifest: the same counts and box as the one-process record's
    mine, theirs = summarize(result.output), summarize(tmp_path / "single.npz")
    for key in ("instances", "mesh_faces", "lots", "per_lot", "assets", "symbols", "polygons"):
        assert mine[key] == theirs[key], key
    np.testing.assert_allclose(manifest["bbox"]["min"], theirs["bbox"]["min"], atol=1e-4)
    np.testing.assert_allclose(manifest["bbox"]["max"], theirs["bbox"]["max"], atol=1e-4)


def test_a_grammar_of_built_in_assets_only(cluster, city_lots, tmp_path):
    """No asset files to send (the facade benchmark's grammar)."""
    address, _ = cluster
    grammar = Path(__file__).resolve().parents[1] / "benchmarks" / "facade.cga"
    result = build_on_dask(grammar, tmp_path / "f.npz", dask=address, lots_path=city_lots, partition_size=200)
    assert_same_records(one_process(grammar, city_lots, tmp_path), result.output)


def test_occlusion_across_partitions_sees_every_lot(cluster, tmp_path):
    """Section 4's buildings ask whether their neighbours' masses hide a wall: the neighbours are in
    other partitions, and their occluders come from the cluster's first pass."""
    address, _ = cluster
    grammar = EXAMPLES / "cga2006" / "simple_building.cga"
    lots = EXAMPLES / "cga2006" / "simple_building.geojson"
    result = build_on_dask(grammar, tmp_path / "s.npz", dask=address, lots_path=lots, partition_size=2)
    assert read_manifest(result.output)["partitions"] > 3
    assert_same_records(one_process(grammar, lots, tmp_path), result.output)


def test_a_worker_killed_mid_run_does_not_change_the_result(cluster, city_lots, tmp_path):
    address, client = cluster
    killed = []

    def kill_one_worker(done, total):
        if 0 < done < total and not killed:  # a shard is done, others are being derived
            pid = next(iter(client.run(os.getpid).values()))
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    result = build_on_dask(CITY, tmp_path / "k.npz", dask=address, lots_path=city_lots, partition_size=50,
                           progress=kill_one_worker)
    assert killed
    assert_same_records(one_process(CITY, city_lots, tmp_path), result.output)
    assert not [p for p in shards_folder(tmp_path / "k.npz").iterdir() if p.name.startswith(".")]
    client.wait_for_workers(2, timeout=60)  # the nanny has started a new one, for the other tests


def test_a_resumed_run_keeps_the_complete_shards_and_redoes_the_rest(cluster, city_lots, tmp_path):
    address, _ = cluster
    out = tmp_path / "r.npz"
    build_on_dask(CITY, out, dask=address, lots_path=city_lots, partition_size=100)
    folder = shards_folder(out)
    stamps = {p.name: p.stat().st_mtime_ns for p in folder.glob("part-*.npz")}
    (folder / "part-00001.npz").unlink()  # lost
    damaged = folder / "part-00003.npz"
    data = bytearray(damaged.read_bytes())
    data[-100] ^= 0xFF  # fails its checksum
    damaged.write_bytes(bytes(data))
    stamps.pop("part-00003.npz")
    reported = []
    build_on_dask(CITY, out, dask=address, lots_path=city_lots, partition_size=100, resume=True,
                  progress=lambda done, total: reported.append(done))
    assert reported[0] == 100 + 100 + 32  # shards 0, 2 and 4 were kept at the start
    after = {p.name: p.stat().st_mtime_ns for p in folder.glob("part-*.npz")}
    assert "part-00001.npz" in after
    for name in ("part-00000.npz", "part-00002.npz", "part-00004.npz"):
        assert after[name] == stamps[name], f"{name} was derived again"
    assert_same_records(one_process(CITY, city_lots, tmp_path), manifest_path(out))
    # another seed is another run: nothing is kept
    build_on_dask(CITY, out, dask=address, lots_path=city_lots, partition_size=100, resume=True,
                  options=BuildOptions(seed=7))
    assert all(p.stat().st_mtime_ns != stamps.get(p.name) for p in folder.glob("part-*.npz"))


def test_usd_shards_and_their_root_layer(cluster, city_lots, tmp_path):
    pytest.importorskip("pxr")
    address, _ = cluster
    root = tmp_path / "city.usdc"
    build_on_dask(CITY, root, dask=address, lots_path=city_lots, partition_size=200)
    from pxr import Usd

    stage = Usd.Stage.Open(str(root))
    assert [p.GetName() for p in stage.GetPrimAtPath("/City").GetChildren()] == ["part_00000", "part_00001",
                                                                                 "part_00002"]
    single = one_process(CITY, city_lots, tmp_path)
    for path in (root, manifest_path(root)):  # info of the root layer reads the manifest
        info = summarize(path)
        assert info["instances"] == len(single["asset"]) and info["lots"] == len(np.unique(single["lot"]))


def test_cli_refuses_what_a_cluster_build_cannot_write(tmp_path, capsys):
    for extra in (["--emit", str(tmp_path / "c.glb")], ["--emit", str(tmp_path / "c.npz"), "--select", "a"]):
        assert main(["build", str(CITY), "--dask", "local:1", *extra]) == 2
    err = capsys.readouterr().err
    assert "--dask writes .npz or USD shards" in err and "--select cannot go with --dask" in err
    assert not list(tmp_path.iterdir())
    assert main(["build", str(CITY), "--dask", "local:two", "--emit", str(tmp_path / "c.npz")]) == 2
    assert "--dask local:two: expected local:N with N workers, or a scheduler address" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_cli_local_cluster(city_lots, tmp_path, capsys):
    out = tmp_path / "c.npz"
    assert main(["build", str(CITY), "--lots", str(city_lots), "--emit", str(out), "--dask", "local:2",
                 "--partition-size", "150"]) == 0
    assert "c.manifest.json: 403,552 instances" in capsys.readouterr().err
    assert main(["info", str(manifest_path(out))]) == 0
    assert "instances" in capsys.readouterr().out


def test_asset_files_are_shipped_to_a_folder_of_the_worker_s_own(tmp_path, monkeypatch):
    """The grammar's asset files travel with the plan, so workers without the client's folders (a rule
    package extracted on the client) load them; a folder once written is reused."""
    from grammarc.cluster import _asset_files, _asset_root, _digest
    from grammarc.compiler import compile_grammar

    grammar = compile_grammar(CITY)
    files = _asset_files(grammar, None)
    assert set(files) == {n for n in grammar.assets if not n.startswith("builtin:")} and files
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    folder = _asset_root(files, _digest(files))
    for name, data in files.items():
        assert (folder / name).read_bytes() == data
    (folder / "marker").write_text("kept")
    assert _asset_root(files, _digest(files)) == folder and (folder / "marker").exists()


def test_bad_lots_are_reported_by_the_shard_that_read_them(cluster, tmp_path):
    """A bad lot is skipped and listed with its number and id, as in one process, whichever partition
    it falls in; a lot whose derivation fails is listed too."""
    address, _ = cluster
    square = [[0, 0], [20, 0], [20, 15], [0, 15], [0, 0]]
    features = [{"type": "Feature", "id": f"lot{k}", "properties": {},
                 "geometry": {"type": "Polygon", "coordinates": [[[x + 30 * k, y] for x, y in square]]}}
                for k in range(7)]
    features[2]["geometry"] = {"type": "Point", "coordinates": [0, 0]}
    features[5]["geometry"]["coordinates"][0][2] = [30 * 5 + 20, -15]  # self-intersecting
    lots = tmp_path / "lots.geojsonl"
    lots.write_text("".join(json.dumps(f) + "\n" for f in features))
    result = build_on_dask(CITY, tmp_path / "b.npz", dask=address, lots_path=lots, partition_size=2)
    single = build(CITY, tmp_path / "one.npz", lots_path=lots, options=BuildOptions(workers=1))
    assert [(b.index, b.id) for b in result.bad] == [(b.index, b.id) for b in single.bad] == [(2, "lot2"),
                                                                                              (5, "lot5")]
    assert [b["id"] for b in read_manifest(result.output)["bad"]] == ["lot2", "lot5"]
    assert result.derived == single.derived == 5
    assert_same_records(read_instances(tmp_path / "one.npz"), result.output)
