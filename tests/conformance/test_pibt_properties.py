"""Properties of decentralized PIBT (hypothesis, derandomized).

* On random *biconnected* maps with at most one robot per three free cells, and
  a network that loses, delays, duplicates and reorders messages, ``pibt``
  never collides and every robot reaches its goal within ``diam(G) * N``
  steps: the reachability theorem of PIBT (Okumura et al., IJCAI 2019 / AIJ
  2022) for graphs where every edge lies on a cycle, with priorities counting
  the steps since a robot last stood on its goal. The swap technique (which
  walks robots away from their goals) is off: the theorem covers plain PIBT.
* With ``heading_aware`` (turns cost time), the same holds in the heading-aware cost:
  within ``D * N`` steps, ``D`` the largest heading-aware cost to a goal.
* On random maps of any shape, with the swap technique, it never collides; with the
  robots ordering their calls themselves (``sequencing: local``) too.
"""

import math

import networkx as nx
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from map_strategies import FAULTS, any_worlds, biconnected_worlds, free_graph
from reaching import assert_every_robot_reaches_its_goal

from mrmp.core import PolicyOptions, Scenario, Timing
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.rounds import RoundsSimulator


@pytest.mark.parametrize("examples", [pytest.param(60, id="default"), pytest.param(600, id="many", marks=pytest.mark.slow)])
def test_reaches_every_goal_within_the_bound_on_biconnected_maps(examples):
    @settings(max_examples=examples, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(world=biconnected_worlds(), faults=FAULTS, seed=st.integers(0, 1000))
    def check(world, faults, seed):
        grid, robots = world
        assert nx.is_biconnected(free_graph(grid))
        scenario = Scenario(
            grid, robots, network=faults, policy=PolicyOptions(name="pibt", swap=False), seed=seed, max_ticks=10**9
        )
        simulator = RoundsSimulator(scenario)
        bound = nx.diameter(free_graph(grid)) * len(robots)
        assert_every_robot_reaches_its_goal(simulator, bound, "steps", lambda steps: steps)

    check()


@settings(max_examples=30, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(world=biconnected_worlds(), faults=FAULTS, seed=st.integers(0, 1000), turn_time=st.sampled_from([0.25, 0.5, 1.0]))
def test_heading_aware_reaches_every_goal_within_its_bound(world, faults, seed, turn_time):
    """With turns costing time, the theorem holds in the heading-aware cost: the top robot's cost to
    its goal drops by at least one cell per step, so ``D * N`` steps suffice, ``D`` the largest finite
    heading-aware cost of any state to any robot's goal (in cells)."""
    grid, robots = world
    scenario = Scenario(
        grid, robots, network=faults, policy=PolicyOptions(name="pibt", swap=False, heading_aware=True),
        timing=Timing(1.0, turn_time), seed=seed, max_ticks=10**9,
    )  # fmt: skip
    simulator = RoundsSimulator(scenario)
    flat = simulator.flat
    largest = max(
        max(value for value in flat.heading_distances(robot.goal, turn_time) if value != float("inf"))
        for robot in simulator.robots
    )
    bound = math.ceil(largest) * len(robots)
    assert_every_robot_reaches_its_goal(simulator, bound, "steps", lambda steps: steps)


@settings(max_examples=80, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(world=any_worlds(), faults=FAULTS, seed=st.integers(0, 1000), radius=st.integers(2, 4))
def test_never_collides_on_any_map(world, faults, seed, radius):
    grid, robots = world
    scenario = Scenario(grid, robots, network=faults, policy=PolicyOptions(name="pibt", radius=radius), seed=seed)
    simulator = RoundsSimulator(scenario.with_changes(max_ticks=10**9))
    for _ in range(40):
        simulator.step()
    assert simulator.referee.collisions == []


@settings(max_examples=60, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(world=any_worlds(), faults=FAULTS, seed=st.integers(0, 1000), radius=st.integers(2, 4))
def test_local_sequencing_never_collides_on_any_map(world, faults, seed, radius):
    """With the robots ordering their calls themselves, over the same faulty networks (a lost message is lost)."""
    grid, robots = world
    policy = PolicyOptions(name="pibt", radius=radius, sequencing="local")
    scenario = Scenario(grid, robots, network=faults, policy=policy, seed=seed, max_ticks=10**9)
    simulator = LocalRoundsSimulator(scenario)
    for _ in range(25):
        simulator.step()
    assert simulator.referee.collisions == []
