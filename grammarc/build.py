"""``grammarc build``: grammar and lots in, instance records out, chunk by chunk.

Lots are derived in chunks of ``chunk_size`` and each chunk's records are streamed to the writer, so memory
is bounded by a chunk (docs/architecture.md, invariant 3). A chunk that cannot be derived whole is not lost:

- lots that fail (a negative size, an unsupported geometry, more shapes than --max-shapes, a recursion
  deeper than --max-depth) are reported by id and skipped, and the chunk is derived again without them;
- a chunk that makes more shapes than its memory budget is split in halves, derived one after the other;
- a chunk on which grammarc itself fails (an exception that is not one of its errors: a fault of grammarc's
  that some lot's geometry meets) is split in halves until the lots it fails on are found; each is reported
  as a bad lot that names the fault, and the others are derived. A city of a million lots is not lost to
  one lot, and the fault is said with the lot to reproduce it. With ``GRAMMARC_STRICT`` set (the tests
  set it) the fault is raised instead, with its traceback.

None changes the output of the other lots, because a lot's records do not depend on its chunk.
"""

from __future__ import annotations

import contextlib
import functools
import gc
import time
import traceback
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from grammarc import __version__
from grammarc.backend.attributes import check_overrides
from grammarc.backend.derive import derive_chunk
from grammarc.backend.fusion.fused import preload
from grammarc.backend.occlusion import Occluders
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS, STRICT, Limits
from grammarc.errors import ChunkTooLarge, GrammarcError, LotFailure, UsageError, check_stopped, stops_held
from grammarc.io import OutputOptions, writer_for, written_paths
from grammarc.io.lot_format import LotsOptions
from grammarc.io.lots_reading import LotsReading
from grammarc.io.output_paths import check_writable
from grammarc.io.reports import staged_reports
from grammarc.io.rpk import MAX_PACKAGE_SIZE
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_ops
from grammarc.model.grammar import Grammar
from grammarc.model.lots import BadLot, Lots
from grammarc.model.records import LotOrigins, MeshChunk
from grammarc.model.reports import Reports
from grammarc.workers import first_tasks, worker_pool

#: Shapes plus records one chunk may make before it is split: ~100 bytes each, so about 2 GB.
CHUNK_BUDGET = 20_000_000
#: Records a chunk aims at (the chunk size adapts to the records per lot seen so far). Each operation of
#: each rule costs a fixed time per chunk in Python besides its work on the columns, so a grammar of
#: many rules (examples/pompeii) wants large chunks; one of a few rules (the facade benchmark) is as fast
#: with small ones (README, "Figures").
ROWS_PER_CHUNK = 600_000
#: A build of at most this many lots is one chunk, derived in this process: forked workers would only wait
#: for it.
ONE_CHUNK = 64
#: Lots of the first chunk of a build with workers, derived in this process before they are forked
#: (``workers.worker_pool``): while it derives, the other cores wait, so it holds few lots (enough to load
#: the kernels and to count the records a lot makes).
FIRST_CHUNK = 16


@dataclass(frozen=True)
class BuildOptions:
    seed: int = 0
    attrs: dict = field(default_factory=dict)
    start: str | None = None
    chunk_size: int = 16384
    limits: Limits = LIMITS
    asset_roots: tuple[Path, ...] = ()
    chunk_budget: int = CHUNK_BUDGET
    #: ``cga2006`` or ``cityengine``; detected from the grammar's text when None.
    dialect: str | None = None
    #: Chunks derived at once, in as many processes (``grammarc.workers``); the output does not depend on it.
    workers: int = 1
    #: A CityEngine workspace (a folder of projects) for workspace paths ``/Project/...`` (``--workspace``).
    workspace: Path | None = None
    #: Whether a warning of the grammar stops the build as an error would (``--warnings-as-errors``).
    warnings_as_errors: bool = False
    #: What the user asks of the lots file: its coordinate system and the one to reproject to, the id
    #: field, the least area (``--lots-crs``, ``--crs``, ``--id-field``, ``--min-area``).
    lots: LotsOptions | None = None
    #: The most bytes a rule package may extract to (``--max-package-size``; ``io.rpk``).
    max_package_size: int = MAX_PACKAGE_SIZE


@dataclass(frozen=True)
class BuildResult:
    output: Path
    lots: int
    derived: int
    bad: tuple[BadLot, ...]
    counts: dict
    seconds: float
    grammar: Grammar
    #: How the lots came to metres where they were reprojected (``Lots.crs_note``), for the build to say.
    crs_note: str | None = None
    #: The lots file read (or the built-in lot's description), and ids that more than one lot has.
    lots_source: str = ""
    duplicate_ids: tuple[str, ...] = ()
    #: False when no lot could be built: the build failed, and the output (an older one too) is untouched.
    written: bool = True


def build(grammar_path, output, *, lots_path=None, options: BuildOptions = BuildOptions(),
          progress=None, output_options: OutputOptions | None = None,
          select: Sequence[str] | None = None, reports_to: Path | None = None,
          reading: LotsReading | None = None) -> BuildResult:
    """Derive the lots with the grammar and write the records to ``output`` (atomically).

    ``progress(done, total)`` is called with the number of lots finished after each chunk.
    ``select``: derive only the lots of these ids (``--select``); occlusion queries still see every
    lot's occluders, so a selected lot looks as it does in the whole city. ``reports_to``: where the
    values of ``report()`` go, ``.json`` or ``.csv`` (default ``reports_path(output)``). ``reading``: these
    lots (of ``lots_path`` and ``options.lots``) already being read (``io.lots_reading``: the command starts
    reading them before it imports this module); by default the build starts reading them.
    """
    started = time.perf_counter()
    if reading is None:
        reading = LotsReading(Path(grammar_path), Path(lots_path) if lots_path else None, options.lots)
    with grammar_source(Path(grammar_path), options) as (source, display, resolved):
        return _build(source, display, Path(grammar_path), output, reading, resolved, progress, started,
                      recorded_roots=options.asset_roots, output_options=output_options or OutputOptions(),
                      select=select,
                      reports_to=reports_to)


@contextlib.contextmanager
def grammar_source(path: Path, options: BuildOptions):
    """The rule file to compile and the options to use: a ``.rpk`` package is opened (extracted, or found
    in the cache of extracted packages) for the duration of the build, its main rule file compiled, its
    assets and start rule used."""
    if path.suffix.lower() != ".rpk":
        yield path, None, options
        return
    from grammarc.io.rpk import open_rpk

    with open_rpk(path, max_size=options.max_package_size) as package:
        if package.main_rule_file is None:
            raise UsageError(f"{path}: the rule package holds no CGA rule file")
        inside = package.main_rule_file.relative_to(package.root).as_posix()
        yield package.main_rule_file, f"{path.name}/{inside}", replace(
            options, asset_roots=(*package.asset_roots, *options.asset_roots),
            start=options.start or package.start_rule, workspace=options.workspace or package.workspace)


def compile_source(source: Path, display: str | None, options: BuildOptions, *, derive: bool = True):
    """Compile the rule file ``grammar_source`` gave, with the options that concern the grammar (``check``
    compiles with ``derive=False``: a start rule's missing arguments are then a warning)."""
    return compile_grammar(source, start=options.start, asset_roots=options.asset_roots,
                           dialect=options.dialect, display=display, workspace=options.workspace,
                           warnings_as_errors=options.warnings_as_errors, derive=derive)


def _build(source: Path, display: str | None, grammar_path: Path, output, reading: LotsReading,
           options: BuildOptions, progress, started: float, recorded_roots: tuple[Path, ...],
           output_options: OutputOptions, select: Sequence[str] | None,
           reports_to: Path | None) -> BuildResult:
    grammar = compile_source(source, display, options)
    plan = make_plan(grammar)
    check_overrides(grammar.module, options.attrs)
    writer_class = writer_for(output, replace(output_options, asset_roots=tuple(grammar.asset_roots)))
    reports_file = Path(reports_to) if reports_to else reports_path(Path(output))
    files, folders = written_paths(output, output_options)
    reporting = reports_to is not None or any(isinstance(op, ir.Report) for op in iter_ops(grammar.module))
    check_writable([*files, *([reports_file] if reporting else [])], folders)
    Path(output).parent.mkdir(parents=True, exist_ok=True)
    every = reading.result(meanwhile=preload(plan))
    lots = every if select is None else every.select(select)
    if display is None:  # a rule file on disk: its CityEngine project's folders too, for a later render
        recorded_roots = (*recorded_roots, *(r for r in grammar.asset_roots[1:] if r not in recorded_roots))
    meta = record_meta(grammar_path, grammar, plan, options, lots.source, recorded_roots, lots.crs)
    writer_class = writer_for(output, replace(output_options, asset_roots=tuple(grammar.asset_roots), lots=every))
    failed: list[BadLot] = []
    reports = Reports()
    counts: dict = {}
    written = False
    with contextlib.suppress(_NothingBuilt), contextlib.ExitStack() as stack:
        with stops_held():  # a stop between the writer's temporaries and their removal set up would leave them
            writer = stack.enter_context(writer_class(output, assets=grammar.assets, symbols=plan.symbol_names,
                                                      meta=meta))
        derived = derive_all(plan, lots, options, writer, failed, reports, progress, every)
        if not derived and (lots.bad or failed):
            raise _NothingBuilt  # a failed build: the writer aborts, an older output stays as it was
        # the reports are written before the output is put in place and renamed after it: a build whose
        # reports cannot be written leaves no new output
        check_stopped()  # a stop whose raise was lost leaves no output either
        with (staged_reports(reports, reports_file, dict(zip(every.index.tolist(), every.ids.tolist())))
              if reports else contextlib.nullcontext()):
            counts = writer.close()
        written = True
    bad = tuple(sorted((*lots.bad, *failed), key=lambda b: b.index))
    return BuildResult(Path(output), len(lots) + len(lots.bad), derived, bad, counts,
                       time.perf_counter() - started, grammar, lots.crs_note, every.source,
                       _duplicates(every.ids), written=written)


def _duplicates(ids: np.ndarray) -> tuple[str, ...]:
    """The ids that more than one lot has, in order; sorted out only where there are any (a set of the
    ids tells, in a tenth of the time sorting them takes)."""
    if len(set(ids.tolist())) == len(ids):
        return ()
    unique, times = np.unique(ids.astype(str), return_counts=True)
    return tuple(unique[times > 1].tolist())


class _NothingBuilt(Exception):
    """Every lot of a build was bad or failed: raised inside the writer so that it writes nothing."""


def record_meta(grammar_path: Path, grammar: Grammar, plan, options: BuildOptions, lots_source: str,
                recorded_roots: tuple[Path, ...], crs: str | None) -> dict:
    """The ``meta`` of a build's record: what it was made from, and the coordinate system of its world
    (``crs``: the lots', after any reprojection; None for metres of a local scene)."""
    return {
        "grammar": str(grammar_path),
        "grammar_sha256": grammar.digest,
        "grammarc": __version__,
        "seed": options.seed,
        "start": plan.symbols[plan.start].name,
        "attrs": {k: v for k, v in sorted(options.attrs.items())},
        "lots_source": lots_source,
        "crs": crs,
        "dialect": grammar.module.dialect,
        # the user's asset folders (baking); a package's own are left out: extracted to the user's cache, or
        # to a fresh temporary folder, their names would make the record differ by where it was built
        "asset_roots": [str(r) for r in recorded_roots],
        # operations accepted without effect on the record (material, texture, print)
        "not_applied": list(plan.not_applied),
    }


def derive(grammar: Grammar, lots: Lots, options: BuildOptions = BuildOptions()) -> dict:
    """Derive ``lots`` in memory: the record's columns as one dict (the same rows ``build`` writes).

    For tests and for callers that want arrays rather than a file. Bad lots are listed under ``"bad"``.
    """
    plan = make_plan(grammar)
    check_overrides(grammar.module, options.attrs)
    chunks: list = []
    failed: list[BadLot] = []

    class Collect:
        write = staticmethod(chunks.append)

    reports = Reports()
    derive_all(plan, lots, options, Collect, failed, reports)
    mesh = MeshChunk.concat([c.mesh for c in chunks]) if chunks else MeshChunk.empty()
    columns = {
        name: (np.concatenate([getattr(c, name) for c in chunks]) if chunks else
               np.zeros((0, 3, 4) if name == "xform" else 0, dtype=np.float32 if name == "xform"
                        else np.int32))
        for name in ("asset", "xform", "lot", "symbol")
    }
    if any(c.uv is not None for c in chunks):  # texture coordinates of set 0 (``TerminalChunk.uv``)
        columns["uv"] = np.concatenate([c.uv if c.uv is not None else np.full((len(c.asset), 2, 4), np.nan, np.float32)
                                        for c in chunks])
    if any(c.color is not None for c in chunks):  # RGBA, white where a chunk set none (``TerminalChunk.colors``)
        columns["color"] = np.concatenate([c.colors() for c in chunks])
    if chunks and chunks[0].material is not None:  # each instance's texture paths, not its chunk's row of them
        columns["material"] = np.concatenate([c.materials[c.material] for c in chunks])
    columns.update(
        assets=np.array(grammar.assets), symbols=np.array(plan.symbol_names), mesh=mesh,
        lot_origin=LotOrigins.concat([c.origins for c in chunks]).table(),
        bad=tuple(sorted((*lots.bad, *failed), key=lambda b: b.index)), reports=reports,
    )
    return columns


def reports_path(output: Path) -> Path:
    """Where the reports of ``output`` go: ``city.npz`` -> ``city.reports.json``."""
    return output.with_name(output.stem + ".reports.json")


def derive_all(plan, lots: Lots, options: BuildOptions, writer, failed: list[BadLot], reports: Reports,
               progress=None, context: Lots | None = None, foreign: Occluders | None = None) -> int:
    """Derive all ``lots`` chunk by chunk into ``writer``; returns the number of lots derived.

    A chunk holds at most ``options.chunk_size`` lots, and fewer when the lots so far made many records:
    the next chunk aims at ``ROWS_PER_CHUNK`` records, which keeps its arrays in the caches and its memory
    small whatever the grammar. The records do not depend on the chunking. A grammar whose occlusion
    queries look at other lots is derived twice: first for everyone's occluders (``occluders``), those of
    ``context`` when given (the whole city of a selection), unless ``foreign`` gives them (a cluster
    build's partition: the occluders of every partition).

    ``options.workers`` chunks are derived at once, each in a worker process (``workers.py``), and one more
    waits in the pool's queue, so a worker that finishes starts on it while the parent writes the chunk it
    returned, rather than wait. Results are written in chunk order, and a chunk's size is decided from the chunks finished before it in that
    order, so the chunking does not depend on timing (and the records never depend on the chunking). The
    first chunk is small (``FIRST_CHUNK``: the other cores wait for it), and the lots left once they are no
    more than a chunk for each worker are shared equally among the workers (``_last_share``), so that no
    worker derives a long last chunk while the others wait.
    """
    if plan.inter and foreign is None:
        foreign = occluders(plan, lots if context is None else context, options)
    if foreign is not None:
        foreign.index  # noqa: B018 - built once here, before the workers inherit it
    with _collecting():
        return _derive_chunks(plan, lots, options, writer, failed, reports, progress, foreign)


@contextlib.contextmanager
def _collecting():
    """The cyclic garbage collector on while chunks are derived (an executor's cycles must go with its
    chunk), after what the set-up made is frozen out of its sight: the grammar's IR, the plan, numba's
    dispatchers live to the end, and full collections need not walk them, nor forked workers touch their
    pages. ``grammarc``'s command turns the collector off for the set-up."""
    was_enabled = gc.isenabled()
    gc.freeze()
    gc.enable()
    try:
        yield
    finally:
        if not was_enabled:
            gc.disable()


def _derive_chunks(plan, lots: Lots, options: BuildOptions, writer, failed: list[BadLot], reports: Reports,
                   progress, foreign) -> int:
    """``derive_all`` once the occluders are known."""
    derived = 0
    first = 0
    rows = 0
    written = 0
    last = None  # the lots of each of the last chunks, once they are shared out
    # lots that make one chunk are derived in this process: forked workers would only wait for it
    workers = options.workers if len(lots) > min(options.chunk_size, ONE_CHUNK) else 1
    # the first chunks are sized before a lot's records are known: one of FIRST_CHUNK lots here while the
    # other cores wait, or in a warm process one of up to ONE_CHUNK lots for each worker at once (a build
    # of up to a chunk for each worker is then shared among them at once, ``_last_share``)
    size = min(options.chunk_size, FIRST_CHUNK if first_tasks(workers) < workers else ONE_CHUNK)
    with worker_pool(functools.partial(_derive, plan, options=options, foreign=foreign), workers) as submit:
        window: deque = deque()
        try:
            while first < len(lots) or window:
                # before the first chunk's records are known: the first chunk alone, or one for each worker
                # (``workers.first_tasks``); then a chunk for each worker and one more, waiting, sized by
                # the records a lot makes
                while first < len(lots) and len(window) < (workers + 1 if written else first_tasks(workers)):
                    last = last or _last_share(size, len(lots) - first, workers)
                    part = lots.take(slice(first, first + (last or size)))
                    window.append((len(part), submit(part)))
                    first += len(part)
                n_lots, future = window.popleft()
                results, part_failed = future.result()
                failed.extend(part_failed)
                for n_lots_derived, (records, per_lot) in results:
                    writer.write(records)
                    reports.add(per_lot)
                    derived += n_lots_derived
                    rows += len(records.asset) + len(records.mesh.lot)
                written += n_lots
                per_lot = rows / max(written, 1)
                size = int(np.clip(ROWS_PER_CHUNK / max(per_lot, 1.0), 1, options.chunk_size))
                if progress is not None:
                    progress(written, len(lots))
        except BaseException:
            for _, future in window:
                future.cancel()
            raise
    return derived


def _last_share(size: int, left: int, workers: int) -> int | None:
    """The lots of each of the last chunks where the ``left`` lots are no more than a chunk of ``size`` for
    each of the ``workers``: an equal share for each (None before then, and with one worker). Shared once,
    not halved again and again: a chunk costs a fixed time besides its lots (much of it on a grammar of
    many rules, examples/pompeii), and one more for each worker is what evens their ends."""
    return -(-left // workers) if workers > 1 and left <= workers * size else None


def _derive(plan, lots: Lots, options: BuildOptions, foreign=None) -> tuple[list, list[BadLot]]:
    """Derive ``lots`` (maybe in a worker process), skipping failing lots and splitting oversized chunks.

    Returns ``[(lots derived, (records, per_lot))]`` in lot order and the lots that failed.
    """
    failed: list[BadLot] = []
    results = [(len(part), result) for part, result in _attempts(lots, lambda part: derive_chunk(
        plan, part, seed=options.seed, limits=options.limits, overrides=options.attrs,
        chunk_budget=options.chunk_budget, foreign=foreign), failed)]
    return results, failed


def _attempts(lots: Lots, derive_part, failed: list[BadLot] | None):
    """``(part, derive_part(part))`` over ``lots``: lots that fail, or that grammarc fails on, are left out
    (and listed in ``failed``), a chunk too large for memory is halved."""
    queue = [lots]
    while queue:
        part = queue.pop(0)
        if not len(part):
            continue
        try:
            result = derive_part(part)
        except LotFailure as failure:
            skip = np.zeros(len(part), dtype=bool)
            skip[failure.lots] = True
            if failed is not None:
                failed.extend(BadLot(int(part.index[i]), str(part.ids[i]), failure.reason(k))
                              for k, i in enumerate(failure.lots))
            queue.insert(0, part.take(~skip))
            continue
        except ChunkTooLarge:
            queue[:0] = _halves(part)
            continue
        except (GrammarcError, MemoryError):
            raise
        except Exception as fault:
            if STRICT:
                raise
            if len(part) > 1:
                queue[:0] = _halves(part)
            elif failed is not None:
                failed.append(BadLot(int(part.index[0]), str(part.ids[0]), _fault(fault)))
            continue
        yield part, result


def _halves(part: Lots) -> list[Lots]:
    half = len(part) // 2
    return [part.take(slice(0, half)), part.take(slice(half, None))]


def _fault(fault: Exception) -> str:
    """What a bad lot says of a fault of grammarc's it met: the exception and where it was raised."""
    frames = traceback.extract_tb(fault.__traceback__)
    where = f" at {Path(frames[-1].filename).name}:{frames[-1].lineno}" if frames else ""
    return (f"grammarc failed on this lot ({type(fault).__name__}{where}: {fault}); this is a fault of "
            "grammarc's, not of the lot: please report it with the lot")


def occluders(plan, lots: Lots, options: BuildOptions) -> Occluders:
    """The first pass of a grammar whose queries look at other lots: every lot derived up to its first
    query, and the occluders made up to there (``backend.occlusion``). Lots that fail are left out here
    and reported by the second pass."""
    tables = []
    for first in range(0, len(lots), options.chunk_size):
        part = lots.take(slice(first, first + options.chunk_size))
        tables.extend(table for _, table in _attempts(part, lambda p: derive_chunk(
            plan, p, seed=options.seed, limits=options.limits, overrides=options.attrs,
            chunk_budget=options.chunk_budget, occluders_only=True), None))
    return Occluders.concat(tables)
