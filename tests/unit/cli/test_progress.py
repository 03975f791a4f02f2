"""``mrmp run`` reports its progress on a terminal, and nothing of it elsewhere."""

from __future__ import annotations

import os
import pty
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
COMMAND = [sys.executable, "-m", "mrmp", "run", str(ROOT / "examples" / "thesis-swap.yaml"), "--max-ticks", "40"]


def _read_all(descriptor: int) -> bytes:
    chunks = []
    while True:
        try:
            chunk = os.read(descriptor, 65536)
        except OSError:  # the terminal's other end closed
            break
        if not chunk:
            break
        chunks.append(chunk)
    return b"".join(chunks)


def test_a_terminal_sees_the_progress_line() -> None:
    parent, child = pty.openpty()
    process = subprocess.Popen(COMMAND, stdin=child, stdout=child, stderr=child, env={**os.environ, "COLUMNS": "120"})
    os.close(child)
    output = _read_all(parent).decode("utf-8", "replace")
    os.close(parent)
    assert process.wait() == 0
    assert "tick 1 of 40: 0 of 2 robots on their goals, 0 collisions so far" in output
    assert "success" in output


def test_a_pipe_sees_no_progress_line() -> None:
    finished = subprocess.run(COMMAND, capture_output=True, text=True, check=False)
    assert finished.returncode == 0 and "success" in finished.stdout
    assert "robots on their goals" not in finished.stdout + finished.stderr


LIVE = [sys.executable, "-m", "mrmp", "run", str(ROOT / "examples" / "thesis-swap.yaml"), "--live", "--time-scale", "10"]


@pytest.mark.slow
def test_a_terminal_sees_the_live_progress_line(tmp_path: Path) -> None:
    parent, child = pty.openpty()
    command = [*LIVE, "--results", str(tmp_path), "--loss", "0.2"]
    process = subprocess.Popen(command, stdin=child, stdout=child, stderr=child, env={**os.environ, "COLUMNS": "120"})
    os.close(child)
    output = _read_all(parent).decode("utf-8", "replace")
    os.close(parent)
    assert process.wait() == 0, output
    assert "0 of 2 robots arrived, 0 messages" in output  # the first report, before any robot has written its own
    assert " s: " in output and "of 2 robots arrived" in output and "success" in output


@pytest.mark.slow
def test_a_pipe_sees_no_live_progress_line(tmp_path: Path) -> None:
    finished = subprocess.run([*LIVE, "--results", str(tmp_path)], capture_output=True, text=True, check=False)
    assert finished.returncode == 0 and "success" in finished.stdout
    assert "robots arrived" not in finished.stdout + finished.stderr
