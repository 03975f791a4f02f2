"""PIBT as a central planner: one PIBT step per tick until every robot is at its goal.

PIBT (Okumura, Machida, Défago and Tamura, "Priority Inheritance with
Backtracking for Iterative Multi-agent Path Finding", IJCAI 2019; Artificial
Intelligence 310, 2022) plans a tick at a time: robots are served in order of
priority, a robot's priority grows by one every tick it is away from its goal
(for ``turning`` bodies, by :data:`~mrmp.policies.pibt_rules.DEAD_END_BONUS` more
in a dead end, as in the League of Robot Runners' Start-Kit) and drops back to its fraction when it arrives, and
:class:`~mrmp.centralized.pibt_step.PIBT` makes the step. This is the
reference the fleet's decentralized ``pibt`` is measured against, and the
generator inside :func:`~mrmp.centralized.lacam.lacam`.

For ``omni`` bodies PIBT's theorem holds (on a graph where every two adjacent
cells lie on a cycle, the robot of highest priority reaches its goal in
finitely many ticks); robots may still be left short of their goals, which is
why LaCAM searches. For ``turning`` bodies it does not hold: a robot PIBT gives
a cell it does not face only turns toward it, and a forward move into the cell
of a robot that stays is cancelled, so priority inheritance no longer finds
the top robot a free way (``docs/protocol.md``, "Body models").

Examples
--------
>>> from mrmp.core.grid import Grid
>>> plan = pibt_plan(Grid(2, 3), [(0, 0), (1, 2)], [(0, 2), (1, 0)])
>>> plan.status, plan.makespan()
('solved', 2)

With ``turning`` bodies, both start facing NORTH and must first turn:

>>> plan = pibt_plan(Grid(2, 3), [(0, 0), (1, 2)], [(0, 2), (1, 0)], body="turning")
>>> plan.status, plan.makespan(), [heading.name for heading in plan.headings[0]]
('solved', 3, ['NORTH', 'EAST', 'EAST', 'EAST'])
"""

from __future__ import annotations

import random
import time
from collections.abc import Sequence

from mrmp.centralized.pibt_step import NO_CELL, PIBT
from mrmp.centralized.plan import MapfProblem, PlanningResult, as_problem, tick_grid
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario
from mrmp.policies.pibt_rules import DEAD_END_BONUS
from mrmp.search.distance import distance_table
from mrmp.search.flat_grid import flat_grid
from mrmp.search.heading_distance import heading_distances

__all__ = ["PIBT_BODIES", "pibt_plan"]

PIBT_BODIES = ("omni", "turning")
"""The bodies :func:`pibt_plan` plans for (:mod:`mrmp.core.body`)."""


def pibt_plan(
    problem: Scenario | Grid | MapfProblem,
    starts: Sequence[Cell] | None = None,
    goals: Sequence[Cell] | None = None,
    *,
    body: str = "omni",
    max_ticks: int | None = None,
    seed: int | None = 0,
    swap: bool | None = None,
) -> PlanningResult:
    """Plan every robot with PIBT, a tick at a time (module docstring).

    Parameters
    ----------
    problem, starts, goals:
        As :func:`~mrmp.centralized.plan.as_problem` reads them.
    body:
        ``omni`` (distances count moves) or ``turning`` (distances count the
        ticks of ``(cell, heading)`` states; the result carries headings).
    max_ticks:
        Ticks before giving up (status ``limit``); by default 64 plus four times
        the longest distance of a robot to its goal, in the body's ticks.
    seed:
        Seed of the random tie-break between equally ranked cells (with the
        tie penalties of :func:`~mrmp.policies.pibt_rules.sorted_candidates`
        for ``omni``, as the fleet's ``pibt`` breaks ties); ``None``: neighbour
        order.
    swap:
        The swap technique of LaCAM* engineering (Okumura, AAMAS 2024); by
        default on for ``omni`` (as the fleet's ``pibt``), and it must be off
        for ``turning`` (it walks a robot backwards).

    Returns
    -------
    PlanningResult
        ``solved`` with paths (and headings for ``turning``), ``limit`` when
        robots are still away from their goals at ``max_ticks``, ``infeasible``
        when a goal cannot be reached.

    Raises
    ------
    ValueError
        If ``body`` is not one of :data:`PIBT_BODIES`, or ``swap`` is asked for ``turning`` bodies.
    """
    if body not in PIBT_BODIES:
        raise ValueError(f"pibt_plan plans for the bodies {', '.join(PIBT_BODIES)}, not {body!r}")
    turning = body == "turning"
    if turning and swap:
        raise ValueError("bodies that turn in place have no swap technique: it walks a robot backwards")

    start_time = time.perf_counter()
    instance = as_problem(problem, starts, goals)
    grid = tick_grid(instance.grid)
    flat = flat_grid(grid)
    count = len(instance)
    cells = [flat.index(cell) for cell in instance.starts]
    goal_cells = [flat.index(cell) for cell in instance.goals]
    distances: list[Sequence[float]]
    if turning:
        distances = [heading_distances(grid, goal, 1.0, both_ways=True) for goal in instance.goals]
        headings = [int(heading) for heading in instance.headings]
        states = [4 * cell + heading - 1 for cell, heading in zip(cells, headings)]
    else:
        distances = [distance_table(grid, goal).as_list() for goal in instance.goals]
        headings, states = [], cells
    far = [distances[robot][states[robot]] for robot in range(count)]
    for robot, distance in enumerate(far):
        if distance == float("inf"):
            message = f"robot {instance.ids[robot]} cannot reach its goal {instance.goals[robot]}"
            return PlanningResult("infeasible", None, time.perf_counter() - start_time, "pibt", message=message)
    limit = max_ticks if max_ticks is not None else 64 + 4 * int(max(far, default=0))
    generator = PIBT(
        flat.neighbours, distances, goal_cells, rng=random.Random(seed) if seed is not None else None,
        rotations=False, turning_y_size=flat.y_size if turning else 0,
        swap=not turning if swap is None else swap, tie_penalties=seed is not None and not turning,
    )  # fmt: skip
    bonus = DEAD_END_BONUS if turning else 0  # the Start-Kit's dead-end rule, as the fleet's turning robots
    scale = 1.0 / (len(flat.neighbours) + 1)
    priorities = [distance * scale for distance in far]
    cell_rows, heading_rows = [list(cells)], [list(headings)]
    tick = 0
    while cells != goal_cells and tick < limit:
        order = sorted(range(count), key=lambda robot: -priorities[robot])
        target = [NO_CELL] * count
        next_headings = [0] * count
        generator.generate(cells, target, order, headings, next_headings if turning else None)
        cells, headings = target, next_headings if turning else headings
        cell_rows.append(list(cells))
        heading_rows.append(list(headings))
        neighbours = flat.neighbours
        priorities = [
            priority + 1 + (bonus if len(neighbours[cells[robot]]) == 1 else 0)
            if cells[robot] != goal_cells[robot]
            else priority - int(priority)
            for robot, priority in enumerate(priorities)
        ]
        tick += 1
    elapsed = time.perf_counter() - start_time
    if cells != goal_cells:
        arrived = sum(cell == goal for cell, goal in zip(cells, goal_cells))
        message = f"{arrived} of {count} robots at their goals after {tick} ticks"
        return PlanningResult("limit", None, elapsed, "pibt", message=message)
    paths = tuple(tuple(flat.cell(row[robot]) for row in cell_rows) for robot in range(count))
    plan_headings = (
        tuple(tuple(Heading(row[robot]) for row in heading_rows) for robot in range(count)) if turning else None
    )
    message = f"all at their goals after {tick} ticks"
    return PlanningResult("solved", paths, elapsed, "pibt", message=message, headings=plan_headings)
