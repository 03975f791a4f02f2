"""One conformance suite, run over every policy in the policy table (as PettingZoo does for environments).

The suite is parametrized over the table's contents; :func:`check_policy` is the
same check for one named policy, for a policy added to the table elsewhere (for
example ``test_toy_policy.py``).

Whatever a policy decides, the run it produces must be judged consistently by the
referee: paths have one cell per tick, move at most one cell per tick when the
referee finds no jump, and every violation the referee reports is real (an
independent pairwise check agrees). Collision-free runs have continuous paths
inside the free space. These properties must hold with and without network faults; with the safety
layer on, no run may ever have a vertex or swap collision.
"""

import itertools
import random

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.body import DEFAULT_BODY, body_model
from mrmp.core.heading import Heading
from mrmp.core.scenario import scenario_problems
from mrmp.sim.policy_table import policy_entry, policy_names
from mrmp.sim.referee import check_paths
from mrmp.sim.simulator import simulate


def body_policy(policy, resolve, body):
    """The policy options of a run of ``policy`` in ``body``'s model (bodies other than omni: pibt's driver sequencing)."""
    if body == DEFAULT_BODY:
        return PolicyOptions(name=policy, resolve=resolve)
    return PolicyOptions(name=policy, resolve=resolve, body=body, sequencing="driver")


@st.composite
def scenarios(draw, policy, body=DEFAULT_BODY):
    x_size, y_size = draw(st.integers(3, 8)), draw(st.integers(3, 8))
    rng = random.Random(draw(st.integers(0, 10**6)))
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    blocked = rng.sample(cells, k=draw(st.integers(0, len(cells) // 5)))
    grid = Grid(x_size, y_size, blocked)
    free = [cell for cell in cells if cell not in set(blocked)]
    count = draw(st.integers(1, max(1, min(6, len(free) // 3))))
    starts = rng.sample(free, count)
    goals = rng.sample(free, count)
    headings = [Heading(rng.randint(1, 4)) for _ in starts]
    robots = tuple(RobotSpec(f"r{i}", s, g, heading=h) for i, (s, g, h) in enumerate(zip(starts, goals, headings)))
    faults = draw(
        st.sampled_from(
            [
                NetworkFaults(),
                NetworkFaults(loss=0.2, delay_min=0, delay_max=2, duplicate=0.1, reorder=0.2),
                NetworkFaults(loss=0.5, delay_min=1, delay_max=3, duplicate=0.3, reorder=0.5),
            ]
        )
    )
    resolve = draw(st.sampled_from(["divert", "wait"]))
    scenario = Scenario(
        grid,
        robots,
        network=faults,
        policy=body_policy(policy, resolve, body),
        safety=rng.random() < 0.6,
        seed=rng.randrange(1000),
    )
    if rng.random() < 0.2:
        scenario = scenario.with_changes(lifelong=True, max_ticks=60)
    return scenario


def pairwise_violations(grid, paths):
    ids = list(paths)
    found = set()
    length = len(next(iter(paths.values())))
    for t in range(length):
        for i, a in enumerate(ids):
            for b in ids[i + 1 :]:
                if paths[a][t] == paths[b][t]:
                    found.add(("vertex", t))
                if t and paths[a][t] == paths[b][t - 1] and paths[b][t] == paths[a][t - 1] and paths[a][t] != paths[b][t]:
                    found.add(("swap", t))
    return found


@pytest.mark.slow
@pytest.mark.parametrize(("policy", "body"), [(name, body) for name in policy_names() for body in policy_entry(name).bodies])
def test_policy_conformance(policy, body):
    check_policy(policy, body=body)


def check_policy(policy, max_examples=80, body=DEFAULT_BODY):
    """Run the conformance checks on ``max_examples`` drawn scenarios of the table's policy ``policy`` in ``body``'s model."""
    assert policy_entry(policy).name == policy

    @settings(max_examples=max_examples, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(data=st.data())
    def conforms(data):
        check_run(data.draw(scenarios(policy, body)))

    conforms()


def check_run(scenario):
    """One drawn scenario's run obeys every property of the module docstring."""
    if scenario_problems(scenario):  # unreachable goals on random maps: nothing to run
        return
    result = simulate(scenario)
    paths = {robot.id: robot.path for robot in result.robots}
    assert {len(path) for path in paths.values()} == {result.ticks + 1}
    assert all(robot.path[0] == robot.start for robot in result.robots)
    # the referee's findings are exactly what an independent judge finds, in the run's body model
    body = body_model(scenario.policy.body)
    headings = {robot.id: robot.headings for robot in result.robots} if body.headed else None
    assert check_paths(scenario.grid, paths, headings, body) == result.collisions
    assert {(c.kind, c.tick) for c in result.collisions if c.kind in ("vertex", "swap")} == pairwise_violations(
        scenario.grid, paths
    )
    if not result.collisions:
        for path in paths.values():
            assert all(scenario.grid.is_free(cell) for cell in path)
            assert all(abs(a[0] - b[0]) + abs(a[1] - b[1]) <= 1 for a, b in itertools.pairwise(path))
    if scenario.lifelong:
        assert result.success == (result.stop_reason == "time up" and not result.collisions)
    else:
        assert result.success == (result.all_arrived and not result.collisions)
    if scenario.safety:  # the safety layer: no two robots in one cell, whatever the network did
        assert not [c for c in result.collisions if c.kind in ("vertex", "swap")]
    assert result.lower_bound <= result.sum_of_costs or not result.all_arrived
