"""``--body``: a run in the turning model where it is planned for, a one-line refusal everywhere else."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app

ROOT = Path(__file__).resolve().parents[3]
CROWD = ROOT / "examples" / "causal-32.yaml"
runner = CliRunner()


def invoke(*args: object):
    return runner.invoke(app, [str(arg) for arg in args])


@pytest.mark.parametrize(
    "policy", [["--policy", "pibt", "--sequencing", "driver"], ["--policy", "astar"], ["--policy", "causal"]]
)
def test_planners_run_turning_bodies_and_the_result_is_judged_in_their_model(policy: list[str]) -> None:
    result = invoke("run", CROWD, *policy, "--body", "turning", "--json", "-")
    assert result.exit_code == 0, result.output
    run = json.loads(result.stdout)
    assert run["success"] and run["collisions"] == []
    for robot in run["robots"]:  # one action per tick: forward in the heading kept, or a turn in place
        cells, headings = robot["path"], robot["headings"]
        for tick in range(1, len(cells)):
            assert cells[tick] == cells[tick - 1] or headings[tick] == headings[tick - 1]


@pytest.mark.parametrize(
    ("flags", "reason"),
    [
        (["--policy", "causal", "--body", "thesis"], "policy.body: causal plans for omni, turning bodies, not thesis"),
        (
            ["--policy", "astar", "--body", "thesis", "--live"],
            "policy.body: astar drives omni, turning bodies live so far, not thesis",
        ),
        (["--body", "thesis", "--planner", "lacam"], "policy.body: central plans are executed by omni, turning bodies, not thesis"),
        (["--body", "wheels"], "must be one of omni, thesis, turning, got 'wheels'"),
    ],
)
def test_a_body_that_cannot_run_that_way_is_refused_in_one_line(flags: list[str], reason: str) -> None:
    result = invoke("run", CROWD, *flags)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and reason in lines[0] and "Traceback" not in result.output


def test_a_plan_for_turning_bodies_is_executed_by_them_in_its_makespan() -> None:
    """Planned for turning bodies and executed by them on a perfect network: the plan's ticks, one legal action each."""
    result = invoke("run", CROWD, "--planner", "lacam", "--body", "turning", "--json", "-")
    assert result.exit_code == 0, result.output
    run = json.loads(result.stdout)
    assert run["success"] and run["collisions"] == [] and run["body"] == "turning"
    assert run["makespan"] == run["plan_makespan"] and run["sum_of_costs"] == run["plan_sum_of_costs"]
    assert sum(robot["turns"] for robot in run["robots"]) > 0
    for robot in run["robots"]:
        cells, headings = robot["path"], robot["headings"]
        for tick in range(1, len(cells)):
            assert cells[tick] == cells[tick - 1] or headings[tick] == headings[tick - 1]


def test_a_ros2_drive_refuses_turning_bodies_in_one_line(tmp_path: Path) -> None:
    """The ROS 2 drive is the thesis's line-counting body, which turns right only and never in place."""
    scenario = tmp_path / "turning.yaml"
    scenario.write_text(CROWD.read_text().replace("policy:\n", "policy:\n  body: turning\n", 1))
    result = invoke("agent", scenario, "--robot", "r0", "--plan", tmp_path / "plan-0.json", "--drive", "ros2")
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "--drive: drives the thesis's line-counting body" in lines[0], result.output


@pytest.mark.parametrize("synchronizer", ["clock", "local"])
def test_pibt_with_local_sequencing_plans_for_turning_bodies(synchronizer: str) -> None:
    result = invoke("run", CROWD, "--policy", "pibt", "--body", "turning", "--synchronizer", synchronizer, "--json", "-")
    assert result.exit_code == 0, result.output
    run = json.loads(result.stdout)
    assert run["success"] and run["collisions"] == [] and run["body"] == "turning"
    assert sum(robot["turns"] for robot in run["robots"]) > 0
