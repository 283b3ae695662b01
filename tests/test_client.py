"""The ``grammarc`` entry point: a server runs the command when one serves this grammarc, else this
process does; ``GRAMMARC_SERVER=off`` and ``grammarc server`` always run here."""

from __future__ import annotations

import pytest

from grammarc import client, server


@pytest.fixture
def asked(monkeypatch):
    """The requests made of a server that takes every command (status 7)."""
    made = []
    monkeypatch.setattr(server, "request", lambda argv: (made.append(argv), 7)[1])
    return made


def test_a_server_that_takes_the_command_gives_its_status(asked, monkeypatch):
    monkeypatch.delenv("GRAMMARC_SERVER", raising=False)
    assert client.main(["check", "g.cga"]) == 7 and asked == [["check", "g.cga"]]


def test_without_a_server_this_process_runs_the_command(monkeypatch, write):
    monkeypatch.setattr(server, "request", lambda argv: None)
    assert client.main(["check", str(write("g.cga", "Lot --> extrude(3)\n"))]) == 0


@pytest.mark.parametrize("argv", [["server", "status"], ["check", "g.cga"]])
def test_off_and_the_server_command_never_ask_a_server(asked, monkeypatch, write, tmp_path, argv):
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    if argv[0] == "check":
        monkeypatch.setenv("GRAMMARC_SERVER", "off")
        argv = ["check", str(write("g.cga", "Lot --> extrude(3)\n"))]
    assert client.main(argv) == 0 and asked == []


def test_where_no_server_can_run_commands_run_here_and_server_says_why(asked, monkeypatch, write, capsys):
    """Windows has no fork: every command runs in its own process, and ``grammarc server`` is refused."""
    monkeypatch.setattr(server, "AVAILABLE", False)
    monkeypatch.delenv("GRAMMARC_SERVER", raising=False)
    assert client.main(["check", str(write("g.cga", "Lot --> extrude(3)\n"))]) == 0 and asked == []
    assert client.main(["server", "start"]) == 2
    assert "grammarc server needs a system that forks" in capsys.readouterr().err


def test_run_as_the_program_the_process_ends_with_the_status_its_exit_functions_run_and_its_output(write):
    """``main()`` without arguments (the console script) ends the process itself (``client._end``): with the
    command's status, after the exit functions, its output flushed; a failing command's status too."""
    import os
    import subprocess
    import sys

    good, bad = write("g.cga", "Lot --> extrude(3)\n"), write("b.cga", "Lot --> extrude(\n")
    program = ("import atexit, sys; from grammarc.client import main; atexit.register(print, 'exit functions ran')"
               "; sys.argv[1:] = ['check', sys.argv[1]]; print('before', end=''); main(); print('not reached')")
    env = {**os.environ, "GRAMMARC_SERVER": "off"}
    ran = [subprocess.run([sys.executable, "-c", program, str(path)], env=env, capture_output=True, text=True,
                          check=False) for path in (good, bad)]
    assert [r.returncode for r in ran] == [0, 2]
    assert all(r.stdout.startswith("before") and r.stdout.endswith("exit functions ran\n") for r in ran)
    assert all("not reached" not in r.stdout for r in ran) and "b.cga:1" in ran[1].stderr
