"""Conflict-Based Search: optimal sum of costs for a fleet on a grid.

Conflict-Based Search (Sharon, Stern, Felner & Sturtevant, "Conflict-based
search for optimal multi-agent pathfinding", Artificial Intelligence 219, 2015)
searches a *constraint tree*. Each node holds a set of constraints per robot
and one path per robot, each the cheapest path that respects that robot's
constraints (found by :func:`~mrmp.centralized.space_time_astar.space_time_astar`).
The high level is best-first on the node's sum of costs (a lower bound ``f``
on it, with the improvements below):

1. take the node of least ``f`` (ties: fewer conflicts, then the older node,
   so the search is deterministic);
2. pick a conflict (the first in time, or see the improvements): a *vertex* conflict (two robots in one cell
   at tick ``t``), an *edge* conflict (two robots swapping cells at tick
   ``t``) or a *rotation* conflict (three or more robots on a cycle of cells,
   each entering at tick ``t`` the cell the next one leaves); robots that have
   arrived stay on their goals, so a robot crossing a
   parked one is a vertex conflict at a tick after the parked robot's arrival;
3. no conflict: the node's paths are an optimal plan; otherwise split the node
   into children, each forbidding the conflict to one of its robots (vertex
   ``(cell, t)`` or edge ``(u, v, t)``; for a rotation, one child per robot
   on the cycle, forbidding it its move ``u -> v`` at ``t``), and replan that
   robot.

**Rotations** are conflicts because the plans are executed by robots that
move one at a time, each entering a cell only once its occupant has left
(:mod:`mrmp.centralized.dependencies`): on a cycle nobody can start. The split
is sound and complete in the usual sense: a plan without that rotation omits
the move of at least one of its robots at ``t``, so it satisfies one of the
children's constraints. CBS therefore returns a plan of least sum of costs
*among rotation-free plans* (which may cost more than the classic optimum,
where rotations are free).

The low level breaks ties between paths of equal length by the fewest
conflicts with the other robots' current paths (the conflict-avoidance table
of Standley 2010).

**Improvements** (``improved=True``, the default; all keep optimality):

* *conflict prioritization* (ICBS: Boyarski, Felner, Stern, Sharon, Tolpin,
  Betzalel & Shimony, "ICBS: Improved Conflict-Based Search Algorithm for
  Multi-Agent Pathfinding", IJCAI 2015): split a *cardinal* conflict (every
  cheapest path of both robots has it, read off their multi-valued decision
  diagrams, :func:`mdd_layers`) before a semi-cardinal one, before the rest
  (rotation conflicts are counted with the rest);
* the *conflict-graph heuristic* (Felner, Li, Boyarski, Ma, Cohen, Kumar &
  Koenig, "Adding Heuristics to Conflict-Based Search for Multi-Agent Path
  Finding", ICAPS 2018): robots joined by a cardinal conflict form a graph, and
  each edge costs at least one more tick, so the size of a minimum vertex
  cover (:func:`min_vertex_cover_size`) is added to the node's bound;
  computed lazily when a node is first taken from the open list, and a child
  inherits its parent's bound;
* *bypass* (Boyarski, Felner, Sharon & Stern, "Don't Split, Try To Work It
  Out: Bypassing Conflicts in Multi-Agent Pathfinding", ICAPS 2015): a child
  path as cheap as the parent's and with fewer conflicts replaces the parent's
  path instead of splitting.

``improved=False`` runs CBS exactly as published in 2015. Robots crossing in
corridors remain exponential for both (symmetry reasoning, Li et al. 2020, is
not implemented): there the limits apply.

**Costs** are the standard MAPF ones (:mod:`mrmp.centralized.plan`): each
robot's first tick from which it stays at its goal, summed. With
``heading_aware=True`` one tick is one move forward, one right turn in place or
a wait (see :mod:`mrmp.centralized.space_time_astar`), and CBS is optimal for
that time model; with ``body="turning"`` (LoRR's ``MAPF_T``,
:mod:`mrmp.core.body`) a tick may also be a left turn, and CBS is optimal for
those bodies.

**Limits and statuses.** The search stops at ``max_nodes`` generated
constraint-tree nodes or after ``time_limit_s`` seconds, whichever comes first,
with status ``"limit"`` and a message naming the limit. CBS cannot in general
prove that an instance has no solution before its limits: an unsolvable
instance normally ends with ``"limit"``. It reports ``"infeasible"`` only when
it has a proof: a robot's goal is not connected to its start; a connected
region is filled with robots of which one is not on its goal (no robot there
can ever move without a rotation, for example two robots swapping in a 1x2
corridor, or four robots on a 2x2 block); or the whole constraint tree was
exhausted (every low-level search is exhaustive, so this proves no
rotation-free plan exists).

``nodes`` in the result counts the constraint-tree nodes generated (the root
included).

Examples
--------
Two robots swapping ends of a corridor with a passing bay:

>>> from mrmp.core.grid import Grid
>>> from mrmp.sim.referee import check_paths
>>> grid = Grid.from_rows(["#.#", "..."])
>>> result = cbs(grid, [(0, 0), (0, 2)], [(0, 2), (0, 0)])
>>> result.status, result.sum_of_costs(), result.makespan()
('solved', 7, 4)
>>> check_paths(grid, dict(zip("AB", result.paths)))
[]
>>> cbs(Grid(1, 2), [(0, 0), (0, 1)], [(0, 1), (0, 0)]).status
'infeasible'
"""

from __future__ import annotations

import heapq
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from mrmp.centralized.dependencies import rotations_at
from mrmp.centralized.plan import (
    MapfProblem,
    PlanningResult,
    as_problem,
    pad_headings,
    pad_paths,
    tick_grid,
)
from mrmp.centralized.space_time_astar import (
    Reservations,
    SpaceTimeResult,
    space_time_astar,
)
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid, connected_regions
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario

__all__ = [
    "DEFAULT_MAX_NODES",
    "DEFAULT_TIME_LIMIT_S",
    "PLANNED_BODIES",
    "Conflict",
    "all_conflicts",
    "cbs",
    "first_conflict",
    "infeasibility_proof",
    "mdd_layers",
    "min_vertex_cover_size",
]

DEFAULT_MAX_NODES = 100_000
"""Constraint-tree nodes CBS generates at most unless told otherwise."""
DEFAULT_TIME_LIMIT_S = 60.0
"""Seconds CBS plans at most unless told otherwise."""
PLANNED_BODIES = ("omni", "turning")
"""The bodies CBS and prioritized planning plan for (:mod:`mrmp.core.body`)."""

_Constraint = tuple[str, Cell, int] | tuple[str, Cell, Cell, int]
"""A CBS constraint: ``("v", cell, t)`` forbids ``cell`` at tick ``t``; ``("e", u, v, t)``
forbids moving ``u -> v`` arriving at tick ``t``."""


@dataclass(frozen=True)
class Conflict:
    """A collision between robots ``first`` and ``second`` (indices) at tick ``tick``.

    ``kind`` is ``"vertex"`` (both on ``cells[0]``), ``"edge"`` (``first``
    moves ``cells[0] -> cells[1]`` while ``second`` moves back) or
    ``"rotation"``: the robots of ``robots`` (``first`` and ``second`` are the
    first two) each move at ``tick`` from their cell in ``cells`` to the next
    one (the last into ``cells[0]``); see
    :func:`mrmp.centralized.dependencies.find_rotations`.
    """

    kind: str
    first: int
    second: int
    cells: tuple[Cell, ...]
    tick: int
    robots: tuple[int, ...] = ()


def all_conflicts(paths: Sequence[Sequence[Cell]], *, rotations: bool = False) -> list[Conflict]:
    """Every conflict among ``paths``, in tick order.

    Robots stay on their last cell after their path ends. At one tick, vertex
    conflicts come before edge conflicts, then rotations, and pairs go in
    robot order. Three robots in one cell give two vertex conflicts, each with
    the first of them.

    Parameters
    ----------
    paths:
        One path per robot, one cell per tick.
    rotations:
        Also report rotations of three or more robots (kind ``"rotation"``),
        which the classic MAPF model allows.

    Returns
    -------
    list of Conflict
        Empty when the paths are a valid plan.

    Examples
    --------
    >>> [(c.kind, c.first, c.second, c.tick) for c in all_conflicts([[(0, 0), (0, 1)], [(0, 1), (0, 0)]])]
    [('edge', 0, 1, 1)]
    >>> all_conflicts([[(0, 0), (0, 1), (0, 2)], [(0, 2)]])[0].kind
    'vertex'
    >>> block = [(0, 0), (0, 1), (1, 1), (1, 0)]
    >>> turning = [[block[i], block[(i + 1) % 4]] for i in range(4)]
    >>> all_conflicts(turning), [(c.kind, c.robots, c.tick) for c in all_conflicts(turning, rotations=True)]
    ([], [('rotation', (0, 1, 2, 3), 1)])
    """
    length = max((len(path) for path in paths), default=0)
    found: list[Conflict] = []
    previous: list[Cell] = []
    for tick in range(length):
        current = [path[tick] if tick < len(path) else path[-1] for path in paths]
        occupants: dict[Cell, int] = {}
        for index, cell in enumerate(current):
            other = occupants.get(cell)
            if other is None:
                occupants[cell] = index
            else:
                found.append(Conflict("vertex", other, index, (cell,), tick))
        if tick > 0:
            moves: dict[tuple[Cell, Cell], int] = {}
            for index, (source, target) in enumerate(zip(previous, current)):
                if source != target:
                    moves[(source, target)] = index
            for (source, target), index in moves.items():
                other = moves.get((target, source))
                if other is not None and other > index:
                    found.append(Conflict("edge", index, other, (source, target), tick))
            if rotations:
                for cycle in rotations_at(tick, previous, current, min_robots=3):
                    robots = cycle.robots
                    found.append(Conflict("rotation", robots[0], robots[1], cycle.cells, tick, robots))
        previous = current
    return found


def first_conflict(paths: Sequence[Sequence[Cell]]) -> tuple[Conflict | None, int]:
    """The earliest conflict among ``paths`` (see :func:`all_conflicts`) and how many there are.

    Examples
    --------
    >>> conflict, count = first_conflict([[(0, 0), (0, 1)], [(0, 1), (0, 0)]])
    >>> conflict.kind, conflict.cells, conflict.tick, count
    ('edge', ((0, 0), (0, 1)), 1, 1)
    >>> first_conflict([[(0, 0), (0, 1)], [(0, 1), (0, 2)]])   # following is allowed
    (None, 0)
    """
    found = all_conflicts(paths)
    return (found[0] if found else None), len(found)


def infeasibility_proof(problem: MapfProblem) -> str | None:
    """A reason the instance has no solution, when a cheap proof exists; else ``None``.

    Two proofs are tried: a robot whose goal is in another connected region
    than its start; and a connected region whose every cell holds a robot,
    one of them not on its goal: no robot there can ever move, since a move
    needs a free cell at the head of its chain of followers, and with none the
    only moves left are rotations (which robots moving one at a time cannot
    execute, :mod:`mrmp.centralized.dependencies`) or, on a region without
    cycles, nothing at all.

    >>> infeasibility_proof(as_problem(Grid(1, 2), [(0, 0), (0, 1)], [(0, 1), (0, 0)]))
    'robots fill the region of 2 cells around (0, 0) and cannot move (only a rotation would move them)'
    >>> infeasibility_proof(as_problem(Grid(2, 2), [(0, 0), (0, 1)], [(0, 1), (0, 0)])) is None
    True
    """
    grid = problem.grid
    labels, regions = connected_regions(grid, problem.starts + problem.goals)
    for robot_id, start, goal in zip(problem.ids, problem.starts, problem.goals):
        if labels[start] != labels[goal]:
            return f"robot {robot_id} cannot reach its goal {goal} from {start}"
    robots_in: dict[int, list[int]] = {}
    for index, start in enumerate(problem.starts):
        robots_in.setdefault(labels[start], []).append(index)
    for label, members in robots_in.items():
        region = regions[label]
        if len(members) != len(region):
            continue
        if any(problem.starts[i] != problem.goals[i] for i in members):
            return (
                f"robots fill the region of {len(region)} cells around {region[0]} and cannot move "
                "(only a rotation would move them)"
            )
    return None


def min_vertex_cover_size(edges: Sequence[tuple[int, int]], exact_up_to: int = 8) -> int:
    """The size of a smallest vertex cover of a graph given by its edges (a lower bound if large).

    Exact by iterative deepening on the cover size (two branches per uncovered
    edge) while the size is at most ``exact_up_to``; beyond that, the size of a
    greedy maximal matching, which never exceeds the true value.

    >>> min_vertex_cover_size([(0, 1), (1, 2), (2, 0)])
    2
    >>> min_vertex_cover_size([(0, 1), (0, 2), (0, 3)])
    1
    >>> min_vertex_cover_size([])
    0
    """
    unique = sorted({(min(u, v), max(u, v)) for u, v in edges})
    matched: set[int] = set()
    matching = 0
    for u, v in unique:
        if u not in matched and v not in matched:
            matched.update((u, v))
            matching += 1

    def coverable(remaining: list[tuple[int, int]], budget: int) -> bool:
        if not remaining:
            return True
        if budget == 0:
            return False
        u, v = remaining[0]
        return coverable([e for e in remaining if u not in e], budget - 1) or coverable(
            [e for e in remaining if v not in e], budget - 1
        )

    size = matching
    while size <= exact_up_to:
        if coverable(unique, size):
            return size
        size += 1
    return matching


_Layers = tuple[frozenset[Cell], ...]


@dataclass
class _Node:
    """A constraint-tree node: constraints, paths, and the bound ``f`` on its subtree's costs."""

    cost: int
    f: int
    conflicts: list[Conflict]
    serial: int
    constraints: tuple[tuple[_Constraint, ...], ...]
    paths: tuple[tuple[Cell, ...], ...]
    headings: tuple[tuple[Heading, ...] | None, ...]
    mdds: list[_Layers | None]
    evaluated: bool = False
    chosen: Conflict | None = None

    def key(self) -> tuple[int, int, int]:
        return (self.f, len(self.conflicts), self.serial)


def _reservations(constraints: Sequence[_Constraint]) -> Reservations:
    table = Reservations()
    for constraint in constraints:
        if len(constraint) == 3:
            _, cell, tick = constraint
            table.forbid_vertex(cell, tick)
        else:
            _, source, target, tick = constraint
            table.forbid_edge(source, target, tick)
    return table


def _avoidance(paths: Sequence[Sequence[Cell] | None], skip: int) -> Reservations:
    table = Reservations()
    for index, path in enumerate(paths):
        if index != skip and path:
            table.reserve_path(path)
    return table


def mdd_layers(
    grid: Grid,
    start: Cell,
    goal: Cell,
    cost: int,
    reservations: Reservations,
    *,
    heading_aware: bool = False,
    heading: Heading = Heading.NORTH,
    both_ways: bool = False,
) -> tuple[frozenset[Cell], ...]:
    """The cells of every path of exactly ``cost`` ticks from ``start`` to ``goal``, tick by tick.

    A multi-valued decision diagram (Sharon et al., "The increasing cost tree
    search for optimal multi-agent pathfinding", AIJ 2013), projected on
    cells: layer ``t`` holds the cells some path respecting ``reservations``
    (vertex and edge entries) visits at tick ``t`` while reaching ``goal`` at
    tick ``cost``. A layer with one cell means every such path is there then:
    forbidding it raises the robot's cost (a *cardinal* conflict, Boyarski et
    al. 2015). ``cost`` must be the least arrival tick under the reservations.

    >>> from mrmp.core.grid import Grid
    >>> [sorted(layer) for layer in mdd_layers(Grid(2, 2), (0, 0), (1, 1), 2, Reservations())]
    [[(0, 0)], [(0, 1), (1, 0)], [(1, 1)]]
    """
    from mrmp.centralized.space_time_astar import (
        heading_distance_table,
        hop_distance_table,
    )

    if heading_aware:
        table = heading_distance_table(tick_grid(grid), goal, both_ways)

        def estimate(state: tuple[Cell, int]) -> float:
            return table.get((state[0], Heading(state[1])), float("inf"))

        def successors(state: tuple[Cell, int]) -> list[tuple[Cell, int]]:
            cell, facing = state
            moves = [(cell, facing), (cell, facing % 4 + 1)]
            if both_ways:
                moves.append((cell, (facing - 2) % 4 + 1))
            ahead = Heading(facing).ahead(cell)
            if grid.is_free(ahead):
                moves.append((ahead, facing))
            return moves

        first: tuple[Cell, int] = (start, int(heading))
    else:
        hop = hop_distance_table(grid, goal).distance

        def estimate(state: tuple[Cell, int]) -> float:
            return hop(state[0])

        def successors(state: tuple[Cell, int]) -> list[tuple[Cell, int]]:
            cell = state[0]
            return [(cell, 0)] + [(n, 0) for n in grid.neighbours(cell)]

        first = (start, 0)
    vertex, edge = reservations.vertex, reservations.edge
    layers: list[set[tuple[Cell, int]]] = [{first}]
    for tick in range(1, cost + 1):
        layer: set[tuple[Cell, int]] = set()
        for state in layers[-1]:
            for nxt in successors(state):
                if (nxt[0], tick) in vertex or (nxt[0] != state[0] and (state[0], nxt[0], tick) in edge):
                    continue
                if tick + estimate(nxt) <= cost:
                    layer.add(nxt)
        layers.append(layer)
    kept: list[set[tuple[Cell, int]]] = [set() for _ in layers]
    kept[cost] = {state for state in layers[cost] if state[0] == goal}
    for tick in range(cost - 1, -1, -1):
        after = kept[tick + 1]
        kept[tick] = {
            state
            for state in layers[tick]
            if any(
                nxt in after and not (nxt[0] != state[0] and (state[0], nxt[0], tick + 1) in edge)
                for nxt in successors(state)
            )
        }
    return tuple(frozenset(state[0] for state in layer) for layer in kept)


def cbs(
    problem: Scenario | Grid | MapfProblem,
    starts: Sequence[Cell] | None = None,
    goals: Sequence[Cell] | None = None,
    *,
    max_nodes: int | None = DEFAULT_MAX_NODES,
    time_limit_s: float | None = DEFAULT_TIME_LIMIT_S,
    heading_aware: bool = False,
    improved: bool = True,
    body: str = "omni",
) -> PlanningResult:
    """Plan every robot with Conflict-Based Search (Sharon et al. 2015): least sum of costs without rotations.

    Parameters
    ----------
    problem:
        A :class:`~mrmp.core.scenario.Scenario`, or a grid with ``starts``
        and ``goals`` (see :func:`~mrmp.centralized.plan.as_problem`).
    starts, goals:
        With a grid: one cell per robot.
    max_nodes:
        Stop after generating this many constraint-tree nodes (``None``: no
        node limit).
    time_limit_s:
        Stop after this many seconds (``None``: no time limit).
    heading_aware:
        Plan with the turn model (one tick per move forward or right turn);
        headings start from the scenario's (NORTH for a bare grid).
    improved:
        Use the optimality-preserving improvements (cardinal conflicts first,
        the conflict-graph heuristic, bypass; see the module docstring).
        ``False`` runs the original CBS: split the first conflict in time.
    body:
        The body planned for (:data:`PLANNED_BODIES`): ``omni`` (the turn model
        of ``heading_aware``), or ``turning``: one tick is one move forward, a
        quarter turn either way, or a wait (``heading_aware`` is then implied).

    Returns
    -------
    PlanningResult
        ``"solved"`` with paths of least sum of costs among rotation-free
        plans (see the module docstring); ``"limit"`` when a limit was reached
        (the message names it); ``"infeasible"`` with a proof in the message
        (see the module docstring). ``nodes`` counts generated nodes.

    Raises
    ------
    InputError
        If the starts or goals are invalid (see :func:`~mrmp.centralized.plan.as_problem`).

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> crowded = Grid.from_rows(["#.#", "..."])
    >>> r = cbs(crowded, [(0, 0), (0, 1), (0, 2)], [(0, 2), (0, 1), (0, 0)], max_nodes=5)
    >>> r.status, r.nodes, r.message
    ('limit', 5, 'node limit of 5 reached')
    """
    if body not in PLANNED_BODIES:
        raise ValueError(f"cbs plans for the bodies {', '.join(PLANNED_BODIES)}, not {body!r}")
    began = time.perf_counter()
    instance = as_problem(problem, starts, goals)
    turning = body == "turning"
    search = _ConflictSearch(instance, began, time_limit_s, max_nodes, heading_aware or turning, improved, turning)
    proof = infeasibility_proof(instance)
    if proof is not None:
        return search.result("infeasible", proof, 0)
    return search.run()


_Split = tuple[int, _Constraint]
"""A child of a split: the robot and the constraint it gets."""


def _splits(conflict: Conflict) -> tuple[_Split, ...]:
    """The children of a split on ``conflict``: each forbids the conflict to one of its robots."""
    if conflict.kind == "vertex":
        cell = conflict.cells[0]
        return ((conflict.first, ("v", cell, conflict.tick)), (conflict.second, ("v", cell, conflict.tick)))
    if conflict.kind == "rotation":
        cycle = conflict.cells
        return tuple(
            (robot, ("e", cycle[k], cycle[(k + 1) % len(cycle)], conflict.tick)) for k, robot in enumerate(conflict.robots)
        )
    source, target = conflict.cells
    return ((conflict.first, ("e", source, target, conflict.tick)), (conflict.second, ("e", target, source, conflict.tick)))


def _replaced(row: tuple[Any, ...], index: int, value: Any) -> tuple[Any, ...]:
    """``row`` with entry ``index`` replaced by ``value``."""
    return (*row[:index], value, *row[index + 1 :])


class _ConflictSearch:
    """One CBS run: the root, the best-first loop over the constraint tree, conflict choice and splits."""

    def __init__(
        self,
        instance: MapfProblem,
        began: float,
        time_limit_s: float | None,
        max_nodes: int | None,
        heading_aware: bool,
        improved: bool,
        both_ways: bool = False,
    ) -> None:
        self.instance = instance
        self.both_ways = both_ways
        self.grid = instance.grid
        self.count = len(instance)
        self.began = began
        self.time_limit_s = time_limit_s
        self.deadline = None if time_limit_s is None else began + time_limit_s
        self.max_nodes = max_nodes
        self.heading_aware = heading_aware
        self.improved = improved
        self.nodes = 0
        self.open_list: list[tuple[tuple[int, int, int], _Node]] = []

    # -- results ---------------------------------------------------------------------

    def result(self, status: str, message: str, nodes: int, node: _Node | None = None) -> PlanningResult:
        """A :class:`PlanningResult` of CBS, timed from the start, with ``node``'s paths when given."""
        elapsed = time.perf_counter() - self.began
        paths = headings = None
        if node is not None:
            paths = pad_paths(node.paths)
            if self.heading_aware:
                headings = pad_headings([row for row in node.headings if row is not None])
        return PlanningResult(status, paths, elapsed, "cbs", nodes=nodes, message=message, headings=headings)

    def _out_of_time(self) -> PlanningResult:
        return self.result("limit", f"time limit of {self.time_limit_s:g} s reached after {self.nodes} nodes", self.nodes)

    # -- the high level ---------------------------------------------------------------

    def run(self) -> PlanningResult:
        """Best-first search of the constraint tree from the root (module docstring, steps 1 to 3)."""
        root = self._root()
        if isinstance(root, PlanningResult):
            return root
        self.nodes = 1
        self._push(root)
        open_list = self.open_list
        while open_list:
            _, node = heapq.heappop(open_list)
            if not node.conflicts:
                return self.result("solved", f"optimal sum of costs {node.cost} after {self.nodes} nodes", self.nodes, node)
            if self.deadline is not None and time.perf_counter() > self.deadline:
                return self._out_of_time()
            if not node.evaluated:
                bound = node.f
                self._evaluate(node)
                if node.f > bound:
                    self._push(node)
                    continue
            stopped = self._split(node)
            if stopped is not None:
                return stopped
        return self.result("infeasible", f"constraint tree exhausted after {self.nodes} nodes: no plan exists", self.nodes)

    def _push(self, node: _Node) -> None:
        heapq.heappush(self.open_list, (node.key(), node))

    def _root(self) -> _Node | PlanningResult:
        """The root: every robot's cheapest path without constraints (avoiding the paths planned before it)."""
        count = self.count
        empty: tuple[_Constraint, ...] = ()
        root_paths: list[tuple[Cell, ...] | None] = [None] * count
        root_headings: list[tuple[Heading, ...] | None] = [None] * count
        for index in range(count):
            found = self._replan(index, empty, root_paths)
            if found.status == "deadline":
                return self.result("limit", f"time limit of {self.time_limit_s:g} s reached while planning the root", 0)
            if not found.found:  # pragma: no cover - excluded by infeasibility_proof
                return self.result("infeasible", f"robot {self.instance.ids[index]} cannot reach its goal", 0)
            root_paths[index] = found.path
            root_headings[index] = found.headings
        paths = tuple(path for path in root_paths if path is not None)
        cost = sum(len(path) - 1 for path in paths)
        conflicts = all_conflicts(paths, rotations=True)
        return _Node(cost, cost, conflicts, 0, (empty,) * count, paths, tuple(root_headings), [None] * count)

    def _split(self, node: _Node) -> PlanningResult | None:
        """Split ``node`` on its chosen conflict (or bypass it); a result when a limit stops the search."""
        conflict = node.chosen
        assert conflict is not None
        children: list[_Node] = []
        for robot, constraint in _splits(conflict):
            if self.max_nodes is not None and self.nodes >= self.max_nodes:
                return self.result("limit", f"node limit of {self.max_nodes} reached", self.nodes)
            constraints = (*node.constraints[robot], constraint)
            found = self._replan(robot, constraints, node.paths)
            if found.status == "deadline":
                return self._out_of_time()
            self.nodes += 1
            if not found.found or found.path is None:
                continue
            child_paths = _replaced(node.paths, robot, found.path)
            child_headings = _replaced(node.headings, robot, found.headings)
            child_conflicts = all_conflicts(child_paths, rotations=True)
            cost = node.cost - (len(node.paths[robot]) - 1) + (len(found.path) - 1)
            if self.improved and cost == node.cost and len(child_conflicts) < len(node.conflicts):
                # bypass (Boyarski et al. 2015): the new path is as cheap and also respects the
                # node's own constraints; adopt it instead of splitting
                node.paths, node.headings, node.conflicts = child_paths, child_headings, child_conflicts
                node.evaluated, node.chosen = False, None
                self._push(node)
                return None
            mdds = list(node.mdds)
            mdds[robot] = None
            child_constraints = _replaced(node.constraints, robot, constraints)
            children.append(
                _Node(cost, max(cost, node.f), child_conflicts, self.nodes, child_constraints, child_paths, child_headings, mdds)
            )
        for child in children:
            self._push(child)
        return None

    # -- the low level and the improvements --------------------------------------------

    def _replan(self, index: int, constraints: Sequence[_Constraint], paths: Sequence[Sequence[Cell] | None]) -> SpaceTimeResult:
        """Robot ``index``'s cheapest path under its constraints, fewest conflicts with ``paths`` among them."""
        instance = self.instance
        return space_time_astar(
            self.grid,
            instance.starts[index],
            instance.goals[index],
            _reservations(constraints),
            heading_aware=self.heading_aware,
            heading=instance.headings[index],
            both_ways=self.both_ways,
            avoid=_avoidance(paths, index),
            deadline=self.deadline,
        )

    def _mdd(self, node: _Node, robot: int) -> _Layers:
        """The MDD of ``robot``'s cheapest paths in ``node``, computed once per node and robot."""
        layers = node.mdds[robot]
        if layers is None:
            instance = self.instance
            layers = mdd_layers(
                self.grid,
                instance.starts[robot],
                instance.goals[robot],
                len(node.paths[robot]) - 1,
                _reservations(node.constraints[robot]),
                heading_aware=self.heading_aware,
                heading=instance.headings[robot],
                both_ways=self.both_ways,
            )
            node.mdds[robot] = layers
        return layers

    def _forced(self, node: _Node, robot: int, conflict: Conflict) -> bool:
        """Whether every cheapest path of ``robot`` has the conflict (splitting raises its cost)."""
        tick = conflict.tick
        cost = len(node.paths[robot]) - 1
        if conflict.kind == "vertex":
            if tick >= cost:
                return True  # settled on its goal: it must leave and come back later
            layer = self._mdd(node, robot)[tick]
            return len(layer) == 1
        layers = self._mdd(node, robot)
        return len(layers[tick - 1]) == 1 and len(layers[tick]) == 1

    def _evaluate(self, node: _Node) -> None:
        """Choose the conflict to split (cardinal, then semi-cardinal, then the earliest) and bound ``f``."""
        node.evaluated = True
        if not self.improved:
            node.chosen = node.conflicts[0]
            return
        best: tuple[int, int] | None = None
        cardinal_pairs: set[tuple[int, int]] = set()
        for position, conflict in enumerate(node.conflicts):
            pair = (conflict.first, conflict.second)
            if pair in cardinal_pairs:
                continue
            if conflict.kind == "rotation":
                kind = 2  # not a pair: never cardinal, never in the conflict graph
            else:
                kind = 2 - self._forced(node, conflict.first, conflict) - self._forced(node, conflict.second, conflict)
            if kind == 0:
                cardinal_pairs.add(pair)
            if best is None or kind < best[0]:
                best = (kind, position)
        node.chosen = node.conflicts[best[1] if best is not None else 0]
        if cardinal_pairs:
            node.f = max(node.f, node.cost + min_vertex_cover_size(sorted(cardinal_pairs)))
