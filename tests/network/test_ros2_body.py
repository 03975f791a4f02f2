"""``mrmp agent --drive ros2``: a robot whose body is driven over ROS 2 (Twist out, odometry in) reaches its goal.

The robot is :mod:`mrmp.live.ros2_robot`, the project's simulated
differential-drive node, in its own process: it integrates the commands and
publishes odometry. DDS is confined to loopback by its configuration
(``CYCLONEDDS_URI``). Skips, saying why, without the ``ros2`` extra.
"""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from dds_loopback import loopback_environment

pytest.importorskip("cyclonedds", reason="needs the ros2 extra (cyclonedds): pip install -e '.[ros2]'")

from mrmp.core.heading import Heading
from mrmp.io.ros_messages import cell_position
from mrmp.live.diff_drive import odometry_in_map, yaw_heading

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def dds_environment(tmp_path: Path) -> dict[str, str]:
    return loopback_environment(tmp_path, salt=1)


@pytest.mark.slow
def test_a_robot_driven_over_ros2_reaches_its_goal_cell_by_cell(tmp_path: Path, dds_environment: dict[str, str]) -> None:
    final = tmp_path / "final.json"
    node = subprocess.Popen(
        [sys.executable, "-m", "mrmp.live.ros2_robot", "--robot", "A", "--out", str(final)],
        env=dds_environment, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert node.stdout is not None and node.stdout.readline().strip() == "ready"
        agent = subprocess.run(
            [sys.executable, "-m", "mrmp", "agent", str(ROOT / "examples" / "thesis-single.yaml"), "--robot", "A",
             "--drive", "ros2", "--time-scale", "4", "--bind", "127.0.0.1:0", "--results", str(tmp_path / "run")],
            env=dds_environment, capture_output=True, text=True, timeout=600, check=False,
        )  # fmt: skip
        assert agent.returncode == 0, agent.stdout + agent.stderr  # 0: arrived
    finally:
        node.send_signal(signal.SIGTERM)
        node.wait(timeout=60)
    # the robot's own account: x first, one right turn, then y, cell by cell
    events = [json.loads(line) for line in (tmp_path / "run" / "trace-0.jsonl").read_text(encoding="utf-8").splitlines()]
    entered = [tuple(event["cell"]) for event in events if event["event"] == "enter"]
    assert entered == [(1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (4, 2), (4, 3), (4, 4)]
    # where the simulated robot really is: the middle of the goal cell, facing east
    pose = json.loads(final.read_text(encoding="utf-8"))
    east, north, yaw = odometry_in_map((0, 0), Heading.NORTH, pose["x"], pose["y"], pose["yaw"])
    assert math.dist((east, north), cell_position((4, 4))[:2]) < 0.25  # well inside the goal cell, even on a busy machine
    assert yaw_heading(yaw) == Heading.EAST and pose["commands"] > 0


@pytest.mark.slow
def test_without_a_driver_the_agent_stops_in_one_line(tmp_path: Path, dds_environment: dict[str, str]) -> None:
    agent = subprocess.run(
        [sys.executable, "-m", "mrmp", "agent", str(ROOT / "examples" / "thesis-single.yaml"), "--robot", "A",
         "--drive", "ros2", "--drive-wait", "1", "--bind", "127.0.0.1:0", "--results", str(tmp_path / "run")],
        env=dds_environment, capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert agent.returncode == 2, agent.stdout + agent.stderr
    assert "--drive: no odometry on /robot_A/odom" in agent.stderr and "Traceback" not in agent.stderr
