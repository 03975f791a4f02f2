"""Golden runs of the thesis's scenarios, trajectories derived by hand from the rules of section 3.6.

Derivation of the head-on swap (A (0,2)->(4,2), B (4,2)->(0,2), both facing NORTH):

* tick 1: A intends (1,2), B intends (3,2): no obstacle; both move.
* tick 2: both intend (2,2): Obstacle Found for both. A's x (1) < B's x (3),
  so A changes route: x is not at its destination and y = 2 is, below Ymax,
  so "Update Y": (1,3). B has priority and continues to (2,2).
* tick 3: A (x first) intends (2,3), B intends (1,2): no obstacle.
* tick 4: A to (3,3); B to (0,2), its goal.
* tick 5: A to (4,3), x at destination.
* tick 6: A steps y toward 2: (4,2), its goal.
"""

from pathlib import Path

import pytest

from mrmp.core.heading import Heading
from mrmp.core.scenario import PolicyOptions
from mrmp.io import load_scenario
from mrmp.sim.simulator import simulate

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST


def run(name, safety=True):
    return simulate(load_scenario(EXAMPLES / f"{name}.yaml").with_changes(safety=safety), record_decisions=True)


both = pytest.mark.parametrize("safety", [True, False], ids=["guarded", "as-written"])


def paths(result):
    return {robot.id: robot.path for robot in result.robots}


@both
def test_head_on_swap(safety):
    """Without faults the safety layer grants every move the thesis makes: same trajectories."""
    result = run("thesis-swap", safety)
    assert paths(result) == {
        "A": [(0, 2), (1, 2), (1, 3), (2, 3), (3, 3), (4, 3), (4, 2)],
        "B": [(4, 2), (3, 2), (2, 2), (1, 2), (0, 2), (0, 2), (0, 2)],
    }
    a, b = result.robots
    assert a.headings == [N, N, E, N, N, N, W]
    assert b.headings == [N, S, S, S, S, S, S]
    assert (a.turns, b.turns) == (1 + 3 + 3, 2)
    assert result.success and result.collisions == []
    assert (result.makespan, result.sum_of_costs, result.lower_bound) == (6, 10, 8)


def test_swap_first_conflict_a_diverts_off_the_row_b_keeps_it():
    from mrmp.sim.simulator import LockstepSimulator

    simulator = LockstepSimulator(load_scenario(EXAMPLES / "thesis-swap.yaml"), record_decisions=True)
    simulator.run()
    reasons = [[decision.reason for decision in tick] for tick in simulator.decisions]
    assert reasons[0] == ["clear", "clear"]
    assert reasons[1] == ["divert", "priority"]  # tick 2: A diverts, B continues
    assert simulator.decisions[1][0].next == (1, 3) and simulator.decisions[1][1].next == (2, 2)
    assert all(r in ("clear", "arrived") for tick in reasons[2:] for r in tick)


@both
def test_single_robot_scenario_1(safety):
    result = run("thesis-single", safety)
    assert paths(result) == {"A": [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (4, 2), (4, 3), (4, 4)]}
    assert result.robots[0].turns == 1  # NORTH to EAST: one right turn
    assert result.success and result.makespan == 8 == result.lower_bound
    assert result.messages == 0  # nobody to talk to


@both
def test_crossing_paths(safety):
    result = run("thesis-cross", safety)
    assert paths(result) == {
        "A": [(0, 0), (1, 0), (1, 1), (2, 1), (3, 1), (4, 1), (4, 2), (4, 3), (4, 4)],
        "B": [(4, 0), (3, 0), (2, 0), (1, 0), (0, 0), (0, 1), (0, 2), (0, 3), (0, 4)],
    }
    assert result.success and (result.makespan, result.sum_of_costs) == (8, 16)


def test_velocity_tuning_as_written_collides_and_is_reported():
    """With resolve=wait the lower robot waits; B walks into it (the thesis's rule lets it), and the referee says so."""
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    waiting = scenario.with_changes(policy=PolicyOptions(name="thesis", resolve="wait"), safety=False)
    result = simulate(waiting)
    assert not result.success
    assert next((c.kind, c.tick, c.robots) for c in result.collisions) == ("vertex", 3, ("A", "B"))


def test_velocity_tuning_guarded_deadlocks_without_collision():
    """The safety layer refuses B the cell A stands on: no collision, and the deadlock is named."""
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    result = simulate(scenario.with_changes(policy=PolicyOptions(name="thesis", resolve="wait")))
    assert result.collisions == [] and result.stop_reason == "deadlock"
    assert result.robots[0].path[-1] == (1, 2) and result.robots[1].path[-1] == (2, 2)


@pytest.mark.parametrize("name", ["thesis-swap", "thesis-single", "thesis-cross"])
def test_time_based_makespan_counts_moves_and_turns(name):
    result = run(name)
    scenario = load_scenario(EXAMPLES / f"{name}.yaml")
    for robot in result.robots:
        waits_before_arrival = robot.waits
        expected = (
            robot.steps * scenario.timing.cell_time
            + robot.turns * scenario.timing.turn_time
            + waits_before_arrival * scenario.timing.cell_time
        )
        assert robot.time_s == pytest.approx(expected)
