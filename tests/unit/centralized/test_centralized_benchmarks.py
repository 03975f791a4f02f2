"""CBS and prioritized planning on a MovingAI benchmark: random-32-32-20, first agents of random-1."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_centralized_support import assert_valid_plan, replay_headings

from mrmp.centralized import cbs, plan_size_bytes, prioritized
from mrmp.core.scenario import Scenario
from mrmp.io import load_movingai_scenario
from mrmp.search import distance_table

MAPS = Path(__file__).resolve().parents[3] / "maps"


def load(agents: int) -> Scenario:
    return load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", agents)


@pytest.mark.parametrize("agents", [10, 20])
def test_cbs_and_pp_solve_the_first_agents(agents: int) -> None:
    scenario = load(agents)
    starts = [robot.start for robot in scenario.robots]
    goals = [robot.goal for robot in scenario.robots]
    lower_bound = sum(int(distance_table(scenario.grid, g).distance(s)) for s, g in zip(starts, goals))
    optimal = cbs(scenario, time_limit_s=20.0)
    assert_valid_plan(scenario.grid, optimal, starts, goals)
    greedy = prioritized(scenario)
    assert_valid_plan(scenario.grid, greedy, starts, goals)
    assert lower_bound <= optimal.sum_of_costs() <= greedy.sum_of_costs()
    assert plan_size_bytes(optimal) == 8 * agents * (optimal.makespan() + 1)
    # the original CBS (no conflict prioritization, heuristic or bypass) agrees on the optimum
    if agents == 10:
        assert cbs(scenario, improved=False, time_limit_s=20.0).sum_of_costs() == optimal.sum_of_costs()


def test_heading_aware_planners_on_the_benchmark() -> None:
    scenario = load(10)
    starts = [robot.start for robot in scenario.robots]
    goals = [robot.goal for robot in scenario.robots]
    optimal = cbs(scenario, heading_aware=True, time_limit_s=20.0)
    greedy = prioritized(scenario, heading_aware=True)
    for result in (optimal, greedy):
        assert_valid_plan(scenario.grid, result, starts, goals)
        replay_headings(scenario.grid, result, [robot.heading for robot in scenario.robots])
    assert optimal.sum_of_costs() <= greedy.sum_of_costs()
    # turns cost ticks: more than the turn-free optimum
    assert optimal.sum_of_costs() > cbs(scenario).sum_of_costs()
