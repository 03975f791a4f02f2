"""Reactive A* plans in the ``turning`` body's model: over (cell, heading), quarter turns either way, one tick each.

The adversarial variant steps along its plan in the tick it turns toward the cell
it chose, as a policy for bodies that turn for free would: a diverted robot then
finds itself off its plan, plans afresh and turns back, and robots spin in place
in the crowd of ``examples/causal-32.yaml``.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from mrmp.api import load
from mrmp.core.body import body_model
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.policies.astar import AstarPolicy
from mrmp.policies.base import Situation
from mrmp.search.planners import astar
from mrmp.sim.simulator import simulate

ROOT = Path(__file__).resolve().parents[3]
CROWD = ROOT / "examples" / "causal-32.yaml"


class StepsWhileTurning(AstarPolicy):
    """Broken: moves along its plan in the tick its body only turns (the policy of a body that turns for free)."""

    def _advance(self, situation: Situation, entered: Cell) -> None:
        if len(self._path) > 1 and self._path[1] == entered:
            self._path.pop(0)


def crowd(policy_type: type[AstarPolicy] | None = None):
    scenario = load(CROWD)
    scenario = scenario.with_changes(policy=replace(scenario.policy, name="astar", body="turning"))
    policies = None
    if policy_type is not None:
        policies = [policy_type(body=body_model("turning")) for _ in scenario.robots]
    return simulate(scenario, policies=policies)


@pytest.mark.parametrize(("facing", "first"), [(Heading.EAST, (0, 1)), (Heading.NORTH, (1, 0))])
def test_of_two_routes_as_long_a_turning_robot_takes_the_one_ahead(facing: Heading, first: Cell) -> None:
    """Two routes of two cells to the far corner: the one that starts ahead costs one quarter turn, the other two."""
    policy = AstarPolicy(body=body_model("turning"))
    situation = Situation(0, (0, 0), facing, (1, 1), Grid(3, 3), {})
    assert policy.intend(situation) == first


def test_planned_turns_cost_one_tick_each_either_way() -> None:
    """A turning body planned in its own model charges a quarter turn one cell time, whatever the timing's turn."""
    policy = AstarPolicy(body=body_model("turning"), timing=Timing(cell_time=2.0, turn_time=0.1))
    situation = Situation(0, (0, 0), Heading.EAST, (2, 0), Grid(3, 1), {})
    policy.intend(situation)
    assert policy._path == [(0, 0), (1, 0), (2, 0)]
    assert policy.search(Grid(3, 1), (0, 0), (2, 0), heading=Heading.EAST, timing=policy.timing, body=policy.body).cost == 6.0


def test_a_crowd_of_turning_robots_arrives_where_stepping_while_turning_spins() -> None:
    result = crowd()
    assert result.success and result.collisions == [], result.stop_reason
    assert all(robot.arrived for robot in result.robots)
    broken = crowd(StepsWhileTurning)
    assert broken.collisions == []
    assert sum(robot.arrived for robot in broken.robots) < len(broken.robots), "the broken variant should jam"


def test_a_live_robot_that_turned_then_drove_on_stays_on_its_plan() -> None:
    """Live, a robot drives into the cell it claimed once its turn toward it ends, with no decision in between:
    the policy finds it on its plan's next cell and steps on, without planning again (a diversion would be lost)."""
    searches: list[Cell] = []

    def counted(grid, start, goal, **options):
        searches.append(start)
        return astar(grid, start, goal, **options)

    policy = AstarPolicy(body=body_model("turning"), search=counted)
    grid = Grid(3, 3)
    facing_north = Situation(0, (0, 0), Heading.NORTH, (0, 2), grid, {})
    first = policy.intend(facing_north)
    assert first == (0, 1) and policy.decide(facing_north, first).next == (0, 1)  # east: a quarter turn first
    assert policy._path[0] == (0, 0)  # its decision was a turn: the plan has not stepped
    drove_on = Situation(0, (0, 1), Heading.EAST, (0, 2), grid, {})
    assert policy.intend(drove_on) == (0, 2)
    assert searches == [(0, 0)]
