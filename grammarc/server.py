"""A resident ``grammarc``: one warm process that forks a ready child for each command.

A command's own start-up (Python's imports, numba's compiler set-up, loading each kernel's machine code
from numba's cache) costs more than deriving a few lots. ``grammarc server start`` pays it once: the
server imports what a build needs, loads every cached kernel, then waits on a Unix socket. The
``grammarc`` command (``client.main``) finds it there and sends its arguments, working folder,
environment, umask and its own standard input, output and error (as file descriptors, ``SCM_RIGHTS``);
the server forks a child that takes them over and runs the command as ``cli.main`` would in the
client's process. Output goes straight to the client's terminal or files; the exit status comes back
over the socket. Each command runs in its own fresh fork: nothing of one command is seen by the next.

Signals: the client forwards SIGINT, SIGTERM and SIGHUP to the child; a client that dies without a word
(SIGKILL) closes the socket, and the child takes that as SIGTERM (its build stops and writes nothing, as
it would in the client's own process).

A server serves only commands that would run the same code in the same way: its socket's name is a
digest of grammarc's version and source files, the Python it runs on, and the environment variables read
at start-up (``GRAMMARC_*``, ``NUMBA_*``, ``PYTHON*``, the locale's, those of the libraries it imports:
``_KEYED_ENV``); a client that computes another
digest finds no server and runs the command itself. The socket lives in a folder only its user can enter
(``$XDG_RUNTIME_DIR/grammarc`` or ``/tmp/grammarc-<uid>``), and the server checks the caller's user id.

This module is imported by the client on every command that a server may run: it imports nothing heavy.
"""

from __future__ import annotations

import contextlib
import gc
import hashlib
import io
import json
import os
import select
import signal
import socket
import struct
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

from grammarc import releases
from grammarc.errors import interruption, raise_stopped, stopped
from grammarc.frontend.user_cache import code_stamp

#: Environment variables that change what the imported code does (read at import time): grammarc's, numba's,
#: Python's, the locale's, and those of the libraries a server imports before it serves
#: (``commands.serving.LIBRARIES``): PROJ's data and network (pyproj), USD's plugins and debugging (``PXR_``,
#: ``TF_``), Arrow's memory pool and threads.
_KEYED_ENV = ("GRAMMARC_", "NUMBA_", "PYTHON", "LANG", "LC_", "PROJ_", "PYPROJ_", "CURL_CA_BUNDLE", "SSL_CERT_FILE",
              "PXR_", "TF_", "ARROW_")
#: Client to server: a request's length, then the request (JSON); then one byte per forwarded signal.
_LENGTH = struct.Struct("!I")
#: Server to client: the command's exit status.
_STATUS = struct.Struct("!i")
_FORWARDED = (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", signal.SIGTERM))
#: Whether this system can run a server: it forks, and passes descriptors over Unix sockets (not Windows).
AVAILABLE = hasattr(os, "fork") and hasattr(socket, "send_fds") and hasattr(signal, "pthread_sigmask")


def folder() -> Path:
    """The folder of this user's servers' sockets (``serve`` makes it, private to the user)."""
    base = os.environ.get("XDG_RUNTIME_DIR") or tempfile.gettempdir()
    name = "grammarc" if os.environ.get("XDG_RUNTIME_DIR") else f"grammarc-{os.getuid()}"
    return Path(base) / name


def _private(path: Path) -> bool:
    """Whether ``path`` is a folder of this user that nobody else can enter."""
    try:
        info = path.stat()
    except OSError:
        return False
    return info.st_uid == os.getuid() and not info.st_mode & 0o077


def key() -> str:
    """The digest that names the server this process may use: same code, same Python, same settings."""
    settings = sorted((k, v) for k, v in os.environ.items() if k.startswith(_KEYED_ENV) and k != "GRAMMARC_SERVER")
    return hashlib.sha256(json.dumps([code_stamp(), sys.warnoptions, settings]).encode()).hexdigest()[:16]


def address(digest: str | None = None) -> Path:
    """The socket of the server for ``digest`` (default: this process's ``key()``)."""
    return folder() / f"server-{digest or key()}.sock"


# -- the client's side ---------------------------------------------------------------------------------

def request(argv: list[str]) -> int | None:
    """Run ``argv`` in the server, if one serves this process's key: its exit status, else None."""
    home = folder()
    if not _private(home):
        return None
    # signals are held from before the server can start the command until the request is sent, then
    # forwarded: a signal byte must not come before the request, nor end this process while it runs
    signal.pthread_sigmask(signal.SIG_BLOCK, _FORWARDED)
    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
            try:
                connection.connect(str(address()))
                here = os.getcwd()
            except OSError:  # no server, a stale socket of a killed one, a working folder removed
                return None
            status = _run_remotely(connection, argv, here)
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _FORWARDED)
    if status is None:
        print("grammarc: error: the grammarc server's process ended without an exit status",
              file=sys.stderr)
        return 1
    return _STATUS.unpack(status)[0]


def _run_remotely(connection: socket.socket, argv: list[str], here: str) -> bytes | None:
    """Send the request, forward signals until the status comes back; the status, or None."""
    def forward(signum, frame) -> None:
        with contextlib.suppress(OSError):  # the child already ended: its status is on its way
            connection.send(bytes([signum]))

    previous = {s: signal.signal(s, forward) for s in _FORWARDED}
    try:
        payload = json.dumps({"argv": argv, "cwd": here, "env": dict(os.environ), "umask": _umask()}).encode()
        socket.send_fds(connection, [_LENGTH.pack(len(payload))], [0, 1, 2])
        connection.sendall(payload)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _FORWARDED)
        return _receive_exactly(connection, _STATUS.size)
    finally:
        signal.pthread_sigmask(signal.SIG_BLOCK, _FORWARDED)  # restored before they are let through
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _receive_exactly(connection: socket.socket, size: int) -> bytes | None:
    """``size`` bytes from ``connection``, or None if it ends first."""
    data = b""
    while len(data) < size:
        part = connection.recv(size - len(data))
        if not part:
            return None
        data += part
    return data


# -- the server's side ---------------------------------------------------------------------------------

def servers() -> dict[Path, int]:
    """The servers of this user that answer: socket -> process id (those of other versions of grammarc or
    other settings too). Files of servers that were killed are removed."""
    home = folder()
    found = {}
    if not _private(home):
        return found
    for pid_file in sorted(home.glob("server-*.pid")):
        socket_path = pid_file.with_suffix(".sock")
        probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            probe.connect(str(socket_path))
            found[socket_path] = int(pid_file.read_text())
        except (OSError, ValueError):
            socket_path.unlink(missing_ok=True)
            pid_file.unlink(missing_ok=True)
        finally:
            probe.close()
    return found


def load_cached_kernels() -> int:
    """Load the machine code of every kernel of grammarc's imported modules (its own, and the generated
    modules of fused regions, ``backend.fusion.compiled``) that numba's cache holds for this version of
    its source; returns how many were loaded. Kernels not cached yet are left to be
    compiled on their first call, as without a server.

    numba offers no public way to list a function's cached signatures: its cache index is read through
    the dispatcher's cache object, and only entries whose key matches the function's current bytecode are
    loaded (``Dispatcher.compile`` then takes them from the cache rather than compiling).
    """
    from numba.core.dispatcher import Dispatcher

    from grammarc.backend.fusion.compiled import MODULE_PREFIX

    loaded = 0
    for name, module in list(sys.modules.items()):
        if not name.startswith(("grammarc.", MODULE_PREFIX)) or module is None:
            continue
        for kernel in list(vars(module).values()):
            if not isinstance(kernel, Dispatcher) or kernel.__module__ != name:
                continue
            cache = kernel._cache
            try:
                index = cache._cache_file._load_index()
            except AttributeError:  # not cached (``cache=False``)
                continue
            codegen = kernel.targetctx.codegen()
            for entry in index:
                if entry == cache._index_key(entry[0], codegen):
                    kernel.compile(entry[0])
                    loaded += 1
    return loaded


def serve(run: Callable[[list[str]], int], warm: Callable[[], None], *, idle_timeout: float,
          ready: Callable[[float], None] | None = None) -> None:
    """Warm up, then serve commands until ``idle_timeout`` seconds pass without one, or SIGTERM.

    ``run(argv)`` runs one command in a forked child and returns its exit status; ``warm()`` imports and
    loads what commands need, before the socket appears; ``ready(seconds)`` is called once it has.
    """
    started = time.perf_counter()
    warm()
    gc.collect()
    gc.freeze()  # what warm-up made stays out of the children's collections: their pages stay shared
    home = folder()
    home.mkdir(mode=0o700, parents=True, exist_ok=True)
    if not _private(home):
        raise OSError(f"{home}: not a private folder of this user; the server was not started")
    final = address()
    pid_file = final.with_suffix(".pid")
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    # bound under a private name and renamed into place once listening: a client never finds a socket
    # that does not answer yet
    provisional = home / f".server-{os.getpid()}.sock"
    with contextlib.suppress(FileNotFoundError):
        provisional.unlink()
    listener.bind(str(provisional))
    listener.listen(16)
    pid_file.write_text(str(os.getpid()))
    os.replace(provisional, final)

    # SIGTERM and SIGHUP wake the loop through a socket rather than raise where the server happens to be
    # (an exception raised in ``fork``'s hooks is lost)
    wake, woken = socket.socketpair()
    woken.setblocking(False)
    signal.set_wakeup_fd(woken.fileno())
    for signum in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, lambda signum, frame: None)
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # the kernel reaps the children
    if ready is not None:
        ready(time.perf_counter() - started)
    try:
        while True:
            asked, _, _ = select.select([listener, wake], [], [], idle_timeout)
            if listener not in asked:  # idle for too long, or told to stop
                return
            connection, _ = listener.accept()
            uid = struct.unpack("3i", connection.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, 12))[1]
            if uid != os.getuid():
                connection.close()
                continue
            if os.fork() == 0:
                signal.set_wakeup_fd(-1)
                for own in (listener, wake, woken):
                    own.close()
                _child(connection, run)  # never returns
            connection.close()
    finally:
        listener.close()
        if pid_file.exists() and pid_file.read_text() == str(os.getpid()):
            final.unlink(missing_ok=True)
            pid_file.unlink(missing_ok=True)


def _child(connection: socket.socket, run: Callable[[list[str]], int]) -> None:
    """In a forked child: take over the client's place and streams, run its command, report the status."""
    status = 1
    releases.hold()  # until the client has its status (``releases``)
    try:
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        for signum in _FORWARDED:  # as the command will, from before it begins
            signal.signal(signum, raise_stopped)
        status = _run_request(connection, run)
    except BaseException as error:  # noqa: BLE001 - whatever happened, the client hears a status
        stop = interruption(error)  # a signal forwarded before the command began
        if stop is not None:
            status = stopped(stop)
        else:
            with contextlib.suppress(BaseException):
                import traceback

                traceback.print_exc()
    finally:
        # The command is over: a client that hangs up once it has its status makes ``_watch`` send a
        # SIGTERM, which must not raise here, past ``_exit``, into the server's own code (which would say
        # "error: 15" on the client's streams)
        for signum in _FORWARDED:
            signal.signal(signum, signal.SIG_IGN)
        with contextlib.suppress(BaseException):
            sys.stdout.flush()
            sys.stderr.flush()
        with contextlib.suppress(OSError):
            connection.sendall(_STATUS.pack(status))
        _let_go(connection)
        releases.release_all()
        os._exit(status & 0xFF)


def _let_go(connection: socket.socket) -> None:
    """End the connection (which wakes ``_watch``: its SIGTERM is ignored by now) and let go of the client's
    streams (``/dev/null`` in their place): a client whose output goes into a pipe is done when every
    writer of the pipe is gone, not when it has its status."""
    with contextlib.suppress(OSError):  # the client may be gone already
        connection.shutdown(socket.SHUT_RDWR)
    with contextlib.suppress(OSError):
        null = os.open(os.devnull, os.O_RDWR)
        for fd in (0, 1, 2):
            os.dup2(null, fd)
        os.close(null)


def _run_request(connection: socket.socket, run: Callable[[list[str]], int]) -> int:
    head, fds, _, _ = socket.recv_fds(connection, _LENGTH.size, 3)
    if not head:  # a probe (``servers``): it only looked whether the server answers
        return 0
    head += _receive_exactly(connection, _LENGTH.size - len(head)) or b""
    body = _receive_exactly(connection, _LENGTH.unpack(head)[0]) if len(head) == _LENGTH.size else None
    if len(fds) != 3 or body is None:
        return 1
    for target, fd in enumerate(fds):
        os.dup2(fd, target)
        os.close(fd)
    command = json.loads(body)
    os.chdir(command["cwd"])
    os.environ.clear()
    os.environ.update(command["env"])
    os.umask(command["umask"])
    _open_streams()
    sys.argv = ["grammarc", *command["argv"]]
    try:
        threading.Thread(target=_watch, args=(connection,), daemon=True).start()
        return run(command["argv"])
    except SystemExit as done:  # argparse's --help and usage errors
        if done.code is None or isinstance(done.code, int):
            return done.code or 0
        print(done.code, file=sys.stderr)
        return 1


def _open_streams() -> None:
    """``sys.stdin``, ``stdout`` and ``stderr`` over the client's descriptors, buffered as Python would
    buffer them in the client (line by line on a terminal); their encoding is the server's, which has the
    client's locale settings (they are part of the key)."""
    unbuffered = bool(os.environ.get("PYTHONUNBUFFERED"))
    for fd, name in ((0, "stdin"), (1, "stdout"), (2, "stderr")):
        model = getattr(sys, f"__{name}__")
        raw = io.FileIO(fd, "r" if fd == 0 else "w", closefd=False)
        setattr(sys, name, io.TextIOWrapper(io.BufferedReader(raw) if fd == 0 else io.BufferedWriter(raw),
                                            encoding=model.encoding, errors=model.errors,
                                            line_buffering=fd == 2 or os.isatty(fd), write_through=unbuffered))


def _watch(connection: socket.socket) -> None:
    """Signals the client forwards, raised here; the client's end (it died) is a SIGTERM."""
    while True:
        try:
            data = connection.recv(16)
        except OSError:
            data = b""
        if not data:
            os.kill(os.getpid(), signal.SIGTERM)
            return
        for signum in data:
            os.kill(os.getpid(), signum)
