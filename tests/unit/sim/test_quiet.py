"""A quiet fleet on a perfect network: unchanged states every few ticks, standing refused claims, the same paths.

On a perfect network the lockstep simulator's robots send an unchanged state
only every ``STATE_REFRESH`` ticks (a changed one at once; a robot coming near
is answered; a robot that has moved names the peers it knew near the cell it
left), leave out the repairs of lost messages, and keep refused claims standing
instead of sending them every tick (``docs/protocol.md``, "What it costs"). Their
policies see what they saw with states every tick, so they make the same paths,
for fewer messages. Two broken variants (no answer to a robot coming near; no
state by name to the peers left behind) show a stale view as other paths. On a
faulty network nothing changes.
"""

from pathlib import Path

import pytest

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.registry import plan_with
from mrmp.core import NetworkFaults, PolicyOptions
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.robot.robot import Robot
from mrmp.sim import simulator
from mrmp.sim.simulator import LockstepSimulator

MAPS = Path(__file__).resolve().parents[3] / "maps"


def movingai(name, agents, **changes):
    return load_movingai_scenario(MAPS / f"{name}.map", MAPS / f"{name}-random-1.scen", agents).with_changes(**changes)


def paths(result):
    return [robot.path for robot in result.robots]


def state_messages(result):
    return sum(1 for tick in result.message_log for _, _, kind in tick if kind == "state")


def claims(result):
    return sum(1 for tick in result.message_log for _, _, kind in tick if kind == "claim")


@pytest.mark.parametrize(
    ("name", "agents", "policy"),
    [("random-32-32-20", 100, "thesis"), ("random-32-32-20", 100, "astar"), ("empty-32-32", 100, "thesis")],
)
@pytest.mark.slow
def test_a_quiet_fleet_makes_the_same_paths_for_fewer_messages(name, agents, policy):
    scenario = movingai(name, agents, max_ticks=60, policy=PolicyOptions(name=policy))
    quiet = LockstepSimulator(scenario, record_messages=True).run()
    loud = LockstepSimulator(scenario, record_messages=True, quiet=False).run()
    assert paths(quiet) == paths(loud)
    assert quiet.stop_reason == loud.stop_reason
    assert state_messages(quiet) < 0.7 * state_messages(loud)
    assert claims(quiet) < claims(loud)
    assert quiet.messages < loud.messages


def test_a_quiet_plan_execution_keeps_its_paths():
    scenario = movingai("random-32-32-20", 60, max_ticks=300)
    plan = plan_with("lacam", scenario, time_limit_s=30.0)
    quiet = LockstepSimulator(scenario, plan_policies(plan), record_messages=True).run()
    loud = LockstepSimulator(scenario, plan_policies(plan), record_messages=True, quiet=False).run()
    assert quiet.stop_reason == loud.stop_reason
    assert paths(quiet) == paths(loud)
    assert state_messages(quiet) < state_messages(loud)


def test_nothing_changes_on_a_faulty_network():
    scenario = movingai(
        "random-32-32-20", 40, max_ticks=40, policy=PolicyOptions(name="thesis"), network=NetworkFaults(loss=0.2)
    )
    quiet = LockstepSimulator(scenario).run()
    loud = LockstepSimulator(scenario, quiet=False).run()
    assert paths(quiet) == paths(loud)
    assert quiet.messages == loud.messages


class Unanswering(Robot):
    """Broken: takes every peer for one it already knows near, so it never answers a robot coming near."""

    def _near(self, peer):
        return True


class LeavesPeersBehind(Robot):
    """Broken: a robot that has moved sends its state to the radius of its new cell only."""

    def arrived_at(self, cell, heading):
        super().arrived_at(cell, heading)
        self._behind = {}


@pytest.mark.parametrize("variant", [Unanswering, LeavesPeersBehind])
def test_a_stale_view_shows_as_other_paths(variant, monkeypatch):
    scenario = movingai("random-32-32-20", 100, max_ticks=60, policy=PolicyOptions(name="thesis"))
    loud = LockstepSimulator(scenario, quiet=False).run()
    monkeypatch.setattr(simulator, "Robot", variant)
    broken = LockstepSimulator(scenario).run()
    assert paths(broken) != paths(loud)
