"""``--ros2``: a live fleet's robots publish their poses and states on ROS 2 topics, read by another DDS participant.

A listener process (``ros2_listener.py``) joins the same ROS 2 domain and
records what it receives while ``mrmp run --live --ros2`` runs the thesis's
swap. DDS is confined to loopback (unicast discovery to 127.0.0.1, no
multicast) by its own configuration, ``CYCLONEDDS_URI``. Skips, saying why,
without the ``ros2`` extra.
"""

from __future__ import annotations

import itertools
import json
import subprocess
import sys
from pathlib import Path

import pytest
from dds_loopback import loopback_environment

from mrmp.core.heading import Heading
from mrmp.io.ros_messages import cell_position, heading_quaternion

pytest.importorskip("cyclonedds", reason="needs the ros2 extra (cyclonedds): pip install -e '.[ros2]'")

ROOT = Path(__file__).resolve().parents[2]
LISTENER = Path(__file__).with_name("ros2_listener.py")


@pytest.fixture
def dds_environment(tmp_path: Path) -> dict[str, str]:
    return loopback_environment(tmp_path, salt=0)


def cell_of(line: dict) -> tuple[int, int]:
    """The cell whose centre a pose's (east, north) position is (cells of 1 m)."""
    return (round(line["y"] - 0.5), round(line["x"] - 0.5))


@pytest.mark.slow
def test_every_robot_publishes_its_poses_and_states_during_a_live_run(tmp_path: Path, dds_environment: dict[str, str]) -> None:
    received = tmp_path / "received.jsonl"
    listener = subprocess.Popen(
        [sys.executable, str(LISTENER), dds_environment["ROS_DOMAIN_ID"], str(received), "A,B"],
        env=dds_environment, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert listener.stdout is not None and listener.stdout.readline().strip() == "ready"
        run = subprocess.run(
            [sys.executable, "-m", "mrmp", "run", str(ROOT / "examples" / "thesis-swap.yaml"), "--live", "--time-scale", "10",
             "--ros2", "--results", str(tmp_path / "run"), "--json", str(tmp_path / "run.json")],
            env=dds_environment, capture_output=True, text=True, timeout=600, check=False,
        )  # fmt: skip
        assert run.returncode == 0, run.stdout + run.stderr
        assert listener.wait(timeout=120) == 0  # every robot's "stop" arrived
    finally:
        listener.kill()
        listener.wait()
    lines = [json.loads(line) for line in received.read_text(encoding="utf-8").splitlines()]
    result = json.loads((tmp_path / "run.json").read_text(encoding="utf-8"))
    for robot in result["robots"]:
        poses = [line for line in lines if line["robot"] == robot["id"] and "x" in line]
        states = [line["state"] for line in lines if line["robot"] == robot["id"] and "state" in line]
        cells = [cell_of(pose) for pose in poses]
        # from its start to its goal, one cell at a time, every pose in frame map
        assert cells[0] == tuple(robot["start"]) and cells[-1] == tuple(robot["goal"])
        assert all(abs(a[0] - b[0]) + abs(a[1] - b[1]) == 1 for a, b in itertools.pairwise(cells))
        assert {pose["frame"] for pose in poses} == {"map"}
        # the cells entered are those of the body's own trace, in order; each pose faces the way it moved
        entered = [tuple(state["cell"]) for state in states if state["event"] == "enter"]
        assert entered == cells[1:]
        for before, pose in zip(cells, poses[1:]):
            heading = Heading.between(before, cell_of(pose))
            assert (pose["qz"], pose["qw"]) == pytest.approx(heading_quaternion(heading)[2:])
        assert states[0]["event"] == "start" and states[-1]["event"] == "stop"
        assert cell_position(tuple(robot["goal"]))[:2] == (poses[-1]["x"], poses[-1]["y"])
