"""Causal-PIBT live: one OS process per robot, real time, over UDP or Zenoh with loss; judged by the referee process."""

import json
import time
from pathlib import Path

import pytest

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.io import load_scenario
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.slow
@pytest.mark.parametrize("body", ["omni", "turning"])
def test_four_robots_cross_over_lossy_udp(tmp_path, body):
    """Two head-on pairs on a 5x5 grid with a pillar, 20% of datagrams lost, late and duplicated; ``turning``
    bodies turn a quarter at a time toward the head they may enter, and the referee judges those actions too."""
    robots = (
        RobotSpec("a", (0, 2), (4, 2)),
        RobotSpec("b", (4, 2), (0, 2)),
        RobotSpec("c", (2, 0), (2, 4)),
        RobotSpec("d", (2, 4), (2, 0)),
    )
    policy = PolicyOptions(name="causal", body=body)
    scenario = Scenario(Grid(5, 5, [(2, 2)]), robots, timing=Timing(1.0, 0.5), policy=policy, name="causal-four")
    faults = LiveFaults(loss=0.2, delay_min=0.0, delay_max=0.02, duplicate=0.1)
    results = tmp_path / "run"
    result = run_live(scenario, LiveOptions(results=results, time_scale=10, faults=faults, seed=2))
    assert result.collisions == [] and result.success, result.stop_reason
    assert result.policy == "causal" and result.network["injected_lost"] > 0
    assert all(robot.arrived and robot.messages_sent > 0 for robot in result.robots)
    if body == "turning":  # every robot faces north and must turn; each turn is in its trace
        for index in range(len(robots)):
            report = json.loads((results / f"agent-{index}.json").read_text())
            trace = (results / f"trace-{index}.jsonl").read_text().splitlines()
            turns = [line for line in trace if json.loads(line)["event"] == "heading"]
            assert len(turns) == report["turns"] > 0


@pytest.mark.slow
def test_thirty_two_robots_over_zenoh_with_ten_percent_loss(tmp_path):
    """32 robot processes on a 16x16 map with obstacles, Zenoh peers on loopback TCP, 10% of datagrams lost."""
    pytest.importorskip("zenoh")
    scenario = load_scenario(EXAMPLES / "causal-32.yaml")
    assert len(scenario.robots) == 32 and (scenario.grid.x_size, scenario.grid.y_size) == (16, 16)
    started = time.monotonic()
    result = run_live(
        scenario,
        # the time limit is generous: the test asserts arrival, not speed (an idle run takes about 60 s, one
        # beside the rest of .ci/run on 2 cores once took 142 s and hit the default limit of 150 s)
        LiveOptions(
            results=tmp_path / "run", transport="zenoh", time_scale=5, faults=LiveFaults(loss=0.1), seed=0, timeout=600.0
        ),
    )
    wall = time.monotonic() - started
    print(
        f"causal-32 over zenoh, 10% loss: wall {wall:.1f} s, makespan {result.time_makespan_s:.2f} s "
        f"(ideal {result.ideal_makespan_s:.2f} s), messages {result.messages}, "
        f"datagrams lost {result.network.get('injected_lost', 0)} of {result.network.get('injected_sent', 0)}"
    )
    assert result.collisions == [], result.collisions
    assert result.success and result.all_arrived, result.stop_reason
