"""More rounds of exchange per tick on a lossy network: what is lost is made up within the tick.

``docs/protocol.md``, "More rounds on a lossy network": the lockstep simulator gives a tick
``EXTRA_ROUNDS`` more rounds when the network is not perfect, none on a perfect one. A lossy
execution of a central plan then stays close to the plan; with the rounds taken away, the
same run (same seed, same losses drawn) falls far behind it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.registry import plan_with
from mrmp.core import NetworkFaults
from mrmp.experiments.execution import execution_max_ticks
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.sim.simulator import EXTRA_ROUNDS, LockstepSimulator

MAPS = Path(__file__).resolve().parents[3] / "maps"


def _lossy_execution(agents: int, extra_rounds: int | None) -> tuple[int, int, LockstepSimulator]:
    """The plan's sum of costs, the executed one, and the simulator, for LaCAM on random-32-32-20 at 10% loss."""
    scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", agents)
    plan = plan_with("lacam", scenario, time_limit_s=60)
    assert plan.solved
    scenario = scenario.with_changes(network=NetworkFaults(loss=0.1), seed=0)
    scenario = scenario.with_changes(max_ticks=execution_max_ticks(scenario, plan))
    simulator = LockstepSimulator(scenario, policies=plan_policies(plan, following=True, scheduled=True))
    if extra_rounds is not None:
        simulator.extra_rounds = extra_rounds
    result = simulator.run()
    assert result.success and not result.collisions
    return plan.sum_of_costs(), result.sum_of_costs, simulator


def test_a_perfect_network_gets_no_extra_rounds_and_a_lossy_one_does() -> None:
    scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", 4)
    assert LockstepSimulator(scenario).extra_rounds == 0
    assert LockstepSimulator(scenario.with_changes(network=NetworkFaults(loss=0.1))).extra_rounds == EXTRA_ROUNDS > 0


@pytest.mark.slow
def test_a_lossy_plan_execution_stays_within_five_percent_of_its_plan() -> None:
    planned, executed, _ = _lossy_execution(100, None)
    assert planned <= executed <= 1.05 * planned


@pytest.mark.slow
def test_without_the_extra_rounds_the_same_execution_falls_behind_its_plan() -> None:
    planned, executed, _ = _lossy_execution(100, 0)
    assert executed > 1.15 * planned
