"""Problems of the League of Robot Runners (LoRR), read as they are: the problem JSON, its map, agents and tasks.

A LoRR problem (MAPF-Competition/Start-Kit, ``Input_Output_Format.md``; Chan
et al., "The League of Robot Runners", ICAPS 2024 demo track) is a JSON file
naming, relative to its own folder:

* ``mapFile``: a grid in the MovingAI format (``type octile``, ``height``,
  ``width``, ``map``, then the rows, the top one first); ``@`` and ``T`` are
  obstacles, ``.``, ``E`` (emitter) and ``S`` (service point) free;
* ``agentFile``: the number of robots, then one start location per line;
* ``taskFile``: the number of tasks, then one task per line: its errands'
  locations, comma-separated, to be visited in order;

and ``teamSize`` (robots), ``numTasksReveal`` (tasks kept revealed per robot),
and optionally ``agentSize``, ``agentCounter`` (ticks per action),
``delayConfig`` and ``version``. A location is ``row * width + column``, row 0
at the top; in mrmp's axes (x north, y east; ``docs/thesis.md``, "Axes") that
is cell ``(height - 1 - row, column)``. Lines that begin with ``#`` (the
files' version notes) are skipped. Every problem of a file is reported as
``file:line: reason``.

Examples
--------
>>> problem = read_lorr_problem("examples/lorr/maze-example_40.json")
>>> problem.team_size, len(problem.starts), len(problem.tasks), problem.grid.x_size, problem.tasks_reveal
(40, 40, 160, 32, 1.5)
>>> problem.starts[0], lorr_location(problem.starts[0], problem.grid)   # location 1005: row 31 (the bottom), column 13
((0, 13), 1005)
>>> problem.tasks[0], problem.agent_counter, problem.version
(((25, 11), (17, 5)), 3, '2026 LoRR')
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.limits import MAX_ROBOTS
from mrmp.core.scenario import PolicyOptions, RobotSpec, Scenario
from mrmp.core.tasks import TaskStream
from mrmp.io._files import PathLike, read_text
from mrmp.io.movingai import parse_map

__all__ = [
    "LORR_HEADING",
    "LORR_STEPS",
    "MAX_TASKS",
    "LorrProblem",
    "is_lorr_problem",
    "load_lorr_scenario",
    "lorr_cell",
    "lorr_location",
    "lorr_scenario",
    "read_lorr_problem",
]

MAX_TASKS = 1_000_000
"""The most tasks a task file may hold (read before any work starts)."""
MAX_REVEAL = 100.0
"""The largest ``numTasksReveal`` accepted (tasks revealed per robot)."""
_REQUIRED = ("mapFile", "agentFile", "taskFile", "teamSize", "numTasksReveal")


@dataclass(frozen=True)
class LorrProblem:
    """One LoRR problem (module docstring), its locations as mrmp cells.

    Attributes
    ----------
    name:
        The problem file's name without ``.json``.
    grid:
        The map (``E`` and ``S`` free).
    starts:
        The first ``team_size`` start cells of the agents file.
    tasks:
        Every task, as the cells of its errands in order.
    team_size, tasks_reveal:
        ``teamSize`` and ``numTasksReveal``.
    agent_counter, agent_size:
        ``agentCounter`` (ticks per action; 1 when absent) and ``agentSize`` (1.0 when absent).
    version:
        ``version``, when given.
    source:
        The problem file.
    """

    name: str
    grid: Grid
    starts: tuple[Cell, ...]
    tasks: tuple[tuple[Cell, ...], ...]
    team_size: int
    tasks_reveal: float
    agent_counter: int = 1
    agent_size: float = 1.0
    version: str | None = None
    source: str = ""

    def with_team(self, team_size: int) -> LorrProblem:
        """The same problem for its first ``team_size`` robots, as if its ``teamSize`` said so (tasks revealed
        ``numTasksReveal x team_size`` at a time).

        >>> problem = read_lorr_problem("examples/lorr/maze-example_40.json").with_team(10)
        >>> problem.team_size, len(problem.starts)
        (10, 10)
        """
        if not 1 <= team_size <= self.team_size:
            raise ValueError(f"{self.name} has {self.team_size} robots; cannot keep {team_size}")
        return replace(self, starts=self.starts[:team_size], team_size=team_size)


def lorr_cell(location: int, grid: Grid) -> Cell:
    """The mrmp cell of LoRR location ``location`` (``row * width + column``, row 0 at the top).

    >>> lorr_cell(0, Grid(4, 3)), lorr_cell(5, Grid(4, 3))
    ((3, 0), (2, 2))
    """
    row, column = divmod(location, grid.y_size)
    return (grid.x_size - 1 - row, column)


def lorr_location(cell: Cell, grid: Grid) -> int:
    """The LoRR location of an mrmp cell (the inverse of :func:`lorr_cell`).

    >>> lorr_location((2, 2), Grid(4, 3))
    5
    """
    x, y = cell
    return (grid.x_size - 1 - x) * grid.y_size + y


def read_lorr_problem(path: PathLike) -> LorrProblem:
    """Read a LoRR problem JSON and the files it names (module docstring).

    Raises
    ------
    InputError
        Naming ``file:line`` and the reason for every problem found: bad JSON, a
        missing or mistyped field, a file that is not there, a location off the
        map or on an obstacle, two robots on one start, fewer agents than
        ``teamSize``, a task without errands.
    """
    source = Path(path)
    data = _problem_json(source)
    folder = source.parent
    team_size = _whole(data, "teamSize", source, 1, MAX_ROBOTS)
    reveal = _number(data, "numTasksReveal", source, MAX_REVEAL)
    agent_counter = _whole(data, "agentCounter", source, 1, 10_000) if "agentCounter" in data else 1
    agent_size = _number(data, "agentSize", source, 100.0) if "agentSize" in data else 1.0
    version = data.get("version")
    if version is not None and not isinstance(version, str):
        raise InputError(Problem(str(source), f"version: expected text, got {version!r}"))
    files = {field: _named_file(data, field, source, folder) for field in ("mapFile", "agentFile", "taskFile")}
    grid = _lorr_map(files["mapFile"])
    starts = _agents(files["agentFile"], grid, team_size)
    tasks = _tasks(files["taskFile"], grid)
    return LorrProblem(source.stem, grid, starts, tasks, team_size, reveal, agent_counter, agent_size, version, str(source))


# -- the problem file ------------------------------------------------------------------------------


def _problem_json(source: Path) -> dict[str, Any]:
    text = read_text(source)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise InputError(Problem(f"{source}:{error.lineno}", f"not valid JSON ({error.msg})")) from None
    if not isinstance(data, dict):
        raise InputError(Problem(str(source), "expected a JSON object with mapFile, agentFile, taskFile, teamSize, ..."))
    missing = [field for field in _REQUIRED if field not in data]
    if missing:
        raise InputError([Problem(str(source), f"{field}: missing (a LoRR problem names it)") for field in missing])
    return data


def _whole(data: dict[str, Any], field: str, source: Path, least: int, most: int) -> int:
    value = data[field]
    if isinstance(value, bool) or not isinstance(value, int) or not least <= value <= most:
        raise InputError(Problem(str(source), f"{field}: expected a whole number from {least} to {most}, got {value!r}"))
    return value


def _number(data: dict[str, Any], field: str, source: Path, most: float) -> float:
    value = data[field]
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0 < value <= most or not math.isfinite(value):
        raise InputError(Problem(str(source), f"{field}: expected a number above 0 and at most {most:g}, got {value!r}"))
    return float(value)


def _named_file(data: dict[str, Any], field: str, source: Path, folder: Path) -> Path:
    value = data[field]
    if not isinstance(value, str) or not value:
        raise InputError(Problem(str(source), f"{field}: expected a file name, got {value!r}"))
    file = folder / value
    if not file.is_file():
        raise InputError(Problem(str(source), f"{field}: no such file: {value} (looked in {folder})"))
    return file


# -- the map, agents and tasks files ---------------------------------------------------------------


def _lorr_map(file: Path) -> Grid:
    """A LoRR map: MovingAI's format, with emitter (``E``) cells free."""
    text = read_text(file)
    return parse_map(text.replace("E", "."), str(file), name=file.stem)


def _lines(file: Path) -> list[tuple[int, str]]:
    """The lines of ``file`` that carry data, numbered from 1 (``#`` lines and blank lines skipped)."""
    return [
        (number, line.strip())
        for number, line in enumerate(read_text(file).splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]


def _count(lines: list[tuple[int, str]], file: Path, what: str, most: int) -> int:
    if not lines:
        raise InputError(Problem(str(file), f"empty: expected the number of {what} first"))
    number, text = lines[0]
    if not text.isdigit() or not 1 <= int(text) <= most:
        raise InputError(Problem(f"{file}:{number}", f"expected the number of {what} (1 to {most}), got {text!r}"))
    count = int(text)
    if len(lines) - 1 < count:
        raise InputError(Problem(str(file), f"{count} {what} announced, {len(lines) - 1} given"))
    return count


def _location(text: str, grid: Grid, where: str) -> Cell:
    size = grid.x_size * grid.y_size
    if not text.isdigit() or int(text) >= size:
        raise InputError(Problem(where, f"location {text!r} is not on the {grid.y_size}x{grid.x_size} map (0 to {size - 1})"))
    cell = lorr_cell(int(text), grid)
    if not grid.is_free(cell):
        raise InputError(Problem(where, f"location {text} (cell {cell}) is an obstacle"))
    return cell


def _agents(file: Path, grid: Grid, team_size: int) -> tuple[Cell, ...]:
    lines = _lines(file)
    count = _count(lines, file, "agents", MAX_ROBOTS)
    if count < team_size:
        raise InputError(Problem(str(file), f"{count} agents for a teamSize of {team_size}"))
    starts: list[Cell] = []
    taken: dict[Cell, int] = {}
    for number, text in lines[1 : team_size + 1]:
        cell = _location(text, grid, f"{file}:{number}")
        if cell in taken:
            raise InputError(Problem(f"{file}:{number}", f"start {text} is the start of the agent on line {taken[cell]} too"))
        taken[cell] = number
        starts.append(cell)
    return tuple(starts)


def _tasks(file: Path, grid: Grid) -> tuple[tuple[Cell, ...], ...]:
    lines = _lines(file)
    count = _count(lines, file, "tasks", MAX_TASKS)
    tasks: list[tuple[Cell, ...]] = []
    for number, text in lines[1 : count + 1]:
        where = f"{file}:{number}"
        errands = [part.strip() for part in text.split(",")]
        if not errands or any(not part for part in errands):
            raise InputError(Problem(where, f"expected errand locations separated by commas, got {text!r}"))
        tasks.append(tuple(_location(part, grid, where) for part in errands))
    return tuple(tasks)


LORR_STEPS = 5000
"""The steps a LoRR run lasts when not told (the Start-Kit's ``--simulationTime`` default)."""
LORR_HEADING = Heading.EAST
"""Where every LoRR robot faces at the start (the Start-Kit's orientation 0: toward the next column)."""


def lorr_scenario(problem: LorrProblem, steps: int = LORR_STEPS) -> Scenario:
    """A lifelong mrmp scenario of ``problem``: its robots on their starts facing east, its task stream, ``steps`` ticks.

    The robots compute ``pibt`` by messages in the ``turning`` body (LoRR's
    ``MAPF_T``), ordering their calls themselves (``sequencing: local``, the
    default of ``pibt``), their tables guided by the crisscross lanes
    (``guidance: crisscross``, :mod:`mrmp.search.guidance`); every
    robot's goal is its start until the scheduler gives it a task. One tick is
    one LoRR action (the 2024 rules; a 2026 problem's ``agentCounter``
    execution ticks per action are not simulated).

    >>> scenario = lorr_scenario(read_lorr_problem("examples/lorr/maze-example_40.json"), steps=100)
    >>> scenario.max_ticks, scenario.tasks.reveal, scenario.policy.body, scenario.robots[0].heading.name
    (100, 60, 'turning', 'EAST')
    """
    robots = tuple(RobotSpec(str(index), start, start, LORR_HEADING) for index, start in enumerate(problem.starts))
    stream = TaskStream(problem.tasks, reveal=max(1, int(problem.tasks_reveal * problem.team_size)))
    return Scenario(
        problem.grid,
        robots,
        policy=PolicyOptions(name="pibt", body="turning", sequencing="local", guidance="crisscross"),
        lifelong=True,
        tasks=stream,
        max_ticks=steps,
        name=problem.name,
        description=f"League of Robot Runners problem {problem.source}",
    )


def load_lorr_scenario(path: PathLike, steps: int = LORR_STEPS) -> Scenario:
    """:func:`lorr_scenario` of the LoRR problem file ``path`` (its errors as :func:`read_lorr_problem`'s)."""
    return lorr_scenario(read_lorr_problem(path), steps)


def is_lorr_problem(path: PathLike) -> bool:
    """Whether ``path`` names a LoRR problem (a ``.json`` file), not a YAML scenario."""
    return Path(path).suffix.lower() == ".json"
