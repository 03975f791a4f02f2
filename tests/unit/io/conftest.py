"""Shared fixtures for the I/O layer's tests."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

MAPS = Path(__file__).resolve().parents[3] / "maps"


@pytest.fixture
def maps_dir() -> Path:
    """The repository's folder of MovingAI benchmark files."""
    return MAPS


@pytest.fixture
def make_file(tmp_path: Path) -> Callable[[str, str], Path]:
    """A function writing ``text`` to ``tmp_path / name`` and returning that path."""

    def write(name: str, text: str) -> Path:
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        return path

    return write
