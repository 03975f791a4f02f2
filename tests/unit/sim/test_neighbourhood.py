"""Neighbourhood messaging: states go to the robots within the policy's radius, and that is enough.

On a perfect network the thesis's rule and plan execution decide exactly as with
states sent to every peer; a radius smaller than the rule reads makes the
unguarded thesis collide where the right one does not; under 30% loss a robot
coming near is known before it is within the interaction radius; and the cost
of a state does not grow with the fleet.
"""

from collections import Counter
from pathlib import Path

import pytest

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.registry import plan_with
from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.policies.thesis import ThesisPolicy
from mrmp.sim import simulator
from mrmp.sim.simulator import LOSS_LEASE, LockstepSimulator, simulate

MAPS = Path(__file__).resolve().parents[3] / "maps"
SWAP = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))), name="swap")


def movingai(name, agents, **changes):
    return load_movingai_scenario(MAPS / f"{name}.map", MAPS / f"{name}-random-1.scen", agents).with_changes(**changes)


class FleetWide(ThesisPolicy):
    """The thesis's rule, its states sent to every peer (no interaction radius)."""

    interaction_radius = None


class ShortSighted(ThesisPolicy):
    """A broken variant: the thesis's rule claiming to read only peers next to it (it reads peers two cells away)."""

    interaction_radius = 1


def paths(result):
    return [robot.path for robot in result.robots]


INSTANCES = [
    (SWAP, "swap"),
    (movingai("random-32-32-20", 40, max_ticks=80), "random"),
    (movingai("empty-32-32", 50, max_ticks=80), "empty"),
    (movingai("room-32-32-4", 20, max_ticks=80), "room"),
]


@pytest.mark.slow
@pytest.mark.parametrize("safety", [True, False], ids=["guarded", "unguarded"])
@pytest.mark.parametrize(("scenario", "name"), INSTANCES, ids=[name for _, name in INSTANCES])
def test_the_thesis_rule_decides_as_with_states_to_everyone(scenario, name, safety):
    scenario = scenario.with_changes(safety=safety, policy=PolicyOptions(name="thesis"))
    local = simulate(scenario)
    everyone = simulate(scenario, policies=[FleetWide() for _ in scenario.robots])
    assert paths(local) == paths(everyone)
    assert len(local.collisions) == len(everyone.collisions)
    if len(scenario.robots) > 10:
        assert local.messages < everyone.messages / 3


@pytest.mark.slow
def test_a_plan_executes_as_with_states_to_everyone():
    scenario = movingai("random-32-32-20", 60, max_ticks=300)
    plan = plan_with("lacam", scenario, time_limit_s=30.0)
    local = simulate(scenario, policies=plan_policies(plan))
    everyone = simulate(scenario, policies=[PlanFollowingPolicy(p.moves, p.dependencies) for p in plan_policies(plan)])
    assert local.stop_reason == "all arrived"
    assert paths(local) == paths(everyone)
    assert local.messages < everyone.messages / 5


def test_a_lost_push_is_pulled_by_the_waiting_robot():
    """Under 30% loss a plan still executes to the end without a collision: waiting robots ask for the news."""
    scenario = movingai("random-32-32-20", 40, max_ticks=600, network=NetworkFaults(loss=0.3))
    plan = plan_with("lacam", scenario, time_limit_s=30.0)
    result = simulate(scenario, policies=plan_policies(plan))
    assert result.stop_reason == "all arrived"
    assert result.collisions == []


def test_a_radius_smaller_than_the_rule_reads_makes_the_unguarded_thesis_collide():
    unguarded = SWAP.with_changes(safety=False)
    right = simulate(unguarded)
    assert right.collisions == [] and right.success
    short = simulate(unguarded, policies=[ShortSighted() for _ in SWAP.robots])
    assert short.collisions  # both took the middle cell: neither heard the other two cells away


def first_contacts(scenario, seeds):
    """Each time a robot comes within the interaction radius of another (not at the start): whether it knew of it.

    A robot knows of a peer when its belief holds a state of the peer heard within
    its knowledge lease at the tick's decisions (the policy is shown every such
    peer whose last known cell lies within its radius).
    """
    radius = ThesisPolicy.interaction_radius
    known = Counter()
    for seed in seeds:
        run = LockstepSimulator(scenario.with_changes(seed=seed))
        robots = run.robots
        near_before = None
        while run.tick < run.max_ticks and not all(robot.arrived for robot in robots):
            cells = [robot.present for robot in robots]
            run.step()
            near = {
                (a, b)
                for a in range(len(robots))
                for b in range(len(robots))
                if a != b and abs(cells[a][0] - cells[b][0]) + abs(cells[a][1] - cells[b][1]) <= radius
            }
            if near_before is not None:
                for a, b in near - near_before:
                    known[b in robots[a].belief.peers] += 1
            near_before = near
    return known


@pytest.mark.slow
def test_a_robot_coming_near_is_known_before_it_is_within_the_radius_under_loss(monkeypatch):
    """30% loss: with the radius widened by twice the lease, a robot is known at first contact (all but 0.3^3).

    The broken variant sends states only as far as the rule reads (no room for the
    lease): the first state of a robot coming near is then the one sent when it is
    already there, lost 30% of the time.
    """
    scenario = movingai("empty-32-32", 60, max_ticks=40, network=NetworkFaults(loss=0.3), safety=True)
    scenario = scenario.with_changes(policy=PolicyOptions(name="thesis"))
    right = first_contacts(scenario, range(3))
    assert sum(right.values()) > 50
    assert right[False] <= 0.04 * sum(right.values())
    real = simulator.neighbourhood
    monkeypatch.setattr(simulator, "neighbourhood", lambda policy, faults: (real(policy, faults)[0] - 2 * LOSS_LEASE, LOSS_LEASE))
    narrow = first_contacts(scenario, range(3))
    assert narrow[False] >= 0.15 * sum(narrow.values())


def test_states_per_robot_tick_do_not_grow_with_the_fleet():
    """The same density on a map 4 times as large: a state reaches about as many robots."""
    small = movingai("random-32-32-20", 60, max_ticks=10, policy=PolicyOptions(name="thesis"))
    large = movingai("random-64-64-20", 240, max_ticks=10, policy=PolicyOptions(name="thesis"))
    per_robot_tick = []
    for scenario in (small, large):
        result = simulate(scenario, record_messages=True)
        states = sum(1 for tick in result.message_log for _, _, kind in tick if kind == "state")
        per_robot_tick.append(states / (len(scenario.robots) * result.ticks))
    assert per_robot_tick[1] < 2 * per_robot_tick[0] + 1
    assert max(per_robot_tick) < 12
