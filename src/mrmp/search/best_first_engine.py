"""One best-first search engine; Dijkstra, greedy best-first and A* are priority functions.

All three planners of the thesis's chapter 1 list that search (Dijkstra, Best
First, A*) are the same loop: keep an open list ordered by a priority
``f(g, h)``, pop the best node, stop at the goal, otherwise push its
successors. Only the priority differs (Pearl 1984, *Heuristics*, ch. 2-3):

* Dijkstra (1959, "A note on two problems in connexion with graphs"):
  ``f = g``, uniform-cost, optimal, no heuristic.
* greedy best-first (Pearl 1984): ``f = h``, fast but not optimal.
* A* (Hart, Nilsson & Raphael 1968, "A formal basis for the heuristic
  determination of minimum cost paths"): ``f = g + h`` with an admissible and
  consistent ``h``, optimal.

The engine searches one of two state spaces, chosen once by the caller:

* cells, when no heading is given: moving into ``c`` costs
  ``cell_time * cost(c)``;
* ``(cell, heading)`` pairs, when the robot's heading is given (the Khepera III
  only turns right, thesis section 3.3): moving to the neighbour in direction
  ``d`` from heading ``h`` costs ``right_turns(h, d) * turn_time +
  cell_time * cost(neighbour)`` and leaves the robot facing ``d``. With a
  body model (:mod:`mrmp.core.body`) the turns are the body's: a ``turning``
  body turns a quarter either way in one tick, so the move costs
  ``quarter_turns(h, d) * cell_time`` more (the ``(cell, heading)`` search of
  the League of Robot Runners' ``MAPF_T`` model); a ``thesis`` body turns
  right at ``turn_time`` as above; an ``omni`` body's turns cost nothing.

Heuristics (both admissible and consistent, so A* with a closed list returns
optimal paths, Hart et al. 1968, theorems 1-3):

* ``manhattan(cell, goal) * min_cost * cell_time``: every path needs at least
  ``manhattan`` moves, each entering a cell that costs at least ``min_cost``;
  one move changes the manhattan distance by one and costs at least
  ``min_cost * cell_time``, so ``h`` never drops by more than a step costs.
* plus, when heading-aware, ``minimum_right_turns(h, needed) * turn_time``,
  where ``needed`` holds NORTH/SOUTH if the goal's x is above/below and
  EAST/WEST if its y is east/west: every path must move in (so face) each
  needed direction, and :func:`~mrmp.core.heading.minimum_right_turns` is the
  fewest right turns that face them all in any order (for a body turning
  either way, :func:`~mrmp.core.heading.minimum_quarter_turns`, the same
  argument with the quarter-turn count, also a cyclic distance). For consistency: a
  move in direction ``d`` from heading ``h`` costs ``right_turns(h, d)``
  turns, and every direction needed before the move is ``d`` or still needed
  after it. Facing ``d`` first and then the new needed set in its best order
  faces the old set too, and the right-turn count is a cyclic distance (it
  obeys the triangle inequality, so facing a subset never takes more turns);
  hence the bound before the move is at most ``right_turns(h, d)`` plus the
  bound after it.

Ties between equal priorities go to the larger ``g`` (the node nearer the
goal for A*), then to the earlier insertion, so results are reproducible.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> grid = Grid.from_rows(["...", ".@.", "..."])
>>> best_first_search(grid, (0, 0), (2, 2), ASTAR).cost
4.0
>>> best_first_search(grid, (0, 0), (2, 2), DIJKSTRA).path
((0, 0), (1, 0), (2, 0), (2, 1), (2, 2))
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable, Collection, Hashable, Iterable
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Protocol, TypeVar

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell
from mrmp.core.errors import NoPathError
from mrmp.core.heading import HEADINGS, Heading, minimum_quarter_turns, minimum_right_turns, quarter_turns, right_turns
from mrmp.core.scenario import Timing
from mrmp.search.graph import GridMap, check_endpoints
from mrmp.search.result import SearchResult

__all__ = [
    "ASTAR",
    "DIJKSTRA",
    "GREEDY_BEST_FIRST",
    "PriorityFunction",
    "Strategy",
    "a_star_priority",
    "best_first_search",
    "greedy_priority",
    "uniform_cost_priority",
]

PriorityFunction = Callable[[float, float], float]
"""Maps a node's cost so far ``g`` and its heuristic estimate ``h`` to its priority (lower first)."""


def uniform_cost_priority(g: float, h: float) -> float:
    """Dijkstra's priority: the cost so far, ``g`` (Dijkstra 1959).

    >>> uniform_cost_priority(3.0, 7.0)
    3.0
    """
    return g


def greedy_priority(g: float, h: float) -> float:
    """Greedy best-first priority: the estimate to the goal, ``h`` (Pearl 1984).

    >>> greedy_priority(3.0, 7.0)
    7.0
    """
    return h


def a_star_priority(g: float, h: float) -> float:
    """A*'s priority: ``g + h`` (Hart, Nilsson & Raphael 1968).

    >>> a_star_priority(3.0, 7.0)
    10.0
    """
    return g + h


@dataclass(frozen=True)
class Strategy:
    """A best-first search strategy: a name, a priority function, and whether it needs ``h``.

    Attributes
    ----------
    name:
        The planner's name (a key of :data:`mrmp.search.PLANNERS`).
    priority:
        ``f(g, h)``; the open list pops the lowest.
    uses_heuristic:
        When false the engine never computes ``h`` (passes 0).

    Examples
    --------
    >>> ASTAR.priority(1.0, 2.0), DIJKSTRA.uses_heuristic
    (3.0, False)
    """

    name: str
    priority: PriorityFunction
    uses_heuristic: bool = True


DIJKSTRA = Strategy("dijkstra", uniform_cost_priority, uses_heuristic=False)
"""Uniform-cost search (Dijkstra 1959)."""
GREEDY_BEST_FIRST = Strategy("best_first", greedy_priority)
"""Greedy best-first search (Pearl 1984)."""
ASTAR = Strategy("astar", a_star_priority)
"""A* search (Hart, Nilsson & Raphael 1968)."""

# Internally headings are plain ints (1-4): enum members hash in Python code,
# which would slow every dictionary lookup of a (cell, heading) state.
# _TURN_BOUND[heading][sx + 1][sy + 1]: fewest right turns from `heading` that face
# every direction a path must move in, when the goal lies in direction (sx, sy)
# (the signs of goal - cell along x and y).
_X_NEED = {1: {Heading.NORTH}, 0: set(), -1: {Heading.SOUTH}}
_Y_NEED = {1: {Heading.EAST}, 0: set(), -1: {Heading.WEST}}
_TURN_BOUND: list[tuple[tuple[int, ...], ...]] = [()] + [
    tuple(tuple(minimum_right_turns(heading, _X_NEED[sx] | _Y_NEED[sy]) for sy in (-1, 0, 1)) for sx in (-1, 0, 1))
    for heading in HEADINGS
]
_QUARTER_BOUND: list[tuple[tuple[int, ...], ...]] = [()] + [
    tuple(tuple(minimum_quarter_turns(heading, _X_NEED[sx] | _Y_NEED[sy]) for sy in (-1, 0, 1)) for sx in (-1, 0, 1))
    for heading in HEADINGS
]
_TURNS: list[list[int]] = [[]] + [[0] + [right_turns(h, d) for d in HEADINGS] for h in HEADINGS]
_QUARTERS: list[list[int]] = [[]] + [[0] + [quarter_turns(h, d) for d in HEADINGS] for h in HEADINGS]
_DIRECTION_OF: dict[Cell, int] = {heading.delta: int(heading) for heading in HEADINGS}

State = TypeVar("State", bound=Hashable)


class _Model(Protocol[State]):
    """A state space over a grid: start state, successors with step costs, heuristic."""

    start: State

    def cell(self, state: State) -> Cell:
        """The grid cell of ``state``."""
        ...

    def successors(self, state: State) -> Iterable[tuple[State, float]]:
        """The states one move from ``state``, with the move's cost."""
        ...

    def estimate(self, state: State) -> float:
        """A consistent lower bound on the cost from ``state`` to the goal."""
        ...


class _CellModel:
    """States are cells; entering ``c`` costs ``cell_time * cost(c)``."""

    def __init__(self, grid: GridMap, start: Cell, goal: Cell, blocked: AbstractSet[Cell], cell_time: float) -> None:
        self.grid = grid
        self.start = start
        self.goal = goal
        self.blocked = blocked
        self.cell_time = cell_time
        self.unit = grid.min_cost * cell_time

    def cell(self, state: Cell) -> Cell:
        return state

    def successors(self, state: Cell) -> Iterable[tuple[Cell, float]]:
        blocked, cost, cell_time = self.blocked, self.grid.cost, self.cell_time
        return [(n, cell_time * cost(n)) for n in self.grid.neighbours(state) if n not in blocked]

    def estimate(self, state: Cell) -> float:
        return self.unit * (abs(state[0] - self.goal[0]) + abs(state[1] - self.goal[1]))


class _HeadingModel:
    """States are ``(cell, heading number)``; a move charges the turns toward it, then the entered cell.

    The turns are right turns at ``timing.turn_time`` each without a body
    model, else the body's turns at the body's time per quarter turn.
    """

    def __init__(
        self,
        grid: GridMap,
        start: Cell,
        goal: Cell,
        blocked: AbstractSet[Cell],
        heading: Heading,
        timing: Timing,
        body: BodyModel | None = None,
    ) -> None:
        self.grid = grid
        self.start = (start, int(Heading(heading)))
        self.goal = goal
        self.blocked = blocked
        self.cell_time = timing.cell_time
        self.unit = grid.min_cost * timing.cell_time
        if body is None:
            self.turn_time = timing.turn_time
        else:
            self.turn_time = body.turn_ticks(timing.turn_time, timing.cell_time) * timing.cell_time
        both_ways = body is not None and not body.clockwise_only
        self.turn_counts = _QUARTERS if both_ways else _TURNS
        self.turn_bound = _QUARTER_BOUND if both_ways else _TURN_BOUND

    def cell(self, state: tuple[Cell, int]) -> Cell:
        return state[0]

    def successors(self, state: tuple[Cell, int]) -> Iterable[tuple[tuple[Cell, int], float]]:
        cell, heading = state
        x, y = cell
        turns = self.turn_counts[heading]
        blocked, cost, cell_time, turn_time = self.blocked, self.grid.cost, self.cell_time, self.turn_time
        result = []
        for n in self.grid.neighbours(cell):
            if n in blocked:
                continue
            direction = _DIRECTION_OF.get((n[0] - x, n[1] - y))
            if direction is None:
                raise ValueError(f"cells {cell} and {n} are not adjacent")
            result.append(((n, direction), turns[direction] * turn_time + cell_time * cost(n)))
        return result

    def estimate(self, state: tuple[Cell, int]) -> float:
        (x, y), heading = state
        dx, dy = self.goal[0] - x, self.goal[1] - y
        sx = (dx > 0) - (dx < 0)
        sy = (dy > 0) - (dy < 0)
        return self.unit * (abs(dx) + abs(dy)) + self.turn_time * self.turn_bound[heading][sx + 1][sy + 1]


def _search(model: _Model[State], goal: Cell, strategy: Strategy) -> tuple[list[State], float, int]:
    """The best-first loop: the states from start to a goal state, the cost, the expansions."""
    priority = strategy.priority
    estimate = model.estimate if strategy.uses_heuristic else None
    successors = model.successors
    cell_of = model.cell
    start = model.start
    counter = itertools.count()
    best_g: dict[State, float] = {start: 0.0}
    parent: dict[State, State | None] = {start: None}
    closed: set[State] = set()
    h0 = estimate(start) if estimate is not None else 0.0
    # Entries: (priority, -g, insertion order, g, state); the unique insertion
    # order makes ties deterministic and keeps states out of comparisons.
    open_list: list[tuple[float, float, int, float, State]] = [(priority(0.0, h0), -0.0, next(counter), 0.0, start)]
    push, pop = heapq.heappush, heapq.heappop
    expansions = 0
    while open_list:
        _, _, _, g, state = pop(open_list)
        if state in closed or g > best_g[state]:
            continue  # a stale entry: the state was expanded, or re-queued with a smaller g
        if cell_of(state) == goal:
            states = [state]
            previous = parent[state]
            while previous is not None:
                states.append(previous)
                previous = parent[previous]
            states.reverse()
            return states, g, expansions
        closed.add(state)
        expansions += 1
        for successor, step in successors(state):
            if successor in closed:
                continue
            new_g = g + step
            old_g = best_g.get(successor)
            if old_g is not None and new_g >= old_g:
                continue
            best_g[successor] = new_g
            parent[successor] = state
            h = estimate(successor) if estimate is not None else 0.0
            push(open_list, (priority(new_g, h), -new_g, next(counter), new_g, successor))
    raise NoPathError(f"no path: goal {goal} cannot be reached (searched {expansions} states)")


def best_first_search(
    grid: GridMap,
    start: Cell,
    goal: Cell,
    strategy: Strategy,
    *,
    blocked: Collection[Cell] = frozenset(),
    heading: Heading | None = None,
    timing: Timing | None = None,
    body: BodyModel | None = None,
) -> SearchResult:
    """Search ``grid`` from ``start`` to ``goal`` in the order ``strategy`` gives.

    Parameters
    ----------
    grid:
        The grid; moves follow ``grid.neighbours``.
    start, goal:
        The path's ends.
    strategy:
        :data:`DIJKSTRA`, :data:`GREEDY_BEST_FIRST`, :data:`ASTAR` or any
        :class:`Strategy`.
    blocked:
        Extra cells to treat as obstacles (other robots); ``start`` is always
        allowed.
    heading:
        The robot's heading on ``start``. When given, the search runs over
        ``(cell, heading)`` states, charges ``timing.turn_time`` per right turn
        and returns the headings along the path.
    timing:
        Cell and turn durations; ``Timing()`` when omitted. Without a heading
        only ``cell_time`` is used (it scales every step).
    body:
        The body model whose turns a heading-aware search charges (module
        docstring); right turns at ``timing.turn_time`` when omitted.

    Returns
    -------
    SearchResult
        The path (start and goal included), its cost, the number of expanded
        states and, when heading-aware, the headings.

    Raises
    ------
    NoPathError
        If ``start`` or ``goal`` is not free, ``goal`` is in ``blocked``, or no
        path exists.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> from mrmp.core.heading import Heading
    >>> result = best_first_search(Grid(3, 3), (0, 0), (1, 1), ASTAR, heading=Heading.EAST)
    >>> result.path, [h.name for h in result.headings], result.cost
    (((0, 0), (0, 1), (1, 1)), ['EAST', 'EAST', 'NORTH'], 3.5)

    A ``turning`` body facing EAST turns a quarter left, one tick, instead of three right turns:

    >>> from mrmp.core.body import body_model
    >>> best_first_search(Grid(3, 3), (0, 0), (2, 0), ASTAR, heading=Heading.EAST, body=body_model("turning")).cost
    3.0
    >>> best_first_search(Grid(3, 3), (0, 0), (2, 0), ASTAR, heading=Heading.EAST).cost
    3.5
    """
    if not isinstance(blocked, AbstractSet):
        blocked = frozenset(blocked)
    check_endpoints(grid, start, goal, blocked)
    if heading is None:
        cell_time = 1.0 if timing is None else timing.cell_time
        cells, cost, expansions = _search(_CellModel(grid, start, goal, blocked, cell_time), goal, strategy)
        return SearchResult(path=tuple(cells), cost=cost, expansions=expansions)
    model = _HeadingModel(grid, start, goal, blocked, heading, timing or Timing(), body)
    states, cost, expansions = _search(model, goal, strategy)
    return SearchResult(
        path=tuple(cell for cell, _ in states),
        cost=cost,
        expansions=expansions,
        headings=tuple(Heading(h) for _, h in states),
    )
