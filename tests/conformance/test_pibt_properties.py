"""Properties of decentralized PIBT (hypothesis, derandomized).

* On random *biconnected* maps with at most one robot per three free cells, and
  a network that loses, delays, duplicates and reorders messages, ``pibt``
  never collides and every robot reaches its goal within ``diam(G) * N``
  steps: the reachability theorem of PIBT (Okumura et al., IJCAI 2019 / AIJ
  2022) for graphs where every edge lies on a cycle, with priorities counting
  the steps since a robot last stood on its goal. The swap technique (which
  walks robots away from their goals) is off: the theorem covers plain PIBT.
* On random maps of any shape, with the swap technique, it never collides.
"""

import random

import networkx as nx
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.grid import connected_regions
from mrmp.sim.rounds import RoundsSimulator

FAULTS = st.builds(
    NetworkFaults,
    loss=st.sampled_from([0.0, 0.1, 0.3]),
    delay_min=st.just(0),
    delay_max=st.integers(0, 2),
    duplicate=st.sampled_from([0.0, 0.2]),
    reorder=st.sampled_from([0.0, 0.3]),
)


def free_graph(grid):
    graph = nx.Graph()
    for cell in grid.free_cells():
        graph.add_node(cell)
        graph.add_edges_from((cell, other) for other in grid.neighbours(cell))
    return graph


@st.composite
def biconnected_worlds(draw):
    """A random grid whose free cells form a biconnected graph, and robots at most one per three free cells."""
    rng = random.Random(draw(st.integers(0, 10**6)))
    x_size, y_size = draw(st.integers(2, 7)), draw(st.integers(3, 7))
    blocked: set = set()
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    for cell in rng.sample(cells, k=len(cells) // 4):  # block a cell only if the rest stays biconnected
        graph = free_graph(Grid(x_size, y_size, blocked | {cell}))
        if graph.number_of_nodes() >= 3 and nx.is_biconnected(graph):
            blocked.add(cell)
    grid = Grid(x_size, y_size, blocked)
    free = grid.free_cells()
    count = draw(st.integers(1, len(free) // 3))
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    return grid, tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))


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
        reached = {robot.index for robot in simulator.robots if robot.at_goal}
        for _ in range(bound):
            simulator.step()
            reached |= {robot.index for robot in simulator.robots if robot.at_goal}
        assert simulator.referee.collisions == []
        assert reached == set(range(len(robots))), f"not at their goals within {bound} steps: {set(range(len(robots))) - reached}"

    check()


@st.composite
def any_worlds(draw):
    rng = random.Random(draw(st.integers(0, 10**6)))
    x_size, y_size = draw(st.integers(1, 8)), draw(st.integers(2, 8))
    cells = [(x, y) for x in range(x_size) for y in range(y_size)]
    grid = Grid(x_size, y_size, rng.sample(cells, k=rng.randint(0, len(cells) // 3)))
    _, regions = connected_regions(grid, grid.free_cells())
    starts, goals = [], []
    for region in regions:  # goals in the start's region: every robot could arrive
        count = rng.randint(0, len(region) // 2)
        starts += rng.sample(region, count)
        goals += rng.sample(region, count)
    return grid, tuple(RobotSpec(f"r{i}", s, g) for i, (s, g) in enumerate(zip(starts, goals)))


@settings(max_examples=80, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(world=any_worlds(), faults=FAULTS, seed=st.integers(0, 1000), radius=st.integers(2, 4))
def test_never_collides_on_any_map(world, faults, seed, radius):
    grid, robots = world
    scenario = Scenario(grid, robots, network=faults, policy=PolicyOptions(name="pibt", radius=radius), seed=seed)
    simulator = RoundsSimulator(scenario.with_changes(max_ticks=10**9))
    for _ in range(40):
        simulator.step()
    assert simulator.referee.collisions == []
