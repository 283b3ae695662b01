"""``grammarc build ... --dask ADDRESS|local:N``: a build spread over a Dask cluster (the ``dask`` extra).

A region's footprints outgrow one machine; a Dask cluster takes them with no change to the grammar, and
gives the records a one-process build gives (tests). The build runs in passes, each a task per partition
of the lots (``io.lots``):

1. counting: each partition's lot numbers (a lot's number seeds its random stream, so a partition must
   know where its numbers start); skipped for a file read whole, whose lots keep their numbers;
2. only for a grammar whose occlusion queries look at other lots: every partition's occluders, brought
   together on the client and sent to each worker once (``build.occluders``, as one process does);
3. deriving: each task reads its partition itself (from the path: lots never go through the scheduler),
   derives it with the plan that was sent to each worker once, and writes its shard and sidecar
   (``io.shards``), atomically. The client writes the manifest (and a USD root layer) when all are done.

A task lost with its worker is run again by Dask, and a failed one is retried (``RETRIES``); either way a
shard is complete or absent, never half written. With ``--resume`` a shard that is complete and whose
checksums hold is kept: only the others are derived.

Partitions hold ``--partition-size`` features (default ``PARTITION_SIZE``): each task then costs seconds,
far above Dask's per-task overhead (about a millisecond), and its records stay well within a worker's
memory. The lots file must be readable at the same path by every worker (a shared filesystem). The
grammar's asset files (which USD prototypes and CityEngine's trim planes load) are read on the client,
sent once to each worker and written to a folder of its own (``_asset_root``), so a rule package
extracted on the client, or an ``--assets`` folder only the client has, works on a cluster of machines.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path, PurePosixPath

import numpy as np

from grammarc import __version__
from grammarc.backend.occlusion import Occluders
from grammarc.backend.plan import make_plan
from grammarc.build import (
    BuildOptions,
    BuildResult,
    check_overrides,
    compile_source,
    derive_all,
    grammar_source,
    occluders,
    record_meta,
)
from grammarc.constants import PARTITION_SIZE
from grammarc.errors import UsageError
from grammarc.io import OutputOptions, writer_for
from grammarc.io.lots import Partition, count_lots, file_stamp, partition_lots, read_partition
from grammarc.io.lots_reading import find_lots
from grammarc.io.reports import write_reports
from grammarc.io.shards import (
    complete_shard,
    file_digests,
    instance_box,
    manifest_path,
    run_key,
    shard_name,
    shards_folder,
    sidecar_path,
    write_json,
)
from grammarc.ir.asset_names import resolve_asset
from grammarc.model.lots import BadLot
from grammarc.model.reports import Reports

__all__ = ["build_on_dask"]
#: Times Dask runs a failed task again.
RETRIES = 3
#: Shard formats: the suffixes ``--emit`` may have with ``--dask``.
_FORMATS = (".npz", ".usd", ".usda", ".usdc")


@dataclass(frozen=True)
class _Job:
    """What every shard task needs besides its partition, sent once per task (small)."""

    folder: Path
    suffix: str
    key: str
    options: BuildOptions
    output_options: OutputOptions
    assets: tuple[str, ...]
    symbols: tuple[str, ...]
    meta: dict
    #: The SHA-256 of the shipped asset files (``_asset_files``), which name their folder on a worker.
    assets_digest: str = ""


def build_on_dask(grammar_path, output, *, dask: str, lots_path=None, options: BuildOptions | None = None,
                  output_options: OutputOptions | None = None, partition_size: int = PARTITION_SIZE,
                  resume: bool = False, progress=None) -> BuildResult:
    """Derive a lots file on the Dask cluster ``dask`` (a scheduler address, or ``local:N`` for a local
    cluster of N worker processes) into shards and a manifest beside ``output``; the result's
    ``output`` is the manifest. ``progress(done, total)`` counts lots as shards finish."""
    started = time.perf_counter()
    options = options or BuildOptions()
    output = Path(output)
    suffix = output.suffix.lower()
    if suffix not in _FORMATS:
        raise UsageError(f"--dask writes .npz or USD shards, not `{output.name}`: bake or convert the shards "
                         "afterwards")
    local_workers = _local_workers(dask)  # a bad address is refused before anything is written
    lots_path = Path(lots_path) if lots_path else find_lots(Path(grammar_path))
    if lots_path is None:
        raise UsageError("--dask needs a lots file (--lots), which every worker reads its partitions of")
    with grammar_source(Path(grammar_path), options) as (source, display, resolved):
        grammar = compile_source(source, display, resolved)
        plan = make_plan(grammar)
        check_overrides(grammar.module, resolved.attrs)
        output_options = replace(output_options or OutputOptions(), asset_roots=tuple(grammar.asset_roots))
        writer_for(output, output_options)  # refuses a format it cannot write before the cluster starts
        partitions = partition_lots(lots_path, partition_size, options.lots)
        # the lots' own coordinate system is known to the workers only; a reprojection's is --crs
        meta = record_meta(Path(grammar_path), grammar, plan, options, str(lots_path), options.asset_roots,
                           options.lots.crs if options.lots is not None else None)
        files = _asset_files(grammar, output_options.lod)
        assets_digest = _digest(files)
        key = run_key({"meta": meta, "lots": file_stamp(lots_path), "partition_size": partition_size,
                       "format": suffix, "limits": options.limits, "version": __version__,
                       "assets": assets_digest})
        folder = shards_folder(output)
        if folder.exists() and not resume:
            shutil.rmtree(folder)
        folder.mkdir(parents=True, exist_ok=True)
        job = _Job(folder, suffix, key, replace(resolved, workers=1), output_options, tuple(grammar.assets),
                   tuple(plan.symbol_names), meta, assets_digest)
        with _client(dask, local_workers) as client:
            firsts = _first_numbers(client, partitions)
            sidecars = _derive_partitions(client, plan, files, partitions, firsts, job, resume, progress)
        _remove_temporaries(folder)
        manifest = _manifest(output, job, partitions, sidecars)
        write_json(manifest_path(output), manifest)
        if suffix != ".npz":
            from grammarc.io.usd import write_shards_root

            write_shards_root(output, manifest)
    bad = tuple(BadLot(b["index"], b["id"], b["reason"]) for s in sidecars for b in s["bad"])
    return BuildResult(manifest_path(output), manifest["lots"], manifest["derived"], bad, manifest["counts"],
                       time.perf_counter() - started, grammar)


def _local_workers(address: str) -> int | None:
    """The workers of a local cluster (``local:N``, ``local``: one per core), or None for an address."""
    if not address.startswith("local"):
        return None
    _, _, n = address.partition(":")
    if n and not n.isdigit() or n == "0":
        raise UsageError(f"--dask {address}: expected local:N with N workers, or a scheduler address")
    return int(n) if n else os.cpu_count() or 1


@contextlib.contextmanager
def _client(address: str, local_workers: int | None):
    """A client of the cluster at ``address``, or of a new local cluster of ``local_workers``."""
    try:
        from dask import distributed
    except ImportError as error:
        raise UsageError("--dask needs dask.distributed: pip install 'grammarc[dask]'") from error
    if local_workers is not None:
        with distributed.LocalCluster(n_workers=local_workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            yield client
        return
    try:
        client = distributed.Client(address, timeout="30s")
    except OSError as error:
        raise UsageError(f"--dask {address}: cannot reach the scheduler: {error}") from error
    with client:
        yield client


def _first_numbers(client, partitions: list[Partition]) -> list[int]:
    """The lot number each partition starts at (pass 1)."""
    if not partitions or partitions[0].kind == "whole":
        return [p.start for p in partitions]
    counts = client.gather(client.map(count_lots, partitions, pure=False, retries=RETRIES))
    return np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int).tolist()


def _derive_partitions(client, plan, files, partitions, firsts, job: _Job, resume: bool,
                       progress) -> list[dict]:
    """Passes 2 and 3: the occluders (if the grammar asks), then a shard per partition not yet complete;
    the sidecars in partition order."""
    from dask.distributed import as_completed

    sidecars: dict[int, dict] = {}
    if resume:
        for part in partitions:
            done = complete_shard(job.folder, part.number, job.key)
            if done is not None:
                sidecars[part.number] = done
    total = partitions[-1].stop if partitions else 0
    lots_done = sum(partitions[n].stop - partitions[n].start for n in sidecars)
    if progress is not None:
        progress(lots_done, total)
    remaining = [(p, f) for p, f in zip(partitions, firsts) if p.number not in sidecars]
    if not remaining:
        return [sidecars[p.number] for p in partitions]
    plan_future = client.scatter(plan, broadcast=True)
    files_future = client.scatter([files], broadcast=True)[0]  # a dict alone would be taken as many items
    foreign = None
    if plan.inter:
        tables = client.gather([client.submit(_occluders_task, plan_future, p, f, job.options, pure=False,
                                              retries=RETRIES) for p, f in zip(partitions, firsts)])
        foreign = client.scatter(Occluders.concat(tables), broadcast=True)
    futures = [client.submit(_shard_task, plan_future, part, first, job, foreign, files_future, pure=False,
                             retries=RETRIES) for part, first in remaining]
    try:
        for future in as_completed(futures):
            sidecar = future.result()
            sidecars[sidecar["partition"]] = sidecar
            part = partitions[sidecar["partition"]]
            lots_done += part.stop - part.start
            if progress is not None:
                progress(lots_done, total)
    except BaseException:
        client.cancel(futures)
        raise
    return [sidecars[p.number] for p in partitions]


def _occluders_task(plan, part: Partition, first: int, options: BuildOptions) -> Occluders:
    """On a worker: the occluders of a partition's lots (``build.occluders``)."""
    return occluders(plan, read_partition(part, first, options.lots), options)


def _shard_task(plan, part: Partition, first: int, job: _Job, foreign, files: dict[str, bytes]) -> dict:
    """On a worker: read the partition, derive it into its shard, write the sidecar; the sidecar."""
    roots = (_asset_root(files, job.assets_digest),)
    plan = replace(plan, grammar=replace(plan.grammar, asset_roots=roots))
    job = replace(job, output_options=replace(job.output_options, asset_roots=roots))
    lots = read_partition(part, first, job.options.lots)
    path = job.folder / shard_name(part.number, job.suffix)
    failed: list[BadLot] = []
    reports = Reports()
    meta = {**job.meta, "shard": {"partition": part.number, "features": [part.start, part.stop]}}
    writer_class = writer_for(path, job.output_options)
    with writer_class(path, assets=job.assets, symbols=job.symbols, meta=meta) as writer:
        bounded = _Bounded(writer)
        derived = derive_all(plan, lots, job.options, bounded, failed, reports, foreign=foreign)
        counts = writer.close()
    files = [path]
    if job.suffix != ".npz":
        from grammarc.io.usd import tiles_folder

        files += [f for f in tiles_folder(path).rglob("*") if f.is_file()]
    if reports:
        report = job.folder / shard_name(part.number, ".reports.json")
        write_reports(reports, report, dict(zip(lots.index.tolist(), lots.ids.tolist())))
        files.append(report)
    bad = sorted((*lots.bad, *failed), key=lambda b: b.index)
    sidecar = {
        "partition": part.number,
        "run": job.key,
        "path": path.name,
        "features": [part.start, part.stop],
        "first_lot": first,
        "lots": len(lots) + len(lots.bad),
        "derived": derived,
        "bad": [{"index": b.index, "id": b.id, "reason": b.reason} for b in bad],
        "counts": counts,
        "bbox": bounded.box(),
        "files": file_digests(files, job.folder),
    }
    write_json(sidecar_path(job.folder, part.number), sidecar)
    return sidecar


def _asset_files(grammar, lod: str | None) -> dict[str, bytes]:
    """The grammar's asset files (and their ``lod`` variants), by their names in the record."""
    files = {}
    for name in grammar.assets:
        found = resolve_asset(name, list(grammar.asset_roots))
        if found.path is None:
            continue  # a built-in, or missing: reported where it is loaded, as in one process
        variants = [found.path] + ([found.path.with_name(f"{found.path.stem}.{lod}{found.path.suffix}")]
                                   if lod else [])
        for path in variants:
            if path.is_file():
                files[(PurePosixPath(found.name).parent / path.name).as_posix()] = path.read_bytes()
    return files


def _digest(files: dict[str, bytes]) -> str:
    """The SHA-256 of named files, in name order."""
    digest = hashlib.sha256()
    for name in sorted(files):
        digest.update(name.encode() + b"\0" + hashlib.sha256(files[name]).digest())
    return digest.hexdigest()


def _asset_root(files: dict[str, bytes], digest: str) -> Path:
    """On a worker: the shipped asset files written to a folder named by their digest, once per machine
    (a worker that finds it complete uses it; one that writes it renames it into place when done)."""
    folder = Path(tempfile.gettempdir()) / f"grammarc-assets-{digest[:24]}"
    if folder.is_dir():
        return folder
    staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", dir=folder.parent))
    for name, data in files.items():
        path = staging / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    try:
        os.rename(staging, folder)
    except OSError:  # another worker of this machine was first
        shutil.rmtree(staging, ignore_errors=True)
    return folder


class _Bounded:
    """A writer's ``write``, keeping the box of the records written: instances' boxes and mesh vertices."""

    def __init__(self, writer) -> None:
        self.writer = writer
        self.low = np.full(3, np.inf)
        self.high = np.full(3, -np.inf)

    def write(self, records) -> None:
        instance_box(records.world_xform(), self.low, self.high)
        if len(records.mesh.vertices):
            vertices = records.mesh.world(records.origins)
            self.low = np.minimum(self.low, vertices.min(axis=0))
            self.high = np.maximum(self.high, vertices.max(axis=0))
        self.writer.write(records)

    def box(self) -> dict | None:
        return None if np.isinf(self.low).any() else {"min": self.low.tolist(), "max": self.high.tolist()}


def _manifest(output: Path, job: _Job, partitions: list[Partition], sidecars: list[dict]) -> dict:
    boxes = [s["bbox"] for s in sidecars if s["bbox"]]
    counts: Counter = Counter()
    for sidecar in sidecars:
        counts.update(sidecar["counts"])
    folder = job.folder.name
    return {
        "kind": "grammarc-shards",
        "run": job.key,
        "meta": job.meta,
        "format": job.suffix,
        "symbols": list(job.symbols),
        "partitions": len(partitions),
        "lots": sum(s["lots"] for s in sidecars),
        "derived": sum(s["derived"] for s in sidecars),
        "counts": dict(counts),
        "bbox": ({"min": np.min([b["min"] for b in boxes], axis=0).tolist(),
                  "max": np.max([b["max"] for b in boxes], axis=0).tolist()} if boxes else None),
        "bad": [b for s in sidecars for b in s["bad"]],
        "shards": [{**{k: v for k, v in s.items() if k not in ("run", "bad")}, "path": f"{folder}/{s['path']}",
                    "files": {f"{folder}/{name}": digest for name, digest in s["files"].items()}}
                   for s in sidecars],
    }


def _remove_temporaries(folder: Path) -> None:
    """What tasks lost mid-write left (their writers' temporaries, ``.part-*.tmp*``)."""
    for leftover in folder.glob(".part-*"):
        if leftover.is_dir():
            shutil.rmtree(leftover, ignore_errors=True)
        else:
            leftover.unlink(missing_ok=True)
