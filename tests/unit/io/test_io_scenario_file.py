"""The strict YAML scenario format: loading, writing back, and one test per problem kind."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from mrmp.core import (
    Grid,
    Heading,
    InputError,
    NetworkFaults,
    PolicyOptions,
    RobotSpec,
    Scenario,
    Timing,
)
from mrmp.io.scenario_file import (
    load_movingai_scenario,
    load_scenario,
    save_scenario,
    scenario_from_text,
    scenario_to_yaml,
)

SWAP = """\
name: thesis-swap
description: two robots swap the ends of a column
map:
  rows: [".....", ".....", "..@..", ".....", "....."]
robots:
  - id: A
    start: [0, 1]
    goal: [4, 1]
    heading: NORTH
  - id: 7
    start: [4, 1]
    goal: [0, 1]
    heading: 3
timing: {cell_time: 2.0, turn_time: 0.25}
network: {loss: 0.1, delay: "1..3", duplicate: 0.05, reorder: 0.2}
policy: {name: thesis, resolve: wait, heading_aware: true}
seed: 42
max_ticks: 100
"""


def problems(text: str, source: str = "s.yaml", **options: object) -> list[tuple[str, str]]:
    """The (where, reason) pairs raised when loading ``text``."""
    with pytest.raises(InputError) as error:
        scenario_from_text(text, source, **options)  # type: ignore[arg-type]
    return [(problem.where, problem.reason) for problem in error.value.problems]


def only_problem(text: str, source: str = "s.yaml", **options: object) -> tuple[str, str]:
    """The single problem raised when loading ``text``."""
    found = problems(text, source, **options)
    assert len(found) == 1, found
    return found[0]


MINIMAL = """\
map: {rows: ["...", "...", "..."]}
robots:
  - {id: A, start: [0, 0], goal: [2, 2]}
"""


# -- loading --------------------------------------------------------------------------------


def test_full_scenario_loads_every_field() -> None:
    scenario = scenario_from_text(SWAP, "examples/swap.yaml")
    assert scenario.name == "thesis-swap"
    assert scenario.description == "two robots swap the ends of a column"
    assert (scenario.grid.x_size, scenario.grid.y_size) == (5, 5)
    assert scenario.grid.blocked_cells() == [(2, 2)]
    assert scenario.robots == (
        RobotSpec("A", (0, 1), (4, 1), Heading.NORTH),
        RobotSpec("7", (4, 1), (0, 1), Heading.SOUTH),
    )
    assert scenario.timing == Timing(2.0, 0.25)
    assert scenario.network == NetworkFaults(loss=0.1, delay_min=1, delay_max=3, duplicate=0.05, reorder=0.2)
    assert scenario.policy == PolicyOptions("thesis", "wait", True)
    assert (scenario.seed, scenario.max_ticks) == (42, 100)


def test_defaults_and_name_from_file_stem() -> None:
    scenario = scenario_from_text(MINIMAL, "some/folder/corner.yaml")
    assert scenario.name == "corner"
    assert scenario.description == ""
    assert scenario.robots[0].heading is Heading.NORTH
    assert scenario.timing == Timing() and scenario.network == NetworkFaults() and scenario.policy == PolicyOptions()
    assert (scenario.seed, scenario.max_ticks) == (0, None)


def test_first_row_is_the_northmost() -> None:
    text = MINIMAL.replace('"...", "...", "..."', '"..@", "...", "@.."').replace(
        "[0, 0], goal: [2, 2]", "[0, 2], goal: [2, 0]"
    )
    scenario = scenario_from_text(text, "n.yaml")
    assert scenario.grid.is_blocked((2, 2))  # first row, last column: north-east corner
    assert scenario.grid.is_blocked((0, 0))  # last row, first column: south-west corner


def test_width_and_height_map() -> None:
    text = "map: {width: 7, height: 3}\nrobots: [{id: A, start: [2, 6], goal: [0, 0]}]\n"
    grid = scenario_from_text(text, "wh.yaml").grid
    assert (grid.x_size, grid.y_size) == (3, 7)
    assert grid.blocked_cells() == []


@pytest.mark.parametrize(
    ("delay", "expected"), [("2", (2, 2)), ('"1..4"', (1, 4)), ("[0, 3]", (0, 3)), ("1 .. 2", (1, 2))]
)
def test_delay_forms(delay: str, expected: tuple[int, int]) -> None:
    scenario = scenario_from_text(MINIMAL + f"network: {{delay: {delay}}}\n", "d.yaml")
    assert (scenario.network.delay_min, scenario.network.delay_max) == expected


def test_plain_exponent_numbers_are_numbers() -> None:
    scenario = scenario_from_text(MINIMAL + "network: {loss: 1e-3}\n", "e.yaml")
    assert scenario.network.loss == pytest.approx(0.001)


def test_map_file_is_relative_to_the_yaml_folder(maps_dir: Path, tmp_path: Path) -> None:
    (tmp_path / "maps").mkdir()
    shutil.copy(maps_dir / "random-32-32-20.map", tmp_path / "maps")
    path = tmp_path / "scenarios" / "on-random.yaml"
    path.parent.mkdir()
    path.write_text("map: {file: ../maps/random-32-32-20.map}\nrobots:\n  - {id: A, start: [15, 5], goal: [7, 31]}\n")
    scenario = load_scenario(path)
    assert scenario.grid.name == "random-32-32-20"
    assert scenario.grid.is_blocked((31, 10))
    assert scenario.name == "on-random"


def test_scen_and_agents_instead_of_robots(maps_dir: Path, tmp_path: Path) -> None:
    path = tmp_path / "bench.yaml"
    path.write_text(f"scen: {maps_dir / 'random-32-32-20-random-1.scen'}\nagents: 20\nseed: 3\n")
    scenario = load_scenario(path)
    assert len(scenario.robots) == 20
    assert scenario.robots[0] == RobotSpec("0", (15, 5), (7, 31))
    assert scenario.grid.name == "random-32-32-20"  # found next to the .scen file
    assert scenario.seed == 3


def test_known_policies_accepts_a_known_name() -> None:
    scenario = scenario_from_text(MINIMAL + "policy: {name: astar}\n", "p.yaml", known_policies=("thesis", "astar"))
    assert scenario.policy.name == "astar"


def test_load_movingai_scenario_first_20(maps_dir: Path) -> None:
    scenario = load_movingai_scenario(
        maps_dir / "random-32-32-20.map", maps_dir / "random-32-32-20-random-1.scen", agents=20
    )
    assert scenario.name == "random-32-32-20-random-1"
    assert [robot.id for robot in scenario.robots] == [str(index) for index in range(20)]
    assert scenario.robots[1] == RobotSpec("1", (2, 21), (9, 24))
    assert all(scenario.grid.is_free(robot.start) for robot in scenario.robots)


def test_load_movingai_scenario_fewer_agents(maps_dir: Path) -> None:
    scen = maps_dir / "maze-32-32-2-random-1.scen"
    with pytest.raises(InputError) as error:
        load_movingai_scenario(maps_dir / "maze-32-32-2.map", scen, agents=1000)
    assert [p.where for p in error.value.problems] == [f"{scen}:334"]
    assert "asked for 1000 agents but the file lists only 333" in error.value.problems[0].reason


def test_load_movingai_scenario_obstacle_names_the_scen_line(maps_dir: Path, tmp_path: Path) -> None:
    scen = tmp_path / "x.scen"
    # Agent 2 starts at column 0, row 31: the map's bottom-left '@', cell (0, 0).
    scen.write_text("version 1\n0\tm.map\t32\t32\t2\t31\t3\t31\t1\n0\tm.map\t32\t32\t0\t31\t5\t5\t1\n")
    with pytest.raises(InputError) as error:
        load_movingai_scenario(maps_dir / "random-32-32-20.map", scen, agents=2)
    assert [(p.where, p.reason) for p in error.value.problems] == [
        (f"{scen}:3", "robots[1].start: cell (0, 0) is an obstacle")
    ]


# -- writing ----------------------------------------------------------------------------------


def test_round_trip_of_the_full_example() -> None:
    scenario = scenario_from_text(SWAP, "swap.yaml")
    assert scenario_from_text(scenario_to_yaml(scenario), "other.yaml") == scenario


def test_round_trip_of_awkward_values(tmp_path: Path) -> None:
    scenario = Scenario(
        grid=Grid.from_rows(["..3@", "9...", "...."], name="awkward"),
        robots=(
            RobotSpec('we"ird: id', (0, 0), (2, 0), Heading.WEST),
            RobotSpec("123", (0, 3), (1, 1), Heading.EAST),
            RobotSpec("yes", (2, 1), (0, 1)),
        ),
        timing=Timing(cell_time=1e-05, turn_time=0.0),
        network=NetworkFaults(loss=0.3333333333333333, delay_min=2, delay_max=2, duplicate=1.0, reorder=0.0),
        policy=PolicyOptions("thesis", "divert", False),
        seed=-5,
        max_ticks=7,
        name="awk: ward # not a comment",
        description="line one\nline 'two'",
    )
    path = tmp_path / "awkward.yaml"
    save_scenario(scenario, path)
    loaded = load_scenario(path)
    assert loaded == scenario
    assert loaded.grid.cost((2, 2)) == 3.0


def test_writing_with_a_map_file(maps_dir: Path, tmp_path: Path) -> None:
    scenario = load_movingai_scenario(maps_dir / "room-32-32-4.map", maps_dir / "room-32-32-4-random-1.scen", 5)
    shutil.copy(maps_dir / "room-32-32-4.map", tmp_path)
    save_scenario(scenario, tmp_path / "room.yaml", map_file="room-32-32-4.map")
    assert 'file: "room-32-32-4.map"' in (tmp_path / "room.yaml").read_text()
    assert load_scenario(tmp_path / "room.yaml") == scenario


def test_fractional_costs_cannot_be_written() -> None:
    scenario = Scenario(Grid(2, 2, costs={(0, 0): 1.5}), (RobotSpec("A", (0, 1), (1, 1)),))
    with pytest.raises(ValueError, match=r"costs 1\.5"):
        scenario_to_yaml(scenario)


# -- problems: syntax and shape -------------------------------------------------------------


def test_yaml_syntax_error_names_its_line() -> None:
    where, reason = only_problem("map: {rows: ['...']}\nrobots:\n  - id: A\n    start: [0, 0\n    goal: [0, 2]\n")
    assert where.startswith("s.yaml:")
    assert int(where.split(":")[1]) in (5, 6)
    assert reason.startswith("invalid YAML:") and "started at line 4" in reason


def test_tab_indentation_is_a_yaml_error() -> None:
    where, reason = only_problem("map:\n\trows: ['.']\n")
    assert where == "s.yaml:2" and reason.startswith("invalid YAML:")


def test_empty_file(make_file) -> None:
    path = make_file("empty.yaml", "# only a comment\n")
    with pytest.raises(InputError) as error:
        load_scenario(path)
    assert [(p.where, p.reason) for p in error.value.problems] == [
        (f"{path}:1", "the file is empty: expected a mapping with map and robots")
    ]


def test_top_level_list() -> None:
    where, reason = only_problem("- map\n- robots\n")
    assert where == "s.yaml:1" and "top level must be a mapping" in reason and "got a list" in reason


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError) as error:
        load_scenario(tmp_path / "absent.yaml")
    assert str(error.value) == f"{tmp_path / 'absent.yaml'}: file not found"


# -- problems: keys ------------------------------------------------------------------------------


def test_unknown_top_level_key() -> None:
    assert only_problem(MINIMAL + "sed: 4\n") == ("s.yaml:4", "unknown key 'sed' (did you mean 'seed'?)")


def test_unknown_nested_key() -> None:
    assert only_problem(MINIMAL + "timing:\n  cell_tim: 1.0\n") == (
        "s.yaml:5",
        "timing: unknown key 'cell_tim' (did you mean 'cell_time'?)",
    )


def test_unknown_robot_key_without_close_match() -> None:
    where, reason = only_problem(MINIMAL.replace("goal: [2, 2]}", "goal: [2, 2], colour: red}"))
    assert where == "s.yaml:3"
    assert reason == "robots[0]: unknown key 'colour' (allowed: id, start, goal, heading)"


def test_duplicate_key() -> None:
    assert only_problem(MINIMAL + "seed: 1\nseed: 2\n") == ("s.yaml:5", "key 'seed' is given twice (first at line 4)")


def test_missing_robots() -> None:
    assert only_problem('map: {rows: ["..."]}\n') == ("s.yaml:1", "missing required key 'robots'")


def test_missing_robot_goal() -> None:
    text = 'map: {rows: ["..."]}\nrobots:\n  - id: A\n    start: [0, 0]\n'
    assert only_problem(text) == ("s.yaml:3", "robots[0]: missing required key 'goal'")


def test_rows_and_file_together() -> None:
    text = 'map:\n  rows: ["..."]\n  file: x.map\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\n'
    assert only_problem(text) == (
        "s.yaml:2",
        "map: give exactly one of rows, file, or width and height; got rows and file",
    )


def test_width_without_height() -> None:
    text = "map: {width: 3}\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\n"
    assert only_problem(text) == ("s.yaml:1", "map: missing required key 'height' (width and height go together)")


def test_agents_without_scen() -> None:
    assert only_problem(MINIMAL + "agents: 3\n") == ("s.yaml:4", "agents: only allowed together with scen")


def test_scen_without_agents(maps_dir: Path) -> None:
    text = f"scen: {maps_dir / 'random-32-32-20-random-1.scen'}\n"
    assert only_problem(text) == ("s.yaml:1", "scen: needs agents: N next to it")


# -- problems: types -------------------------------------------------------------------------------


def test_start_not_two_integers() -> None:
    assert only_problem(MINIMAL.replace("start: [0, 0]", "start: [0]")) == (
        "s.yaml:3",
        "robots[0].start: expected a list of two integers [x, y], got a list of 1 items",
    )


def test_start_with_a_float() -> None:
    where, reason = only_problem(MINIMAL.replace("start: [0, 0]", "start: [0, 1.5]"))
    assert where == "s.yaml:3" and reason == "robots[0].start: expected a list of two integers [x, y], got [0, 1.5]"


def test_boolean_where_an_integer_is_expected() -> None:
    assert only_problem(MINIMAL + "seed: true\n") == ("s.yaml:4", "seed: expected an integer, got a boolean 'true'")


def test_string_where_a_number_is_expected() -> None:
    assert only_problem(MINIMAL + "timing:\n  turn_time: slow\n") == (
        "s.yaml:5",
        "timing.turn_time: expected a number, got a string 'slow'",
    )


def test_quoted_number_is_not_a_number() -> None:
    where, reason = only_problem(MINIMAL + "network: {loss: '0.5'}\n")
    assert where == "s.yaml:4" and reason == "network.loss: expected a number, got a string '0.5'"


def test_bad_heading() -> None:
    where, reason = only_problem(MINIMAL.replace("goal: [2, 2]}", "goal: [2, 2], heading: UP}"))
    assert where == "s.yaml:3" and reason.startswith("robots[0].heading: unknown heading a string 'UP'")


def test_bad_delay_text() -> None:
    where, reason = only_problem(MINIMAL + "network:\n  delay: soon\n")
    assert where == "s.yaml:5" and reason.startswith("network.delay: expected ticks as N")


def test_yaml_boolean_id_must_be_quoted() -> None:
    where, reason = only_problem(MINIMAL.replace("id: A", "id: no"))
    assert where == "s.yaml:3" and "got a boolean 'no' (quote it)" in reason


def test_map_row_of_wrong_length() -> None:
    text = 'map:\n  rows:\n    - "..."\n    - ".."\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\n'
    assert only_problem(text) == ("s.yaml:4", "map.rows[1]: has 2 symbols, expected 3 like map.rows[0]")


def test_map_row_with_unknown_symbol() -> None:
    text = 'map:\n  rows:\n    - "..."\n    - ".x."\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\n'
    where, reason = only_problem(text)
    assert where == "s.yaml:4" and reason.startswith("map.rows[1]: column 1: unknown symbol 'x'")


# -- problems: referenced files -----------------------------------------------------------------


def test_missing_map_file(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    path.write_text("robots: [{id: A, start: [0, 0], goal: [0, 1]}]\nmap:\n  file: nothere.map\n")
    with pytest.raises(InputError) as error:
        load_scenario(path)
    assert [(p.where, p.reason) for p in error.value.problems] == [
        (f"{path}:3", f"map.file: map file not found: {tmp_path / 'nothere.map'}")
    ]


def test_malformed_map_file_propagates_its_line(tmp_path: Path) -> None:
    (tmp_path / "bad.map").write_text("type octile\nheight 2\nwidth 2\nmap\n..\n.?\n")
    path = tmp_path / "s.yaml"
    path.write_text("map: {file: bad.map}\nrobots: [{id: A, start: [0, 0], goal: [0, 1]}]\n")
    with pytest.raises(InputError) as error:
        load_scenario(path)
    (problem,) = error.value.problems
    assert problem.where == f"{tmp_path / 'bad.map'}:6" and "unknown symbol '?'" in problem.reason


def test_scen_naming_a_missing_map(tmp_path: Path) -> None:
    (tmp_path / "a.scen").write_text("version 1\n0\tgone.map\t2\t2\t0\t0\t1\t1\t2\n")
    path = tmp_path / "s.yaml"
    path.write_text("scen: a.scen\nagents: 1\n")
    with pytest.raises(InputError) as error:
        load_scenario(path)
    (problem,) = error.value.problems
    assert problem.where == f"{path}:1" and "map file 'gone.map' named by" in problem.reason


def test_scen_problems_point_at_the_scen_lines(maps_dir: Path, tmp_path: Path) -> None:
    shutil.copy(maps_dir / "random-32-32-20.map", tmp_path / "m.map")
    (tmp_path / "a.scen").write_text("version 1\n0\tm.map\t32\t32\t2\t31\t3\t31\t1\n0\tm.map\t32\t32\t2\t0\t0\t31\t1\n")
    path = tmp_path / "s.yaml"
    path.write_text("scen: a.scen\nagents: 2\n")
    with pytest.raises(InputError) as error:
        load_scenario(path)
    assert [(p.where, p.reason) for p in error.value.problems] == [
        (f"{tmp_path / 'a.scen'}:3", "robots[1].goal: cell (0, 0) is an obstacle")
    ]


# -- problems: meaning, placed at the field's line ----------------------------------------


def test_start_on_an_obstacle_names_the_start_line() -> None:
    text = SWAP.replace("start: [4, 1]", "start: [2, 2]")
    assert only_problem(text) == ("s.yaml:11", "robots[1].start: cell (2, 2) is an obstacle")


def test_goal_outside_the_grid_names_the_goal_line() -> None:
    text = SWAP.replace("goal: [4, 1]", "goal: [5, 1]")
    assert only_problem(text) == ("s.yaml:8", "robots[0].goal: cell (5, 1) is outside the 5x5 grid")


def test_negative_cell_time_names_the_timing_line() -> None:
    text = SWAP.replace("cell_time: 2.0", "cell_time: -2.0")
    assert only_problem(text) == ("s.yaml:14", "timing.cell_time: must be positive, got -2.0")


def test_bad_delay_range_names_the_network_line() -> None:
    text = SWAP.replace('delay: "1..3"', "delay: [3, 1]")
    assert only_problem(text) == ("s.yaml:15", "network.delay: must be a range 0 <= min <= max ticks, got 3..1")


def test_duplicate_ids() -> None:
    text = SWAP.replace("id: 7", "id: A")
    assert only_problem(text) == ("s.yaml:10", "robots[1].id: id 'A' is already used by robots[0]")


def test_non_positive_max_ticks() -> None:
    assert only_problem(SWAP.replace("max_ticks: 100", "max_ticks: 0")) == (
        "s.yaml:18",
        "max_ticks: must be positive, got 0",
    )


def test_unknown_policy_lists_the_known_ones() -> None:
    where, reason = only_problem(SWAP, known_policies=("greedy", "astar"))
    assert where == "s.yaml:16"
    assert reason == "policy.name: unknown policy 'thesis'; known policies: greedy, astar"


def test_unreachable_goal() -> None:
    text = 'map: {rows: [".@."]}\nrobots:\n  - id: A\n    start: [0, 0]\n    goal: [0, 2]\n'
    assert only_problem(text) == ("s.yaml:5", "robots[0].goal: cell (0, 2) cannot be reached from start (0, 0)")


def test_indices_stay_right_when_an_earlier_robot_is_malformed() -> None:
    text = """\
map: {rows: ["....."]}
robots:
  - {id: A, start: oops, goal: [0, 4]}
  - {id: B, start: [0, 1], goal: [0, 2]}
  - {id: C, start: [0, 1], goal: [0, 3]}
"""
    assert problems(text) == [
        ("s.yaml:3", "robots[0].start: expected a list of two integers [x, y], got a string 'oops'"),
        ("s.yaml:5", "robots[2].start: cell (0, 1) is also the start of robots[1]"),
    ]


def test_all_problems_are_collected_in_line_order() -> None:
    text = """\
name: many
map: {rows: ["...", "..."]}
robots:
  - {id: A, start: [0, 0], goal: [5, 5]}
timing: {cell_time: 0}
network: {loss: 1.5, jitter: 2}
seed: yes
"""
    assert problems(text) == [
        ("s.yaml:4", "robots[0].goal: cell (5, 5) is outside the 2x3 grid"),
        ("s.yaml:5", "timing.cell_time: must be positive, got 0.0"),
        ("s.yaml:6", "network: unknown key 'jitter' (allowed: loss, delay, duplicate, reorder, links)"),
        ("s.yaml:6", "network.loss: must be a probability in [0, 1], got 1.5"),
        ("s.yaml:7", "seed: expected an integer, got a boolean 'yes'"),
    ]


def test_error_message_is_one_line_per_problem() -> None:
    with pytest.raises(InputError) as error:
        scenario_from_text(MINIMAL + "sed: 1\nmax_tick: 3\n", "x.yaml")
    assert str(error.value).splitlines() == [
        "x.yaml:4: unknown key 'sed' (did you mean 'seed'?)",
        "x.yaml:5: unknown key 'max_tick' (did you mean 'max_ticks'?)",
    ]


LINKED = """\
map: {width: 5, height: 5}
robots:
  - {id: A, start: [0, 2], goal: [4, 2]}
  - {id: B, start: [4, 2], goal: [0, 2]}
network:
  delay: 1
  links:
    - {from: A, to: B, loss: 1.0}
    - {from: B, to: Z, delay: "0..2"}
    - {to: A}
"""


def test_links_inherit_network_faults_and_name_bad_robots() -> None:
    found = problems(LINKED)
    assert ("s.yaml:10", "network.links[2]: missing required key 'from'") in found
    assert ("s.yaml:9", "network.links[1].to: no robot has the id 'Z'") in found
    fixed = LINKED.replace("to: Z", "to: A").replace("    - {to: A}\n", "")
    scenario = scenario_from_text(fixed, "s.yaml")
    first, second = scenario.links
    assert (first.sender, first.recipient, first.faults.loss, first.faults.delay_max) == ("A", "B", 1.0, 1)
    assert (second.faults.delay_min, second.faults.delay_max, second.faults.loss) == (0, 2, 0.0)
    assert scenario_from_text(scenario_to_yaml(scenario), "t.yaml").links == scenario.links
