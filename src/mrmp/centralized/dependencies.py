"""The Action Dependency Graph of a plan (Hönig et al., RA-L 2019).

Each robot's path (one cell per tick) becomes its *moves*: the cells it enters,
in order. Move ``k`` of robot ``i`` entering cell ``c`` at tick ``t`` depends on
every other robot ``j`` that stood on ``c`` at some tick before ``t``: ``i`` may
enter ``c`` only once ``j`` has completed the move by which it left ``c`` after
its last visit before ``t`` (``j``'s progress, the count of its completed moves,
is then larger than that move's index). In a collision-free plan every such
move exists, and the graph is acyclic (edges point from earlier to later ticks).

Examples
--------
>>> moves, needs = action_dependencies([[(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 2), (0, 3)]])
>>> moves
[[(0, 1), (0, 2)], [(0, 2), (0, 3)]]
>>> needs[0]   # robot 0's first move, into (0, 1), waits for robot 1's first move (leaving it)
{0: [(1, 1)], 1: [(1, 2)]}
>>> needs[1]
{}
"""

from __future__ import annotations

from collections.abc import Sequence

from mrmp.core.cell import Cell


def plan_moves(path: Sequence[Cell]) -> tuple[list[Cell], list[int]]:
    """A path's moves (cells entered) and the tick of each.

    >>> plan_moves([(0, 0), (0, 0), (0, 1), (1, 1)])
    ([(0, 1), (1, 1)], [2, 3])
    """
    cells, ticks = [], []
    for tick in range(1, len(path)):
        if path[tick] != path[tick - 1]:
            cells.append(path[tick])
            ticks.append(tick)
    return cells, ticks


def action_dependencies(paths: Sequence[Sequence[Cell]]) -> tuple[list[list[Cell]], list[dict[int, list[tuple[int, int]]]]]:
    """Every robot's moves and, per move, the ``(robot, progress)`` pairs it must wait for.

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
    dependencies: list[dict[int, list[tuple[int, int]]]] = []
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
                needs.setdefault(move, []).append((other, leaving + 1))
        dependencies.append(needs)
    return [cells for cells, _ in moves_and_ticks], dependencies
