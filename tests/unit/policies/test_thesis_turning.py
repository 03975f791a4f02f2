"""The thesis's rule drives ``turning`` bodies: the same Next (the update coordinate L ignores headings), turned
toward a quarter at a time; with a search, Next is planned over (cell, heading) in the body's model."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from mrmp.api import load
from mrmp.core.body import body_model
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.policies.base import Situation
from mrmp.policies.thesis import ThesisPolicy
from mrmp.search.planners import astar
from mrmp.sim.simulator import simulate

ROOT = Path(__file__).resolve().parents[3]


@pytest.mark.parametrize("facing", list(Heading))
def test_the_update_coordinate_next_does_not_depend_on_the_heading(facing: Heading) -> None:
    situation = Situation(0, (0, 0), facing, (2, 2), Grid(3, 3), {})
    assert ThesisPolicy(body=body_model("turning")).intend(situation) == (1, 0)


@pytest.mark.parametrize(("facing", "first"), [(Heading.EAST, (0, 1)), (Heading.NORTH, (1, 0))])
def test_with_a_search_next_starts_the_route_ahead(facing: Heading, first: tuple[int, int]) -> None:
    situation = Situation(0, (0, 0), facing, (1, 1), Grid(3, 3), {})
    assert ThesisPolicy(search=astar, body=body_model("turning")).intend(situation) == first


@pytest.mark.parametrize("example", ["thesis-swap.yaml", "thesis-cross.yaml", "thesis-swap-row.yaml"])
def test_the_thesis_experiments_with_turning_bodies_arrive_one_action_a_tick(example: str) -> None:
    scenario = load(ROOT / "examples" / example)
    result = simulate(scenario.with_changes(policy=replace(scenario.policy, name="thesis", body="turning")))
    assert result.success and result.collisions == []
    for robot in result.robots:
        for tick in range(1, len(robot.path)):
            moved = robot.path[tick] != robot.path[tick - 1]
            assert not moved or robot.headings[tick] == robot.headings[tick - 1], (robot.id, tick)
            if moved:
                assert Heading.between(robot.path[tick - 1], robot.path[tick]) == robot.headings[tick]
