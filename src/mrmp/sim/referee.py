"""The referee: the project's single oracle of what really happened.

Every policy, solver and runtime is judged by it. Given where every robot
stands at the end of each tick (and, for a headed body, which way it faces), it
reports:

* ``vertex``: two or more robots in one cell;
* ``swap``: two robots exchanging cells in one tick (an edge collision);
* ``obstacle``: a robot on a static obstacle;
* ``off_grid``: a robot outside the grid;
* ``jump``: a robot moving more than one cell in one tick;
* ``follow``: for a body that never follows, a robot entering a cell that
  another robot stood on at the end of the previous tick and left in this one
  (robots: the follower, then the robot it followed; cells: the cell entered);
* ``rotation``: for a body without rotations, three or more robots moving
  round a cycle of cells in one tick, each into the cell the next one leaves
  (robots in cycle order from the least index, each moving from its cell into
  the next one's, as :class:`~mrmp.centralized.dependencies.Rotation`);
* ``action``: for a headed body, when headings are given, a robot doing in
  one tick what its body cannot (cells: the cell left and the cell entered, or
  the cell it turned on).

The rules are the body's (:mod:`mrmp.core.body`, ``docs/protocol.md``, "Body
models"); without a body the referee judges ``omni``:

* ``omni`` (classic MAPF, Stern et al., SoCS 2019): vertex, swap, obstacle,
  off-grid and jump only. Following (entering a cell another robot leaves in
  the same tick) is allowed, also round a cycle of cells (a rotation), and
  headings are recorded, not obeyed.
* ``thesis``: no following (so no rotation either): a robot may not enter at
  tick ``t`` a cell a robot stood on at the end of tick ``t - 1``. A robot that
  moves faces the way it moved at the end of the tick (its right turns come
  first, in the same tick); one that stays may turn as it likes.
* ``turning`` (``MAPF_T`` of the League of Robot Runners, Chan et al., ICAPS
  2024): following is allowed, rotations are not. In a tick a robot moves one
  cell straight ahead of the heading it had and keeps it, or stays and turns
  at most a quarter, or waits.

A robot entering the cell of a robot that stays is a ``vertex`` collision, not
a ``follow``; a move that is part of a swap (or, for a body without rotations,
of a rotation) is reported as that, not as a follow too; a jump is not also an
``action``. Goal arrival is read off the paths by
:class:`~mrmp.core.result.RobotResult`.

:func:`check_paths` judges a plan given from outside: a list of paths, one cell
per tick; a robot whose path ends stays on its last cell (and keeps its last
heading).

Examples
--------
>>> from mrmp.core.body import body_model
>>> from mrmp.core.grid import Grid
>>> from mrmp.core.heading import Heading
>>> grid = Grid.from_rows([".@.", "...", "..."])
>>> [c.describe() for c in check_paths(grid, {"A": [(0, 0), (0, 1)], "B": [(0, 1), (0, 0)]})]
['tick 1: swap collision of A, B at (0, 0), (0, 1)']
>>> [c.describe() for c in check_paths(grid, {"A": [(1, 1), (2, 1)], "B": [(1, 2), (0, 2)]})]
['tick 1: obstacle collision of A at (2, 1)']

B follows A along a row: classic MAPF and ``turning`` allow it, ``thesis`` does not:

>>> train = {"A": [(1, 1), (1, 2)], "B": [(1, 0), (1, 1)]}
>>> check_paths(grid, train), check_paths(grid, train, body=body_model("turning"))
([], [])
>>> [c.describe() for c in check_paths(grid, train, body=body_model("thesis"))]
['tick 1: follow collision of B, A at (1, 1)']

Four robots turning round a 2x2 block in one tick: a rotation, forbidden to
``turning`` (and ``thesis``) bodies:

>>> block = [(0, 0), (1, 0), (1, 1), (0, 1)]
>>> turn = {name: [block[i], block[(i + 1) % 4]] for i, name in enumerate("ABCD")}
>>> check_paths(Grid(2, 2), turn)
[]
>>> [c.describe() for c in check_paths(Grid(2, 2), turn, body=body_model("turning"))]
['tick 1: rotation collision of A, B, C, D at (0, 0), (1, 0), (1, 1), (0, 1)']

A ``turning`` robot facing north (``x`` increases) cannot step east; a
``thesis`` robot can, turning right first, and then faces east:

>>> step = {"A": [(0, 0), (0, 1)]}
>>> [c.describe() for c in check_paths(grid, step, {"A": [Heading.NORTH]}, body_model("turning"))]
['tick 1: action collision of A at (0, 0), (0, 1)']
>>> check_paths(grid, step, {"A": [Heading.NORTH, Heading.EAST]}, body_model("thesis"))
[]
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from mrmp.core.body import BodyModel, body_model
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.result import Collision


class Referee:
    """Checks successive configurations of a fleet on ``grid``.

    Parameters
    ----------
    grid:
        The map.
    robot_ids:
        Names of the robots, in the order their cells are given.
    body:
        The body model whose rules apply (module docstring); ``None`` is
        ``omni``, the classic MAPF rules.
    """

    def __init__(self, grid: Grid, robot_ids: Sequence[str], body: BodyModel | None = None) -> None:
        self.grid = grid
        self.robot_ids = tuple(robot_ids)
        self.body = body if body is not None else body_model("omni")
        self.collisions: list[Collision] = []
        self._no_follow = not self.body.follows
        self._no_rotation = not self.body.rotations
        self._chains = self._no_follow or self._no_rotation

    def check_start(self, cells: Sequence[Cell], headings: Sequence[Heading] | None = None) -> list[Collision]:
        """Check the configuration at tick 0.

        ``headings`` (one per robot) may be given as at every tick; no rule binds
        a start heading, so only their number is checked.

        Raises
        ------
        ValueError
            If ``headings`` does not give one heading per cell.
        """
        if headings is not None and len(headings) != len(cells):
            raise ValueError(f"{len(headings)} headings for {len(cells)} robots")
        found = self._check_cells(0, cells)
        self.collisions.extend(found)
        return found

    def check_tick(
        self,
        tick: int,
        before: Sequence[Cell],
        after: Sequence[Cell],
        headings_before: Sequence[Heading] | None = None,
        headings_after: Sequence[Heading] | None = None,
    ) -> list[Collision]:
        """Check the move from ``before`` (end of tick - 1) to ``after`` (end of ``tick``).

        ``headings_before`` and ``headings_after`` are the robots' headings at
        the same two moments; a headed body's actions are checked only when both
        are given.

        Raises
        ------
        ValueError
            If a heading list does not give one heading per robot.
        """
        found: list[Collision] = []
        ids = self.robot_ids
        moves: dict[tuple[Cell, Cell], int] = {}
        movers: list[int] = []
        for index, (source, target) in enumerate(zip(before, after)):
            if source == target:
                continue
            if abs(source[0] - target[0]) + abs(source[1] - target[1]) > 1:
                found.append(Collision("jump", tick, (ids[index],), (source, target)))
            moves[(source, target)] = index
            movers.append(index)
        for (source, target), index in moves.items():
            other = moves.get((target, source))
            if other is not None and index < other:
                first, second = sorted((source, target))
                found.append(Collision("swap", tick, (ids[index], ids[other]), (first, second)))
        if self._chains and movers:
            found.extend(self._check_chains(tick, before, after, movers))
        if self.body.headed and headings_before is not None and headings_after is not None:
            if len(headings_before) != len(before) or len(headings_after) != len(after):
                raise ValueError(f"headings for {len(headings_before)} and {len(headings_after)} of {len(before)} robots")
            found.extend(self._check_actions(tick, before, after, headings_before, headings_after))
        found.extend(self._check_cells(tick, after))
        self.collisions.extend(found)
        return found

    def _check_chains(self, tick: int, before: Sequence[Cell], after: Sequence[Cell], movers: Sequence[int]) -> list[Collision]:
        """Following and rotations: walk the chains of robots that moved into a cell a moving robot left.

        Each such robot points to the robot whose cell it entered (a functional
        graph); its cycles of three or more robots are the rotations, those of
        two the swaps. Linear in the number of robots that moved. Robots that
        shared a cell at the end of the previous tick (a vertex collision,
        reported then) count as one, the last in order, leaving it.
        """
        found: list[Collision] = []
        ids = self.robot_ids
        leaving = {before[index]: index for index in movers}
        ahead: dict[int, int] = {}
        for index in movers:
            leader = leaving.get(after[index])
            if leader is not None and leader != index:
                ahead[index] = leader
        if not ahead:
            return found
        in_cycle: set[int] = set()
        walked: dict[int, int] = {}
        for walk, first in enumerate(ahead):
            if first in walked:
                continue
            chain: list[int] = []
            robot = first
            while robot in ahead and robot not in walked:
                walked[robot] = walk
                chain.append(robot)
                robot = ahead[robot]
            if walked.get(robot) != walk:
                continue  # the chain ends at a robot that entered a free cell, or joins one walked before
            cycle = chain[chain.index(robot) :]
            if len(cycle) < 3:
                continue  # a swap, reported already
            if self._no_rotation:
                least = cycle.index(min(cycle))
                cycle = cycle[least:] + cycle[:least]
                robots = tuple(ids[member] for member in cycle)
                found.append(Collision("rotation", tick, robots, tuple(before[member] for member in cycle)))
                in_cycle.update(cycle)
        if self._no_follow:
            for index, leader in ahead.items():
                if index not in in_cycle and after[leader] != before[index]:  # not in a rotation, not a swap
                    found.append(Collision("follow", tick, (ids[index], ids[leader]), (after[index],)))
        return found

    def _check_actions(
        self,
        tick: int,
        before: Sequence[Cell],
        after: Sequence[Cell],
        headings_before: Sequence[Heading],
        headings_after: Sequence[Heading],
    ) -> list[Collision]:
        """What a headed body cannot do in one tick (module docstring): one ``action`` per robot at most."""
        found: list[Collision] = []
        ids = self.robot_ids
        in_place = self.body.turns_in_place
        for index, (source, target) in enumerate(zip(before, after)):
            facing, faced = headings_before[index], headings_after[index]
            if source == target:
                if in_place and (int(faced) - int(facing)) % 4 == 2:
                    found.append(Collision("action", tick, (ids[index],), (source,)))
                continue
            if abs(source[0] - target[0]) + abs(source[1] - target[1]) != 1:
                continue  # a jump, reported already
            direction = Heading.between(source, target)
            wrong = (direction != facing or faced != facing) if in_place else faced != direction
            if wrong:
                found.append(Collision("action", tick, (ids[index],), (source, target)))
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


def check_paths(
    grid: Grid,
    paths: Mapping[str, Sequence[Cell]],
    headings: Mapping[str, Sequence[Heading]] | None = None,
    body: BodyModel | None = None,
) -> list[Collision]:
    """Judge a whole plan: every robot's path, one cell per tick, tick 0 first.

    Shorter paths are extended by their last cell (the robot waits there).
    ``headings`` gives, per robot, its heading at every tick, extended in the
    same way by its last heading (a heading list may outlast its path: the
    robot turns on its last cell); ``body`` is the body whose rules apply
    (``None``: ``omni``). Returns every violation, in tick order; an empty list
    means a valid plan.

    Raises
    ------
    ValueError
        If a path is empty, or ``headings`` is given without a non-empty list
        for every robot.
    """
    ids = list(paths)
    sequences = [list(paths[robot]) for robot in ids]
    if any(not sequence for sequence in sequences):
        raise ValueError("every path needs at least its start cell")
    turns: list[list[Heading]] | None = None
    if headings is not None:
        missing = [robot for robot in ids if not headings.get(robot)]
        if missing:
            raise ValueError(f"no headings for {', '.join(missing)}")
        turns = [list(headings[robot]) for robot in ids]
    length = max(max(len(sequence) for sequence in sequences), max((len(sequence) for sequence in turns or ()), default=0))
    padded = [sequence + [sequence[-1]] * (length - len(sequence)) for sequence in sequences]
    facing = None if turns is None else [sequence + [sequence[-1]] * (length - len(sequence)) for sequence in turns]
    referee = Referee(grid, ids, body)
    referee.check_start([sequence[0] for sequence in padded], None if facing is None else [f[0] for f in facing])
    for tick in range(1, length):
        referee.check_tick(
            tick,
            [sequence[tick - 1] for sequence in padded],
            [sequence[tick] for sequence in padded],
            None if facing is None else [sequence[tick - 1] for sequence in facing],
            None if facing is None else [sequence[tick] for sequence in facing],
        )
    return referee.collisions
