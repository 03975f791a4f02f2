"""The table of searches a per-robot policy may plan with, and the known properties of each."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.core.options import SEARCH_NAMES
from mrmp.io import read_map
from mrmp.search import PLANNERS, distance_table, update_coordinate_cells
from mrmp.search.choices import SEARCH_TABLE, chosen_search

MAPS = Path(__file__).resolve().parents[3] / "maps"

TRAP = Grid.from_rows([
    ".......",
    ".......",
    ".@@@@@.",
    ".@...@.",
    ".@...@.",
    ".......",
    ".......",
])
"""A pocket open to the south: from (2, 0) to (3, 3) inside it greedy best-first heads north, around the top."""


def random_pairs(grid: Grid, count: int, seed: int) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    cells = sorted(grid.free_cells())
    chooser = random.Random(seed)
    return [(chooser.choice(cells), chooser.choice(cells)) for _ in range(count)]


def test_one_entry_per_search_name_each_a_library_planner():
    assert tuple(SEARCH_TABLE) == SEARCH_NAMES
    assert all(choice.name == name for name, choice in SEARCH_TABLE.items())
    assert {choice.planner for choice in SEARCH_TABLE.values()} == set(PLANNERS.values())


def test_default_stands_for_the_policys_own_search():
    assert chosen_search("default", own="update-coordinate") is SEARCH_TABLE["update-coordinate"]
    assert chosen_search("default", own="astar") is SEARCH_TABLE["astar"]
    assert chosen_search("dijkstra", own="astar") is SEARCH_TABLE["dijkstra"]


@pytest.mark.parametrize("map_name", ["random-32-32-20", "maze-32-32-2", "room-32-32-4"])
@pytest.mark.parametrize("name", [name for name, choice in SEARCH_TABLE.items() if choice.optimal])
def test_optimal_searches_find_cheapest_paths(map_name, name):
    grid = read_map(MAPS / f"{map_name}.map")
    planner = SEARCH_TABLE[name].planner
    for start, goal in random_pairs(grid, 60, seed=3):
        cheapest = distance_table(grid, goal).distance(start)
        if cheapest == float("inf"):
            with pytest.raises(NoPathError):
                planner(grid, start, goal)
            continue
        assert planner(grid, start, goal).cost == cheapest, (start, goal)


def test_optimal_searches_with_cell_costs():
    grid = Grid.from_rows([".....", ".999.", ".9.9.", ".....", "....."])
    for name in ("dijkstra", "astar"):
        for start, goal in random_pairs(grid, 40, seed=5):
            assert SEARCH_TABLE[name].planner(grid, start, goal).cost == distance_table(grid, goal).distance(start)


def test_best_first_is_not_always_cheapest():
    assert not SEARCH_TABLE["best-first"].optimal
    cheapest = distance_table(TRAP, (3, 3)).distance((2, 0))
    greedy = SEARCH_TABLE["best-first"].planner(TRAP, (2, 0), (3, 3))
    assert (cheapest, greedy.cost) == (6.0, 18.0)


def test_best_first_expands_no_more_than_dijkstra_on_an_open_grid():
    grid = Grid(16, 16)
    greedy = SEARCH_TABLE["best-first"].planner(grid, (0, 0), (15, 15))
    uniform = SEARCH_TABLE["dijkstra"].planner(grid, (0, 0), (15, 15))
    assert greedy.cost == uniform.cost and greedy.expansions < uniform.expansions


def test_update_coordinate_is_the_thesis_x_then_y():
    planner = SEARCH_TABLE["update-coordinate"].planner
    grid = read_map(MAPS / "warehouse-10-20-10-2-1.map")
    found = 0
    for start, goal in random_pairs(grid, 200, seed=7):
        try:
            path = planner(grid, start, goal).path
        except NoPathError:
            assert any(not grid.is_free(cell) for cell in update_coordinate_cells(start, goal))
            continue
        found += 1
        assert path == update_coordinate_cells(start, goal)
        corner = path.index((goal[0], start[1]))
        assert all(cell[1] == start[1] for cell in path[: corner + 1])  # x changes first
        assert all(cell[0] == goal[0] for cell in path[corner:])  # then y
    assert found > 0


def test_update_coordinate_never_detours():
    with pytest.raises(NoPathError, match="blocked at"):
        SEARCH_TABLE["update-coordinate"].planner(TRAP, (2, 0), (3, 3))
