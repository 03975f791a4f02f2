"""``compare_methods`` runs every policy with the scenario's own settings."""

from __future__ import annotations

from pathlib import Path

from mrmp.experiments.compare import compare_methods
from mrmp.io import load_scenario
from mrmp.sim.simulator import simulate

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def test_a_heading_aware_scenario_is_compared_heading_aware() -> None:
    scenario = load_scenario(EXAMPLES / "warehouse-astar.yaml")
    assert scenario.policy.heading_aware
    rows = {row.method: row for row in compare_methods(scenario, time_limit_s=10)}
    alone = simulate(scenario)
    assert rows["astar"].makespan == alone.makespan and rows["astar"].sum_of_costs == alone.sum_of_costs
