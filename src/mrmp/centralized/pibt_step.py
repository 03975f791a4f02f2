"""PIBT as a configuration generator: one collision-free step for every robot at once.

PIBT, *Priority Inheritance with Backtracking* (Okumura, Machida, Défago and
Tamura, "Priority Inheritance with Backtracking for Iterative Multi-agent Path
Finding", IJCAI 2019; extended in Artificial Intelligence 310, 2022), decides
the next cell of every robot from the current configuration:

* robots are served in priority order; a robot tries its candidate cells (its
  free neighbours and its own cell) from nearest to farthest from its goal;
* a robot never takes a cell another robot has already reserved for the next
  step, nor the cell of a robot that is moving into its own cell (no swap);
* when a robot ``i`` reserves the cell of a robot ``j`` that has not decided
  yet, ``j`` *inherits* ``i``'s priority and decides at once, and must leave
  that cell; when ``j`` cannot move anywhere it stays, and ``i`` *backtracks*
  to its next candidate.

LaCAM (Okumura, "LaCAM: Search-Based Algorithm for Quick Multi-Agent
Pathfinding", AAAI 2023) uses PIBT as its successor generator *under
constraints*: some robots' next cells are fixed in advance and PIBT plans the
others around them, or reports that it cannot (:meth:`PIBT.generate`).

**Swap.** PIBT alone cannot make two robots exchange places in a corridor
(each wants the other's cell, and swaps are forbidden). The *swap* technique
of LaCAM* engineering (Okumura, "Engineering LaCAM*: Towards Real-Time,
Large-Scale, and Near-Optimal Multi-Agent Pathfinding", AAMAS 2024) detects
such a head-on situation, makes the robot walk backwards (its candidates are
tried in reverse order) and *pulls* the other robot behind it, until the pair
reaches a cell of degree three or more where they can pass each other. It is
off by default here and turned on with ``swap=True``; it follows
``lacam3/src/pibt.cpp`` of Kei18/lacam3 (``is_swap_required``,
``is_swap_possible``, the pull after a first-choice move).

The inner loop works on the flat cells of :mod:`mrmp.search.flat_grid`
(``x * y_size + y``), its neighbour tuples precomputed once per grid and one
distance list per robot in its distance convention (``inf`` where the goal
cannot be reached). Priority inheritance is run with an explicit
stack, so chains of any length need no deep Python recursion.

Examples
--------
Two robots in a corridor with a bay above its middle cell: robot 0 must
pass robot 1, so robot 1 steps into the bay (priority inheritance pushes it
there, since it may neither stay nor swap):

>>> from mrmp.core.grid import Grid
>>> grid = Grid.from_rows(["#.#", "..."])
>>> pibt_step(grid, [(0, 0), (0, 1)], [(0, 2), (0, 0)])
[(0, 1), (1, 1)]

A robot whose next cell is fixed gets exactly that cell:

>>> pibt_step(grid, [(0, 0), (0, 1)], [(0, 2), (0, 0)], constraints={1: (0, 2)})
[(0, 1), (0, 2)]

Constraints that cannot be met (here: a swap) give ``None``:

>>> pibt_step(grid, [(0, 0), (0, 1)], [(0, 2), (0, 0)], constraints={0: (0, 1), 1: (0, 0)}) is None
True
"""

from __future__ import annotations

import random
from collections.abc import Mapping, Sequence

from mrmp.centralized.plan import tick_grid
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.policies.pibt_rules import (
    sorted_candidates,
    swap_possible,
    swap_required,
    turning_action,
    turning_candidates,
)
from mrmp.search.distance import DistanceTable, distance_table
from mrmp.search.flat_grid import flat_grid

__all__ = ["NO_AGENT", "NO_CELL", "PIBT", "pibt_step"]

NO_AGENT = -1
"""Marks a cell that no robot occupies (or reserves)."""
NO_CELL = -1
"""Marks a robot whose next cell is not decided yet."""


class PIBT:
    """A reusable PIBT configuration generator on flat cell indices.

    Parameters
    ----------
    neighbours:
        For every flat cell index, the indices of the cells one move away
        (:attr:`~mrmp.search.flat_grid.FlatGrid.neighbours`).
    distances:
        For every robot, the distance (number of moves) from every flat cell to
        its goal, ``inf`` where the goal cannot be reached
        (:meth:`~mrmp.search.distance.DistanceTable.as_list`).
    goals:
        Every robot's goal, as a flat index.
    swap:
        Whether to use the swap technique of LaCAM* engineering (Okumura,
        AAMAS 2024); see the module docstring.
    rng:
        Breaks ties between equally distant candidate cells at random when
        given; otherwise ties keep the neighbour order (NORTH, EAST, SOUTH,
        WEST, then staying), so results are deterministic.
    tie_penalties:
        Rank equally distant cells by the tie penalties of
        :func:`~mrmp.policies.pibt_rules.sorted_candidates` first (dead ends
        last; cells of robots standing on their goals after free ones), as the
        robots of policy ``pibt`` do with random ties.
    rotations:
        Whether a step may contain a *rotation*: robots on a cycle of cells
        each moving into the cell the next one leaves (the classic MAPF model
        allows it). With ``False`` a robot never takes a cell when the chain
        of robots that follow one another from that cell's occupant leads
        back to itself (for a robot planned by priority inheritance: the cell
        of an ancestor in its own chain), and constraints that form such a
        cycle fail; central plans are then executable by robots moving one at
        a time (:mod:`mrmp.centralized.dependencies`).
    turning_y_size:
        Plan for bodies that turn in place (the ``turning`` body of
        :mod:`mrmp.core.body`, LoRR's ``MAPF_T``), on a grid of this many
        columns (``y_size``; 0, the default: bodies that move in any
        direction). ``distances`` are then ``(cell, heading)`` tables in ticks
        (:func:`~mrmp.search.heading_distance.heading_distances`, ``both_ways``,
        entry ``4 * cell + heading - 1``) and :meth:`generate` takes every
        robot's heading. PIBT then chooses every robot's next *cell* among all
        its neighbours, ranked with their turns
        (:func:`~mrmp.policies.pibt_rules.turning_candidates`), as the
        Start-Kit of the League of Robot Runners does
        (MAPF-Competition/Start-Kit, ``default_planner``): a robot given the
        cell ahead drives there, any other robot turns toward its cell or
        waits (:func:`~mrmp.policies.pibt_rules.turning_action`) and stays;
        last, a forward move into the cell of a robot that does not drive on
        out of it is cancelled (the robot waits, facing it), and so on down the
        chain of robots following it (the Start-Kit's ``moveCheck``). A robot
        pushed by priority inheritance never takes the cell of a robot already
        moving, as the decentralized robots decide. Needs ``swap`` off and
        ``rotations`` off, so that no cycle of robots follows round a loop of
        cells.

    Notes
    -----
    :meth:`generate` follows ``PIBT::set_new_config`` and ``funcPIBT`` of the
    reference implementations (Kei18/pypibt, Kei18/lacam, Kei18/lacam3): the
    candidates of robot ``i`` at ``v`` are ``v`` and its neighbours sorted by
    distance to ``i``'s goal; a candidate is skipped when reserved, or when its
    occupant already moves into ``v``; after reserving a cell whose occupant
    has not decided, that occupant is planned at once (priority inheritance)
    and on its failure the next candidate is tried (backtracking). A robot with
    no candidate left stays where it is and reports failure.

    Examples
    --------
    A 1x3 corridor, flat indices 0, 1, 2. Robot 0 at 0 heads for 2; robot 1
    is at home on 1. Robot 0 (served first) asks for cell 1, robot 1 inherits
    its priority and, unable to stay or to swap, steps on to 2:

    >>> neighbours = [(1,), (2, 0), (1,)]
    >>> pibt = PIBT(neighbours, [[2, 1, 0], [1, 0, 1]], [2, 1])
    >>> pibt.step([0, 1], order=[0, 1])
    [1, 2]

    When robot 1 is constrained to stay, robot 0 waits:

    >>> pibt.step([0, 1], order=[0, 1], constraints={1: 1})
    [0, 1]
    """

    __slots__ = (
        "_distances",
        "_goals",
        "_headings",
        "_neighbours",
        "_occ_next",
        "_occ_now",
        "_random",
        "_settled",
        "rotations",
        "swap",
        "tie_penalties",
        "turning_y_size",
    )

    def __init__(
        self,
        neighbours: Sequence[tuple[int, ...]],
        distances: Sequence[Sequence[float]],
        goals: Sequence[int],
        *,
        swap: bool = False,
        rng: random.Random | None = None,
        tie_penalties: bool = False,
        rotations: bool = True,
        turning_y_size: int = 0,
    ) -> None:
        if len(distances) != len(goals):
            raise ValueError(f"{len(distances)} distance lists for {len(goals)} goals")
        if turning_y_size and (swap or rotations):
            raise ValueError("bodies that turn in place need swap and rotations off")
        self._neighbours = list(neighbours)
        self._distances = list(distances)
        self._goals = list(goals)
        self._occ_now = [NO_AGENT] * len(self._neighbours)
        self._occ_next = [NO_AGENT] * len(self._neighbours)
        self._random = rng.random if rng is not None else None
        self._settled: set[int] = set()
        self.swap = swap
        self.tie_penalties = tie_penalties
        self.rotations = rotations
        self.turning_y_size = turning_y_size
        self._headings: Sequence[int] = ()

    @property
    def clean(self) -> bool:
        """Whether no cell is marked occupied (true between calls; for tests).

        >>> PIBT([(1,), (0,)], [[1, 0]], [1]).clean
        True
        """
        return all(a == NO_AGENT for a in self._occ_now) and all(a == NO_AGENT for a in self._occ_next)

    def step(
        self,
        current: Sequence[int],
        order: Sequence[int],
        constraints: Mapping[int, int] | None = None,
    ) -> list[int] | None:
        """The next configuration, or ``None`` when PIBT fails under ``constraints``.

        Parameters
        ----------
        current:
            Every robot's flat cell.
        order:
            Robot indices, highest priority first; every robot must appear.
        constraints:
            Robots whose next cell is fixed: ``{robot: flat cell}``.

        Returns
        -------
        list of int or None
            Every robot's next flat cell (collision-free, constrained robots on
            their constrained cells), or ``None``.

        Examples
        --------
        >>> PIBT([(1,), (0,)], [[1, 0]], [1]).step([0], [0])
        [1]
        """
        target = [NO_CELL] * len(current)
        for robot, cell in (constraints or {}).items():
            target[robot] = cell
        return target if self.generate(current, target, order) else None

    def generate(
        self,
        current: Sequence[int],
        target: list[int],
        order: Sequence[int],
        headings: Sequence[int] = (),
        next_headings: list[int] | None = None,
    ) -> bool:
        """Fill ``target`` (``NO_CELL`` where free, a flat cell where constrained) in place.

        This is ``set_new_config`` of LaCAM: check that the constrained cells
        are free of vertex and swap collisions among themselves, then run PIBT
        for every unconstrained robot in ``order``.

        Parameters
        ----------
        current:
            Every robot's flat cell; cells must be distinct.
        target:
            One entry per robot: its constrained next cell (which must be
            ``current`` or a neighbour of it), or :data:`NO_CELL`. Filled in.
        order:
            Robot indices, highest priority first.
        headings:
            For bodies that turn in place (``turning_y_size``): every robot's
            heading (1-4).
        next_headings:
            For bodies that turn in place: one entry per robot, its constrained
            next heading or 0; filled in with every robot's next heading (a
            moving robot keeps its heading; a staying one waits or turns a quarter).

        Returns
        -------
        bool
            Whether ``target`` now holds a valid next configuration. On
            ``False`` its content is unspecified.

        Examples
        --------
        >>> pibt = PIBT([(1,), (0, 2), (1,)], [[2, 1, 0], [0, 1, 2]], [2, 0])
        >>> target = [NO_CELL, 2]
        >>> pibt.generate([0, 1], target, [0, 1]), target
        (True, [1, 2])
        >>> target = [1, 0]
        >>> pibt.generate([0, 1], target, [0, 1])
        False
        """
        occ_now, occ_next = self._occ_now, self._occ_next
        count = len(current)
        success = True
        goals = self._goals
        self._headings = headings
        for robot in range(count):
            occ_now[current[robot]] = robot
        self._settled = {current[robot] for robot in range(count) if current[robot] == goals[robot]}
        for robot in range(count):
            cell = target[robot]
            if cell == NO_CELL:
                continue
            if occ_next[cell] != NO_AGENT:
                success = False
                break
            other = occ_now[cell]
            if other != NO_AGENT and other != robot and target[other] == current[robot]:
                success = False
                break
            occ_next[cell] = robot
        if success and not self.rotations:
            success = not any(
                self._in_cycle(robot, current, target) for robot in range(count) if target[robot] != NO_CELL
            )
        if success:
            for robot in order:
                if target[robot] == NO_CELL and not self._plan(robot, current, target):
                    success = False
                    break
        for robot in range(count):
            cell = target[robot]
            if cell != NO_CELL:
                occ_next[cell] = NO_AGENT
        if success and self.turning_y_size:
            success = self._act(current, target, next_headings if next_headings is not None else [0] * count)
        for robot in range(count):
            occ_now[current[robot]] = NO_AGENT
        return success

    # -- bodies that turn in place ------------------------------------------------------

    def _act(self, current: Sequence[int], target: list[int], next_headings: list[int]) -> bool:
        """Turn PIBT's cells into actions (class docstring); ``False`` when a constrained forward move is cancelled.

        Constrained robots have their next heading in ``next_headings``
        already; every other entry is filled in. ``target`` ends as every
        robot's cell at the next tick.
        """
        headings, neighbours, y_size, distances = self._headings, self._neighbours, self.turning_y_size, self._distances
        constrained = [heading != 0 for heading in next_headings]
        for robot, cell in enumerate(target):
            if constrained[robot]:
                continue
            here, heading = current[robot], headings[robot]
            facing = turning_action(neighbours, here, heading, cell, distances[robot], y_size)
            next_headings[robot] = facing
            if cell != here and facing != heading:
                target[robot] = here  # turns toward its cell this tick
        return self._cancel_blocked(current, target, constrained)

    def _cancel_blocked(self, current: Sequence[int], target: list[int], constrained: Sequence[bool]) -> bool:
        """Cancel every forward move into a cell whose robot stays; ``False`` if a constrained one is among them."""
        occ_now = self._occ_now
        drives: list[bool | None] = [None] * len(current)  # None: not decided yet
        for first in range(len(current)):
            chain: list[int] = []
            robot, verdict = first, True
            while drives[robot] is None:
                if target[robot] == current[robot] or robot in chain:
                    verdict = False
                    break
                chain.append(robot)
                occupant = occ_now[target[robot]]
                if occupant == NO_AGENT:
                    break
                robot = occupant
            else:
                verdict = bool(drives[robot])
            if not chain and drives[first] is None:
                drives[first] = False
            for robot in chain:
                drives[robot] = verdict
        for robot, drive in enumerate(drives):
            if not drive and target[robot] != current[robot]:
                if constrained[robot]:
                    return False
                target[robot] = current[robot]
        return True

    # -- PIBT proper ------------------------------------------------------------

    def _sorted_candidates(self, robot: int, current: Sequence[int], target: list[int]) -> tuple[list[int], int]:
        """Robot's candidate cells, best first, and the robot to pull (or ``NO_AGENT``)."""
        if self.turning_y_size:
            here = current[robot]
            table = self._distances[robot]
            return turning_candidates(
                self._neighbours, here, self._headings[robot], table, self.turning_y_size, None, self._random
            ), NO_AGENT
        candidates = sorted_candidates(
            self._neighbours,
            current[robot],
            self._distances[robot],
            self._random,
            self._settled if self.tie_penalties else None,
        )
        pulled = NO_AGENT
        if self.swap:
            pulled = self._swap_agent(robot, candidates, current, target)
            if pulled != NO_AGENT:
                candidates.reverse()
        return candidates, pulled

    def _plan(self, root: int, current: Sequence[int], target: list[int]) -> bool:
        """``funcPIBT`` for ``root``, priority inheritance on an explicit stack."""
        occ_now, occ_next = self._occ_now, self._occ_next
        stack: list[tuple[int, list[int], int, int]] = []
        robot = root
        candidates, pulled = self._sorted_candidates(robot, current, target)
        k = 0
        while True:
            here = current[robot]
            child = NO_AGENT
            success = False
            size = len(candidates)
            while k < size:
                cell = candidates[k]
                if occ_next[cell] != NO_AGENT:
                    k += 1
                    continue
                occupant = occ_now[cell]
                if occupant != NO_AGENT and target[occupant] == here:
                    k += 1  # the occupant moves into our cell: taking its cell would swap
                    continue
                if (
                    not self.rotations
                    and occupant != NO_AGENT
                    and occupant != robot
                    and self._leads_to(occupant, robot, current, target)
                ):
                    k += 1  # the robots following from the occupant end in our cell: a rotation
                    continue
                if stack and self.turning_y_size and self._closes_cycle(occupant, cell, target):
                    k += 1
                    continue
                occ_next[cell] = robot
                target[robot] = cell
                if occupant != NO_AGENT and occupant != robot and target[occupant] == NO_CELL:
                    child = occupant  # priority inheritance
                else:
                    success = True
                break
            if child != NO_AGENT:
                stack.append((robot, candidates, k, pulled))
                robot = child
                candidates, pulled = self._sorted_candidates(robot, current, target)
                k = 0
                continue
            if not success:  # no candidate left: stay
                occ_next[here] = robot
                target[robot] = here
            while True:  # return ``success`` to the robots that pushed this one
                if success and k == 0 and pulled != NO_AGENT:
                    self._pull(robot, pulled, current, target)
                if not stack:
                    return success
                robot, candidates, k, pulled = stack.pop()
                if not success:
                    k += 1  # backtrack: the pushed robot could not leave
                    break

    # -- rotations ------------------------------------------------------------------

    def _closes_cycle(self, occupant: int, cell: int, target: list[int]) -> bool:
        """Bodies that turn in place: whether a pushed robot taking ``cell`` could close a cycle (``occupant`` moves).

        The last robot of a cycle to decide was pushed and takes the cell of a
        robot that decided to move (``docs/protocol.md``, "Planning for
        ``turning`` bodies"); the decentralized robots apply the same rule
        (:class:`~mrmp.robot.pibt_robot.PibtRobot`), which needs no knowledge
        of the whole chain.
        """
        return occupant != NO_AGENT and target[occupant] != NO_CELL and target[occupant] != cell

    def _leads_to(self, first: int, robot: int, current: Sequence[int], target: list[int]) -> bool:
        """Whether following moves from ``first`` (each robot into the cell of the next) reach ``robot``.

        ``robot`` taking ``first``'s cell would then close a rotation. The walk
        stops at a robot that stays, has not decided, or moves into a free cell.
        """
        occ_now = self._occ_now
        other, steps = first, len(current)
        while other != NO_AGENT and steps > 0:
            if other == robot:
                return True
            cell = target[other]
            if cell == NO_CELL or cell == current[other]:
                return False
            other = occ_now[cell]
            steps -= 1
        return False

    def _in_cycle(self, robot: int, current: Sequence[int], target: list[int]) -> bool:
        """Whether ``robot``'s constrained move is part of a rotation among the constrained robots."""
        cell = target[robot]
        occupant = self._occ_now[cell]
        return cell != current[robot] and occupant != NO_AGENT and self._leads_to(occupant, robot, current, target)

    # -- swap (LaCAM* engineering, Okumura AAMAS 2024) -----------------------------

    def _pull(self, robot: int, pulled: int, current: Sequence[int], target: list[int]) -> None:
        """Move ``pulled`` into the cell ``robot`` leaves, if both are still possible."""
        here = current[robot]
        if (
            target[pulled] == NO_CELL
            and self._occ_next[here] == NO_AGENT
            and (self.rotations or not self._leads_to(robot, pulled, current, target))
        ):
            self._occ_next[here] = pulled
            target[pulled] = here

    def _swap_agent(self, robot: int, candidates: list[int], current: Sequence[int], target: list[int]) -> int:
        """``is_swap_required_and_possible``: the robot to pull behind ``robot``, or ``NO_AGENT``."""
        occ_now, neighbours, dists = self._occ_now, self._neighbours, self._distances
        settled = self._settled
        best = candidates[0]
        here = current[robot]
        other = occ_now[best]
        if (
            other != NO_AGENT
            and other != robot
            and target[other] == NO_CELL
            and swap_required(neighbours, settled, dists[robot], dists[other], here, current[other])
            and swap_possible(neighbours, settled, current[other], here)
        ):
            return other
        if best != here:  # "clear" operation, as in push and swap
            for cell in neighbours[here]:
                other = occ_now[cell]
                if (
                    other != NO_AGENT
                    and best != current[other]
                    and swap_required(neighbours, settled, dists[other], dists[robot], here, best)
                    and swap_possible(neighbours, settled, best, here)
                ):
                    return other
        return NO_AGENT


def pibt_step(
    grid: Grid,
    config: Sequence[Cell],
    goals: Sequence[Cell],
    *,
    priorities: Sequence[float] | None = None,
    constraints: Mapping[int, Cell] | None = None,
    tables: Sequence[DistanceTable] | None = None,
    swap: bool = False,
    seed: int | None = None,
) -> list[Cell] | None:
    """One PIBT step on cells: every robot's next cell, or ``None`` if PIBT fails.

    A convenience wrapper around :class:`PIBT` (Okumura et al., IJCAI 2019 /
    AIJ 2022); planners that step many times should build a :class:`PIBT`
    once and work on flat indices.

    Parameters
    ----------
    grid:
        The map; entry costs are ignored (distances count moves).
    config:
        Every robot's cell; cells must be free and distinct.
    goals:
        Every robot's goal.
    priorities:
        Higher moves first; ties go to the lower index. By default, robots
        farther from their goals come first (LaCAM's initial priorities).
    constraints:
        Robots whose next cell is fixed, ``{robot index: cell}``; each cell must
        be the robot's own cell or a neighbour of it.
    tables:
        Every robot's distance table to its goal (computed when not given).
    swap:
        Use the swap technique of LaCAM* engineering (Okumura, AAMAS 2024).
    seed:
        Seed of a random tie-break between equally distant cells; ``None``
        breaks ties by neighbour order.

    Returns
    -------
    list of Cell or None
        The next configuration (no vertex or swap collision, constrained robots
        on their cells), or ``None`` when the constraints collide or a robot
        cannot make way for them.

    Raises
    ------
    ValueError
        If the sizes disagree, a cell is not free, two robots share a cell, or
        a constrained cell is not reachable in one move.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> pibt_step(Grid(1, 4), [(0, 0), (0, 1)], [(0, 1), (0, 3)])
    [(0, 1), (0, 2)]
    >>> pibt_step(Grid(1, 2), [(0, 0), (0, 1)], [(0, 1), (0, 0)])  # no room to swap: both wait
    [(0, 0), (0, 1)]
    """
    if len(config) != len(goals):
        raise ValueError(f"{len(config)} cells for {len(goals)} goals")
    for cell in (*config, *goals):
        if not grid.is_free(cell):
            raise ValueError(f"cell {cell} is not a free cell of the grid")
    if len(set(config)) != len(config):
        raise ValueError("two robots share a cell")
    plain = tick_grid(grid)
    if tables is None:
        tables = [distance_table(plain, goal) for goal in goals]
    elif len(tables) != len(goals):
        raise ValueError(f"{len(tables)} distance tables for {len(goals)} goals")
    flat = flat_grid(grid)
    neighbours = flat.neighbours
    current = [flat.index(cell) for cell in config]
    fixed: dict[int, int] = {}
    for robot, cell in (constraints or {}).items():
        index = flat.index(cell)
        if not 0 <= robot < len(config):
            raise ValueError(f"constraint on robot {robot}, which does not exist")
        if index != current[robot] and index not in neighbours[current[robot]]:
            raise ValueError(f"robot {robot} cannot reach {cell} from {config[robot]} in one move")
        fixed[robot] = index
    if priorities is None:
        priorities = [min(table.distance(cell), flat.size) for table, cell in zip(tables, config)]
    elif len(priorities) != len(config):
        raise ValueError(f"{len(priorities)} priorities for {len(config)} robots")
    order = sorted(range(len(config)), key=lambda robot: -priorities[robot])
    pibt = PIBT(
        neighbours,
        [table.as_list() for table in tables],
        [flat.index(goal) for goal in goals],
        swap=swap,
        rng=random.Random(seed) if seed is not None else None,
    )
    result = pibt.step(current, order, fixed)
    return None if result is None else [flat.cell(index) for index in result]
