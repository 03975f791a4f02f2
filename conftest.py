"""Doctests run from the repository's root, so that their examples can name ``examples/`` and ``maps/``.

Without the optional extra ``ros2`` the module of ROS 2's DDS types is left out
of the doctests (it imports ``cyclonedds``); the tests that need it skip.

Property tests (hypothesis) have no per-example deadline: a wall-clock limit
would make them fail on a loaded machine, and the project asserts counts, never
durations.
"""

from __future__ import annotations

import importlib.util
import signal
from pathlib import Path

import pytest
from _pytest.doctest import DoctestItem
from hypothesis import settings

ROOT = Path(__file__).resolve().parent

collect_ignore = [] if importlib.util.find_spec("cyclonedds") else ["src/mrmp/live/ros2_types.py"]
"""Without the ``ros2`` extra, the module of DDS types cannot be imported for its doctests (the rest of mrmp can)."""

settings.register_profile("mrmp", deadline=None)
settings.load_profile("mrmp")


def pytest_configure(config: pytest.Config) -> None:
    """Let Ctrl-C reach the processes the tests start, even from a test run that ignores it.

    Tests interrupt runs with SIGINT, as a terminal does. A shell starts a
    background job with SIGINT ignored, and an ignored signal stays ignored in
    every process started from it (Python then installs no KeyboardInterrupt):
    the test run takes SIGINT back, so its children start with the default.
    """
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(autouse=True)
def _doctests_run_from_the_root(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    if isinstance(request.node, DoctestItem):
        monkeypatch.chdir(ROOT)
