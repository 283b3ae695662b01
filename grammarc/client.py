"""The ``grammarc`` command's entry point: a running server (``grammarc server start``) runs the command
warm; without one, this process runs it.

A command runs in the server only when the server runs the same grammarc in the same settings
(``server.key``); ``GRAMMARC_SERVER=off`` keeps every command in its own process, and ``grammarc server``
itself always runs here. The server's child gives the same output, messages and exit status as this
process would.
"""

from __future__ import annotations

import os
import sys


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if os.environ.get("GRAMMARC_SERVER") != "off" and argv[:1] != ["server"]:
        from grammarc import server  # not imported by a command that runs here in any case

        if server.AVAILABLE:
            status = server.request(argv)
            if status is not None:
                return status
    from grammarc.cli import main as run

    return run(argv)


if __name__ == "__main__":
    sys.exit(main())
