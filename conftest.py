"""Doctests run from the repository's root, so that their examples can name ``examples/`` and ``maps/``.

Property tests (hypothesis) have no per-example deadline: a wall-clock limit
would make them fail on a loaded machine, and the project asserts counts, never
durations.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from _pytest.doctest import DoctestItem
from hypothesis import settings

ROOT = Path(__file__).resolve().parent

settings.register_profile("mrmp", deadline=None)
settings.load_profile("mrmp")


@pytest.fixture(autouse=True)
def _doctests_run_from_the_root(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    if isinstance(request.node, DoctestItem):
        monkeypatch.chdir(ROOT)
