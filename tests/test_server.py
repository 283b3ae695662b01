"""The resident server: a command it runs gives the same files, messages and exit status as in its own
process; signals reach the command; a client that dies stops its command; only a server of the same code
and settings is used."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from grammarc import server
from grammarc.cli import main

ROOT = Path(__file__).resolve().parents[1]
#: A derivation that goes on for minutes, one rule application after another: time to send signals.
SLOW = "Lot --> A(0)\nA(k) --> case k < 1000000000 : A(k + 1) else : X.\n"


@pytest.fixture(scope="module")
def runtime(tmp_path_factory):
    """A server in its own runtime folder, started in the foreground; stopped (by SIGTERM) at the end."""
    folder = tmp_path_factory.mktemp("run")
    folder.chmod(0o700)
    env = {**os.environ, "XDG_RUNTIME_DIR": str(folder)}
    process = subprocess.Popen([sys.executable, "-m", "grammarc.client", "server", "start", "--foreground",
                                "--idle-timeout", "5"],
                               env=env, stdout=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    assert line.startswith(f"grammarc server {process.pid} ready at {folder}"), line
    yield folder, process
    process.send_signal(signal.SIGTERM)
    assert process.wait(timeout=60) == 0
    assert not list((folder / "grammarc").iterdir())  # its socket and its pid file went with it


@pytest.fixture
def served(runtime, monkeypatch):
    folder, process = runtime
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(folder))
    return process


def _client(*args, env=None, **kwargs) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "grammarc.client", *args], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kwargs)


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (from /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def test_a_served_build_writes_the_bytes_its_own_process_writes(served, tmp_path):
    grammar = ROOT / "examples" / "city" / "city.cga"
    (tmp_path / "served.npz").write_bytes(b"an older output")
    assert server.request(["build", str(grammar), "--emit", str(tmp_path / "served.npz"), "--quiet"]) == 0
    assert main(["build", str(grammar), "--emit", str(tmp_path / "own.npz"), "--quiet"]) == 0
    assert (tmp_path / "served.npz").read_bytes() == (tmp_path / "own.npz").read_bytes()
    # what the build left to release after its reply (its workers, the older output) goes, and its child
    deadline = time.monotonic() + 60
    while _children(served.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _children(served.pid)


@pytest.mark.parametrize("emit", ["g.usda", "g.obj"])
def test_a_served_build_through_the_libraries_its_server_imported_writes_the_same_bytes(served, georeferenced_lots,
                                                                                    emit):
    """The server imported Arrow, PROJ, USD and trimesh before it forked the command (``serving.LIBRARIES``)."""
    if emit.endswith(".usda"):
        pytest.importorskip("pxr")
    folder = georeferenced_lots.parent
    (folder / "g.cga").write_text("Lot --> extrude(3) split(y) { 1 : X | ~1 : Y. }*\n")
    build = ["build", str(folder / "g.cga"), "--lots", str(georeferenced_lots), "--quiet", "--emit"]
    assert server.request([*build, str(folder / "served" / emit)]) == 0
    assert main([*build, str(folder / "own" / emit)]) == 0
    assert (folder / "served" / emit).read_bytes() == (folder / "own" / emit).read_bytes()


def test_a_served_command_runs_in_the_clients_folder(served, tmp_path):
    (tmp_path / "g.cga").write_text("Lot --> extrude(3)\n")
    client = _client("build", "g.cga", "--emit", "out/g.npz", cwd=tmp_path, env=os.environ.copy())
    _, err = client.communicate(timeout=120)
    assert client.returncode == 0, err
    assert "out/g.npz: 1 instances, 0 mesh faces from 1 lots" in err
    assert (tmp_path / "out" / "g.npz").is_file()


def test_a_served_build_gives_every_grammar_error_and_exit_status_2(served, tmp_path, capfd):
    (tmp_path / "bad.cga").write_text("Lot --> extrude(3) A\nA --> foo(\n")
    assert server.request(["build", str(tmp_path / "bad.cga"), "--emit", str(tmp_path / "x.npz")]) == 2
    err = capfd.readouterr().err
    assert f"{tmp_path / 'bad.cga'}:2:10: error: unclosed `(`" in err and "1 error; nothing was written" in err
    assert not (tmp_path / "x.npz").exists()


@pytest.mark.parametrize(("signum", "status", "said"), [
    (signal.SIGINT, 130, "grammarc: interrupted; nothing was written"),
    (signal.SIGTERM, 143, "grammarc: SIGTERM: stopped; nothing was written"),
])
def test_a_signal_to_the_client_stops_its_served_command(served, tmp_path, signum, status, said):
    (tmp_path / "slow.cga").write_text(SLOW)
    _wait_for(lambda: not _children(served.pid))  # the commands of earlier tests have ended
    client = _client("build", str(tmp_path / "slow.cga"), "--emit", str(tmp_path / "x.npz"), "--max-depth",
                     "2000000000", "--quiet", env=os.environ.copy())
    _wait_for(lambda: _children(served.pid))  # it connected: the signal is held, then forwarded
    client.send_signal(signum)
    _, err = client.communicate(timeout=60)
    assert client.returncode == status and said in err and not (tmp_path / "x.npz").exists(), err
    _wait_for(lambda: not _children(served.pid))


def test_a_client_killed_without_a_word_stops_its_served_command(served, tmp_path):
    (tmp_path / "slow.cga").write_text(SLOW)
    _wait_for(lambda: not _children(served.pid))  # the commands of earlier tests have ended
    client = _client("build", str(tmp_path / "slow.cga"), "--emit", str(tmp_path / "x.npz"), "--max-depth",
                     "2000000000", "--quiet", env=os.environ.copy())
    _wait_for(lambda: _children(served.pid))
    client.kill()
    client.wait(timeout=60)
    _wait_for(lambda: not _children(served.pid))
    assert not list(tmp_path.glob("*.npz*"))


def _wait_for(condition, timeout: float = 60.0) -> None:
    end = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.05)


@pytest.mark.parametrize("name", ["GRAMMARC_STRICT", "PROJ_DATA", "PXR_PLUGINPATH_NAME"])
def test_a_server_of_other_settings_is_not_used(served, monkeypatch, name):
    """Settings read when grammarc, or a library its server imported, is imported (``server._KEYED_ENV``)."""
    monkeypatch.setenv(name, "0" if os.environ.get(name) == "1" else "1")
    assert server.request(["--version"]) is None


def test_status_names_the_servers_and_which_serves_this_grammarc(served):
    client = _client("server", "status", env=os.environ.copy())
    out, _ = client.communicate(timeout=60)
    assert out == f"grammarc server {served.pid} at {server.address()} (this grammarc's)\n"


def test_a_started_server_runs_detached_until_it_is_stopped(tmp_path):
    """``grammarc server start`` returns once its daemon is ready; ``stop`` ends it and its files go."""
    tmp_path.chmod(0o700)
    env = {**os.environ, "XDG_RUNTIME_DIR": str(tmp_path)}
    start = subprocess.run([sys.executable, "-m", "grammarc.client", "server", "start"], env=env,
                           capture_output=True, text=True, timeout=300, check=True)
    pid = int(start.stdout.split()[2])
    assert "ready at" in start.stdout and os.getpgid(pid) != os.getpgid(0)
    again = subprocess.run([sys.executable, "-m", "grammarc.client", "server", "start"], env=env,
                           capture_output=True, text=True, timeout=300, check=True)
    assert again.stdout.startswith(f"grammarc server {pid} already running")
    stop = subprocess.run([sys.executable, "-m", "grammarc.client", "server", "stop"], env=env,
                          capture_output=True, text=True, timeout=60, check=True)
    assert stop.stdout.startswith(f"grammarc server {pid} at ") and stop.stdout.endswith(" stopped\n")
    _wait_for(lambda: not list((tmp_path / "grammarc").iterdir()))  # socket, pid file and log gone
    _wait_for(lambda: not Path(f"/proc/{pid}").exists())


def test_without_a_server_a_request_is_not_taken(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    assert server.request(["--version"]) is None
    (tmp_path / "grammarc").mkdir(mode=0o755)  # a folder others may enter: not used
    assert server.servers() == {} and server.request(["--version"]) is None


def test_the_kernels_numba_cached_are_loaded_without_a_call():
    script = ("from grammarc import ragged, server\n"
              "assert not ragged.grow.overloads\n"
              "print(server.load_cached_kernels(), len(ragged.grow.overloads))\n")
    first_call = "import numpy as np\nfrom grammarc import ragged\nragged.grow(np.zeros(3, np.int64), 5)\n"
    subprocess.run([sys.executable, "-c", first_call], check=True)
    loaded, overloads = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True,
                                       text=True).stdout.split()
    assert int(loaded) >= 1 and int(overloads) >= 1


def test_a_fused_kernel_a_build_compiled_is_loaded_without_a_call(tmp_path):
    text = '"""A stand-in for a generated module."""\nfrom numba import njit\n\n\n' \
           '@njit(cache=True)\ndef derive(x):\n    return x + 1\n'
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    build = ("from grammarc.backend.fusion import compiled\n"
             f"module, path = compiled.load({text!r})\nmodule.derive(1)\n"
             "path.with_suffix('.compiled').touch(mode=0o600)\n")
    subprocess.run([sys.executable, "-c", build], env=env, check=True)
    warm = ("from grammarc import server\nfrom grammarc.backend.fusion import compiled\n"
            "print(compiled.import_compiled(), server.load_cached_kernels(), "
            f"len(compiled._KERNELS[{text!r}].overloads))\n")
    imported, loaded, overloads = subprocess.run([sys.executable, "-c", warm], env=env, check=True,
                                                 capture_output=True, text=True).stdout.split()
    assert (imported, overloads) == ("1", "1") and int(loaded) >= 1
