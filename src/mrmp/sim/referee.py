"""The referee: the project's single oracle of what really happened.

Every policy, solver and runtime is judged by it. Given where every robot
stands at the end of each tick, it reports:

* ``vertex``: two or more robots in one cell;
* ``swap``: two robots exchanging cells in one tick (an edge collision);
* ``obstacle``: a robot on a static obstacle;
* ``off_grid``: a robot outside the grid;
* ``jump``: a robot moving more than one cell in one tick.

Following (entering a cell another robot leaves in the same tick) is allowed, as
in the standard MAPF definition (Stern et al., SoCS 2019). Goal arrival is
read off the paths by :class:`~mrmp.core.result.RobotResult`.

:func:`check_paths` judges a plan given from outside: a list of paths, one cell
per tick; a robot whose path ends stays on its last cell.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> grid = Grid.from_rows([".@.", "...", "..."])
>>> [c.describe() for c in check_paths(grid, {"A": [(0, 0), (0, 1)], "B": [(0, 1), (0, 0)]})]
['tick 1: swap collision of A, B at (0, 0), (0, 1)']
>>> [c.describe() for c in check_paths(grid, {"A": [(1, 1), (2, 1)], "B": [(1, 2), (0, 2)]})]
['tick 1: obstacle collision of A at (2, 1)']
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.result import Collision


class Referee:
    """Checks successive configurations of a fleet on ``grid``.

    Parameters
    ----------
    grid:
        The map.
    robot_ids:
        Names of the robots, in the order their cells are given.
    """

    def __init__(self, grid: Grid, robot_ids: Sequence[str]) -> None:
        self.grid = grid
        self.robot_ids = tuple(robot_ids)
        self.collisions: list[Collision] = []

    def check_start(self, cells: Sequence[Cell]) -> list[Collision]:
        """Check the configuration at tick 0."""
        found = self._check_cells(0, cells)
        self.collisions.extend(found)
        return found

    def check_tick(self, tick: int, before: Sequence[Cell], after: Sequence[Cell]) -> list[Collision]:
        """Check the move from ``before`` (end of tick - 1) to ``after`` (end of ``tick``)."""
        found: list[Collision] = []
        ids = self.robot_ids
        moves: dict[tuple[Cell, Cell], int] = {}
        for index, (source, target) in enumerate(zip(before, after)):
            if source == target:
                continue
            if abs(source[0] - target[0]) + abs(source[1] - target[1]) > 1:
                found.append(Collision("jump", tick, (ids[index],), (source, target)))
            moves[(source, target)] = index
        for (source, target), index in moves.items():
            other = moves.get((target, source))
            if other is not None and index < other:
                first, second = sorted((source, target))
                found.append(Collision("swap", tick, (ids[index], ids[other]), (first, second)))
        found.extend(self._check_cells(tick, after))
        self.collisions.extend(found)
        return found

    def _check_cells(self, tick: int, cells: Sequence[Cell]) -> list[Collision]:
        found: list[Collision] = []
        grid = self.grid
        ids = self.robot_ids
        occupants: dict[Cell, list[int]] = {}
        for index, cell in enumerate(cells):
            occupants.setdefault(cell, []).append(index)
            if not grid.in_bounds(cell):
                found.append(Collision("off_grid", tick, (ids[index],), (cell,)))
            elif grid.is_blocked(cell):
                found.append(Collision("obstacle", tick, (ids[index],), (cell,)))
        for cell, indices in occupants.items():
            if len(indices) > 1:
                found.append(Collision("vertex", tick, tuple(ids[index] for index in indices), (cell,)))
        return found


def check_paths(grid: Grid, paths: Mapping[str, Sequence[Cell]]) -> list[Collision]:
    """Judge a whole plan: every robot's path, one cell per tick, tick 0 first.

    Shorter paths are extended by their last cell (the robot waits there).
    Returns every violation, in tick order; an empty list means a valid plan.
    """
    ids = list(paths)
    sequences = [list(paths[robot]) for robot in ids]
    if any(not sequence for sequence in sequences):
        raise ValueError("every path needs at least its start cell")
    length = max(len(sequence) for sequence in sequences)
    padded = [sequence + [sequence[-1]] * (length - len(sequence)) for sequence in sequences]
    referee = Referee(grid, ids)
    referee.check_start([sequence[0] for sequence in padded])
    for tick in range(1, length):
        referee.check_tick(tick, [sequence[tick - 1] for sequence in padded], [sequence[tick] for sequence in padded])
    return referee.collisions
