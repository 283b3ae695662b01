"""The ``grammarc`` command's entry point: a running server (``grammarc server start``) runs the command
warm; without one, this process runs it.

A command runs in the server only when the server runs the same grammarc in the same settings
(``server.key``); ``GRAMMARC_SERVER=off`` keeps every command in its own process, and ``grammarc server``
itself always runs here. The server's child gives the same output, messages and exit status as this
process would.

Run as the program (``argv`` None), the process ends as soon as a command (other than ``grammarc server``)
is done (``_end``): the exit functions run and the output is flushed, but the interpreter is not torn down
object by object. After a city's build that took 0.1-0.2 s of the whole command (the modules, numba's and
LLVM's objects, the lots), for memory that the system takes back at once when the process ends.
"""

from __future__ import annotations

import atexit
import os
import sys
import threading
from typing import NoReturn


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    status = None
    if os.environ.get("GRAMMARC_SERVER") != "off" and args[:1] != ["server"]:
        from grammarc import server  # not imported by a command that runs here in any case

        if server.AVAILABLE:
            status = server.request(args)
    if status is None:
        from grammarc.cli import main as run

        status = run(args)
    if argv is None and args[:1] != ["server"]:
        _end(status)
    return status


def _end(status: int) -> NoReturn:
    """End the process with ``status``: threads that are not daemons are waited for, the exit functions
    (``atexit``: finalizers of temporary files) run and the standard streams are flushed, as at any exit,
    but without the interpreter's teardown (the module docstring). A stream that cannot be flushed (a
    closed pipe) makes the status 120, as Python's exit does."""
    for thread in threading.enumerate():
        if thread is not threading.current_thread() and not thread.daemon:
            thread.join()
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe, a closed stream
            status = status or 120
    os._exit(status)


if __name__ == "__main__":
    sys.exit(main())
