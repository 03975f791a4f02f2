"""Lifelong runs: the next goal of a robot that reached its goal.

Both simulators draw new goals the same way, with the run's seed: uniformly
among the free cells that are nobody's goal and not the robot's own cell.

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
from collections.abc import Container, Sequence

from mrmp.core.cell import Cell


def goal_random(seed: int) -> random.Random:
    """The random generator of a run's new goals (independent of the network's)."""
    return random.Random(seed * 1_000_003 + 7)


def new_goal(rng: random.Random, free_cells: Sequence[Cell], taken: Container[Cell], here: Cell) -> Cell | None:
    """A new goal for a robot on ``here``, or None when no free cell is left."""
    choices = [cell for cell in free_cells if cell not in taken and cell != here]
    return rng.choice(choices) if choices else None
