"""A width/height map may list its obstacles; every bad entry is reported at its file and line."""

from __future__ import annotations

import pytest

from mrmp.core.errors import InputError
from mrmp.io.scenario_file import scenario_from_text, scenario_to_yaml

HEADER = "map:\n  width: 5\n  height: 4\n  obstacles:\n"


def problems(text: str) -> list[str]:
    with pytest.raises(InputError) as caught:
        scenario_from_text(text, "s.yaml")
    return [str(problem) for problem in caught.value.problems]


def test_obstacles_block_their_cells_and_round_trip_through_the_writer() -> None:
    text = HEADER + "    - [1, 1]\n    - [3, 4]\nrobots:\n  - {id: A, start: [0, 0], goal: [3, 3]}\n"
    scenario = scenario_from_text(text, "s.yaml")
    grid = scenario.grid
    assert (grid.x_size, grid.y_size) == (4, 5) and sorted(grid.blocked_cells()) == [(1, 1), (3, 4)]
    assert scenario_from_text(scenario_to_yaml(scenario), "s.yaml") == scenario
    assert grid.to_rows()[0] == "....@"  # x = 3 is the northmost row, y = 4 its east end


def test_an_empty_list_of_obstacles_is_an_empty_map() -> None:
    scenario = scenario_from_text(HEADER.replace("obstacles:\n", "obstacles: []\n") + "robots: [{id: A, start: [0, 0], goal: [1, 1]}]\n", "s")
    assert scenario.grid.blocked_cells() == []


def test_every_bad_entry_is_named_with_its_line() -> None:
    text = HEADER + "    - [1, 1]\n    - [1, 1]\n    - [4, 0]\n    - [2, x]\n    - [0, -1]\nrobots:\n  - {id: A, start: [0, 0], goal: [2, 2]}\n"
    assert problems(text) == [
        "s.yaml:6: map.obstacles[1]: cell (1, 1) is already map.obstacles[0]",
        "s.yaml:7: map.obstacles[2]: cell (4, 0) is outside the 4x5 map (x from 0 to 3, y from 0 to 4)",
        "s.yaml:8: map.obstacles[3]: expected a list of two integers [x, y], got [2, x]",
        "s.yaml:9: map.obstacles[4]: cell (0, -1) is outside the 4x5 map (x from 0 to 3, y from 0 to 4)",
    ]


def test_a_robot_on_an_obstacle_is_told_which_entry_blocks_it() -> None:
    text = HEADER + "    - [0, 0]\n    - [2, 2]\nrobots:\n  - {id: A, start: [0, 0], goal: [3, 3]}\n  - {id: B, start: [1, 0], goal: [2, 2]}\n"
    assert problems(text) == [
        "s.yaml:8: robots[0].start: cell (0, 0) is an obstacle (map.obstacles[0], line 5; cells are [x, y], x growing north)",
        "s.yaml:9: robots[1].goal: cell (2, 2) is an obstacle (map.obstacles[1], line 6; cells are [x, y], x growing north)",
    ]


@pytest.mark.parametrize("form", ['  rows: ["..", ".."]\n', "  file: x.map\n"])
def test_obstacles_go_with_width_and_height_only(form: str) -> None:
    text = "map:\n" + form + "  obstacles: [[0, 0]]\nrobots: [{id: A, start: [0, 0], goal: [1, 1]}]\n"
    assert problems(text)[0] == f"s.yaml:3: map.obstacles: goes with width and height; draw obstacles in the map's {'rows' if 'rows' in form else 'file'}"


def test_obstacles_must_be_a_list() -> None:
    text = HEADER.replace("obstacles:\n", "obstacles: 3\n") + "robots: [{id: A, start: [0, 0], goal: [1, 1]}]\n"
    assert problems(text)[0] == "s.yaml:4: map.obstacles: expected a list of cells [x, y], got a number 3"
