"""Lifelong runs: new goals as old ones are reached, throughput as the figure."""

import json

from typer.testing import CliRunner

from mrmp.cli import app
from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
from mrmp.sim.simulator import LockstepSimulator, simulate

OPEN = Scenario(
    Grid.from_rows(["......", ".@..@.", "......", "......"]),
    (RobotSpec("A", (0, 0), (3, 5)), RobotSpec("B", (3, 0), (0, 5)), RobotSpec("C", (0, 3), (3, 2))),
    policy=PolicyOptions(name="astar"),
    lifelong=True,
    max_ticks=120,
    seed=3,
)


def test_goals_keep_coming_and_are_counted():
    simulator = LockstepSimulator(OPEN)
    goals_seen = {robot.index: [robot.goal] for robot in simulator.robots}
    original = simulator._count_goals

    def watching():
        original()
        for robot in simulator.robots:
            if robot.goal != goals_seen[robot.index][-1]:
                goals_seen[robot.index].append(robot.goal)
                assert simulator.scenario.grid.is_free(robot.goal)
                assert robot.goal not in {other.goal for other in simulator.robots if other is not robot}

    simulator._count_goals = watching
    result = simulator.run()
    assert result.collisions == []
    reached = [robot.goals_reached for robot in result.robots]
    assert sum(reached) >= 6 and result.throughput == sum(reached) / result.ticks
    assert all(len(goals_seen[i]) >= reached[i] for i in range(3))  # each goal reached brought a new one
    if result.stop_reason == "time up":
        assert result.success and result.ticks == 120


def test_lifelong_is_deterministic_for_a_seed_and_differs_across_seeds():
    first, again = simulate(OPEN), simulate(OPEN)
    assert [r.path for r in first.robots] == [r.path for r in again.robots]
    other = simulate(OPEN.with_changes(seed=4))
    assert [r.path for r in other.robots] != [r.path for r in first.robots]


def test_one_shot_runs_count_each_robot_once():
    result = simulate(OPEN.with_changes(lifelong=False))
    assert result.success and [robot.goals_reached for robot in result.robots] == [1, 1, 1]


def test_cli_lifelong_reports_throughput(tmp_path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(
        "map: {rows: ['......', '.@..@.', '......', '......']}\n"
        "robots:\n  - {id: A, start: [0, 0], goal: [3, 5]}\n  - {id: B, start: [3, 0], goal: [0, 5]}\n"
        "policy: {name: astar}\nlifelong: true\nmax_ticks: 60\n"
    )
    out = tmp_path / "r.json"
    result = CliRunner().invoke(app, ["run", str(scenario), "--json", str(out)])
    assert "throughput" in result.output and "did not arrive" not in result.output
    data = json.loads(out.read_text())
    assert data["lifelong"] is True and data["throughput"] > 0
    assert sum(robot["goals_reached"] for robot in data["robots"]) == round(data["throughput"] * data["ticks"])
    refused = CliRunner().invoke(app, ["run", str(scenario), "--live"])
    assert refused.exit_code == 2 and "--lifelong: a live lifelong run takes its tasks from a task stream" in refused.output
