"""Hypothesis strategies of the property tests: random maps with robots, and a faulty network.

``biconnected_worlds`` draws maps on which PIBT and Causal-PIBT promise that
every robot reaches its goal (free cells forming a biconnected graph, at most
one robot per three free cells); ``any_worlds`` draws maps of any shape, with
every goal in its start's region.
"""

import random

import networkx as nx
from hypothesis import strategies as st

from mrmp.core import Grid, NetworkFaults, RobotSpec
from mrmp.core.grid import connected_regions

FAULTS = st.builds(
    NetworkFaults,
    loss=st.sampled_from([0.0, 0.1, 0.3]),
    delay_min=st.just(0),
    delay_max=st.integers(0, 2),
    duplicate=st.sampled_from([0.0, 0.2]),
    reorder=st.sampled_from([0.0, 0.3]),
)
"""A network that loses, delays, duplicates and reorders messages (or not)."""


def free_graph(grid):
    """The graph of the free cells of ``grid`` and their moves."""
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


@st.composite
def any_worlds(draw):
    """A random grid of any shape, and robots whose goals lie in their start's region."""
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
