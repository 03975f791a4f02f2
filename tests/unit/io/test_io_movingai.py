"""MovingAI .map and .scen reading and writing: axes, round trips and every error kind."""

from __future__ import annotations

from pathlib import Path

import pytest

from mrmp.core import Grid, InputError, RobotSpec, manhattan
from mrmp.core.grid import cell_from_movingai
from mrmp.io.movingai import (
    map_to_text,
    parse_map,
    parse_scen,
    read_map,
    read_scen,
    read_scen_entries,
    scen_to_text,
    shortest_path_length,
    write_map,
    write_scen,
)

SCEN_FILES = sorted(path.name for path in (Path(__file__).resolve().parents[3] / "maps").glob("*.scen"))

TINY_MAP = "type octile\nheight 3\nwidth 4\nmap\n....\n.@..\n....\n"


def problems_of(error: pytest.ExceptionInfo[InputError]) -> list[tuple[str, str]]:
    """The (where, reason) pairs of a raised InputError."""
    return [(problem.where, problem.reason) for problem in error.value.problems]


def single_problem(error: pytest.ExceptionInfo[InputError]) -> tuple[str, str]:
    """The only problem of a raised InputError."""
    problems = problems_of(error)
    assert len(problems) == 1, problems
    return problems[0]


# -- reading real maps: the axis mapping -------------------------------------------------


def test_random_map_sizes_name_and_known_cells(maps_dir: Path) -> None:
    grid = read_map(maps_dir / "random-32-32-20.map")
    assert grid.name == "random-32-32-20"
    assert (grid.x_size, grid.y_size) == (32, 32)
    # Top row of the file is "..........@......@...@.@........": row 0 is the northmost x = 31.
    assert grid.is_blocked((31, 10))
    assert grid.is_free((31, 9))
    assert grid.is_blocked((31, 17))
    # Bottom row is "@@.............@..@.........@...": row 31 is x = 0.
    assert grid.is_blocked((0, 0)) and grid.is_blocked((0, 1))
    assert grid.is_free((0, 2))
    assert grid.is_blocked((0, 15))


def test_map_cells_follow_the_file_symbols(maps_dir: Path) -> None:
    path = maps_dir / "random-32-32-20.map"
    rows = path.read_text().splitlines()[4:]
    grid = read_map(path)
    for row, line in enumerate(rows):
        for column, symbol in enumerate(line):
            assert grid.is_blocked(cell_from_movingai(column, row, 32)) == (symbol in "@T")


def test_warehouse_is_not_square_and_trees_are_blocked(maps_dir: Path) -> None:
    grid = read_map(maps_dir / "warehouse-10-20-10-2-1.map")
    assert (grid.x_size, grid.y_size) == (63, 161)  # height 63 rows north-south, width 161 columns
    assert grid.is_blocked((62, 0))  # the top-left 'T'


def test_map_round_trip_keeps_the_text_up_to_obstacle_kind(maps_dir: Path, tmp_path: Path) -> None:
    original = maps_dir / "random-32-32-20.map"
    copy = tmp_path / "copy.map"
    write_map(copy, read_map(original))
    # Every blocked symbol (this map has a few trees 'T') is written back as '@'.
    assert copy.read_text() == original.read_text().replace("T", "@")
    assert read_map(copy) == read_map(original)


def test_map_round_trip_keeps_costs_and_shape(tmp_path: Path) -> None:
    grid = Grid.from_rows(["..@..", ".3...", "....9"], name="costly")
    write_map(tmp_path / "costly.map", grid)
    again = read_map(tmp_path / "costly.map")
    assert again == grid
    assert again.cost((1, 1)) == 3.0 and again.cost((0, 4)) == 9.0
    assert again.name == "costly"


def test_writing_a_fractional_cost_is_refused() -> None:
    with pytest.raises(ValueError, match=r"costs 2\.5"):
        map_to_text(Grid(2, 2, costs={(0, 0): 2.5}))


def test_crlf_map_and_trailing_blank_lines_are_accepted() -> None:
    grid = parse_map(TINY_MAP.replace("\n", "\r\n") + "\r\n\r\n", "tiny.map")
    assert (grid.x_size, grid.y_size) == (3, 4)
    assert grid.blocked_cells() == [(1, 1)]


# -- .map errors --------------------------------------------------------------------------


def test_bad_type_line() -> None:
    with pytest.raises(InputError) as error:
        parse_map(TINY_MAP.replace("type octile", "kind octile"), "t.map")
    where, reason = single_problem(error)
    assert where == "t.map:1"
    assert "bad header" in reason and "'type octile'" in reason


def test_unsupported_map_type() -> None:
    with pytest.raises(InputError) as error:
        parse_map(TINY_MAP.replace("octile", "hexagonal"), "t.map")
    assert single_problem(error) == ("t.map:1", "bad header: unsupported map type 'hexagonal', expected 'octile'")


def test_non_integer_height() -> None:
    with pytest.raises(InputError) as error:
        parse_map(TINY_MAP.replace("height 3", "height three"), "t.map")
    assert single_problem(error) == ("t.map:2", "bad header: height must be a positive integer, got 'three'")


def test_misspelt_header_line() -> None:
    with pytest.raises(InputError) as error:
        parse_map(TINY_MAP.replace("width 4", "widht 4"), "t.map")
    where, reason = single_problem(error)
    assert where == "t.map:3" and "expected 'height N', 'width N' or 'map'" in reason


def test_missing_map_line() -> None:
    with pytest.raises(InputError) as error:
        parse_map("type octile\nheight 1\nwidth 1\n", "t.map")
    assert single_problem(error) == ("t.map:3", "bad header: missing the 'map' line before the rows")


def test_missing_width() -> None:
    with pytest.raises(InputError) as error:
        parse_map("type octile\nheight 1\nmap\n.\n", "t.map")
    assert single_problem(error) == ("t.map:3", "bad header: missing 'width N' before 'map'")


def test_empty_map_file(make_file) -> None:
    path = make_file("empty.map", "")
    with pytest.raises(InputError) as error:
        read_map(path)
    where, reason = single_problem(error)
    assert where == f"{path}:1" and "empty" in reason


def test_wrong_row_length_names_its_line() -> None:
    with pytest.raises(InputError) as error:
        parse_map(TINY_MAP.replace(".@..", ".@."), "t.map")
    assert single_problem(error) == ("t.map:6", "map row 1 has 3 symbols, expected 4 (the header's width)")


def test_unknown_symbol_names_line_and_column() -> None:
    with pytest.raises(InputError) as error:
        parse_map(TINY_MAP.replace(".@..", ".@.x"), "t.map")
    where, reason = single_problem(error)
    assert where == "t.map:6"
    assert reason.startswith("map row 1, column 3: unknown symbol 'x'")


def test_every_bad_row_is_reported() -> None:
    with pytest.raises(InputError) as error:
        parse_map("type octile\nheight 3\nwidth 2\nmap\n.x\n...\n?.\n", "t.map")
    assert [where for where, _ in problems_of(error)] == ["t.map:5", "t.map:6", "t.map:7"]


def test_too_few_rows() -> None:
    with pytest.raises(InputError) as error:
        parse_map("type octile\nheight 3\nwidth 2\nmap\n..\n..\n", "t.map")
    assert single_problem(error) == ("t.map:6", "expected 3 map rows after 'map' (the header's height), found 2")


def test_too_many_rows() -> None:
    with pytest.raises(InputError) as error:
        parse_map("type octile\nheight 1\nwidth 2\nmap\n..\n..\n", "t.map")
    where, reason = single_problem(error)
    assert where == "t.map:6" and "extra line" in reason


def test_missing_file_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError) as error:
        read_map(tmp_path / "nowhere.map")
    assert single_problem(error) == (str(tmp_path / "nowhere.map"), "file not found")


def test_folder_instead_of_file_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError) as error:
        read_map(tmp_path)
    assert single_problem(error) == (str(tmp_path), "is a folder, not a file")


def test_binary_file_is_an_input_error_naming_the_line(tmp_path: Path) -> None:
    path = tmp_path / "binary.map"
    path.write_bytes(b"type octile\nheight 1\n\xff\xfe\n")
    with pytest.raises(InputError) as error:
        read_map(path)
    where, reason = single_problem(error)
    assert where == f"{path}:3" and "not a UTF-8 text file" in reason


# -- .scen ----------------------------------------------------------------------------------


def test_first_20_agents_of_random_32_32_20(maps_dir: Path) -> None:
    grid = read_map(maps_dir / "random-32-32-20.map")
    robots = read_scen(maps_dir / "random-32-32-20-random-1.scen", agents=20, grid=grid)
    assert [robot.id for robot in robots] == [str(index) for index in range(20)]
    # Line 2: start column 5, row 16; goal column 31, row 24 on a 32-row map.
    assert robots[0].start == (15, 5) and robots[0].goal == (7, 31)
    # Line 3: start column 21, row 29; goal column 24, row 22.
    assert robots[1].start == (2, 21) and robots[1].goal == (9, 24)
    assert all(grid.is_free(robot.start) and grid.is_free(robot.goal) for robot in robots)
    assert len({robot.start for robot in robots}) == 20


@pytest.mark.parametrize("scen_name", SCEN_FILES)
def test_every_agent_of_the_shipped_scen_files_is_on_free_cells(maps_dir: Path, scen_name: str) -> None:
    entries = read_scen_entries(maps_dir / scen_name)
    grid = read_map(maps_dir / entries[0].map_name)
    robots = read_scen(maps_dir / scen_name, grid=grid)
    assert len(robots) == len(entries) > 100
    assert all(grid.is_free(robot.start) and grid.is_free(robot.goal) for robot in robots)


def test_scen_entry_keeps_the_file_fields(maps_dir: Path) -> None:
    entry = read_scen_entries(maps_dir / "random-32-32-20-random-1.scen")[0]
    assert entry.line == 2
    assert entry.bucket == 7 and entry.map_name == "random-32-32-20.map"
    assert (entry.width, entry.height, entry.start, entry.goal) == (32, 32, (5, 16), (31, 24))
    assert entry.optimal_length == pytest.approx(31.3137085)


def test_scen_round_trip(maps_dir: Path, tmp_path: Path) -> None:
    grid = read_map(maps_dir / "random-32-32-20.map")
    robots = read_scen(maps_dir / "random-32-32-20-random-1.scen", agents=30, grid=grid)
    write_scen(tmp_path / "mine.scen", "random-32-32-20.map", grid, robots)
    assert read_scen(tmp_path / "mine.scen", grid=grid) == robots
    entries = read_scen_entries(tmp_path / "mine.scen")
    for entry, robot in zip(entries, robots, strict=True):
        assert entry.map_name == "random-32-32-20.map"
        assert entry.optimal_length == shortest_path_length(grid, robot.start, robot.goal)
        assert entry.optimal_length >= manhattan(robot.start, robot.goal)
        assert entry.bucket == int(entry.optimal_length) // 4


def test_written_optimal_length_is_the_bfs_length_around_walls(tmp_path: Path) -> None:
    grid = Grid.from_rows(["...", "@@.", "..."])
    robot = RobotSpec("A", (0, 0), (2, 0))  # must walk around the wall: 6 moves, manhattan says 2
    text = scen_to_text("w.map", grid, [robot])
    assert text.splitlines()[1].split("\t") == ["1", "w.map", "3", "3", "0", "2", "0", "0", "6.00000000"]


def test_unreachable_goal_cannot_be_written() -> None:
    grid = Grid.from_rows([".@."])
    with pytest.raises(InputError) as error:
        scen_to_text("w.map", grid, [RobotSpec("A", (0, 0), (0, 2))])
    where, reason = single_problem(error)
    assert where == "robots[0]" and "no path" in reason


def test_empty_map_optimal_length_is_manhattan(maps_dir: Path, tmp_path: Path) -> None:
    grid = read_map(maps_dir / "empty-32-32.map")
    robots = read_scen(maps_dir / "empty-32-32-random-1.scen", agents=10)
    write_scen(tmp_path / "e.scen", "empty-32-32.map", grid, robots)
    lengths = [entry.optimal_length for entry in read_scen_entries(tmp_path / "e.scen")]
    assert lengths == [manhattan(robot.start, robot.goal) for robot in robots]


# -- .scen errors -------------------------------------------------------------------------

GOOD_LINE = "0\tm.map\t4\t3\t0\t0\t3\t2\t5.0"


def test_scen_bad_header() -> None:
    with pytest.raises(InputError) as error:
        parse_scen("version 2\n" + GOOD_LINE + "\n", "m.scen")
    assert single_problem(error) == ("m.scen:1", "bad header: expected 'version 1', got 'version 2'")


def test_scen_empty_file() -> None:
    with pytest.raises(InputError) as error:
        parse_scen("", "m.scen")
    assert single_problem(error) == ("m.scen:1", "bad header: expected 'version 1', got an empty file")


def test_scen_wrong_number_of_fields() -> None:
    with pytest.raises(InputError) as error:
        parse_scen(f"version 1\n{GOOD_LINE}\n0\tm.map\t4\t3\t0\n", "m.scen")
    where, reason = single_problem(error)
    assert where == "m.scen:3" and reason.startswith("expected 9 tab-separated fields") and reason.endswith("found 5")


def test_scen_non_integer_field() -> None:
    with pytest.raises(InputError) as error:
        parse_scen(f"version 1\n{GOOD_LINE}\n\n0\tm.map\t4\t3\tone\t0\t3\t2\t5.0\n", "m.scen")
    assert single_problem(error) == ("m.scen:4", "field 5 (start column) must be an integer, got 'one'")


def test_scen_non_number_optimal_length() -> None:
    with pytest.raises(InputError) as error:
        parse_scen("version 1\n0\tm.map\t4\t3\t0\t0\t3\t2\tfar\n", "m.scen")
    assert single_problem(error) == ("m.scen:2", "field 9 (optimal length) must be a number, got 'far'")


def test_scen_cell_outside_its_declared_map() -> None:
    with pytest.raises(InputError) as error:
        parse_scen("version 1\n0\tm.map\t4\t3\t0\t0\t4\t2\t5.0\n", "m.scen")
    assert single_problem(error) == ("m.scen:2", "goal (column 4, row 2) is outside the 4x3 map (width x height)")


def test_scen_size_mismatch_with_map(maps_dir: Path) -> None:
    small = Grid(16, 16, name="small")
    path = maps_dir / "random-32-32-20-random-1.scen"
    with pytest.raises(InputError) as error:
        read_scen(path, agents=5, grid=small)
    where, reason = single_problem(error)
    assert where == f"{path}:2"
    assert reason.startswith("map size 32x32 (width x height) does not match map 'small', which is 16x16")
    assert "408 more lines" in reason


def test_scen_fewer_agents_than_asked(maps_dir: Path) -> None:
    path = maps_dir / "random-32-32-20-random-1.scen"
    with pytest.raises(InputError) as error:
        read_scen(path, agents=500)
    assert single_problem(error) == (f"{path}:410", "asked for 500 agents but the file lists only 409")


def test_scen_zero_agents_asked(maps_dir: Path) -> None:
    with pytest.raises(InputError) as error:
        read_scen(maps_dir / "random-32-32-20-random-1.scen", agents=0)
    assert "at least 1" in single_problem(error)[1]


def test_scen_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError) as error:
        read_scen(tmp_path / "none.scen", agents=1)
    assert single_problem(error) == (str(tmp_path / "none.scen"), "file not found")


def test_many_bad_lines_are_capped() -> None:
    text = "version 1\n" + "x\n" * 30
    with pytest.raises(InputError) as error:
        parse_scen(text, "m.scen")
    problems = problems_of(error)
    assert len(problems) == 21
    assert problems[-1] == ("m.scen", "10 more problems not shown")
