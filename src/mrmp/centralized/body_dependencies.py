"""The Action Dependency Graph for bodies that follow: each move waits for the *start* of the moves out of its cell.

:func:`~mrmp.centralized.dependencies.action_dependencies` makes a move wait
until every robot that stood on its target cell earlier in the plan has
*completed* its move out (the rule of bodies that never follow, ``thesis``).
A body that follows (``omni``, ``turning``: :mod:`mrmp.core.body`) may start
into a cell as soon as the robot leaving it starts out, so its graph names the
leader's move out itself, not the count of moves it has completed.
:func:`~mrmp.centralized.dependencies.leaving_dependencies` builds that
graph, the one :func:`~mrmp.centralized.dependencies.action_dependencies`
(Hönig et al., RA-L 2019) is made from, without checking it:
:func:`~mrmp.centralized.dependencies.strict_dependencies` gives the
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

from collections.abc import Sequence

from mrmp.centralized.dependencies import find_rotations, leaving_dependencies, strict_dependencies
from mrmp.core.cell import Cell

__all__ = ["leaving_dependencies", "rotation_moves", "strict_dependencies"]  # two of them from .dependencies


def rotation_moves(paths: Sequence[Sequence[Cell]], ticks: Sequence[Sequence[int]]) -> list[list[tuple[int, int]]]:
    """The rotations of a plan, three robots or more, as ``(robot, move)`` lists, in cycle order.

    As found by :func:`~mrmp.centralized.dependencies.find_rotations`; ``ticks``
    are the ticks of every robot's moves (from :func:`~mrmp.centralized.dependencies.leaving_dependencies`).
    """
    index_at = [{tick: move for move, tick in enumerate(robot_ticks)} for robot_ticks in ticks]
    return [
        [(robot, index_at[robot][rotation.tick]) for robot in rotation.robots] for rotation in find_rotations(paths, min_robots=3)
    ]
