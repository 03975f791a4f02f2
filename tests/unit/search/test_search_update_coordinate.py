"""The thesis's update-coordinate method (sections 3.1 item 4, 3.2 assumption 2)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrmp.core.errors import NoPathError
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.search import path_cost, update_coordinate_cells, update_coordinate_path

THESIS_PATH = ((0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (4, 2), (4, 3), (4, 4))


def test_thesis_example_goes_x_first_then_y() -> None:
    result = update_coordinate_path(Grid(5, 5), (0, 0), (4, 4))
    assert result.path == THESIS_PATH
    assert result.cost == 8.0
    assert result.expansions == len(THESIS_PATH)
    assert result.headings is None


def test_decreasing_coordinates() -> None:
    assert update_coordinate_path(Grid(5, 5), (4, 4), (2, 1)).path == ((4, 4), (3, 4), (2, 4), (2, 3), (2, 2), (2, 1))


def test_start_is_goal() -> None:
    result = update_coordinate_path(Grid(3, 3), (1, 1), (1, 1))
    assert result.path == ((1, 1),)
    assert result.cost == 0.0
    assert result.expansions == 1


def test_obstacle_on_the_l_names_the_cell() -> None:
    grid = Grid(5, 5, blocked=[(4, 2)])
    with pytest.raises(NoPathError, match=r"\(4, 2\)"):
        update_coordinate_path(grid, (0, 0), (4, 4))


def test_obstacle_off_the_l_is_ignored() -> None:
    grid = Grid(5, 5, blocked=[(1, 1), (0, 4)])
    assert update_coordinate_path(grid, (0, 0), (4, 4)).path == THESIS_PATH


def test_blocked_extras_stop_the_path_but_not_the_start() -> None:
    with pytest.raises(NoPathError, match=r"\(3, 0\)"):
        update_coordinate_path(Grid(5, 5), (0, 0), (4, 4), blocked={(3, 0)})
    assert update_coordinate_path(Grid(5, 5), (0, 0), (4, 4), blocked={(0, 0)}).path == THESIS_PATH


def test_unusable_ends() -> None:
    grid = Grid(3, 3, blocked=[(2, 2)])
    with pytest.raises(NoPathError, match="goal"):
        update_coordinate_path(grid, (0, 0), (2, 2))
    with pytest.raises(NoPathError, match="start"):
        update_coordinate_path(grid, (2, 2), (0, 0))
    with pytest.raises(NoPathError, match="goal"):
        update_coordinate_path(grid, (0, 0), (5, 5))
    with pytest.raises(NoPathError, match="blocked"):
        update_coordinate_path(Grid(3, 3), (0, 0), (1, 1), blocked=[(1, 1)])


def test_heading_aware_cost_and_headings() -> None:
    timing = Timing(cell_time=2.0, turn_time=0.25)
    result = update_coordinate_path(Grid(5, 5), (0, 0), (4, 4), heading=Heading.NORTH, timing=timing)
    assert result.path == THESIS_PATH
    assert result.headings == (Heading.NORTH,) * 5 + (Heading.EAST,) * 4
    assert result.cost == pytest.approx(8 * 2.0 + 1 * 0.25)
    # facing EAST the robot needs three right turns to face NORTH first
    east = update_coordinate_path(Grid(5, 5), (0, 0), (4, 4), heading=Heading.EAST, timing=timing)
    assert east.cost == pytest.approx(8 * 2.0 + 4 * 0.25)


def test_costs_are_summed() -> None:
    grid = Grid(5, 5, costs={(2, 0): 3.0, (4, 4): 2.0, (0, 0): 9.0})
    result = update_coordinate_path(grid, (0, 0), (4, 4))
    assert result.cost == 8.0 + 2.0 + 1.0  # the start's cost is never paid


@settings(max_examples=60, derandomize=True, deadline=None)
@given(
    st.integers(1, 9),
    st.integers(1, 9),
    st.data(),
)
def test_l_shape_property(x_size: int, y_size: int, data: st.DataObject) -> None:
    grid = Grid(x_size, y_size)
    start = (data.draw(st.integers(0, x_size - 1)), data.draw(st.integers(0, y_size - 1)))
    goal = (data.draw(st.integers(0, x_size - 1)), data.draw(st.integers(0, y_size - 1)))
    result = update_coordinate_path(grid, start, goal)
    path = result.path
    assert path == update_coordinate_cells(start, goal)
    assert path[0] == start and path[-1] == goal
    assert len(path) == abs(start[0] - goal[0]) + abs(start[1] - goal[1]) + 1
    corner = path.index((goal[0], start[1]))
    assert all(cell[1] == start[1] for cell in path[: corner + 1])  # x changes first
    assert all(cell[0] == goal[0] for cell in path[corner:])  # then y
    assert result.cost == path_cost(grid, path)
