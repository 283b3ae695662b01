"""``grammarc server start|stop|status``: a resident grammarc, started as a daemon, that runs each command
warm (``server``); what it loads before it serves (``warm``)."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Callable

from grammarc.errors import UsageError


def run_server(args, serve_command: Callable[[list[str]], int]) -> int:
    """``grammarc server ACTION``; a server runs each command with ``serve_command`` (``cli.main``, which
    parses the command line as this command's did)."""
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
        server.serve(serve_command, warm, idle_timeout=60.0 * args.idle_timeout, ready=ready)

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


#: The libraries grammarc's readers and writers import where a command first needs one, imported by a server
#: before it serves, where installed: a served command is a fork, which would otherwise import its own on
#: every command that needs it (README, "Start-up"). Lots with a coordinate system (``io.crs``),
#: GeoParquet files (``io.arrow_lots``; reading a file goes through Arrow's datasets),
#: rule packages not kept yet (``io.rpk``), baked meshes and glTF assets (``io.bake``, ``model.assets``), USD
#: (``io.usd``). None starts a thread that a fork would lose but the allocator's, which forks take care of,
#: and none changes the environment; the settings they read from it when imported are part of the server's
#: key (``server.key``). GIS files' pyogrio is left out: its import sets GDAL's and PROJ's certificate
#: bundles in the environment, which a served command, given its client's environment, would not have.
LIBRARIES = ("pyproj", "pyarrow.parquet", "pyarrow.dataset", "py7zr", "trimesh",
             "pxr.Gf", "pxr.Sdf", "pxr.Tf", "pxr.Usd", "pxr.UsdGeom", "pxr.UsdShade", "pxr.Vt")


def warm() -> None:
    """What a server loads before serving: every module of grammarc (those of extras not installed
    excepted) and the libraries its readers and writers import when first needed (``LIBRARIES``), the
    dialects' parsers, the fused regions' kernels that builds compiled, and the machine code of every kernel
    numba has cached; then its builds' workers need load none (``workers.warm``)."""
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
    for name in LIBRARIES:
        # an extra not installed, or one that cannot start here (pyproj without its data): the command that
        # needs it imports it again, and says what failed as it would in its own process
        with contextlib.suppress(Exception):
            importlib.import_module(name)
    for dialect in DIALECTS.values():
        parser_for(dialect.grammar)
    compiled.import_compiled()
    server.load_cached_kernels()
    workers.warm()
