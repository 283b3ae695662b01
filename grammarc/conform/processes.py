"""PRT's processes that the harness starts, none of which may outlive it.

PRT derives a batch in its own process while grammarc judges the batch before (``fuzz``), so PRT's process
is waited for in a thread. A stop (Ctrl-C, SIGTERM) is raised in the main thread only, and the thread would
go on waiting for PRT, and then start the next process: ``Processes.stop`` kills the processes running and
refuses to start any other, so the harness ends at once and leaves no process behind.
"""

from __future__ import annotations

import subprocess
import threading

__all__ = ["Processes", "Stopping"]


class Stopping(Exception):
    """The harness is stopping: a process was killed, or one was asked for after the stop."""


class Processes:
    """The processes started through ``run`` and not yet ended, for ``stop`` to kill."""

    def __init__(self):
        self._lock = threading.Lock()
        self._running: set[subprocess.Popen] = set()
        self._stopped = False

    def run(self, command: list[str], timeout: float) -> tuple[int, str]:
        """Run ``command`` to its end: its exit status and standard error (text).

        Raises
        ------
        subprocess.TimeoutExpired
            It ran more than ``timeout`` seconds (it is killed).
        Stopping
            ``stop`` was called before it started or while it ran.
        """
        with self._lock:
            if self._stopped:
                raise Stopping
            process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            self._running.add(process)
        try:
            _, stderr = process.communicate(timeout=timeout)
        except BaseException:
            process.kill()
            process.communicate()
            raise
        finally:
            with self._lock:
                self._running.discard(process)
        if self._stopped:
            raise Stopping
        return process.returncode, stderr

    def stop(self) -> None:
        """Kill the processes running, and start no other."""
        with self._lock:
            self._stopped = True
            for process in self._running:
                process.kill()
