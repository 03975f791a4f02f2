"""Goals reached, and in lifelong runs the next goal of a robot that reached its goal.

Both simulators count arrivals and draw new goals the same way
(:class:`GoalBook`), with the run's seed: uniformly among the free cells that
are nobody's goal and not the robot's own cell.

Examples
--------
>>> import random
>>> new_goal(random.Random(0), [(0, 0), (0, 1), (0, 2)], taken={(0, 1)}, here=(0, 0))
(0, 2)
>>> new_goal(random.Random(0), [(0, 0)], taken=set(), here=(0, 0)) is None
True
"""

from __future__ import annotations

import random
from collections.abc import Container, Iterable, Sequence

from mrmp.core.cell import Cell
from mrmp.core.seeds import Stream, stream_random


def goal_random(seed: int) -> random.Random:
    """The random generator of a run's new goals (independent of the network's)."""
    return stream_random(seed, Stream.GOALS)


def new_goal(rng: random.Random, free_cells: Sequence[Cell], taken: Container[Cell], here: Cell) -> Cell | None:
    """A new goal for a robot on ``here``, or None when no free cell is left."""
    choices = [cell for cell in free_cells if cell not in taken and cell != here]
    return rng.choice(choices) if choices else None


class GoalBook:
    """Which robots reached a goal this tick, each counted once per goal; new goals when lifelong.

    >>> book = GoalBook(seed=0, free_cells=[(0, 0), (0, 1), (0, 2)])
    >>> book.arrivals([True, False]), book.arrivals([True, True])
    ([0], [1])
    >>> book.next_goal(0, taken={(0, 0), (0, 1)}, here=(0, 0))
    (0, 2)
    >>> book.arrivals([True, True])   # robot 0 has a new goal to reach first
    [0]
    """

    def __init__(self, seed: int, free_cells: Sequence[Cell]) -> None:
        self._random = goal_random(seed)
        self._free_cells = free_cells
        self._settled: set[int] = set()

    def arrivals(self, on_goal: Iterable[bool]) -> list[int]:
        """The robots (by index) standing on a goal not counted yet; a robot that leaves its goal may count again."""
        reached = []
        for index, arrived in enumerate(on_goal):
            if not arrived:
                self._settled.discard(index)
            elif index not in self._settled:
                self._settled.add(index)
                reached.append(index)
        return reached

    def next_goal(self, index: int, taken: Container[Cell], here: Cell) -> Cell | None:
        """Robot ``index``'s new goal (:func:`new_goal`), or None when no free cell is left."""
        goal = new_goal(self._random, self._free_cells, taken, here)
        if goal is not None:
            self._settled.discard(index)
        return goal
