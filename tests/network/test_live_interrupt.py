"""Ctrl-C on a live run: every process stops, nothing is left behind, what was gathered is written."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def processes_mentioning(text):
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if text in (entry / "cmdline").read_bytes().decode(errors="replace"):
                    found.append(int(entry.name))
            except OSError:
                continue
    return found


def fleet_started(results, robots):
    """Whether every robot has written a report saying its run began (it does so at the fleet's start)."""
    for index in range(robots):
        try:
            report = json.loads((results / f"agent-{index}.json").read_text())
        except (OSError, ValueError):
            return False
        if not report.get("started_at"):
            return False
    return True


@pytest.mark.slow
def test_ctrl_c_stops_everything_and_writes_results(tmp_path):
    results = tmp_path / "run"
    out = tmp_path / "result.json"
    command = [
        sys.executable, "-m", "mrmp", "run", str(EXAMPLES / "thesis-swap.yaml"), "--live", "--time-scale", "0.5",
        "--results", str(results), "--json", str(out),
    ]
    launcher = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
    deadline = time.monotonic() + 120  # a bound on a hang only: the wait ends when the fleet has started
    while not fleet_started(results, 2) and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.5)  # the robots are moving (one cell takes 4 s at this speed)
    os.killpg(launcher.pid, signal.SIGINT)  # what the terminal does on Ctrl-C
    output, _ = launcher.communicate(timeout=30)
    text = output.decode()
    assert launcher.returncode == 1, text
    assert "interrupted" in text
    assert processes_mentioning(str(results)) == [], "robot or referee processes were left running"
    data = json.loads(out.read_text())
    assert data["success"] is False and data["mode"] == "live"
    assert len(data["robots"]) == 2 and (results / "referee.json").exists()
    for index in range(2):
        report = json.loads((results / f"agent-{index}.json").read_text())
        assert report["stop_reason"] == "interrupted", text
