"""Space-time A*: plan one robot through time around reservations and constraints.

Space-time A* (Silver 2005, "Cooperative Pathfinding", AIIDE) searches states
``(cell, t)``: each tick a robot waits or moves to a free 4-neighbour, and a
:class:`Reservations` table says which states and moves other robots (or a
constraint-tree node of CBS) forbid:

* a *vertex* entry ``(cell, t)``: the robot must not be on ``cell`` at tick
  ``t``;
* an *edge* entry ``(u, v, t)``: the robot must not move from ``u`` (tick
  ``t - 1``) to ``v`` (tick ``t``); prioritized planning stores the reverse of
  every move of an earlier robot here, which forbids swaps;
* a *parking* entry ``cell -> T``: ``cell`` is occupied at every tick from
  ``T`` on (a robot that has arrived at its goal and stays there);
* a *move* entry ``(v, t) -> u``: another robot moves from ``u`` (tick
  ``t - 1``) into ``v`` (tick ``t``). The robot must not make a move that
  closes a *rotation* with them: ``u' -> v'`` at tick ``t`` is forbidden when
  the robots entering cells at ``t`` form a chain from ``v'`` into ``u'``
  (the occupant of ``v'`` moves on into the cell of the next, and so on, and
  the last enters ``u'``). Robots on such a cycle, each entering the cell the
  next one leaves at the same tick, can only be executed all at once; robots
  moving one at a time, each waiting for the cell ahead to be vacated
  (:mod:`mrmp.centralized.dependencies`), never start. Following a robot (entering
  the cell it leaves at the same tick) is allowed otherwise.

A path ends when the robot reaches its goal and may stay there forever: its
arrival tick must come after every vertex entry on its goal (someone passing
its goal later), and no one may be parked on its goal. Prioritized planning
(Silver 2005; Erdmann & Lozano-Perez 1987, "On multiple moving objects",
Algorithmica) passes the paths of the robots planned before; Conflict-Based
Search (Sharon et al. 2015) passes its negative constraints.

**Search.** A* (Hart, Nilsson & Raphael 1968) on ``f = max(t + h, T_goal)``,
where ``h`` is the exact distance in ticks to the goal on the static grid
(:func:`mrmp.search.distance.distance_table` on the grid without cell costs:
the planners count ticks, not entry costs) and ``T_goal`` is the earliest tick
at which the robot may settle on its goal. Both parts are consistent, so the
first goal state popped is a path of least arrival tick. After the last tick
``T_last`` mentioned by any entry the world is static, so all states of one
cell with ``t > T_last`` are merged: the search is finite even without a
horizon, and an exhausted search proves that no path exists. Ties on ``f`` go
to fewer hits of an optional ``avoid`` table (CBS's conflict-avoidance table,
Standley 2010), then to smaller ``h``, then to generation order: the result is
deterministic.

**Heading-aware mode** (``heading_aware=True``): states are
``(cell, heading, t)`` and each tick the robot does one of: wait, turn right in
place (heading ``h`` becomes ``h + 1`` mod 4, thesis section 3.3), or move one
cell forward into the cell ahead. So one tick is one move *or* one right turn,
and a robot changes direction only after spending ticks turning in place. The
heuristic is the exact static distance over ``(cell, heading)`` states
(:func:`heading_distance_table`). Reservations still speak of cells: a robot
turning in place occupies its cell like a waiting one. With ``both_ways`` a
robot may also turn a quarter counter-clockwise in a tick: the ``turning`` body
(LoRR's ``MAPF_T``, :mod:`mrmp.core.body`), whose following rule (a robot may
enter a cell as its occupant drives out of it, never round a cycle) is the one
the move entries above enforce.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> grid = Grid.from_rows(["...", "...", "..."])
>>> reservations = Reservations()
>>> reservations.forbid_vertex((0, 1), 1)
>>> result = space_time_astar(grid, (0, 0), (0, 2), reservations)
>>> result.status, result.path
('found', ((0, 0), (0, 0), (0, 1), (0, 2)))
>>> blocked = Reservations()
>>> blocked.park((0, 1), 0)
>>> space_time_astar(Grid.from_rows(["..."]), (0, 0), (0, 2), blocked).status
'unreachable'
"""

from __future__ import annotations

import heapq
import math
import time
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache

from mrmp.centralized.plan import tick_grid
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, Heading
from mrmp.search.distance import DistanceTable, distance_table

__all__ = [
    "SEARCH_STATUSES",
    "Reservations",
    "SpaceTimeResult",
    "heading_distance_table",
    "hop_distance_table",
    "space_time_astar",
]

SEARCH_STATUSES = ("found", "unreachable", "horizon", "deadline", "expansions")
"""How a space-time search ends: a path was ``found``; the goal is
``unreachable`` under the reservations (proved: the search was exhausted);
the ``horizon`` ``max_time`` cut the search before a path was found; the
``deadline`` passed; the ``expansions`` limit was reached."""

_DEADLINE_CHECK_EVERY = 512
"""Expansions between two reads of the clock."""


class Reservations:
    """Forbidden states and moves for one robot: vertex, edge and parking entries.

    See the module docstring for the meaning of each kind of entry.

    Examples
    --------
    >>> table = Reservations()
    >>> table.reserve_path([(0, 0), (0, 1), (0, 2)])
    >>> table.blocks((0, 1), 1), table.blocks((0, 2), 7), table.blocks((0, 2), 1)
    (True, True, False)
    >>> table.forbids_move((0, 2), (0, 1), 2)   # a swap with the reserved robot
    True
    >>> table.last_time, table.last_vertex_time((0, 1))
    (2, 1)
    """

    __slots__ = ("_last_vertex", "edge", "entering", "last_time", "parked", "vertex")

    def __init__(self) -> None:
        self.vertex: set[tuple[Cell, int]] = set()
        self.edge: set[tuple[Cell, Cell, int]] = set()
        self.parked: dict[Cell, int] = {}
        self.entering: dict[tuple[Cell, int], Cell] = {}
        """Move entries: ``(cell, t) -> the cell at t - 1 of the robot entering cell at t``."""
        self._last_vertex: dict[Cell, int] = {}
        self.last_time = -1
        """The largest tick any entry mentions (-1 when empty)."""

    @classmethod
    def from_entries(
        cls,
        vertex: Iterable[tuple[Cell, int]] = (),
        edge: Iterable[tuple[Cell, Cell, int]] = (),
        parked: Iterable[tuple[Cell, int]] = (),
    ) -> Reservations:
        """A table holding the given entries.

        >>> Reservations.from_entries(vertex=[((1, 1), 3)]).blocks((1, 1), 3)
        True
        """
        table = cls()
        for cell, tick in vertex:
            table.forbid_vertex(cell, tick)
        for source, target, tick in edge:
            table.forbid_edge(source, target, tick)
        for cell, tick in parked:
            table.park(cell, tick)
        return table

    def forbid_vertex(self, cell: Cell, tick: int) -> None:
        """Forbid standing on ``cell`` at ``tick``."""
        self.vertex.add((cell, tick))
        if tick > self._last_vertex.get(cell, -1):
            self._last_vertex[cell] = tick
        self.last_time = max(self.last_time, tick)

    def forbid_edge(self, source: Cell, target: Cell, tick: int) -> None:
        """Forbid moving from ``source`` at ``tick - 1`` to ``target`` at ``tick``."""
        self.edge.add((source, target, tick))
        self.last_time = max(self.last_time, tick)

    def park(self, cell: Cell, tick: int) -> None:
        """Mark ``cell`` occupied at every tick from ``tick`` on (keeps the earliest)."""
        if tick < self.parked.get(cell, math.inf):
            self.parked[cell] = tick
        self.last_time = max(self.last_time, tick)

    def record_move(self, source: Cell, target: Cell, tick: int) -> None:
        """Record that another robot moves ``source -> target`` arriving at ``tick`` (a move entry)."""
        self.entering[(target, tick)] = source
        self.last_time = max(self.last_time, tick)

    def reserve_path(self, path: Sequence[Cell]) -> None:
        """Reserve a whole path of another robot, which then stays on its last cell forever.

        Adds a vertex entry per tick, an edge entry for the reverse of every
        move (forbidding swaps), a move entry for every move (forbidding the
        rotations that would close on it) and a parking entry on the last cell
        from the tick the path ends.
        """
        last = len(path) - 1
        for tick in range(last):
            self.forbid_vertex(path[tick], tick)
        for tick in range(1, last + 1):
            if path[tick] != path[tick - 1]:
                self.forbid_edge(path[tick], path[tick - 1], tick)
                self.record_move(path[tick - 1], path[tick], tick)
        if last >= 0:
            self.park(path[last], last)

    def closes_rotation(self, source: Cell, target: Cell, tick: int) -> bool:
        """Whether the move ``source -> target`` arriving at ``tick`` closes a cycle with the move entries.

        Walks back from ``source``: the robot entering it at ``tick`` came from
        some cell, the robot entering that one came from another, and so on;
        the move closes a cycle when the walk reaches ``target`` (two robots:
        a swap, which edge entries forbid as well).

        >>> table = Reservations()
        >>> table.reserve_path([(0, 0), (0, 1)])
        >>> table.reserve_path([(0, 1), (1, 1)])
        >>> table.reserve_path([(1, 1), (1, 0)])
        >>> table.closes_rotation((1, 0), (0, 0), 1), table.closes_rotation((1, 0), (0, 0), 2)
        (True, False)
        """
        entering = self.entering
        cell = source
        for _ in range(len(entering)):
            previous = entering.get((cell, tick))
            if previous is None:
                return False
            if previous == target:
                return True
            cell = previous
        return False

    def blocks(self, cell: Cell, tick: int) -> bool:
        """Whether standing on ``cell`` at ``tick`` is forbidden."""
        return (cell, tick) in self.vertex or self.parked.get(cell, math.inf) <= tick

    def forbids_move(self, source: Cell, target: Cell, tick: int) -> bool:
        """Whether the move ``source -> target`` arriving at ``tick`` is forbidden (edge entries only)."""
        return (source, target, tick) in self.edge

    def last_vertex_time(self, cell: Cell) -> int:
        """The last tick at which a vertex entry forbids ``cell`` (-1 if none)."""
        return self._last_vertex.get(cell, -1)

    def __len__(self) -> int:
        return len(self.vertex) + len(self.edge) + len(self.parked) + len(self.entering)

    def __repr__(self) -> str:
        return (
            f"<Reservations {len(self.vertex)} vertex, {len(self.edge)} edge, {len(self.parked)} parked, "
            f"{len(self.entering)} moves>"
        )


@dataclass(frozen=True)
class SpaceTimeResult:
    """The outcome of one space-time search.

    Attributes
    ----------
    status:
        One of :data:`SEARCH_STATUSES`.
    path:
        When found: one cell per tick from the start (tick 0) to the tick the
        robot settles on its goal; ``None`` otherwise.
    headings:
        In heading-aware mode, the heading at each tick of ``path``.
    expansions:
        States taken from the open list and expanded.
    """

    status: str
    path: tuple[Cell, ...] | None
    headings: tuple[Heading, ...] | None
    expansions: int

    @property
    def found(self) -> bool:
        """Whether a path was found."""
        return self.status == "found"

    @property
    def cost(self) -> int:
        """The arrival tick (path length minus one).

        Raises
        ------
        ValueError
            If no path was found.
        """
        if self.path is None:
            raise ValueError(f"no path ({self.status})")
        return len(self.path) - 1


def hop_distance_table(grid: Grid, goal: Cell) -> DistanceTable:
    """The number of moves from every cell to ``goal``, ignoring entry costs.

    >>> hop_distance_table(Grid(2, 2, costs={(0, 1): 9.0}), (0, 1)).distance((1, 0))
    2.0
    """
    return distance_table(tick_grid(grid), goal)


@lru_cache(maxsize=64)
def heading_distance_table(grid: Grid, goal: Cell, both_ways: bool = False) -> dict[tuple[Cell, Heading], int]:
    """Ticks from every ``(cell, heading)`` to ``goal`` under the turn model, on the static grid.

    One tick moves one cell ahead or turns right once (``both_ways``: or left
    once); the goal may be reached facing any heading. Computed by a
    breadth-first search backwards from the four goal states (Moore 1959).
    States that cannot reach the goal are left out. Entry costs are ignored.
    Cached per grid, goal and turn model.

    >>> table = heading_distance_table(Grid(1, 3), (0, 2))
    >>> table[((0, 0), Heading.EAST)], table[((0, 0), Heading.NORTH)], table[((0, 0), Heading.SOUTH)]
    (2, 3, 5)
    >>> heading_distance_table(Grid(1, 3), (0, 2), both_ways=True)[((0, 0), Heading.SOUTH)]
    3
    """
    distances: dict[tuple[Cell, Heading], int] = {}
    queue: deque[tuple[Cell, Heading]] = deque()
    for heading in HEADINGS:
        distances[(goal, heading)] = 0
        queue.append((goal, heading))
    while queue:
        state = queue.popleft()
        cell, heading = state
        d = distances[state] + 1
        dx, dy = heading.delta
        behind = (cell[0] - dx, cell[1] - dy)
        predecessors = [(Heading((int(heading) - 2) % 4 + 1), cell)]  # turned right into `heading`
        if both_ways:
            predecessors.append((Heading(int(heading) % 4 + 1), cell))  # turned left into `heading`
        if grid.is_free(behind):
            predecessors.append((heading, behind))
        for previous_heading, previous_cell in predecessors:
            key = (previous_cell, previous_heading)
            if key not in distances:
                distances[key] = d
                queue.append(key)
    return distances


def space_time_astar(
    grid: Grid,
    start: Cell,
    goal: Cell,
    reservations: Reservations | None = None,
    *,
    heading_aware: bool = False,
    heading: Heading = Heading.NORTH,
    both_ways: bool = False,
    max_time: int | None = None,
    avoid: Reservations | None = None,
    deadline: float | None = None,
    max_expansions: int | None = None,
) -> SpaceTimeResult:
    """Plan one robot from ``start`` to ``goal`` through time, respecting ``reservations``.

    Space-time A* (Silver 2005, "Cooperative Pathfinding"); see the module
    docstring for the state space, the goal condition and the search.

    Parameters
    ----------
    grid:
        The map; only its free cells matter (entry costs are ignored, one move
        or one wait takes one tick).
    start, goal:
        Free cells.
    reservations:
        What the robot must avoid; ``None`` for nothing.
    heading_aware:
        Plan states ``(cell, heading, t)``, where one tick is one move forward,
        one right turn in place, or a wait.
    heading:
        The robot's heading at tick 0 (heading-aware mode only).
    both_ways:
        Heading-aware mode: a tick may also be a left turn (``turning`` bodies).
    max_time:
        The horizon: no state later than this tick is searched; ``None`` for
        no horizon (the search is still finite, see the module docstring).
    avoid:
        Soft reservations: among states of equal ``f``, fewer hits of these
        entries go first (a conflict-avoidance table; moves closing a
        rotation with its move entries count as hits). Never changes the
        arrival tick.
    deadline:
        A :func:`time.perf_counter` value after which the search gives up.
    max_expansions:
        Give up after this many expansions.

    Returns
    -------
    SpaceTimeResult
        ``status == "found"`` with the path of least arrival tick, or why not.

    Raises
    ------
    ValueError
        If ``start`` or ``goal`` is not a free cell.

    Examples
    --------
    A robot whose goal another robot crosses at tick 3 cannot settle there earlier:

    >>> grid = Grid.from_rows([".....", "....."])
    >>> crossing = Reservations.from_entries(vertex=[((0, 2), 3)])
    >>> result = space_time_astar(grid, (0, 0), (0, 2), crossing)
    >>> result.cost, result.path[3] != (0, 2), result.path[-1]
    (4, True, (0, 2))

    A horizon too short for any path:

    >>> space_time_astar(grid, (0, 0), (0, 4), max_time=3).status
    'horizon'

    A deadline already passed:

    >>> space_time_astar(grid, (0, 0), (0, 4), deadline=0.0).status
    'deadline'

    Heading-aware: facing NORTH, going EAST costs one right turn first:

    >>> result = space_time_astar(grid, (0, 0), (0, 2), heading_aware=True)
    >>> result.path
    ((0, 0), (0, 0), (0, 1), (0, 2))
    >>> [h.name for h in result.headings]
    ['NORTH', 'EAST', 'EAST', 'EAST']

    Facing EAST, a body that turns both ways turns left once toward NORTH, not right three times:

    >>> turning = space_time_astar(grid, (0, 0), (1, 0), heading_aware=True, heading=Heading.EAST, both_ways=True)
    >>> [h.name for h in turning.headings]
    ['EAST', 'NORTH', 'NORTH']
    """
    if not grid.is_free(start):
        raise ValueError(f"start {start} is not a free cell")
    if not grid.is_free(goal):
        raise ValueError(f"goal {goal} is not a free cell")
    if deadline is not None and time.perf_counter() > deadline:  # before the distance table, as long as a search
        return SpaceTimeResult("deadline", None, None, 0)
    search = _SpaceTimeSearch(grid, goal, reservations or Reservations(), avoid, heading_aware, both_ways)
    start_facing = int(heading) if heading_aware else 0
    if search.hopeless(start, start_facing):
        return SpaceTimeResult("unreachable", None, None, 0)
    return search.run(start, start_facing, max_time, deadline, max_expansions)


class _SpaceTimeSearch:
    """One space-time A* search (the module docstring): its estimate, move rules and open list.

    States are records ``(cell, facing, tick, parent)`` kept in parallel lists;
    the open list holds ``(f, conflicts with avoid, h, record)``, where ``f``
    is at least the first tick the goal may be kept for good.
    """

    def __init__(
        self,
        grid: Grid,
        goal: Cell,
        reservations: Reservations,
        avoid: Reservations | None,
        heading_aware: bool,
        both_ways: bool = False,
    ) -> None:
        self.grid = grid
        self.goal = goal
        self.reservations = reservations
        self.avoid = avoid
        self.heading_aware = heading_aware
        self.both_ways = both_ways
        if heading_aware:
            heading_table = heading_distance_table(grid, goal, both_ways)
            self.estimate = lambda cell, facing: heading_table.get((cell, Heading(facing)), math.inf)
        else:
            hop = hop_distance_table(grid, goal).distance
            self.estimate = lambda cell, facing: hop(cell)
        self.earliest_final = reservations.last_vertex_time(goal) + 1
        self.static_from = max(reservations.last_time, avoid.last_time if avoid is not None else -1) + 1
        self.cells: list[Cell] = []
        self.facings: list[int] = []
        self.ticks: list[int] = []
        self.parents: list[int] = []
        self.open_list: list[tuple[float, int, float, int]] = []
        self.best: dict[tuple[Cell, int, int], tuple[int, int]] = {}
        self.closed: set[tuple[Cell, int, int]] = set()

    def hopeless(self, start: Cell, facing: int) -> bool:
        """Whether the search cannot succeed: the goal is parked on, the start taken, or the goal out of reach."""
        reservations = self.reservations
        return self.goal in reservations.parked or reservations.blocks(start, 0) or self.estimate(start, facing) == math.inf

    def run(
        self, start: Cell, facing: int, max_time: int | None, deadline: float | None, max_expansions: int | None
    ) -> SpaceTimeResult:
        """Expand states best first until the goal is kept for good, or a limit or the state space ends."""
        h0 = self.estimate(start, facing)
        self._record(start, facing, 0, -1)
        self.open_list.append((max(h0, self.earliest_final), 0, h0, 0))
        self.best[(start, facing, 0)] = (0, 0)
        goal, earliest_final, static_from, closed = self.goal, self.earliest_final, self.static_from, self.closed
        cells, facings, ticks, open_list = self.cells, self.facings, self.ticks, self.open_list
        expansions = 0
        cut_by_horizon = False
        pop = heapq.heappop
        while open_list:
            _, conflicts, _, index = pop(open_list)
            cell, facing, tick = cells[index], facings[index], ticks[index]
            key = (cell, facing, min(static_from, tick))
            if key in closed:
                continue
            closed.add(key)
            expansions += 1
            if cell == goal and tick >= earliest_final:
                return _finish(cells, facings, self.parents, index, self.heading_aware, expansions)
            if max_expansions is not None and expansions >= max_expansions:
                return SpaceTimeResult("expansions", None, None, expansions)
            if deadline is not None and expansions % _DEADLINE_CHECK_EVERY == 0 and time.perf_counter() > deadline:
                return SpaceTimeResult("deadline", None, None, expansions)
            if max_time is not None and tick + 1 > max_time:
                cut_by_horizon = True
                continue
            self._expand(index, conflicts)
        return SpaceTimeResult("horizon" if cut_by_horizon else "unreachable", None, None, expansions)

    def _moves(self, cell: Cell, facing: int) -> list[tuple[Cell, int]]:
        """The ``(cell, facing)`` pairs one tick can lead to: wait, (turn right, turn left,) move."""
        if self.heading_aware:
            ahead = Heading(facing).ahead(cell)
            moves = [(cell, facing), (cell, facing % 4 + 1)]
            if self.both_ways:
                moves.append((cell, (facing - 2) % 4 + 1))
            if self.grid.is_free(ahead):
                moves.append((ahead, facing))
            return moves
        moves = [(cell, 0)]
        moves.extend((n, 0) for n in self.grid.neighbours(cell))
        return moves

    def _expand(self, index: int, conflicts: int) -> None:
        """Offer every allowed successor of state ``index`` to the open list."""
        cell, facing, next_tick = self.cells[index], self.facings[index], self.ticks[index] + 1
        next_key_tick = min(self.static_from, next_tick)
        closed, best, estimate, avoid = self.closed, self.best, self.estimate, self.avoid
        for next_cell, next_facing in self._moves(cell, facing):
            if _forbidden(self.reservations, cell, next_cell, next_tick):
                continue
            next_key = (next_cell, next_facing, next_key_tick)
            if next_key in closed:
                continue
            h = estimate(next_cell, next_facing)
            if h == math.inf:
                continue
            next_conflicts = conflicts
            if avoid is not None:
                next_conflicts += _conflicts(avoid, cell, next_cell, next_tick)
            rank = (next_tick, next_conflicts)
            previous = best.get(next_key)
            if previous is not None and previous <= rank:
                continue
            best[next_key] = rank
            self._record(next_cell, next_facing, next_tick, index)
            heapq.heappush(self.open_list, (max(self.earliest_final, next_tick + h), next_conflicts, h, len(self.cells) - 1))

    def _record(self, cell: Cell, facing: int, tick: int, parent: int) -> None:
        self.cells.append(cell)
        self.facings.append(facing)
        self.ticks.append(tick)
        self.parents.append(parent)


def _forbidden(reservations: Reservations, cell: Cell, next_cell: Cell, next_tick: int) -> bool:
    """Whether ``reservations`` forbid the move ``cell -> next_cell`` arriving at ``next_tick``."""
    if (next_cell, next_tick) in reservations.vertex or reservations.parked.get(next_cell, math.inf) <= next_tick:
        return True
    if next_cell == cell:
        return False
    if (cell, next_cell, next_tick) in reservations.edge:
        return True
    # someone enters our cell as we leave it: no cycle of such moves
    return (cell, next_tick) in reservations.entering and reservations.closes_rotation(cell, next_cell, next_tick)


def _conflicts(avoid: Reservations, cell: Cell, next_cell: Cell, next_tick: int) -> int:
    """How many of ``avoid``'s reservations the move ``cell -> next_cell`` at ``next_tick`` collides with."""
    count = 0
    if (next_cell, next_tick) in avoid.vertex or avoid.parked.get(next_cell, math.inf) <= next_tick:
        count += 1
    if next_cell != cell and (cell, next_cell, next_tick) in avoid.edge:
        count += 1
    if next_cell != cell and (cell, next_tick) in avoid.entering and avoid.closes_rotation(cell, next_cell, next_tick):
        count += 1
    return count


def _finish(
    cells: list[Cell], facings: list[int], parents: list[int], index: int, heading_aware: bool, expansions: int
) -> SpaceTimeResult:
    """Follow parent links back from state ``index`` to the start."""
    path: list[Cell] = []
    faced: list[int] = []
    while index >= 0:
        path.append(cells[index])
        faced.append(facings[index])
        index = parents[index]
    path.reverse()
    faced.reverse()
    headings = tuple(Heading(value) for value in faced) if heading_aware else None
    return SpaceTimeResult("found", tuple(path), headings, expansions)
