"""The Action Dependency Graph for bodies that follow: each move waits for the *start* of the moves out of its cell.

:func:`~mrmp.centralized.dependencies.action_dependencies` makes a move wait
until every robot that stood on its target cell earlier in the plan has
*completed* its move out (the rule of bodies that never follow, ``thesis``).
A body that follows (``omni``, ``turning``: :mod:`mrmp.core.body`) may start
into a cell as soon as the robot leaving it starts out, so its graph names the
leader's move out itself, not the count of moves it has completed.
:func:`leaving_dependencies` builds that graph, from the same visits as
:func:`~mrmp.centralized.dependencies.action_dependencies` (Hönig et al.,
RA-L 2019), without checking it: :func:`strict_dependencies` gives the
completed-move form that
:func:`~mrmp.centralized.dependencies.check_executable` checks, and
:func:`rotation_moves` the moves of the rotations a body with rotations
(``omni``) carries out all at once.

Examples
--------
>>> moves, ticks, needs = leaving_dependencies([[(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 2), (0, 3)]])
>>> needs[0]   # robot 0's first move, into (0, 1), may start with robot 1's first move (out of it)
{0: [(1, 0)], 1: [(1, 1)]}
>>> strict_dependencies(needs)[0]
{0: [(1, 1)], 1: [(1, 2)]}
>>> block = [(0, 0), (0, 1), (1, 1), (1, 0)]
>>> rotation_moves([[block[i], block[(i + 1) % 4]] for i in range(4)], [[1]] * 4)
[[(0, 0), (1, 0), (2, 0), (3, 0)]]
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from mrmp.centralized.dependencies import find_rotations, plan_moves
from mrmp.core.cell import Cell

__all__ = ["leaving_dependencies", "rotation_moves", "strict_dependencies"]

Needs = list[dict[int, list[tuple[int, int]]]]
"""Per robot, per move index, the ``(robot, move index)`` pairs the move waits for."""


def leaving_dependencies(paths: Sequence[Sequence[Cell]]) -> tuple[list[list[Cell]], list[list[int]], Needs]:
    """Every robot's moves, the tick of each, and per move the ``(robot, move)`` moves out of its target cell it waits for.

    Move ``k`` of robot ``i`` entering cell ``c`` at tick ``t`` waits for every
    other robot ``j`` that stood on ``c`` at some tick before ``t``: for ``j``'s
    move out of ``c`` after its last visit before ``t`` (named by its index in
    ``j``'s moves). Not checked: a rotation or a swap makes it cyclic.

    Raises
    ------
    ValueError
        If the plan makes a robot enter a cell another robot never leaves
        afterwards (the plan collides).
    """
    moves_and_ticks = [plan_moves(path) for path in paths]
    visits: dict[Cell, list[tuple[int, int]]] = {}
    for robot, path in enumerate(paths):
        for tick, cell in enumerate(path):
            visits.setdefault(cell, []).append((tick, robot))
    for cell_visits in visits.values():
        cell_visits.sort()
    dependencies: Needs = []
    for robot, (cells, ticks) in enumerate(moves_and_ticks):
        needs: dict[int, list[tuple[int, int]]] = {}
        for move, (cell, tick) in enumerate(zip(cells, ticks)):
            last_visit: dict[int, int] = {}
            for visit_tick, other in visits[cell]:
                if visit_tick >= tick:
                    break
                if other != robot:
                    last_visit[other] = visit_tick
            for other, visit_tick in sorted(last_visit.items()):
                other_ticks = moves_and_ticks[other][1]
                leaving = next((index for index, t in enumerate(other_ticks) if t > visit_tick), None)
                if leaving is None:
                    raise ValueError(f"robot {robot} enters {cell} at tick {tick} but robot {other} never leaves it")
                needs.setdefault(move, []).append((other, leaving))
        dependencies.append(needs)
    return [cells for cells, _ in moves_and_ticks], [ticks for _, ticks in moves_and_ticks], dependencies


def strict_dependencies(needs: Sequence[Mapping[int, Sequence[tuple[int, int]]]]) -> Needs:
    """The same graph in the form of :func:`~mrmp.centralized.dependencies.action_dependencies`: ``(robot, progress)``.

    Waiting for a move to start becomes waiting for it to be completed
    (progress one more than its index): the same edges between moves, so one
    form is acyclic when the other is.
    """
    return [{move: [(other, index + 1) for other, index in waits] for move, waits in robot.items()} for robot in needs]


def rotation_moves(paths: Sequence[Sequence[Cell]], ticks: Sequence[Sequence[int]]) -> list[list[tuple[int, int]]]:
    """The rotations of a plan, three robots or more, as ``(robot, move)`` lists, in cycle order.

    As found by :func:`~mrmp.centralized.dependencies.find_rotations`; ``ticks``
    are the ticks of every robot's moves (from :func:`leaving_dependencies`).
    """
    index_at = [{tick: move for move, tick in enumerate(robot_ticks)} for robot_ticks in ticks]
    return [
        [(robot, index_at[robot][rotation.tick]) for robot in rotation.robots] for rotation in find_rotations(paths, min_robots=3)
    ]
