"""Grid geometry and the single MovingAI mapping."""

import pytest

from mrmp.core.grid import Grid, cell_from_movingai, movingai_from_cell


def test_rows_are_drawn_north_up():
    grid = Grid.from_rows(["@..", "...", "..#"])
    assert (grid.x_size, grid.y_size) == (3, 3)
    assert grid.is_blocked((2, 0))  # top-left = northmost row, westmost column
    assert grid.is_blocked((0, 2))  # bottom-right
    assert grid.to_rows() == ["@..", "...", "..@"]


def test_mapping_round_trip():
    for column in range(4):
        for row in range(3):
            cell = cell_from_movingai(column, row, height=3)
            assert movingai_from_cell(cell, height=3) == (column, row)


def test_neighbours_skip_blocked_and_edges():
    grid = Grid.from_rows(["...", ".@.", "..."])
    assert grid.neighbours((1, 0)) == [(2, 0), (0, 0)]
    assert (1, 1) not in grid.neighbours((1, 2))


def test_costs_and_errors():
    grid = Grid.from_rows([".3", ".."])
    assert grid.cost((1, 1)) == 3.0 and grid.cost((0, 0)) == 1.0 and grid.has_costs
    with pytest.raises(ValueError, match="row 1 has 1 symbols"):
        Grid.from_rows(["..", "."])
    with pytest.raises(ValueError, match="unknown map symbol"):
        Grid.from_rows([".x"])
    with pytest.raises(ValueError, match="outside"):
        Grid(2, 2, blocked=[(2, 0)])
    with pytest.raises(ValueError, match="positive"):
        Grid(2, 2, costs={(0, 0): 0})
