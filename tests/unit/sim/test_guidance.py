"""Guided pibt: robots rank moves by tables that charge moves against the map's lanes, and stay collision-free."""

from dataclasses import replace

import pytest

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
from mrmp.core.heading import Heading
from mrmp.core.scenario import NetworkFaults
from mrmp.io.lorr import load_lorr_scenario
from mrmp.sim.simulator import simulate


@pytest.mark.parametrize("sequencing", ["driver", "local"])
def test_a_guided_robot_leaves_a_row_whose_lane_runs_against_it(sequencing):
    """Row 1 of two runs WEST: going EAST along it costs 11 moves against the lane (22); row 0, whose lane runs
    EAST, costs 18 with its turns and the two moves against columns 0 and 11, so a guided robot takes it and an
    unguided one does not."""
    grid = Grid(2, 12)
    robots = (RobotSpec("A", (1, 0), (1, 11), Heading.EAST),)
    rows = {}
    for guidance in ("none", "crisscross"):
        policy = PolicyOptions(name="pibt", body="turning", sequencing=sequencing, guidance=guidance)
        result = simulate(Scenario(grid, robots, policy=policy))
        assert result.success
        rows[guidance] = {cell[0] for cell in result.robots[0].path}
    assert rows == {"none": {1}, "crisscross": {0, 1}}


@pytest.mark.slow
@pytest.mark.parametrize(("sequencing", "loss"), [("driver", 0.2), ("local", 0.0)])
def test_a_guided_fleet_finishes_its_tasks_without_collision(sequencing, loss):
    scenario = load_lorr_scenario("examples/lorr/maze-example_40.json", 120)
    policy = replace(scenario.policy, guidance="crisscross", sequencing=sequencing)
    result = simulate(scenario.with_changes(policy=policy, network=NetworkFaults(loss=loss)))
    assert result.tasks is not None and result.tasks.finished > 20
    assert result.collisions == []
