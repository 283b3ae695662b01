"""PRT's processes end with the harness: ``Processes`` kills them on a stop, and a harness stopped by SIGTERM
leaves neither a process nor its temporary folder."""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from conftest import needs_kit

from grammarc.conform.processes import Processes, Stopping

SLEEP = [sys.executable, "-c", "import time; time.sleep(60)"]


def test_a_process_gives_its_status_and_standard_error():
    status, stderr = Processes().run([sys.executable, "-c", "import sys; sys.exit('no lots')"], timeout=60)
    assert (status, stderr.strip()) == (1, "no lots")


def test_a_stop_kills_a_running_process_and_starts_no_other():
    processes = Processes()
    threading.Timer(0.5, processes.stop).start()
    begun = time.perf_counter()
    with pytest.raises(Stopping):
        processes.run(SLEEP, timeout=60)
    assert time.perf_counter() - begun < 10
    with pytest.raises(Stopping):
        processes.run([sys.executable, "-c", "pass"], timeout=60)


def test_a_process_past_its_timeout_is_killed():
    with pytest.raises(subprocess.TimeoutExpired):
        Processes().run(SLEEP, timeout=0.5)


@needs_kit
def test_a_harness_stopped_by_sigterm_leaves_no_prt_process_and_no_temporary_folder(tmp_path):
    # a PRT "interpreter" that notes its process id and sleeps: the harness waits for it in a thread
    marker = tmp_path / "prt.pid"
    fake = tmp_path / "python"
    fake.write_text(f"#!/bin/sh\necho $$ > {marker}\nexec sleep 60\n")
    fake.chmod(0o755)
    (tmp_path / "tmp").mkdir()
    env = {**os.environ, "GRAMMARC_PRT_PYTHON": str(fake), "TMPDIR": str(tmp_path / "tmp")}
    harness = subprocess.Popen([sys.executable, "-m", "grammarc.conform", "--fuzz", "1", "--packages",
                                "extrusion_rule", "--out", str(tmp_path / "out")], env=env,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (marker.exists() and marker.read_text().strip()) and time.monotonic() < deadline:
        time.sleep(0.1)
    prt = int(marker.read_text())
    harness.send_signal(signal.SIGTERM)
    _, stderr = harness.communicate(timeout=60)
    assert harness.returncode == 128 + signal.SIGTERM, stderr
    assert "SIGTERM: stopped" in stderr and "Traceback" not in stderr
    with pytest.raises(ProcessLookupError):
        os.kill(prt, 0)
    assert list((tmp_path / "tmp").iterdir()) == []
