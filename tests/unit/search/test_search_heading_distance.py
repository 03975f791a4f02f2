"""Heading-aware distance tables: equal to heading-aware A* from every state; errors named."""

import random

import pytest

from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS
from mrmp.core.scenario import Timing
from mrmp.search import astar
from mrmp.search.heading_distance import heading_distances


def random_grid(seed: int) -> Grid:
    rng = random.Random(seed)
    rows = ["".join("@" if rng.random() < 0.2 else "." for _ in range(7)) for _ in range(6)]
    plain = Grid.from_rows(rows)
    costs = {cell: rng.choice((1.0, 1.0, 2.0, 3.5)) for cell in plain.free_cells()}
    return Grid(plain.x_size, plain.y_size, plain.blocked_cells(), costs)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("turn_cost", [0.0, 0.5, 2.0])
def test_every_state_costs_what_heading_aware_astar_finds(seed, turn_cost):
    grid = random_grid(seed)
    free = grid.free_cells()
    goal = random.Random(seed).choice(free)
    table = heading_distances(grid, goal, turn_cost)
    for cell in free:
        for heading in HEADINGS:
            value = table[4 * (cell[0] * grid.y_size + cell[1]) + int(heading) - 1]
            try:
                expected = astar(grid, cell, goal, heading=heading, timing=Timing(1.0, turn_cost)).cost
            except NoPathError:
                expected = float("inf")
            assert value == pytest.approx(expected), (cell, heading)


def test_blocked_cells_are_unreachable_and_bad_arguments_are_refused():
    grid = Grid.from_rows([".@.", "..."])
    table = heading_distances(grid, (0, 0), 0.5)
    blocked = 4 * (1 * 3 + 1)  # (1, 1) is the '@' (rows are drawn north up)
    assert table[blocked : blocked + 4] == [float("inf")] * 4
    with pytest.raises(ValueError, match="not a free cell"):
        heading_distances(grid, (1, 1), 0.5)
    with pytest.raises(ValueError, match="must not be negative"):
        heading_distances(grid, (0, 0), -1.0)
