"""The public surface of mrmp.search."""

from __future__ import annotations

import dataclasses

import pytest

from mrmp import search
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.search import GridMap, SearchResult, SizedGridMap, path_cost, path_headings


def test_exports() -> None:
    for name in search.__all__:
        assert hasattr(search, name), name
    for name in ("astar", "dijkstra", "greedy_best_first", "update_coordinate_path", "distance_table", "PLANNERS"):
        assert name in search.__all__


def test_grid_satisfies_the_protocols() -> None:
    grid = Grid(3, 4)
    assert isinstance(grid, GridMap)
    assert isinstance(grid, SizedGridMap)
    assert not isinstance(object(), GridMap)


def test_search_result_is_frozen() -> None:
    result = SearchResult(((0, 0), (0, 1)), 1.0, 1)
    assert result.steps == 1
    assert result.headings is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.cost = 2.0  # type: ignore[misc]


def test_path_cost_and_headings() -> None:
    grid = Grid(3, 3, costs={(2, 2): 4.0})
    path = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2)]
    assert path_cost(grid, path) == 7.0
    assert path_cost(grid, path, timing=Timing(2.0, 9.0)) == 14.0
    assert path_headings(path, Heading.WEST) == (Heading.WEST, Heading.NORTH, Heading.NORTH, Heading.EAST, Heading.EAST)
    # WEST -> NORTH is one right turn, NORTH -> EAST another
    assert path_cost(grid, path, heading=Heading.WEST, timing=Timing(1.0, 0.5)) == 8.0
    assert path_cost(grid, path, heading=Heading.NORTH) == 7.5  # default Timing: 0.5 s per turn
    assert path_cost(grid, [(1, 1)], heading=Heading.NORTH) == 0.0
    with pytest.raises(ValueError):
        path_headings([(0, 0), (2, 0)], Heading.NORTH)
