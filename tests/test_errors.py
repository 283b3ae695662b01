"""Stops: a signal's stop is raised where the program is, except inside numba's and llvmlite's code, where
it is held until the command next looks; a stop behind another error is found."""

from __future__ import annotations

import os
import signal
import sys

import numba
import pytest

from grammarc.errors import Stopped, check_stopped, clear_stopped, interruption, raise_stopped


@pytest.fixture(autouse=True)
def _no_stop_left():
    yield
    clear_stopped()


def test_a_signal_in_grammarcs_own_code_raises_its_stop_there():
    with pytest.raises(Stopped) as stop:
        raise_stopped(signal.SIGTERM, sys._getframe())
    assert stop.value.signum == signal.SIGTERM


def test_a_signal_inside_numbas_code_is_held_until_the_command_looks():
    """As when it comes while numba compiles: raising there leaves llvmlite's objects to be freed twice."""
    def handle(signum):
        raise_stopped(signum, sys._getframe())

    handle.__code__ = handle.__code__.replace(
        co_filename=os.path.join(os.path.dirname(numba.__file__), "core", "compiler.py"))
    handle(signal.SIGTERM)  # held: nothing raised
    with pytest.raises(Stopped) as stop:
        check_stopped()
    assert stop.value.signum == signal.SIGTERM


def test_no_stop_nothing_raised():
    check_stopped()
    assert interruption(ValueError("x")) is None


def test_the_stop_behind_another_error_is_found():
    try:
        try:
            raise Stopped(signal.SIGHUP)
        except Stopped as stop:
            raise SystemError("returned a result with an exception set") from stop
    except SystemError as error:
        assert interruption(error).signum == signal.SIGHUP


def test_a_held_stop_is_behind_whatever_failed_after_it():
    with pytest.raises(Stopped):
        raise_stopped(signal.SIGINT, sys._getframe())
    assert interruption(RuntimeError("a later failure")).signum == signal.SIGINT
