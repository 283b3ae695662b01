"""``grammarc build`` and ``grammarc search``: the options of a build or a search from the command line, a
progress bar, and what is said of the result."""

from __future__ import annotations

import sys
from collections import Counter
from dataclasses import replace
from pathlib import Path

from grammarc.commands.arguments import lots_options
from grammarc.commands.grammar_report import warn
from grammarc.constants import LIMITS
from grammarc.errors import UsageError


class _ProgressBar:
    """A tqdm bar of lots (with lots/s), made when the number of lots is known; silent off a terminal."""

    def __init__(self) -> None:
        self.bar = None

    def __call__(self, done: int, total: int) -> None:
        if self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(total=total, unit=" lots", desc="deriving", disable=None, dynamic_ncols=True,
                            leave=False)
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _build_on_dask(args, options, bar):
    from grammarc.cluster import build_on_dask
    from grammarc.io import OutputOptions
    from grammarc.io.output_paths import check_writable
    from grammarc.io.shards import manifest_path, shards_folder

    refused = [flag for flag, given in (("--select", args.select is not None), ("--reports", args.reports),
                                        ("--bake", args.bake)) if given]
    if refused:
        raise UsageError(f"{', '.join(refused)} cannot go with --dask: a cluster build writes shards (with "
                         "their reports beside them); select, bake or convert from them")
    output = Path(args.emit)
    check_writable([output, manifest_path(output)], [shards_folder(output)])
    return build_on_dask(args.grammar, args.emit, dask=args.dask, lots_path=args.lots, options=options,
                         output_options=OutputOptions(lod=args.lod, tile_size=args.tile_size),
                         partition_size=args.partition_size, resume=args.resume, progress=bar)


def run_build(args) -> int:
    from grammarc.io.lots_reading import LotsReading

    reading_options = lots_options(args)
    # the lots are read while the derivation is imported and the grammar compiled (``io.lots_reading``)
    reading = None if args.dask else LotsReading(args.grammar, args.lots, reading_options)

    from grammarc.backend.attributes import parse_override
    from grammarc.build import BuildOptions, build
    from grammarc.io import OutputOptions

    options = BuildOptions(
        seed=args.seed,
        attrs=dict(parse_override(a) for a in args.attr),
        start=args.start,
        chunk_size=args.chunk_size,
        limits=replace(LIMITS, max_depth=args.max_depth, max_shapes=args.max_shapes),
        asset_roots=tuple(args.assets),
        dialect=args.dialect,
        workers=args.workers,
        workspace=args.workspace,
        warnings_as_errors=args.warnings_as_errors,
        lots=reading_options,
        max_package_size=args.max_package_size,
    )
    bar = _ProgressBar() if not args.quiet else None
    try:
        if args.dask:
            result = _build_on_dask(args, options, bar)
        else:
            result = build(args.grammar, args.emit, lots_path=args.lots, options=options, progress=bar,
                           output_options=OutputOptions(bake=args.bake, lod=args.lod, tile_size=args.tile_size,
                                                        max_triangles=args.max_triangles, bake_origin=args.bake_origin),
                           select=None if args.select is None else [i for i in args.select.split(",") if i],
                           reports_to=args.reports, reading=reading)
    finally:
        if bar is not None:
            bar.close()
    # said even with --quiet: which lots were built where none were named, and where a file's numbers went
    if args.lots is None and not args.dask:
        print(f"grammarc: no --lots: built {result.lots_source}", file=sys.stderr)
    if result.crs_note is not None:
        print(f"grammarc: lots in {result.crs_note}", file=sys.stderr)
    if not args.quiet:
        warn(result.grammar)
        if result.duplicate_ids:
            shown = ", ".join(repr(i) for i in result.duplicate_ids[:5])
            print(f"grammarc: warning: {len(result.duplicate_ids):,} lot ids belong to more than one lot ({shown}"
                  f"{', ...' if len(result.duplicate_ids) > 5 else ''}): --id-field names the field of unique "
                  "ids", file=sys.stderr)
        for bad in result.bad:
            print(f"grammarc: lot {bad.id} (#{bad.index}) skipped: {bad.reason}", file=sys.stderr)
        if result.written:
            n = result.counts.get("instances", 0)
            rate = n / result.seconds if result.seconds > 0 else 0.0
            print(f"{result.output}: {n:,} instances, {result.counts.get('mesh_faces', 0):,} mesh faces from "
                  f"{result.derived:,} lots ({len(result.bad)} skipped) in {result.seconds:.2f} s "
                  f"({rate:,.0f} terminals/s)", file=sys.stderr)
    if result.bad and result.derived == 0:
        reasons = Counter(b.reason for b in result.bad).most_common(3)
        print(f"grammarc: none of the {result.lots:,} lots could be built ("
              + "; ".join(f"{n:,} {reason}" for reason, n in reasons) + ")"
              + ("" if result.written else "; nothing was written"), file=sys.stderr)
        return 1
    if result.bad:
        print(f"grammarc: {len(result.bad):,} of {result.lots:,} lots skipped", file=sys.stderr)
    return 1 if result.bad and args.strict else 0


def run_search(args) -> int:
    from grammarc.backend.attributes import check_overrides, parse_override
    from grammarc.backend.plan import make_plan
    from grammarc.build import BuildOptions, compile_source, record_meta
    from grammarc.io import written_paths
    from grammarc.io.lots_reading import load_lots
    from grammarc.io.output_paths import check_writable
    from grammarc.search import Deriving, SearchOptions, run_search, write_solutions

    options = BuildOptions(seed=args.seed, attrs=dict(parse_override(a) for a in args.attr),
                           limits=replace(LIMITS, max_depth=args.max_depth, max_shapes=args.max_shapes))
    grammar = compile_source(args.grammar, None, options)
    if grammar.module.dialect != "cga2006":
        raise UsageError(f"{args.grammar}: search takes grammars in the paper notation (choose, `?`, goal:)")
    check_overrides(grammar.module, options.attrs)
    outputs = [*(written_paths(args.emit)[0] if args.emit else []), *([args.tree] if args.tree else [])]
    check_writable(outputs, [])
    lots = load_lots(args.grammar, args.lots)
    plan = make_plan(grammar)
    deriving = Deriving(plan, lots, seed=args.seed, limits=options.limits, overrides=tuple(options.attrs.items()))
    search = SearchOptions(args.strategy, args.solutions, args.max_states, args.batch)
    result = run_search(deriving, search, record_tree=args.tree is not None, workers=args.workers)
    meta = record_meta(args.grammar, grammar, plan, options, lots.source, (), lots.crs)
    if args.emit:
        write_solutions(args.emit, deriving, result, search, meta)
    if args.tree:
        result.tree.write(args.tree, grammar.module, lots.ids, {**meta, "search": result.summary(deriving, search)})
    found = sum(r.found for r in result.lots)
    for lot in result.lots:  # said even with --quiet: the search did not end on its own
        if lot.limited:
            print(f"grammarc: lot {lots.ids[lot.lot]}: stopped at --max-states {args.max_states:,} "
                  f"({lot.states:,} states derived, {lot.found:,} solutions)", file=sys.stderr)
    if not args.quiet:
        warn(grammar)
        rate = result.states / result.seconds if result.seconds > 0 else 0.0
        print(f"{args.strategy}: {found:,} solutions from {result.states:,} states of {len(lots):,} lots in "
              f"{result.seconds:.2f} s ({rate:,.0f} states/s)", file=sys.stderr)
    return 0
