"""The commands that read a file and say or show what it holds: ``grammarc lots`` (a lots file, converted
to GeoParquet), ``info`` (a record), ``render`` (a picture of a record, or of a search's tree) and ``view``
(a record or a tileset in a browser)."""

from __future__ import annotations

import sys
from pathlib import Path

from grammarc.commands.arguments import lots_options
from grammarc.errors import UsageError


def run_lots(args) -> int:
    from grammarc.io.lots import read_lots
    from grammarc.io.output_paths import check_writable

    if args.to is not None:
        if args.to.suffix.lower() != ".parquet":
            raise UsageError(f"--to writes GeoParquet: give a .parquet path, not `{args.to}`")
        check_writable([args.to])  # before the lots are read, which may take long
    lots = read_lots(args.path, lots_options(args))
    for bad in lots.bad:
        print(f"grammarc: lot {bad.id} (#{bad.index}) is bad: {bad.reason}", file=sys.stderr)
    print(f"{args.path}: {len(lots):,} lots, {len(lots.bad):,} bad, {len(lots.vertices):,} vertices, "
          f"properties: {', '.join(lots.attrs) or '-'}")
    where = lots.crs_note or lots.crs or "none named (metres of a local scene)"
    print(f"coordinate system: {where if len(where) < 200 else where[:197] + '...'}")
    if args.to is not None:
        from grammarc.io.geoparquet import write_geoparquet

        write_geoparquet(lots, args.to)
        print(f"{args.to}: written")
    return 0


def run_info(args) -> int:
    import json

    from grammarc.io.summary import READS, format_summary, summarize, what_file

    try:
        summary = summarize(args.record, args.assets, args.lod)
    except OSError as error:
        raise UsageError(f"{args.record}: {error.strerror or error}") from error
    except (ValueError, KeyError) as error:
        raise UsageError(f"{args.record}: not a file info reads ({READS}): {what_file(args.record)}") from error
    print(json.dumps(summary, indent=1) if args.json else format_summary(summary))
    return 0


def run_render(args) -> int:
    from grammarc.io.npz import load_record
    from grammarc.io.output_paths import check_writable
    from grammarc.io.rpk import record_asset_roots
    from grammarc.render.picture import parse_size, png_path, render

    size = parse_size(args.size)
    check_writable([png_path(args.output)])  # before the record is read, which may be large
    if args.record.suffix.lower() == ".json":
        return _render_tree(args)
    record = load_record(args.record)
    with record_asset_roots(record.get("meta"), args.assets or None) as roots:
        result = render(record, args.output, size=size, view=args.view, color=args.color, asset_roots=roots)
    for problem in result["asset_problems"]:
        print(f"grammarc: {problem}; drawn as boxes (--assets DIR gives a folder)", file=sys.stderr)
    print(f"{args.output}: {result['instances']:,} instances, {result['mesh_faces']:,} mesh faces",
          file=sys.stderr)
    return 0


def _render_tree(args) -> int:
    """``grammarc render tree.json``: the derivation graph of ``grammarc search --tree``, a thumbnail per
    state, its states derived again from the grammar and lots its meta names."""
    import json

    from grammarc.backend.plan import make_plan
    from grammarc.build import BuildOptions, compile_source
    from grammarc.io.lots_reading import load_lots
    from grammarc.search import Deriving
    from grammarc.search.tree_picture import draw_tree

    try:
        tree = json.loads(args.record.read_text(encoding="utf-8"))
        meta, nodes = tree, tree["states"]
        grammar_path = Path(meta["grammar"])
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise UsageError(f"{args.record}: not a tree of `grammarc search --tree` ({error})") from error
    options = BuildOptions(seed=meta.get("seed", 0), attrs=meta.get("attrs", {}))
    grammar = compile_source(grammar_path, None, options)
    lots_source = meta.get("lots_source")
    lots = load_lots(grammar_path, Path(lots_source) if lots_source and Path(lots_source).is_file() else None)
    deriving = Deriving(make_plan(grammar), lots, seed=options.seed, overrides=tuple(options.attrs.items()))
    drawn = draw_tree(deriving, nodes, args.output)
    print(f"{args.output}: {drawn['states']:,} states in {drawn['rows']:,} rows", file=sys.stderr)
    return 0


def run_view(args) -> int:
    import tempfile

    from grammarc.render.view import page_missing, serve

    problem = page_missing()  # said before an .npz is written as a tileset
    if problem is not None:
        raise UsageError(problem)

    def show(folder: Path) -> int:
        serve(folder, port=args.port, open_browser=not args.no_browser,
              ready=lambda url: print(f"grammarc view: {url} (Ctrl-C stops)", flush=True))
        return 0

    if args.city.is_dir():
        if not (args.city / "tileset.json").is_file():
            raise UsageError(f"`{args.city}` has no tileset.json: give a folder written with --emit CITY.3dtiles")
        return show(args.city)
    from grammarc.io.npz import load_record
    from grammarc.io.tiles3d import write_record

    record = load_record(args.city)  # a UsageError where it is not a record
    with tempfile.TemporaryDirectory(prefix="grammarc-view-") as folder:
        tileset = Path(folder) / f"{args.city.stem}.3dtiles"
        write_record(record, tileset, args.lod)
        return show(tileset)
