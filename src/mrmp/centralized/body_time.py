"""How soon live bodies can carry out a plan: its action dependency graph timed with their moves.

A plan counts ticks; a live body counts seconds, and takes more than a cell
time for some moves: it turns right only (thesis, section 3.3: a left turn is
three right turns), and it covers both cells while it moves, so a robot enters
a cell only once the robot leaving it has arrived in its next cell. A plan in
which robots follow one another closely (a robot entering, at tick ``t``, a
cell left at tick ``t``) is carried out one robot after the other.

:func:`execution_seconds` times the plan's Action Dependency Graph (W. Hönig,
S. Kiesel, A. Tinka, J. W. Durham, N. Ayanian, "Persistent and robust
execution of MAPF schedules in warehouses", IEEE RA-L 4(2), 2019;
:func:`~mrmp.centralized.dependencies.action_dependencies`) with those
durations: each move starts as soon as the robot's previous move has ended and
every robot that stood on its target cell earlier in the plan has left it
(its move out has ended), and lasts the body's right turns and one cell. No
execution by such bodies ends sooner, whatever its messages cost: it is the
bound a live execution is measured against.

Examples
--------
Two robots side by side drive north (``x`` increases) at once; the second faces
east and turns right three times first:

>>> from mrmp.core import Timing
>>> from mrmp.core.heading import Heading
>>> timing = Timing(cell_time=1.0, turn_time=0.5)
>>> execution_seconds([[(0, 0), (1, 0)], [(0, 1), (1, 1)]], [Heading.NORTH, Heading.EAST], timing)
2.5

Two robots in a row drive north in the same tick: the second follows the first,
so it starts when the first has arrived (at time scale 2, half a second a cell):

>>> execution_seconds([[(1, 0), (2, 0)], [(0, 0), (1, 0)]], [Heading.NORTH, Heading.NORTH], timing, time_scale=2.0)
1.0
"""

from __future__ import annotations

from collections.abc import Sequence

from mrmp.centralized.dependencies import action_dependencies
from mrmp.core.cell import Cell
from mrmp.core.heading import Heading, right_turns
from mrmp.core.scenario import Timing


def execution_seconds(
    paths: Sequence[Sequence[Cell]], headings: Sequence[Heading], timing: Timing, time_scale: float = 1.0
) -> float:
    """The soonest (seconds) bodies starting with ``headings`` end ``paths`` (module docstring).

    ``timing`` gives a body's cell time and right-turn time, divided by ``time_scale``.

    Raises
    ------
    ValueError, PlanDeadlockError
        As :func:`~mrmp.centralized.dependencies.action_dependencies`, for a plan
        that collides or whose robots would wait for each other for ever.
    """
    moves, dependencies = action_dependencies(paths)
    cell_seconds = timing.cell_time / time_scale
    turn_seconds = timing.turn_time / time_scale
    durations = [
        _move_seconds(path[0], robot_moves, heading, cell_seconds, turn_seconds)
        for path, robot_moves, heading in zip(paths, moves, headings)
    ]
    ends: dict[tuple[int, int], float] = {}
    for robot, robot_moves in enumerate(moves):
        for move in range(len(robot_moves)):
            _end(robot, move, dependencies, durations, ends)
    return max(ends.values(), default=0.0)


def _move_seconds(start: Cell, moves: Sequence[Cell], heading: Heading, cell_seconds: float, turn_seconds: float) -> list[float]:
    """How long each of a robot's moves lasts: its right turns, then one cell."""
    durations, here = [], start
    for cell in moves:
        direction = Heading.between(here, cell)
        durations.append(right_turns(heading, direction) * turn_seconds + cell_seconds)
        heading, here = direction, cell
    return durations


def _end(
    robot: int,
    move: int,
    dependencies: Sequence[dict[int, list[tuple[int, int]]]],
    durations: Sequence[Sequence[float]],
    ends: dict[tuple[int, int], float],
) -> float:
    """When move ``move`` of ``robot`` ends: after its own previous move and every move it waits for.

    Iterative (a chain of robots following one another is as long as the fleet), over a graph
    that :func:`~mrmp.centralized.dependencies.action_dependencies` has checked acyclic.
    """
    stack = [(robot, move)]
    while stack:
        current = stack[-1]
        if current in ends:
            stack.pop()
            continue
        who, index = current
        needed = [(other, progress - 1) for other, progress in dependencies[who].get(index, ()) if progress > 0]
        if index > 0:
            needed.append((who, index - 1))
        missing = [item for item in needed if item not in ends]
        if missing:
            stack.extend(missing)
            continue
        stack.pop()
        ready = max((ends[item] for item in needed), default=0.0)
        ends[current] = ready + durations[who][index]
    return ends[robot, move]
