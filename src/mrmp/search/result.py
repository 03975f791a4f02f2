"""What a single-robot planner returns.

Examples
--------
>>> result = SearchResult(path=((0, 0), (1, 0)), cost=1.0, expansions=1)
>>> result.path[-1], result.cost, result.headings is None
((1, 0), 1.0, True)
"""

from __future__ import annotations

from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading

__all__ = ["SearchResult"]


@dataclass(frozen=True)
class SearchResult:
    """A planned path, its cost and how much work finding it took.

    Attributes
    ----------
    path:
        The cells from start to goal, both included; consecutive cells are
        4-adjacent. ``(start,)`` when start is the goal.
    cost:
        The sum of the entry costs of every cell entered (the start is not
        entered). With a :class:`~mrmp.core.scenario.Timing`, each entry cost
        is multiplied by ``cell_time``; when the planner is heading-aware,
        ``turn_time`` is added for each right turn.
    expansions:
        How many search nodes the planner expanded (popped from its open list
        and generated successors for); for the update-coordinate method, the
        number of cells visited.
    headings:
        When heading-aware, the robot's heading on each cell of ``path``
        (``headings[0]`` is the initial heading, ``headings[i]`` the direction
        of the move into ``path[i]``); ``None`` otherwise.

    Examples
    --------
    >>> from mrmp.core.heading import Heading
    >>> r = SearchResult(((0, 0), (0, 1)), 1.5, 1, (Heading.NORTH, Heading.EAST))
    >>> [h.name for h in r.headings]
    ['NORTH', 'EAST']
    """

    path: tuple[Cell, ...]
    cost: float
    expansions: int
    headings: tuple[Heading, ...] | None = None

    @property
    def steps(self) -> int:
        """Number of moves along the path (``len(path) - 1``).

        >>> SearchResult(((0, 0), (0, 1), (0, 2)), 2.0, 2).steps
        2
        """
        return len(self.path) - 1
