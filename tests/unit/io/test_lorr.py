"""LoRR problems read as the competition ships them, and every bad input named by file, line and reason."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from mrmp.core.errors import InputError
from mrmp.io.lorr import lorr_cell, lorr_location, read_lorr_problem
from mrmp.io.validate import validate_file

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "lorr"
PROBLEM = "maze-example_40.json"


@pytest.fixture
def copy(tmp_path: Path) -> Path:
    """A copy of the example problem's folder, to spoil."""
    folder = tmp_path / "lorr"
    shutil.copytree(EXAMPLE, folder)
    return folder


def test_the_example_is_read_as_the_start_kit_describes_it() -> None:
    problem = read_lorr_problem(EXAMPLE / PROBLEM)
    grid = problem.grid
    assert (problem.team_size, len(problem.starts), len(problem.tasks)) == (40, 40, 160)
    assert len(set(problem.starts)) == 40 and all(grid.is_free(cell) for cell in problem.starts)
    assert all(task and all(grid.is_free(cell) for cell in task) for task in problem.tasks)
    # locations: row * width + column, row 0 at the top, which is mrmp's northmost row
    lines = (EXAMPLE / "agents" / "maze-example_40.agents").read_text().split()
    assert [lorr_location(cell, grid) for cell in problem.starts] == [int(text) for text in lines[6:46]]  # after "# version for LoRR 2026" and "40"
    rows = (EXAMPLE / "maps" / "maze-32-32-2.map").read_text().splitlines()[4:]
    for location in (0, 31, 33, 1023):
        row, column = divmod(location, 32)
        assert grid.is_free(lorr_cell(location, grid)) == (rows[row][column] != "@")


def write(folder: Path, name: str, text: str) -> None:
    (folder / name).write_text(text, encoding="utf-8")


def problem_with(folder: Path, **changes: object) -> Path:
    data = json.loads((folder / PROBLEM).read_text())
    data.update(changes)
    for key in [key for key, value in changes.items() if value is None]:
        del data[key]
    write(folder, PROBLEM, json.dumps(data))
    return folder / PROBLEM


@pytest.mark.parametrize(
    ("spoil", "where", "reason"),
    [
        (lambda f: write(f, PROBLEM, "{ not json"), PROBLEM + ":1", "not valid JSON"),
        (lambda f: problem_with(f, teamSize=None), PROBLEM, "teamSize: missing"),
        (lambda f: problem_with(f, teamSize=0), PROBLEM, "teamSize: expected a whole number from 1"),
        (lambda f: problem_with(f, numTasksReveal=-1), PROBLEM, "numTasksReveal: expected a number above 0"),
        (lambda f: problem_with(f, mapFile="maps/none.map"), PROBLEM, "mapFile: no such file: maps/none.map"),
        (lambda f: problem_with(f, teamSize=41), "maze-example_40.agents", "40 agents for a teamSize of 41"),
        (lambda f: write(f, "agents/maze-example_40.agents", "40\n0\n" + "1005\n" * 39), "maze-example_40.agents:2",
         "location 0 (cell (31, 0)) is an obstacle"),
        (lambda f: write(f, "agents/maze-example_40.agents", "# v\n40\n" + "5000\n" * 40), "maze-example_40.agents:3",
         "location '5000' is not on the 32x32 map"),
        (lambda f: write(f, "agents/maze-example_40.agents", "40\n" + "1005\n" * 40), "maze-example_40.agents:3",
         "start 1005 is the start of the agent on line 2 too"),
        (lambda f: write(f, "tasks/maze-example_40.tasks", "1\n203,,453\n"), "maze-example_40.tasks:2",
         "expected errand locations separated by commas"),
        (lambda f: write(f, "tasks/maze-example_40.tasks", "many\n203\n"), "maze-example_40.tasks:1",
         "expected the number of tasks"),
        (lambda f: write(f, "tasks/maze-example_40.tasks", "3\n203\n"), "maze-example_40.tasks", "3 tasks announced, 1 given"),
    ],
)  # fmt: skip
def test_a_bad_problem_is_one_line_naming_file_line_and_reason(copy: Path, spoil, where: str, reason: str) -> None:
    spoil(copy)
    with pytest.raises(InputError) as caught:
        read_lorr_problem(copy / PROBLEM)
    problem = caught.value.problems[0]
    assert problem.where.endswith(where) and reason in problem.reason
    assert validate_file(copy / PROBLEM) == list(caught.value.problems)


def test_validate_accepts_the_example() -> None:
    assert validate_file(EXAMPLE / PROBLEM) == []
