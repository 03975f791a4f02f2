"""LaCAM: lazy search over configurations, with PIBT as the successor generator.

LaCAM, *Lazy Constraints Addition search for MAPF* (Okumura, "LaCAM:
Search-Based Algorithm for Quick Multi-Agent Pathfinding", AAAI 2023), is a
depth-first search whose nodes are *configurations* (one cell per robot):

* A high-level node holds a configuration, a robot priority order and a queue
  of *low-level nodes*. A low-level node is a set of constraints "robot ``i``
  moves to cell ``v``", built lazily: expanding one at depth ``d`` creates one
  child per candidate cell (the robot's neighbours and its own cell) of the
  ``d``-th robot in the order, so the queue enumerates, breadth first, every
  combination of moves.
* Each time a node is visited, one low-level node is taken from its queue and
  PIBT (:mod:`mrmp.centralized.pibt_step`) completes its constraints into a
  whole next configuration. A new configuration becomes a new high-level node
  on top of the stack; a known one is pushed again (it is revisited).
* A node whose low-level queue is exhausted has generated every successor
  configuration and is popped.

The first node on top of the stack whose configuration is the goal gives the
plan (backtracked through parents). Because the low-level queues eventually
enumerate every successor, the search is *complete*: when the stack empties
without reaching the goal, no plan exists and the result is ``"infeasible"``.

**Rotation-free plans.** The plans are executed by robots that move one at a
time through the plan's Action Dependency Graph
(:mod:`mrmp.centralized.dependencies`), on which a *rotation* -- robots on a
cycle of cells each moving, at one tick, into the cell the next one leaves --
deadlocks. PIBT therefore runs with ``rotations=False``
(:class:`~mrmp.centralized.pibt_step.PIBT`): a robot never takes a cell whose
occupant is followed, through the robots moving into one another's cells, back
to itself (the cell of an ancestor in its own priority-inheritance chain, or
a cycle closed through constrained robots), and constraints that form a
rotation fail. Completeness holds in this model, the classic one without
rotations (vertex, swap and cycle conflicts forbidden; Stern et al., SoCS
2019): a rotation-free, collision-free successor ``Q'`` of a configuration
``Q`` is reached by the low-level node that constrains every robot to its
cell in ``Q'`` (the queue enumerates it at depth ``N``), and PIBT returns
exactly ``Q'`` there, since its checks of the constraints reject only vertex,
swap and rotation conflicts. Every rotation-free successor is thus generated
eventually, so ``"infeasible"`` means that no rotation-free plan exists (for
example when robots fill a 2x2 block and each wants the next cell: only a
rotation moves anyone).

This module follows the reference implementations of Kei18/lacam
(``lacam/src/planner.cpp``) and Kei18/lacam3 (``hnode.cpp``, ``planner.cpp``):
priorities start at ``dist(start, goal)`` scaled below 1, grow by one per step
for robots away from their goals and drop to their fractional part for robots
at them (dynamic priorities, as in PIBT); the order of a node sorts robots by
decreasing priority; candidates of low-level expansions are shuffled with the
seeded generator.

LaCAM* (Okumura, "Improving LaCAM for Scalable Eventually Optimal Multi-Agent
Pathfinding", IJCAI 2023), the anytime version that keeps searching after the
first solution and rewires parents to shorten it, is available with
``anytime=True`` (off by default); its edge cost counts the robots that are not
resting at their goals. The swap technique of LaCAM* engineering (Okumura,
AAMAS 2024) is on by default in the PIBT successor generator (``swap``).

Examples
--------
Two robots in a corridor with a bay: robot ``A`` must pass robot ``B``, so
``B`` steps aside into the bay.

>>> from mrmp.core.grid import Grid
>>> from mrmp.core.scenario import RobotSpec, Scenario
>>> from mrmp.sim.referee import check_paths
>>> grid = Grid.from_rows(["#.##", "...."])
>>> scenario = Scenario(grid, (RobotSpec("A", (0, 0), (0, 3)), RobotSpec("B", (0, 1), (0, 0))))
>>> result = lacam(scenario)
>>> result.status, result.planner, result.sum_of_costs()
('solved', 'lacam', 6)
>>> check_paths(grid, dict(zip("AB", result.paths)))
[]

Two robots that must exchange places in a corridor with no room cannot:

>>> swap = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 2)), RobotSpec("B", (0, 2), (0, 0))))
>>> lacam(swap).status
'infeasible'
"""

from __future__ import annotations

import random
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import replace

from mrmp.centralized.pibt_step import NO_CELL, PIBT
from mrmp.centralized.plan import MapfProblem, PlanningResult, as_problem, tick_grid
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario
from mrmp.policies.pibt_rules import ahead_cell, turned
from mrmp.search.distance import distance_table
from mrmp.search.flat_grid import FlatGrid, flat_grid
from mrmp.search.heading_distance import heading_distances

PLANNED_BODIES = ("omni", "turning")
"""The bodies LaCAM plans for (:mod:`mrmp.core.body`)."""

__all__ = ["lacam"]

_LowNode = tuple[int, int, int, "_LowNode | None"]
"""A low-level node: ``(depth, robot, cell, parent)``; the root is ``(0, -1, -1, None)``.

Its constraints are the ``(robot, cell)`` pairs along the chain to the root, so
a child costs O(1) to create (the reference copies the lists)."""

_LOW_ROOT: _LowNode = (0, -1, -1, None)


class _Node:
    """A high-level node of LaCAM: a configuration and its lazy low-level queue."""

    __slots__ = ("config", "f", "g", "h", "neighbours", "order", "parent", "priorities", "tree")

    def __init__(
        self,
        config: tuple[int, ...],
        parent: _Node | None,
        priorities: list[float],
        g: int = 0,
        h: float = 0,
    ) -> None:
        self.config = config
        self.parent = parent
        self.priorities = priorities
        self.order = sorted(range(len(config)), key=lambda robot: -priorities[robot])
        self.tree: deque[_LowNode] = deque((_LOW_ROOT,))
        self.g = g
        self.h = h
        self.f = g + h
        self.neighbours: set[_Node] = set()


def _result(
    status: str,
    start: float,
    nodes: int,
    message: str,
    paths: tuple[tuple[tuple[int, int], ...], ...] | None = None,
) -> PlanningResult:
    """A :class:`PlanningResult` of LaCAM, timed from ``start``."""
    return PlanningResult(status, paths, time.perf_counter() - start, "lacam", nodes=nodes, message=message)


def lacam(
    problem: Scenario | Grid | MapfProblem,
    starts: Sequence[Cell] | None = None,
    goals: Sequence[Cell] | None = None,
    *,
    time_limit_s: float | None = 10.0,
    max_nodes: int | None = None,
    seed: int | None = 0,
    swap: bool = True,
    anytime: bool = False,
    body: str = "omni",
) -> PlanningResult:
    """Plan every robot with LaCAM (Okumura, AAAI 2023): quick, complete, suboptimal.

    Time is counted in ticks: every robot moves to a neighbouring cell or waits
    in each tick; entry costs of cells and robot headings are ignored (LaCAM
    has no turn model; the result carries no headings). Plans never contain a
    rotation (see the module docstring).

    Parameters
    ----------
    problem:
        A :class:`~mrmp.core.scenario.Scenario`, or a grid with ``starts``
        and ``goals`` (see :func:`~mrmp.centralized.plan.as_problem`).
    starts, goals:
        With a grid: one cell per robot.
    time_limit_s:
        Wall-clock budget in seconds, distance tables included; ``None`` for
        none. When it runs out before a solution, the status is ``"limit"``.
    max_nodes:
        Largest number of high-level configurations to generate (``None``: no
        limit); reaching it before a solution gives ``"limit"``.
    seed:
        Seed of the random choices (order of low-level candidates, PIBT's
        tie-breaks between equally distant cells). ``None`` makes no random
        choice at all: ties keep the grid's neighbour order. Equal seeds give
        equal plans.
    swap:
        Use the swap technique of LaCAM* engineering (Okumura, AAMAS 2024) in
        PIBT; it lets robots pass each other in corridors without a long
        search (see :mod:`mrmp.centralized.pibt_step`).
    anytime:
        LaCAM* (Okumura, IJCAI 2023): after the first solution keep searching,
        rewiring parents to lower the cost, until the time or node limit (the
        result is then ``"solved"`` with the best plan found) or until the
        search space is exhausted (the plan is then optimal for LaCAM*'s
        cost, which counts in each tick every robot not resting at its goal).
        Off by default: the first solution is returned.
    body:
        The body planned for (:mod:`mrmp.core.body`): ``omni`` (the classic
        model above) or ``turning`` (LoRR's ``MAPF_T``): configurations are then
        every robot's ``(cell, heading)`` state, a low-level node constrains a
        robot to one of its four actions (forward, wait, a quarter turn either
        way), PIBT plans with the rules of bodies that turn in place
        (:class:`~mrmp.centralized.pibt_step.PIBT`'s ``turning_y_size``), the
        distances are ``(cell, heading)`` tables in ticks, and the result
        carries every robot's headings. The completeness argument above holds
        in this model too (the queues enumerate every combination of actions;
        swap is off, since a pull needs a backward move the body does not have).

    Returns
    -------
    PlanningResult
        ``planner="lacam"``; ``nodes`` is the number of high-level
        configurations generated (distinct configurations inserted in the
        search, the start included). When solved, ``paths`` holds one path per
        robot in robot order, all of equal length, ending with every robot
        at its goal. ``"infeasible"`` when the search proved that no
        rotation-free plan exists (at once when a goal cannot be reached
        from its start); ``"limit"`` when ``time_limit_s`` or ``max_nodes`` ran out first.

    Raises
    ------
    InputError
        If the starts or goals are invalid (see :func:`~mrmp.centralized.plan.as_problem`).

    Examples
    --------
    Three robots move round a 2x2 grid, each following the next into the free
    cell, which takes one tick:

    >>> from mrmp.core.grid import Grid
    >>> cells = [(0, 0), (0, 1), (1, 1), (1, 0)]
    >>> result = lacam(Grid(2, 2), cells[:3], cells[1:])
    >>> result.status, result.makespan(), result.nodes
    ('solved', 1, 2)
    >>> lacam(Grid(2, 2), cells[:3], cells[1:], max_nodes=1).status
    'limit'

    With ``turning`` bodies a robot facing NORTH turns before it drives EAST:

    >>> turning = lacam(Grid(1, 3), [(0, 0)], [(0, 2)], body="turning")
    >>> turning.paths, [heading.name for heading in turning.headings[0]]
    ((((0, 0), (0, 0), (0, 1), (0, 2)),), ['NORTH', 'EAST', 'EAST', 'EAST'])
    """
    if body not in PLANNED_BODIES:
        raise ValueError(f"lacam plans for the bodies {', '.join(PLANNED_BODIES)}, not {body!r}")
    start_time = time.perf_counter()
    deadline = None if time_limit_s is None else start_time + time_limit_s
    instance = as_problem(problem, starts, goals)
    if len(instance) == 0:
        return _result("solved", start_time, 0, "no robots", ())
    plain = tick_grid(instance.grid)
    tables = [distance_table(plain, goal) for goal in instance.goals]
    for robot_id, start, goal, table in zip(instance.ids, instance.starts, instance.goals, tables):
        if not table.reachable(start):
            return _result("infeasible", start_time, 0, f"robot {robot_id} cannot reach its goal {goal} from {start}")
    if body == "turning":
        distances = [heading_distances(plain, goal, 1.0, both_ways=True) for goal in instance.goals]
        search: _Search = _TurningSearch(instance, distances, seed, False, anytime)
    else:
        search = _Search(instance, [table.as_list() for table in tables], seed, swap, anytime)
    stopped = search.run(deadline, time_limit_s, max_nodes)
    return search.result(start_time, stopped)


class _Search:
    """One LaCAM (or LaCAM*) search: the high-level stack of configurations and its lazy low-level queues."""

    def __init__(
        self, instance: MapfProblem, distances: Sequence[Sequence[float]], seed: int | None, swap: bool, anytime: bool
    ) -> None:
        self.flat = flat_grid(instance.grid)
        self.count = len(instance)
        self.robot_range = range(self.count)
        self.distances = distances
        self.anytime = anytime
        neighbours = self.flat.neighbours
        self.goal_config = tuple(self.flat.index(cell) for cell in instance.goals)
        self.rng = random.Random(seed) if seed is not None else None
        self.pibt = self._generator(neighbours, distances, swap)
        self.candidates = self._candidates(self.flat)
        self.scale = 1.0 / (self.flat.size + 1)
        start_config = self._start(instance)
        root = self._make_node(start_config, None)
        self.stack: deque[_Node] = deque((root,))
        self.explored: dict[tuple[int, ...], _Node] = {start_config: root}
        self.goal_node: _Node | None = None
        self.iterations = 0

    # -- what a configuration is (a cell per robot; :class:`_TurningSearch`: a state) ---------

    def _generator(self, neighbours: Sequence[tuple[int, ...]], distances: Sequence[Sequence[float]], swap: bool) -> PIBT:
        return PIBT(neighbours, distances, list(self.goal_config), swap=swap, rng=self.rng, rotations=False)

    def _candidates(self, flat: FlatGrid) -> list[tuple[int, ...]]:
        """For every cell, the cells a robot on it may have at the next tick."""
        return [(*row, cell) for cell, row in enumerate(flat.neighbours)]

    def _start(self, instance: MapfProblem) -> tuple[int, ...]:
        return tuple(self.flat.index(cell) for cell in instance.starts)

    def _cell(self, item: int) -> int:
        """The cell of one robot's entry of a configuration."""
        return item

    def _complete(self, config: tuple[int, ...], target: list[int], order: Sequence[int]) -> tuple[int, ...] | None:
        """PIBT completes the constrained ``target`` into the next configuration, or fails."""
        return tuple(target) if self.pibt.generate(config, target, order) else None

    def _headings(self, configs: list[tuple[int, ...]]) -> tuple[tuple[Heading, ...], ...] | None:
        return None

    # -- costs and nodes -------------------------------------------------------------

    def _heuristic(self, config: tuple[int, ...]) -> float:
        distances = self.distances
        return sum(distances[robot][config[robot]] for robot in self.robot_range)

    def _edge_cost(self, before: tuple[int, ...], after: tuple[int, ...]) -> int:
        goal_config = self.goal_config
        cell = self._cell
        return sum(
            1 for robot in self.robot_range if not (cell(before[robot]) == cell(after[robot]) == goal_config[robot])
        )

    def _priorities(self, config: tuple[int, ...], parent: _Node | None) -> list[float]:
        """PIBT's dynamic priorities: distance scaled below 1 at the start, +1 per step away from the goal."""
        if parent is None:
            return [self.distances[robot][config[robot]] * self.scale for robot in self.robot_range]
        old, goal_config, cell = parent.priorities, self.goal_config, self._cell
        return [
            old[robot] + 1 if cell(config[robot]) != goal_config[robot] else old[robot] - int(old[robot])
            for robot in self.robot_range
        ]

    def _make_node(self, config: tuple[int, ...], parent: _Node | None) -> _Node:
        priorities = self._priorities(config, parent)
        if not self.anytime:
            return _Node(config, parent, priorities)
        g = 0 if parent is None else parent.g + self._edge_cost(parent.config, config)
        node = _Node(config, parent, priorities, g, self._heuristic(config))
        if parent is not None:
            node.neighbours.add(parent)
            parent.neighbours.add(node)
        return node

    def _rewrite(self, origin: _Node, reached: _Node) -> None:
        """LaCAM*'s Dijkstra-like update of g-values from ``origin`` after it met ``reached``."""
        origin.neighbours.add(reached)
        queue = deque((origin,))
        while queue:
            node = queue.popleft()
            for other in node.neighbours:
                g = node.g + self._edge_cost(node.config, other.config)
                if g < other.g:
                    other.g = g
                    other.f = g + other.h
                    other.parent = node
                    queue.append(other)
                    if self.goal_node is not None and other.f < self.goal_node.f:
                        self.stack.appendleft(other)

    # -- the search --------------------------------------------------------------------

    def run(self, deadline: float | None, time_limit_s: float | None, max_nodes: int | None) -> str:
        """Search until the goal (LaCAM) or exhaustion or a limit (LaCAM*); return why it stopped early, or ``""``."""
        stack = self.stack
        while stack:
            if deadline is not None and time.perf_counter() > deadline:
                return f"time limit {time_limit_s} s reached"
            self.iterations += 1
            node = stack[0]
            if self._settle(node):
                if self.goal_node is node and not self.anytime:
                    return ""
                continue
            config = self._successor(node)
            if config is None:
                continue
            known = self.explored.get(config)
            if known is not None:
                if self.anytime:
                    self._rewrite(node, known)
                stack.appendleft(known)
                continue
            if max_nodes is not None and len(self.explored) >= max_nodes:
                return f"node limit {max_nodes} reached"
            new = self._make_node(config, node)
            self.explored[config] = new
            stack.appendleft(new)
        return ""

    def _settle(self, node: _Node) -> bool:
        """Handle the top ``node`` when it needs no successor: pruned, the goal, or exhausted (then popped)."""
        goal_node = self.goal_node
        if self.anytime and goal_node is not None and node.f >= goal_node.f:
            self.stack.popleft()
            return True
        if goal_node is None and self._at_goals(node.config):
            self.goal_node = node
            return True
        if not node.tree:
            self.stack.popleft()
            return True
        return False

    def _at_goals(self, config: tuple[int, ...]) -> bool:
        return config == self.goal_config

    def _successor(self, node: _Node) -> tuple[int, ...] | None:
        """Take ``node``'s next low-level node, queue its children, and let PIBT complete its constraints."""
        low = node.tree.popleft()
        depth = low[0]
        if depth < self.count:
            chosen = node.order[depth]
            options = list(self.candidates[node.config[chosen]])
            if self.rng is not None:
                self.rng.shuffle(options)
            node.tree.extend((depth + 1, chosen, cell, low) for cell in options)
        target = [NO_CELL] * self.count
        constraint: _LowNode | None = low
        while constraint is not None and constraint[0] > 0:
            target[constraint[1]] = constraint[2]
            constraint = constraint[3]
        return self._complete(node.config, target, node.order)

    # -- the result ----------------------------------------------------------------------

    def result(self, start_time: float, stopped: str) -> PlanningResult:
        """The plan backtracked from the goal node, or why there is none."""
        nodes, iterations, goal_node = len(self.explored), self.iterations, self.goal_node
        if goal_node is None:
            if stopped:
                return _result("limit", start_time, nodes, f"{stopped} after {iterations} iterations, no solution")
            return _result("infeasible", start_time, nodes, f"search space exhausted after {iterations} iterations")
        configs: list[tuple[int, ...]] = []
        cursor: _Node | None = goal_node
        while cursor is not None:
            configs.append(cursor.config)
            cursor = cursor.parent
        configs.reverse()
        cell, own = self.flat.cell, self._cell
        paths = tuple(tuple(cell(own(config[robot])) for config in configs) for robot in self.robot_range)
        if not self.anytime:
            message = f"first solution after {iterations} iterations"
        elif stopped:
            message = f"best solution when the {stopped} (LaCAM*, cost {goal_node.g})"
        else:
            message = f"optimal for LaCAM*'s cost {goal_node.g} (search space exhausted)"
        result = _result("solved", start_time, nodes, message, paths)
        headings = self._headings(configs)
        return result if headings is None else replace(result, headings=headings)


class _TurningSearch(_Search):
    """LaCAM for ``turning`` bodies: a configuration holds every robot's state ``4 * cell + heading - 1``."""

    def _generator(self, neighbours: Sequence[tuple[int, ...]], distances: Sequence[Sequence[float]], swap: bool) -> PIBT:
        return PIBT(
            neighbours, distances, list(self.goal_config), rng=self.rng, rotations=False, turning_y_size=self.flat.y_size
        )

    def _candidates(self, flat: FlatGrid) -> list[tuple[int, ...]]:
        """For every state, its successors: forward (when free), wait, a quarter turn clockwise and counter-clockwise."""
        table: list[tuple[int, ...]] = []
        for cell in range(len(flat.neighbours)):
            for heading in (1, 2, 3, 4):
                ahead = ahead_cell(flat.neighbours, cell, heading, flat.y_size)
                turns = (4 * cell + turned(heading, 1) - 1, 4 * cell + turned(heading, -1) - 1)
                forward = (4 * ahead + heading - 1,) if ahead >= 0 else ()
                table.append((*forward, 4 * cell + heading - 1, *turns))
        return table

    def _start(self, instance: MapfProblem) -> tuple[int, ...]:
        return tuple(4 * self.flat.index(cell) + int(heading) - 1 for cell, heading in zip(instance.starts, instance.headings))

    def _cell(self, item: int) -> int:
        return item >> 2

    def _at_goals(self, config: tuple[int, ...]) -> bool:
        return all(state >> 2 == goal for state, goal in zip(config, self.goal_config))

    def _complete(self, config: tuple[int, ...], target: list[int], order: Sequence[int]) -> tuple[int, ...] | None:
        cells = [state >> 2 for state in config]
        headings = [(state & 3) + 1 for state in config]
        next_headings = [0] * len(config)
        for robot, state in enumerate(target):
            if state != NO_CELL:
                target[robot], next_headings[robot] = state >> 2, (state & 3) + 1
        if not self.pibt.generate(cells, target, order, headings, next_headings):
            return None
        return tuple(4 * cell + heading - 1 for cell, heading in zip(target, next_headings))

    def _headings(self, configs: list[tuple[int, ...]]) -> tuple[tuple[Heading, ...], ...] | None:
        return tuple(tuple(Heading((config[robot] & 3) + 1) for config in configs) for robot in self.robot_range)
