"""What a centralized planner returns: :class:`PlanningResult`, and helpers on plans.

A centralized planner (CBS, prioritized planning, LaCAM) computes every robot's
whole path at once, before anything moves. Its answer is a
:class:`PlanningResult`: a status, the paths (one cell per tick, tick 0 first,
one path per robot in scenario order, all padded to the same length with
robots waiting at their goals) and a few counters.

Costs follow the standard MAPF definitions (Stern et al., "Multi-Agent
Pathfinding: Definitions, Variants, and Benchmarks", SoCS 2019): a robot's cost
is the first tick from which it stays at its goal until the end of the plan;
the *sum of costs* adds them, the *makespan* is the largest. Time is counted in
ticks (one move or one wait per tick; with heading-aware planning a right turn
in place also takes one tick); the entry costs of cells do not count.

Examples
--------
>>> result = PlanningResult(
...     status="solved",
...     paths=pad_paths([[(0, 0), (0, 1), (0, 2)], [(1, 0)]]),
...     planning_time_s=0.01,
...     planner="cbs",
... )
>>> result.solved, result.sum_of_costs(), result.makespan()
(True, 2, 2)
>>> result.paths[1]
((1, 0), (1, 0), (1, 0))
>>> plan_size_bytes(result)
48
>>> PlanningResult("limit", None, 0.2, "cbs", message="node limit 50 reached").solved
False
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.errors import InputError, Problem
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario

__all__ = [
    "BYTES_PER_CELL",
    "BYTES_PER_HEADING",
    "STATUSES",
    "MapfProblem",
    "PlanningResult",
    "as_problem",
    "pad_headings",
    "pad_paths",
    "path_cost",
    "plan_size_bytes",
    "tick_grid",
]

STATUSES = ("solved", "limit", "infeasible", "failed")
"""The statuses of a :class:`PlanningResult`:

* ``"solved"``: every robot has a path, and the paths do not collide;
* ``"limit"``: a node or time limit was reached before a solution was found;
* ``"infeasible"``: the planner proved that no solution exists;
* ``"failed"``: an incomplete planner gave up (for example prioritized planning
  could not plan one robot, named by ``failed_robot``).
"""

BYTES_PER_CELL = 8
"""Bytes to send one cell of one robot's path: two 32-bit coordinates."""
BYTES_PER_HEADING = 1
"""Bytes to send one heading of one robot's path (heading-aware plans only)."""


def path_cost(path: Sequence[Cell]) -> int:
    """The MAPF cost of one path: the first tick from which it stays on its last cell.

    >>> path_cost([(0, 0), (0, 1), (0, 1), (0, 2), (0, 2)])
    3
    >>> path_cost([(0, 0)])
    0
    """
    tick = len(path) - 1
    if tick < 0:
        return 0
    last = path[tick]
    while tick > 0 and path[tick - 1] == last:
        tick -= 1
    return tick


def pad_paths(paths: Sequence[Sequence[Cell]]) -> tuple[tuple[Cell, ...], ...]:
    """Extend every path with its last cell to the length of the longest one.

    Parameters
    ----------
    paths:
        One path per robot, one cell per tick; each needs at least its start.

    Returns
    -------
    tuple of tuple of Cell
        The paths, all of the same length, as tuples.

    Raises
    ------
    ValueError
        If a path is empty.

    Examples
    --------
    >>> pad_paths([[(0, 0), (0, 1)], [(2, 2)]])
    (((0, 0), (0, 1)), ((2, 2), (2, 2)))
    >>> pad_paths([])
    ()
    """
    if any(len(path) == 0 for path in paths):
        raise ValueError("every path needs at least its start cell")
    length = max((len(path) for path in paths), default=0)
    return tuple(tuple(path) + (path[-1],) * (length - len(path)) for path in paths)


def pad_headings(headings: Sequence[Sequence[Heading]]) -> tuple[tuple[Heading, ...], ...]:
    """Extend every robot's headings with its last heading to the longest length.

    >>> pad_headings([[Heading.NORTH, Heading.EAST], [Heading.SOUTH]])
    ((<Heading.NORTH: 1>, <Heading.EAST: 2>), (<Heading.SOUTH: 3>, <Heading.SOUTH: 3>))
    """
    length = max((len(row) for row in headings), default=0)
    return tuple(tuple(row) + (row[-1],) * (length - len(row)) for row in headings)


@dataclass(frozen=True)
class PlanningResult:
    """The answer of a centralized planner.

    Attributes
    ----------
    status:
        One of :data:`STATUSES`: ``"solved"``, ``"limit"``, ``"infeasible"`` or
        ``"failed"``.
    paths:
        When solved: one path per robot in scenario order, each starting at the
        robot's start, one cell per tick, all of equal length (robots wait at
        their goals). ``None`` otherwise.
    planning_time_s:
        Wall-clock seconds spent planning.
    planner:
        The planner's name (``"cbs"``, ``"pp"``, ``"lacam"``).
    nodes:
        The planner's own work counter: high-level constraint-tree nodes
        generated (CBS), configurations generated (LaCAM), low-level
        space-time A* expansions (prioritized planning). Each planner documents
        which.
    failed_robot:
        The id of the robot that could not be planned (prioritized planning).
    message:
        One line for a person (why it stopped, which limit was reached).
    headings:
        With heading-aware planning, each robot's heading at each tick,
        aligned with ``paths``; ``None`` otherwise.

    Examples
    --------
    >>> r = PlanningResult("solved", (((0, 0), (1, 0)), ((2, 0), (2, 0))), 0.0, "pp")
    >>> r.sum_of_costs(), r.makespan(), r.costs()
    (1, 1, (1, 0))
    """

    status: str
    paths: tuple[tuple[Cell, ...], ...] | None
    planning_time_s: float
    planner: str
    nodes: int = 0
    failed_robot: str | None = None
    message: str = ""
    headings: tuple[tuple[Heading, ...], ...] | None = None

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status must be one of {', '.join(STATUSES)}, got {self.status!r}")
        if self.status == "solved" and self.paths is None:
            raise ValueError("a solved result needs paths")

    @property
    def solved(self) -> bool:
        """Whether the planner found a plan (``status == "solved"``)."""
        return self.status == "solved"

    def costs(self) -> tuple[int, ...]:
        """Each robot's MAPF cost: the first tick from which it stays at its goal.

        Raises
        ------
        ValueError
            If the result holds no paths.
        """
        if self.paths is None:
            raise ValueError(f"a {self.status} result has no paths")
        return tuple(path_cost(path) for path in self.paths)

    def sum_of_costs(self) -> int:
        """The sum over robots of the first tick from which each stays at its goal.

        Raises
        ------
        ValueError
            If the result holds no paths.
        """
        return sum(self.costs())

    def makespan(self) -> int:
        """The largest robot cost: the tick at which the last robot settles at its goal.

        Raises
        ------
        ValueError
            If the result holds no paths.
        """
        return max(self.costs(), default=0)


def plan_size_bytes(result: PlanningResult) -> int:
    """The size of the plan a central planner must distribute to the robots.

    Every robot receives its whole path: :data:`BYTES_PER_CELL` (8: two 32-bit
    coordinates) per cell per tick, tick 0 included, plus
    :data:`BYTES_PER_HEADING` (1) per tick when the plan carries headings.
    Paths are counted as returned (padded to equal length); a result without
    paths has size 0.

    >>> r = PlanningResult("solved", (((0, 0), (0, 1)), ((1, 1), (1, 1))), 0.0, "cbs")
    >>> plan_size_bytes(r)
    32
    >>> r2 = PlanningResult("solved", r.paths, 0.0, "cbs", headings=((Heading.EAST,) * 2,) * 2)
    >>> plan_size_bytes(r2)
    36
    >>> plan_size_bytes(PlanningResult("failed", None, 0.0, "pp"))
    0
    """
    if result.paths is None:
        return 0
    cells = sum(len(path) for path in result.paths)
    size = cells * BYTES_PER_CELL
    if result.headings is not None:
        size += sum(len(row) for row in result.headings) * BYTES_PER_HEADING
    return size


@dataclass(frozen=True)
class MapfProblem:
    """One multi-robot planning instance, as every centralized planner reads it.

    Attributes
    ----------
    grid:
        The map.
    starts, goals:
        One cell per robot, in robot order.
    ids:
        The robots' names (``"0"``, ``"1"``, ... when not given).
    headings:
        The robots' headings at tick 0 (used by heading-aware planning).
    """

    grid: Grid
    starts: tuple[Cell, ...]
    goals: tuple[Cell, ...]
    ids: tuple[str, ...]
    headings: tuple[Heading, ...]

    def __len__(self) -> int:
        return len(self.starts)


def as_problem(
    problem: Scenario | Grid | MapfProblem,
    starts: Sequence[Cell] | None = None,
    goals: Sequence[Cell] | None = None,
    *,
    ids: Sequence[str] | None = None,
    headings: Sequence[Heading] | None = None,
) -> MapfProblem:
    """Read a planner's input: a :class:`~mrmp.core.scenario.Scenario`, or a grid with starts and goals.

    Parameters
    ----------
    problem:
        A scenario (its robots give ids, starts, goals and headings), a
        :class:`MapfProblem`, or a grid (then ``starts`` and ``goals`` are
        required).
    starts, goals:
        With a grid: one cell per robot.
    ids:
        With a grid: the robots' names (default ``"0"``, ``"1"``, ...).
    headings:
        With a grid: the headings at tick 0 (default all NORTH, the thesis's).

    Returns
    -------
    MapfProblem
        The checked instance.

    Raises
    ------
    InputError
        If starts or goals are missing, of different lengths, off the grid, on
        obstacles, or shared by two robots.

    Examples
    --------
    >>> p = as_problem(Grid(2, 2), [(0, 0), (1, 1)], [(1, 1), (0, 0)])
    >>> p.ids, p.headings[0].name, len(p)
    (('0', '1'), 'NORTH', 2)
    >>> as_problem(Grid(2, 2), [(0, 0), (0, 0)], [(1, 1), (1, 0)])
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: starts[1]: cell (0, 0) is also the start of robot 0
    """
    if isinstance(problem, MapfProblem):
        return problem
    if isinstance(problem, Scenario):
        grid = problem.grid
        starts = [robot.start for robot in problem.robots]
        goals = [robot.goal for robot in problem.robots]
        ids = [robot.id for robot in problem.robots]
        headings = [robot.heading for robot in problem.robots]
    else:
        grid = problem
        if starts is None or goals is None:
            raise InputError("a grid needs starts and goals")
    starts = [(int(cell[0]), int(cell[1])) for cell in starts]
    goals = [(int(cell[0]), int(cell[1])) for cell in goals]
    problems: list[Problem] = []
    if len(starts) != len(goals):
        problems.append(Problem("goals", f"{len(goals)} goals for {len(starts)} starts"))
    count = len(starts)
    if ids is None:
        ids = [str(index) for index in range(count)]
    if headings is None:
        headings = [Heading.NORTH] * count
    if len(ids) != count or len(set(ids)) != len(ids):
        problems.append(Problem("ids", f"need {count} distinct robot ids, got {list(ids)}"))
    if len(headings) != count:
        problems.append(Problem("headings", f"{len(headings)} headings for {count} robots"))
    for kind, cells in (("starts", starts), ("goals", goals)):
        seen: dict[Cell, int] = {}
        for index, cell in enumerate(cells):
            if not grid.is_free(cell):
                where = "outside the grid" if not grid.in_bounds(cell) else "an obstacle"
                problems.append(Problem(f"{kind}[{index}]", f"cell {cell} is {where}"))
            elif cell in seen:
                problems.append(Problem(f"{kind}[{index}]", f"cell {cell} is also the {kind[:-1]} of robot {seen[cell]}"))
            else:
                seen[cell] = index
    if problems:
        raise InputError(problems)
    return MapfProblem(
        grid=grid,
        starts=tuple(starts),
        goals=tuple(goals),
        ids=tuple(str(robot_id) for robot_id in ids),
        headings=tuple(Heading.parse(h) if not isinstance(h, Heading) else h for h in headings),
    )


def tick_grid(grid: Grid) -> Grid:
    """``grid`` itself when every cell costs 1 to enter, else a copy without costs.

    Planners that count time in ticks (one move or wait per tick) rank cells by
    the number of moves to the goal, whatever the entry costs.

    >>> grid = Grid(2, 2, costs={(1, 1): 5.0})
    >>> tick_grid(grid).has_costs, tick_grid(Grid(2, 2)) is not None
    (False, True)
    """
    if not grid.has_costs:
        return grid
    return Grid(grid.x_size, grid.y_size, grid.blocked_cells(), name=grid.name)
