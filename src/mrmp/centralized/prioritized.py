"""Prioritized planning: robots planned one at a time, each around those before it.

Prioritized planning (Erdmann & Lozano-Perez, "On multiple moving objects",
Algorithmica 2, 1987; Silver, "Cooperative Pathfinding", AIIDE 2005) orders the
robots by priority and plans each with space-time A*
(:func:`~mrmp.centralized.space_time_astar.space_time_astar`) against a
reservation table holding the paths of every robot planned before it: their
cells at each tick, the reverse of their moves (no swaps) and their goals from
the tick they arrive (they stay there). A robot also never settles on its goal
before the last tick a higher-priority robot crosses it.

**No rotations.** A robot may *follow* a higher-priority one (enter, at tick
``t``, the cell that one leaves at ``t``), but never by a move that closes a
cycle of such moves: robots on a cycle of cells, each entering the cell the
next one leaves at the same tick, cannot be executed by robots moving one at a
time (:mod:`mrmp.centralized.dependencies`). A cycle's last member in priority
order is planned when every other member's path is known, so it suffices that
each robot's search forbids the moves closing a cycle with the robots before
it (the move entries of :class:`~mrmp.centralized.space_time_astar.Reservations`):
such a move ``u -> v`` at tick ``t`` is one into the cell of a robot that
leaves it at ``t`` while the chain of robots following one another from
there ends by entering ``u``. Only those moves are removed (following stays
allowed), so the plans are rotation-free and the method is no less complete
than the classic one in any other respect: it remains incomplete.

The method is fast but incomplete: a robot whose every way to its goal is cut
by the robots before it (for example a higher-priority robot parks on the only
corridor to its goal) cannot be planned, even when another order would work.
Then the result has status ``"failed"`` and ``failed_robot`` names it. Robots
of lower priority are not seen by those before them, so a robot may also fail
because a higher-priority path runs through its start.

Orders: ``"scenario"`` (the robots' order, the default), ``"longest_first"``
(longest shortest-path first, ties by scenario order; van den Berg & Overmars
2005 use distance-based priorities), or an explicit sequence of robot ids.

``nodes`` in the result counts the low-level space-time A* expansions of all
robots.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> from mrmp.sim.referee import check_paths
>>> grid = Grid.from_rows(["#.##", "...."])
>>> starts, goals = [(1, 1), (0, 0)], [(0, 2), (0, 3)]
>>> failed = prioritized(grid, starts, goals)
>>> failed.status, failed.failed_robot
('failed', '1')
>>> solved = prioritized(grid, starts, goals, order="longest_first")
>>> solved.status, solved.sum_of_costs(), check_paths(grid, dict(zip("AB", solved.paths)))
('solved', 6, [])
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from mrmp.centralized.cbs import PLANNED_BODIES, infeasibility_proof
from mrmp.centralized.plan import (
    MapfProblem,
    PlanningResult,
    as_problem,
    pad_headings,
    pad_paths,
)
from mrmp.centralized.space_time_astar import (
    Reservations,
    SpaceTimeResult,
    hop_distance_table,
    space_time_astar,
)
from mrmp.core.cell import Cell
from mrmp.core.errors import InputError
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario

__all__ = ["ORDERS", "prioritized", "priority_order"]

ORDERS = ("scenario", "longest_first")
"""The named priority orders."""


def priority_order(problem: MapfProblem, order: str | Sequence[str] = "scenario") -> list[int]:
    """Robot indices, highest priority first.

    Parameters
    ----------
    problem:
        The instance.
    order:
        ``"scenario"``, ``"longest_first"`` or a sequence naming every robot id once.

    Raises
    ------
    InputError
        If ``order`` is an unknown name or not a permutation of the robot ids.

    Examples
    --------
    >>> p = as_problem(Grid(1, 5), [(0, 0), (0, 1)], [(0, 2), (0, 4)])
    >>> priority_order(p), priority_order(p, "longest_first"), priority_order(p, ["1", "0"])
    ([0, 1], [1, 0], [1, 0])
    """
    if isinstance(order, str):
        if order == "scenario":
            return list(range(len(problem)))
        if order == "longest_first":
            lengths = [
                hop_distance_table(problem.grid, goal).distance(start) for start, goal in zip(problem.starts, problem.goals)
            ]
            return sorted(range(len(problem)), key=lambda index: (-lengths[index], index))
        raise InputError(f"unknown priority order {order!r}: use {', '.join(ORDERS)} or a list of robot ids")
    position = {robot_id: index for index, robot_id in enumerate(problem.ids)}
    chosen = [position.get(str(robot_id), -1) for robot_id in order]
    if sorted(chosen) != list(range(len(problem))):
        raise InputError(f"priority order {list(order)} must name each of the robots {list(problem.ids)} once")
    return chosen


def prioritized(
    problem: Scenario | Grid | MapfProblem,
    starts: Sequence[Cell] | None = None,
    goals: Sequence[Cell] | None = None,
    *,
    order: str | Sequence[str] = "scenario",
    max_time: int | None = None,
    time_limit_s: float | None = None,
    heading_aware: bool = False,
    body: str = "omni",
) -> PlanningResult:
    """Plan the robots one by one in priority order (Silver 2005; Erdmann & Lozano-Perez 1987).

    Parameters
    ----------
    problem:
        A :class:`~mrmp.core.scenario.Scenario`, or a grid with ``starts`` and
        ``goals`` (see :func:`~mrmp.centralized.plan.as_problem`).
    starts, goals:
        With a grid: one cell per robot.
    order:
        The priority order (see :func:`priority_order`).
    max_time:
        The horizon of each robot's search, in ticks (``None``: none; each
        search is still finite, see :mod:`mrmp.centralized.space_time_astar`).
    time_limit_s:
        Stop after this many seconds in all, with status ``"limit"``
        (``None``: no limit).
    heading_aware:
        Plan with the turn model (one tick per move forward or right turn).
    body:
        The body planned for (:data:`~mrmp.centralized.cbs.PLANNED_BODIES`):
        ``omni`` (the turn model of ``heading_aware``), or ``turning`` (LoRR's
        ``MAPF_T``: one tick per move forward, quarter turn either way, or wait;
        ``heading_aware`` implied).

    Returns
    -------
    PlanningResult
        ``"solved"``; ``"failed"`` with ``failed_robot`` when a robot could not
        be planned around those before it; ``"limit"`` when the time limit was
        reached; ``"infeasible"`` when a cheap proof shows that no plan exists
        (:func:`~mrmp.centralized.cbs.infeasibility_proof`: a goal cut off from
        its start, or robots filling a region). ``nodes`` counts low-level
        expansions. Plans never contain a rotation (see the module docstring).

    Raises
    ------
    InputError
        If the input or the order is invalid.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> r = prioritized(Grid(3, 3), [(0, 0), (0, 2)], [(0, 2), (0, 0)])
    >>> r.status, r.sum_of_costs(), r.planner
    ('solved', 6, 'pp')
    """
    if body not in PLANNED_BODIES:
        raise ValueError(f"pp plans for the bodies {', '.join(PLANNED_BODIES)}, not {body!r}")
    began = time.perf_counter()
    instance = as_problem(problem, starts, goals)
    proof = infeasibility_proof(instance)
    if proof is not None:
        return PlanningResult("infeasible", None, time.perf_counter() - began, "pp", message=proof)
    turning = body == "turning"
    planner = _Prioritized(instance, began, time_limit_s, max_time, heading_aware or turning, turning)
    return planner.run(priority_order(instance, order))


class _Prioritized:
    """One run of prioritized planning: plan each robot in turn around the paths reserved before it."""

    def __init__(
        self,
        instance: MapfProblem,
        began: float,
        time_limit_s: float | None,
        max_time: int | None,
        heading_aware: bool,
        both_ways: bool = False,
    ) -> None:
        self.instance = instance
        self.both_ways = both_ways
        self.began = began
        self.time_limit_s = time_limit_s
        self.deadline = None if time_limit_s is None else began + time_limit_s
        self.max_time = max_time
        self.heading_aware = heading_aware
        self.reservations = Reservations()
        self.paths: list[tuple[Cell, ...] | None] = [None] * len(instance)
        self.headings: list[tuple[Heading, ...] | None] = [None] * len(instance)
        self.expansions = 0

    def run(self, ranking: Sequence[int]) -> PlanningResult:
        """Plan the robots in ``ranking`` order; the first that cannot be planned ends the run."""
        for rank, index in enumerate(ranking):
            robot_id = self.instance.ids[index]
            if self.deadline is not None and time.perf_counter() > self.deadline:
                return self._time_limit("before planning", robot_id)
            found = self._plan_robot(index)
            if found.status == "deadline":
                return self._time_limit("while planning", robot_id)
            if not found.found or found.path is None:
                return self._failed(ranking, rank, found)
            self.paths[index] = found.path
            self.headings[index] = found.headings
            self.reservations.reserve_path(found.path)
        return self._solved()

    def _plan_robot(self, index: int) -> SpaceTimeResult:
        """Space-time A* for robot ``index`` around the reservations so far."""
        instance = self.instance
        found = space_time_astar(
            instance.grid,
            instance.starts[index],
            instance.goals[index],
            self.reservations,
            heading_aware=self.heading_aware,
            heading=instance.headings[index],
            both_ways=self.both_ways,
            max_time=self.max_time,
            deadline=self.deadline,
        )
        self.expansions += found.expansions
        return found

    def _elapsed(self) -> float:
        return time.perf_counter() - self.began

    def _time_limit(self, when: str, robot_id: str) -> PlanningResult:
        message = f"time limit of {self.time_limit_s:g} s reached {when} robot {robot_id}"
        return PlanningResult("limit", None, self._elapsed(), "pp", nodes=self.expansions, message=message)

    def _failed(self, ranking: Sequence[int], rank: int, found: SpaceTimeResult) -> PlanningResult:
        instance = self.instance
        robot_id = instance.ids[ranking[rank]]
        reason = "within the horizon" if found.status == "horizon" else "around the robots planned before it"
        before = ", ".join(instance.ids[i] for i in ranking[:rank]) or "none"
        return PlanningResult(
            "failed",
            None,
            self._elapsed(),
            "pp",
            nodes=self.expansions,
            failed_robot=robot_id,
            message=f"robot {robot_id} (priority {rank + 1} of {len(instance)}) has no path {reason} "
            f"(planned before it: {before})",
        )

    def _solved(self) -> PlanningResult:
        done = [path for path in self.paths if path is not None]
        headings = pad_headings([row for row in self.headings if row is not None]) if self.heading_aware else None
        return PlanningResult(
            "solved",
            pad_paths(done),
            self._elapsed(),
            "pp",
            nodes=self.expansions,
            message=f"planned {len(done)} robots in priority order",
            headings=headings,
        )
