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
import functools
import gc
import math
import os
import sys
import warnings
from pathlib import Path

from grammarc import __version__
from grammarc.commands.arguments import add_lots_options
from grammarc.commands.building import run_build, run_search
from grammarc.commands.conformance import run_conform
from grammarc.commands.grammar_report import run_check
from grammarc.commands.serving import run_server
from grammarc.commands.showing import run_info, run_lots, run_render, run_view
from grammarc.constants import LIMITS, PARTITION_SIZE
from grammarc.errors import (
    GrammarcError,
    GrammarError,
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


@functools.cache
def _parser() -> argparse.ArgumentParser:
    """The command line's parser, made once a process: a warm server made it to read its own command, and
    every command it forks parses with it rather than make its own (parsing leaves it unchanged)."""
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
    add_lots_options(build)
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
    build.set_defaults(run=run_build)

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
    search.set_defaults(run=run_search)

    conform = sub.add_parser("conform", help="compare grammarc with Esri's PRT on the conformance kit")
    conform.add_argument("rpk", type=Path, nargs="?", help="a rule package of the kit (.rpk)")
    conform.add_argument("footprint", nargs="?", help="a kit footprint name (rect_30x20) or a lots file")
    conform.add_argument("--attr", action="append", default=[], metavar="NAME=VALUE")
    conform.add_argument("--seed", type=int, default=0)
    conform.add_argument("--all", action="store_true",
                         help="every record of the kit's reference.json, as a table")
    conform.set_defaults(run=run_conform)

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
    check.set_defaults(run=run_check)

    lots = sub.add_parser("lots", help="read a lots file and report its lots; convert it to GeoParquet")
    lots.add_argument("path", type=Path, help="GeoJSON, a GeoJSON sequence, GeoParquet, a GIS file, OBJ or PRT "
                                              "shape JSON")
    lots.add_argument("--to", type=Path, metavar="OUT.parquet",
                      help="write the good lots as GeoParquet (extra `parquet`), which reads faster")
    add_lots_options(lots)
    lots.set_defaults(run=run_lots)

    info = sub.add_parser("info", help="what a city holds: counts, lots, bbox, polygons")
    info.add_argument("record", type=Path, help="an output of build: .npz, .usda/.usdc/.usd, .glb or .3dtiles")
    info.add_argument("--assets", type=Path, action="append", metavar="DIR",
                      help="folders for file assets (default: those the record names)")
    info.add_argument("--lod", metavar="NAME", help="count polygons at this level of detail")
    info.add_argument("--json", action="store_true", help="print the summary as JSON")
    info.set_defaults(run=run_info)

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
    render.set_defaults(run=run_render)

    view = sub.add_parser("view", help="show a city in a browser: a .3dtiles folder or an .npz record, served on "
                                       "this machine")
    view.add_argument("city", type=Path, help="a folder written with --emit CITY.3dtiles, or an instance record "
                                              "(.npz), written as 3D Tiles into a temporary folder first")
    view.add_argument("--port", type=int, default=0, metavar="N", help="the port on 127.0.0.1 (default: a free one)")
    view.add_argument("--no-browser", action="store_true", help="print the page's address, open no browser")
    view.add_argument("--lod", metavar="NAME", help="with an .npz: the assets' level of detail (as build's)")
    view.set_defaults(run=run_view)

    serve = sub.add_parser("server", help="a resident grammarc that starts each command warm: start it, "
                                          "stop (every server of this user), status")
    serve.add_argument("action", choices=("start", "stop", "status"))
    serve.add_argument("--idle-timeout", type=_positive, default=60, metavar="MIN",
                       help="stop after MIN minutes without a command (default 60)")
    serve.add_argument("--foreground", action="store_true", help="serve from this process, logging to stderr")
    serve.set_defaults(run=functools.partial(run_server, serve_command=main))
    return parser


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


if __name__ == "__main__":
    sys.exit(main())
