"""The ``grammarc`` command: ``build`` derives a city, ``check`` reports on a grammar, ``conform`` compares
with Esri's PRT.

Warnings of the libraries grammarc uses are not shown (unless asked for with Python's ``-W``): what the
user should know, grammarc says in its own words.

Exit codes: 0 success; 1 a build failed (unreadable lots, a derivation limit reached, a file system error
while it ran); 2 the grammar has errors or the command line is wrong (an output path that cannot be written
included, found before anything is derived). Errors go to stderr in one line each; no output file is left
by a failed build.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import signal
import sys
import warnings
from collections import Counter
from dataclasses import replace
from pathlib import Path

from grammarc import __version__
from grammarc.constants import LIMITS, PARTITION_SIZE
from grammarc.diagnostics import render_all
from grammarc.errors import (
    GrammarcError,
    GrammarError,
    UsageError,
    interruption,
    signals_stop,
    stopped,
)

_START_HELP = ("the start rule (default: @StartRule, else the first rule); a call `Lot(10, \"a\", true)` "
              "gives the arguments of a start rule with parameters")
_WARNINGS_HELP = "treat the grammar's warnings as errors: exit 2, nothing written"


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    # Imports and compiling make many objects and little garbage: the cyclic collector only costs there
    # (README, "Figures"). ``build.derive_all`` turns it on while chunks are derived.
    collecting = gc.isenabled()
    gc.disable()
    with signals_stop():
        try:
            try:
                with warnings.catch_warnings():
                    # grammarc says what concerns the user itself; the libraries' warnings (numpy's "invalid
                    # value in divide" of a value grammarc handles) are not the user's to read, unless asked
                    # for with Python's -W or PYTHONWARNINGS. The workers are forked with this filter.
                    if not sys.warnoptions:
                        warnings.simplefilter("ignore")
                    return args.run(args)
            except BaseException as error:  # whatever failed after a signal: the command was stopped
                stop = interruption(error)
                if stop is None or stop is error:
                    raise
                raise stop from error
        except GrammarError as error:
            print(str(error), file=sys.stderr)
            n = sum(d.is_error for d in error.diagnostics)
            print(f"{n} error{'s' if n != 1 else ''}; nothing was written", file=sys.stderr)
            return error.exit_code
        except GrammarcError as error:
            print(f"grammarc: error: {error}", file=sys.stderr)
            return error.exit_code
        except KeyboardInterrupt as stop:  # Ctrl-C, or SIGTERM / SIGHUP (``Stopped``)
            return stopped(stop)
        except BrokenPipeError:
            # the reader of our output went away (`grammarc info city.npz | head`): not an error of ours
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            return 0
        except OSError as error:  # the disk filled, a folder's permissions changed: said as a failure, no traceback
            print(f"grammarc: error: {_os_error(error)}; nothing was written", file=sys.stderr)
            return 1
        finally:
            if collecting:
                gc.enable()


def _os_error(error: OSError) -> str:
    """An OSError in one line: the file it concerns and the system's reason (``[Errno 28] No space left on
    device: 'x'`` -> ``x: No space left on device``)."""
    reason = error.strerror or str(error) or type(error).__name__
    return f"{error.filename}: {reason}" if error.filename is not None else reason


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="grammarc", description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("--version", action="version", version=f"grammarc {__version__}")
    sub = parser.add_subparsers(required=True, metavar="COMMAND")

    build = sub.add_parser("build", help="derive lots with a grammar and write instance records")
    build.add_argument("grammar", type=Path,
                       help="the grammar: a .cga file (paper notation or CityEngine CGA) or a .rpk package")
    build.add_argument("--emit", required=True, metavar="OUT",
                       help="output file: .npz (instance record), .usda/.usdc/.usd (instanced USD, extra "
                            "`usd`), .glb (glTF with GPU instancing), .3dtiles (a folder of 3D Tiles 1.1, for "
                            "`grammarc view`), or .obj/.ply/.stl (baked mesh)")
    build.add_argument("--lots", type=Path, metavar="PATH",
                       help="footprints: GeoJSON, a GeoJSON sequence, GeoParquet, a GIS file (.gpkg, .shp, "
                            ".fgb, ...) or OBJ (default: the lots beside the grammar, or one 30 x 20 m lot)")
    build.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    build.add_argument("--attr", action="append", default=[], metavar="NAME=VALUE",
                       help="override an attribute for every lot (repeatable)")
    build.add_argument("--start", metavar="RULE", help=_START_HELP)
    build.add_argument("--warnings-as-errors", action="store_true", help=_WARNINGS_HELP)
    build.add_argument("--chunk-size", type=_positive, default=16384, metavar="N",
                       help="at most N lots derived together (default 16384; fewer when lots make many "
                            "records); the output does not depend on it")
    build.add_argument("--max-depth", type=_positive, default=LIMITS.max_depth, metavar="N",
                       help=f"rule applications along one path (default {LIMITS.max_depth})")
    build.add_argument("--max-shapes", type=_positive, default=LIMITS.max_shapes, metavar="N",
                       help=f"shapes made from one lot (default {LIMITS.max_shapes:,})")
    _workspace_option(build)
    _package_size_option(build)
    build.add_argument("--assets", type=Path, action="append", default=[], metavar="DIR",
                       help="a further folder for I() assets (the grammar's folder comes first)")
    build.add_argument("--dialect", choices=("cga2006", "cityengine"),
                       help="the grammar's notation (default: detected from its text)")
    build.add_argument("--workers", type=_positive, default=_cores(), metavar="N",
                       help=f"chunks derived at once, in N forked processes (default: the {_cores()} cores this "
                            "process may use); the output does not depend on it")
    build.add_argument("--bake", action="store_true",
                       help="expand the instances into one mesh (.glb; .obj/.ply/.stl always are)")
    build.add_argument("--max-triangles", type=_positive, metavar="N",
                       help=f"refuse a baked mesh of more triangles (default {LIMITS.max_triangles:,}, or "
                            "GRAMMARC_MAX_TRIANGLES)")
    build.add_argument("--lod", metavar="NAME",
                       help="level of detail: asset `x.obj` is drawn as `x.NAME.obj` where that file exists; "
                            "`builtin`: a cube stands in for a missing asset file")
    _lots_options_arguments(build)
    build.add_argument("--strict", action="store_true",
                       help="exit 1 when any lot is bad or fails to derive (its output is still written)")
    build.add_argument("--bake-origin", type=_point, metavar="X,Y,Z",
                       help="world point subtracted from a baked mesh's coordinates (default: world coordinates, "
                            "or the middle of the city in float32 formats far from the origin; the file says which)")
    build.add_argument("--tile-size", type=float, metavar="M",
                       help=f"edge of the tiles of .usd*/.glb outputs in metres (default {LIMITS.tile_size:g}; "
                            f"the leaves of .3dtiles: {LIMITS.leaf_size:g})")
    build.add_argument("--select", metavar="IDS",
                       help="derive only these lots (comma-separated ids), e.g. to bake a few")
    build.add_argument("--reports", type=Path, metavar="PATH",
                       help="where report() values go: .json or .csv (default: OUT's name + .reports.json)")
    build.add_argument("--dask", metavar="ADDRESS",
                       help="derive on a Dask cluster: a scheduler address, or local:N for N local worker "
                            "processes; writes OUT's shards and manifest (extra `dask`)")
    build.add_argument("--partition-size", type=_positive, default=PARTITION_SIZE, metavar="N",
                       help=f"with --dask: features of the lots file per task (default {PARTITION_SIZE:,})")
    build.add_argument("--resume", action="store_true",
                       help="with --dask: keep the shards of an earlier run of the same build that are "
                            "complete and verified")
    build.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary")
    build.set_defaults(run=_build)

    search = sub.add_parser("search", help="search a grammar's designs for those that meet its goal: "
                                            "breadth-first, depth-first or A*")
    search.add_argument("grammar", type=Path, help="the grammar (paper notation) with sets of consequents: "
                                                    "choose(...) and `?` alternatives, and a `goal:`")
    search.add_argument("--lots", type=Path, metavar="PATH",
                        help="the lots to search from, each on its own (default: as for build)")
    search.add_argument("--strategy", choices=("bfs", "dfs", "astar"), default="bfs",
                        help="breadth-first (all solutions, fewest choices first), depth-first (in the written "
                             "order of the consequents) or A* (cheapest first, by `cost:` and `heuristic:`)")
    search.add_argument("--solutions", type=_positive, metavar="K", help="stop a lot's search at K solutions "
                        "(default: all)")
    search.add_argument("--max-states", type=_positive, default=1_000_000, metavar="N",
                        help="derive at most N states per lot (default 1,000,000): memory follows it")
    search.add_argument("--batch", type=_positive, default=16384, metavar="N",
                        help="the states DFS and A* take at once, and the most derived together (default 16384); "
                             "the solutions' order does not depend on it")
    search.add_argument("--emit", type=Path, metavar="OUT",
                        help="the solutions' designs as a record (.npz...), its lot column the solution number")
    search.add_argument("--tree", type=Path, metavar="JSON", help="the derivation graph of the states derived")
    search.add_argument("--seed", type=int, default=0, help="random seed of the draws that are not choices")
    search.add_argument("--attr", action="append", default=[], metavar="NAME=VALUE",
                        help="override an attribute for every lot (repeatable)")
    search.add_argument("--max-depth", type=_positive, default=LIMITS.max_depth, metavar="N",
                        help=f"rule applications along one path of a state (default {LIMITS.max_depth})")
    search.add_argument("--max-shapes", type=_positive, default=LIMITS.max_shapes, metavar="N",
                        help=f"shapes made in one state (default {LIMITS.max_shapes:,})")
    search.add_argument("--workers", type=_positive, default=_cores(), metavar="N",
                        help=f"states derived at once in N forked processes (default: the {_cores()} cores this "
                             "process may use); the solutions do not depend on it")
    search.add_argument("--quiet", "-q", action="store_true", help="no summary")
    search.set_defaults(run=_search)

    conform = sub.add_parser("conform", help="compare grammarc with Esri's PRT on the conformance kit")
    conform.add_argument("rpk", type=Path, nargs="?", help="a rule package of the kit (.rpk)")
    conform.add_argument("footprint", nargs="?", help="a kit footprint name (rect_30x20) or a lots file")
    conform.add_argument("--attr", action="append", default=[], metavar="NAME=VALUE")
    conform.add_argument("--seed", type=int, default=0)
    conform.add_argument("--all", action="store_true",
                         help="every record of the kit's reference.json, as a table")
    conform.set_defaults(run=_conform)

    check = sub.add_parser("check", help="report every problem of a grammar, and a summary")
    check.add_argument("grammar", type=Path)
    check.add_argument("--start", metavar="RULE", help=_START_HELP)
    check.add_argument("--warnings-as-errors", action="store_true", help=_WARNINGS_HELP)
    check.add_argument("--dump-ir", action="store_true", help="print the IR after the passes")
    check.add_argument("--fusion", action="store_true",
                       help="say which symbols the fused kernels derive, and why each other one is left to the "
                            "interpreter")
    _workspace_option(check)
    _package_size_option(check)
    check.add_argument("--dialect", choices=("cga2006", "cityengine"),
                       help="the grammar's notation (default: detected from its text)")
    check.set_defaults(run=_check)

    lots = sub.add_parser("lots", help="read a lots file and report its lots; convert it to GeoParquet")
    lots.add_argument("path", type=Path, help="GeoJSON, a GeoJSON sequence, GeoParquet, a GIS file, OBJ or PRT "
                                              "shape JSON")
    lots.add_argument("--to", type=Path, metavar="OUT.parquet",
                      help="write the good lots as GeoParquet (extra `parquet`), which reads faster")
    _lots_options_arguments(lots)
    lots.set_defaults(run=_lots)

    info = sub.add_parser("info", help="what a city holds: counts, lots, bbox, polygons")
    info.add_argument("record", type=Path, help="an output of build: .npz, .usda/.usdc/.usd, .glb or .3dtiles")
    info.add_argument("--assets", type=Path, action="append", metavar="DIR",
                      help="folders for file assets (default: those the record names)")
    info.add_argument("--lod", metavar="NAME", help="count polygons at this level of detail")
    info.add_argument("--json", action="store_true", help="print the summary as JSON")
    info.set_defaults(run=_info)

    render = sub.add_parser("render", help="draw an instance record as a shaded picture (PNG)")
    render.add_argument("record", type=Path, help="an instance record (.npz) written by `grammarc build` or "
                                                   "`grammarc search`, or the tree (.json) of `grammarc search --tree`")
    render.add_argument("-o", "--output", required=True, type=Path, metavar="PNG", help="the picture, .png")
    render.add_argument("--view", choices=("oblique", "top"), default="oblique",
                        help="oblique: perspective from above at an angle (default); top: orthographic")
    render.add_argument("--size", default="1600x1000", metavar="WxH", help="pixels (default 1600x1000)")
    render.add_argument("--color", choices=("material", "symbol", "asset"), default="material",
                        help="the record's colours (default), or a colour per symbol or per asset")
    render.add_argument("--assets", type=Path, action="append", default=[], metavar="DIR",
                        help="a folder for file assets, instead of the grammar's folder (repeatable)")
    render.set_defaults(run=_render)

    view = sub.add_parser("view", help="show a city in a browser: a .3dtiles folder or an .npz record, served on "
                                       "this machine")
    view.add_argument("city", type=Path, help="a folder written with --emit CITY.3dtiles, or an instance record "
                                              "(.npz), written as 3D Tiles into a temporary folder first")
    view.add_argument("--port", type=int, default=0, metavar="N", help="the port on 127.0.0.1 (default: a free one)")
    view.add_argument("--no-browser", action="store_true", help="print the page's address, open no browser")
    view.add_argument("--lod", metavar="NAME", help="with an .npz: the assets' level of detail (as build's)")
    view.set_defaults(run=_view)

    serve = sub.add_parser("server", help="a resident grammarc that starts each command warm: start it, "
                                          "stop (every server of this user), status")
    serve.add_argument("action", choices=("start", "stop", "status"))
    serve.add_argument("--idle-timeout", type=_positive, default=60, metavar="MIN",
                       help="stop after MIN minutes without a command (default 60)")
    serve.add_argument("--foreground", action="store_true", help="serve from this process, logging to stderr")
    serve.set_defaults(run=_server)
    return parser


def _view(args) -> int:
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


def _server(args) -> int:
    from grammarc import server

    if not server.AVAILABLE:
        raise UsageError("grammarc server needs a system that forks and passes descriptors over Unix sockets "
                         "(Linux, macOS)")
    found, mine = server.servers(), server.address()
    if args.action == "status":
        for path, pid in found.items():
            print(f"grammarc server {pid} at {path}" + (" (this grammarc's)" if path == mine else ""))
        if mine not in found:
            print("no grammarc server runs this grammarc")
        return 0
    if args.action == "stop":
        for path, pid in found.items():
            os.kill(pid, signal.SIGTERM)
            print(f"grammarc server {pid} at {path} stopped")
        return 0
    if mine in found:
        print(f"grammarc server {found[mine]} already running at {mine}")
        return 0

    def ready(seconds: float) -> None:
        print(f"grammarc server {os.getpid()} ready at {mine} (warmed up in {seconds:.1f} s; "
              f"stops after {args.idle_timeout} min without a command)", flush=True)

    def serve(ready) -> None:
        server.serve(main, _warm, idle_timeout=60.0 * args.idle_timeout, ready=ready)

    if args.foreground:
        serve(ready)
        return 0
    return _detached(serve, ready)


def _detached(serve, ready) -> int:
    """Run ``serve(ready)`` in a daemon (a grandchild in its own session, its output in a log beside its
    socket); return once it says it is ready (its line printed here), or that it failed."""
    from grammarc import server

    read, write = os.pipe()
    if os.fork():
        os.close(write)
        with os.fdopen(read) as said:
            line = said.read().strip()
        if line.startswith("grammarc server"):
            print(line)
            return 0
        print(line or f"grammarc: error: the server did not start (its log: {server.folder()})", file=sys.stderr)
        return 1
    os.close(read)
    os.setsid()
    if os.fork():
        os._exit(0)
    server.folder().mkdir(mode=0o700, parents=True, exist_ok=True)
    log_path = server.address().with_suffix(".log")
    log = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
    os.dup2(write, 1)  # what it says until it is ready goes to the waiting parent, the rest to the log
    os.close(write)
    os.dup2(log, 2)

    def said(seconds: float) -> None:
        ready(seconds)
        os.dup2(log, 1)  # the pipe's last end closes: the parent reads its line and returns

    try:
        serve(said)
    except BaseException as error:  # noqa: BLE001 - a daemon has no one but its log and its parent to tell
        print(f"grammarc: error: {error}", flush=True)
        os._exit(1)
    os.unlink(log_path)  # it stopped as it should: nothing to look into
    os._exit(0)


def _warm() -> None:
    """What a server loads before serving: every module of grammarc (those of extras not installed
    excepted), the dialects' parsers, the fused regions' kernels that builds compiled, and the machine
    code of every kernel numba has cached; then its builds' workers need load none (``workers.warm``)."""
    import importlib
    import pkgutil

    import grammarc
    from grammarc import server, workers
    from grammarc.backend.fusion import compiled
    from grammarc.frontend.parse import DIALECTS
    from grammarc.frontend.parsers import parser_for

    for module in pkgutil.walk_packages(grammarc.__path__, "grammarc."):
        try:
            importlib.import_module(module.name)
        except ImportError:  # an optional extra's module (USD, Dask, ...) whose library is missing
            continue
    for dialect in DIALECTS.values():
        parser_for(dialect.grammar)
    compiled.import_compiled()
    server.load_cached_kernels()
    workers.warm()


def _cores() -> int:
    """The cores this process may run on (its affinity, as a container or ``taskset`` limits it)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _positive(text: str) -> int:
    value = int(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {value}")
    return value


def _point(text: str) -> tuple[float, float, float]:
    """``X,Y,Z`` world coordinates, finite."""
    try:
        point = tuple(float(v) for v in text.split(","))
    except ValueError:
        point = ()
    if len(point) != 3 or not all(math.isfinite(v) for v in point):
        raise argparse.ArgumentTypeError(f"must be three numbers X,Y,Z, got `{text}`")
    return point


def _lots_options_arguments(command) -> None:
    command.add_argument("--crs", metavar="CRS",
                         help="metric coordinate system to reproject lots in longitude/latitude to (e.g. "
                              "EPSG:2056; default: the UTM zone of their centre)")
    command.add_argument("--lots-crs", metavar="CRS",
                         help="coordinate system of the lots' file where it names none or the wrong one "
                              "(e.g. EPSG:4326)")
    command.add_argument("--id-field", metavar="NAME",
                         help="the lots' property that holds their ids (e.g. osm_id; default: a feature's id, "
                              "else its `id` or `name` property, else its number)")
    command.add_argument("--min-area", type=float, metavar="M2",
                         help="lots of less area (square metres) are bad: slivers")


def _lots_options(args):
    """The ``io.lot_format.LotsOptions`` of ``--lots-crs``, ``--crs``, ``--id-field`` and ``--min-area``;
    None without any."""
    from grammarc.io.lot_format import NO_OPTIONS, LotsOptions

    options = LotsOptions(lots_crs=args.lots_crs, crs=args.crs, id_field=args.id_field, min_area=args.min_area)
    return options if options != NO_OPTIONS else None


def _workspace_option(command) -> None:
    command.add_argument("--workspace", type=Path, metavar="DIR",
                         help="a CityEngine workspace (a folder of projects) where workspace paths "
                              "/Project/rules/x.cga and /Project/assets/x.obj are looked up (default: the "
                              "folder holding the grammar's project)")


def _package_size_option(command) -> None:
    from grammarc.io.rpk import MAX_PACKAGE_SIZE, MAX_RATIO

    command.add_argument("--max-package-size", type=_size, default=MAX_PACKAGE_SIZE, metavar="BYTES",
                         help=f"refuse a rule package (.rpk) that extracts to more (default "
                              f"{MAX_PACKAGE_SIZE >> 30}G; K, M and G are binary units; also never more than "
                              f"{MAX_RATIO} times the package's size)")


def _size(text: str) -> int:
    """A positive number of bytes, with an optional K, M or G (binary units): ``2G``, ``500M``."""
    units = {"K": 1 << 10, "M": 1 << 20, "G": 1 << 30}
    scale = units.get(text[-1:].upper(), 1)
    try:
        value = int(float(text[:-1] if scale > 1 else text) * scale)
    except (ValueError, OverflowError):
        value = 0
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive size in bytes (or with K, M, G), got `{text}`")
    return value


def _warn(grammar) -> None:
    if grammar.warnings:
        print(render_all(list(grammar.warnings), grammar.sources), file=sys.stderr)


def _check(args) -> int:
    from grammarc.build import BuildOptions, compile_source, grammar_source
    from grammarc.ir.nodes import RuleGraph
    from grammarc.ir.printer import print_module

    options = BuildOptions(start=args.start, dialect=args.dialect, workspace=args.workspace,
                           warnings_as_errors=args.warnings_as_errors, max_package_size=args.max_package_size)
    with grammar_source(args.grammar, options) as (source, display, resolved):
        grammar = compile_source(source, display, resolved, derive=False)
    _warn(grammar)
    graph = grammar.graph or RuleGraph("-", (), (), frozenset(), frozenset(), {})  # a file without rules
    if args.dump_ir:
        print(print_module(grammar.module))
    print(f"{args.grammar}: ok")
    print(f"  rules:     {len(grammar.module.rules)} ({len(graph.nonterminals)} symbols with rules)")
    print(f"  start:     {graph.start}")
    print(f"  terminals: {_listed(graph.terminals)}")
    print(f"  recursive: {_listed(sorted(graph.recursive))}")
    print(f"  attrs:     {_listed([a.name for a in grammar.module.attrs])}")
    print(f"  assets:    {_listed(grammar.assets)}")
    if args.fusion:
        _fusion_summary(grammar)
    return 0


def _fusion_summary(grammar) -> None:
    """``check --fusion``: what keeps the grammar, and then each symbol, from the fused kernels
    (``backend.fusion.regions``), and the most frequent reasons among the symbols."""
    from collections import Counter

    from grammarc.backend.fusion.regions import grammar_refusals, symbol_refusals
    from grammarc.backend.plan import make_plan

    plan = make_plan(grammar)
    whole = grammar_refusals(plan)
    refused = symbol_refusals(plan)
    fused = [sym.name for sym in plan.symbols if sym.rules and sym.name not in refused]
    print(f"  fusion:    {'the whole grammar is interpreted: ' + '; '.join(whole) if whole else 'allowed'}")
    print(f"  fusible:   {_listed(fused)}" + (" (were the grammar's reasons gone)" if whole and fused else ""))
    for name, why in refused.items():
        print(f"    {name}: {why}")
    tally = Counter(f"{why.what}{f' `{why.name}`' if why.name else ''}" for why in refused.values())
    print("  most frequent: " + (", ".join(f"{what} ({n})" for what, n in tally.most_common(5)) or "-"))


def _listed(names, most: int = 40) -> str:
    """Names for the summary of ``check``: a grammar of thousands of rules shows the first ``most``."""
    names = list(names)
    if not names:
        return "-"
    more = f" and {len(names) - most:,} more" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def _render(args) -> int:
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


def _lots(args) -> int:
    from grammarc.io.lots import read_lots
    from grammarc.io.output_paths import check_writable

    if args.to is not None:
        if args.to.suffix.lower() != ".parquet":
            raise UsageError(f"--to writes GeoParquet: give a .parquet path, not `{args.to}`")
        check_writable([args.to])  # before the lots are read, which may take long
    lots = read_lots(args.path, _lots_options(args))
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


def _info(args) -> int:
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


def _conform(args) -> int:
    from grammarc.backend.attributes import parse_override
    from grammarc.conform import kit_dir, load_reference, run_conformance

    reference = load_reference()
    if args.all:
        runs = [(kit_dir() / "rpk" / f"{r['rpk']}.rpk", r["footprint"], r.get("attrs", {}))
                for r in reference["records"]]
    elif args.rpk is None or args.footprint is None:
        raise UsageError("conform takes RPK FOOTPRINT, or --all")
    else:
        runs = [(args.rpk, args.footprint, dict(parse_override(a) for a in args.attr))]
    print("| rpk | footprint | attrs | verdict |")
    print("|---|---|---|---|")
    passed = 0
    for rpk, footprint, attrs in runs:
        result = run_conformance(rpk, footprint, attrs, seed=args.seed, reference=reference)
        passed += result.passed
        shown = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in attrs.items())
        print(f"| {result.rpk} | {result.footprint} | {shown or '-'} | {result.summary} |", flush=True)
    print(f"{passed} of {len(runs)} pass")
    return 0 if passed == len(runs) else 1


def _build(args) -> int:
    from grammarc.io.lots_reading import LotsReading

    lots_options = _lots_options(args)
    # the lots are read while the derivation is imported and the grammar compiled (``io.lots_reading``)
    reading = None if args.dask else LotsReading(args.grammar, args.lots, lots_options)

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
        lots=lots_options,
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
        _warn(result.grammar)
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


def _search(args) -> int:
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
        _warn(grammar)
        rate = result.states / result.seconds if result.seconds > 0 else 0.0
        print(f"{args.strategy}: {found:,} solutions from {result.states:,} states of {len(lots):,} lots in "
              f"{result.seconds:.2f} s ({rate:,.0f} states/s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
