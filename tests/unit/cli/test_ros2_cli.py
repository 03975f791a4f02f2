"""``--ros2`` is refused in one line where it cannot publish: not live, a bad ``ROS_DOMAIN_ID``."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app

SWAP = Path(__file__).resolve().parents[3] / "examples" / "thesis-swap.yaml"
runner = CliRunner()


def refusal(args: list[str], environment: dict[str, str] | None = None) -> str:
    result = runner.invoke(app, [str(arg) for arg in args], env=environment)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in result.output
    return lines[0]


def test_ros2_needs_a_live_run() -> None:
    assert "--ros2: publishes the robots of a live run: add --live" in refusal(["run", SWAP, "--ros2"])


@pytest.mark.parametrize("command", [["run", SWAP, "--live", "--ros2"], ["agent", SWAP, "--robot", "A", "--ros2"]])
def test_a_bad_domain_is_refused_before_any_process_starts(command: list[str]) -> None:
    pytest.importorskip("cyclonedds", reason="needs the ros2 extra (cyclonedds)")
    line = refusal(command, {"ROS_DOMAIN_ID": "town"})
    assert "ROS_DOMAIN_ID: expected a whole number from 0 to 232, got 'town'" in line
