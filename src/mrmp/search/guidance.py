"""Guidance: extra costs for moving against a map's lanes, shaping the distance tables robots rank moves by.

A guidance graph (Zhang et al., "Guidance Graph Optimization for Lifelong
Multi-Agent Path Finding", IJCAI 2024; after the highways of Cohen, Uras and
Koenig, "Feasibility Study: Using Highways for Bounded-Suboptimal Multi-Agent
Path Finding", SoCS 2015) gives each move of the map a cost of its own, so that
robots sharing a corridor tend to travel it the same way instead of meeting head
on. Planners then rank moves by distances in the guided graph; the robots still
move one cell a step, so guidance trades a little path length for less
congestion.

:data:`GUIDANCE_TABLE` maps each name of :data:`~mrmp.core.options.GUIDANCES` to
the extra cost of entering every ``(cell, heading)`` state, in the layout of
:mod:`mrmp.search.heading_distance` (state ``4 * i + d``: flat cell ``i``
entered moving in direction ``d``, 0 to 3 for NORTH, EAST, SOUTH, WEST), or to
None for no guidance:

* ``crisscross``: the "crisscross" pattern of Zhang et al.'s baselines. Lanes
  alternate row by row and column by column: along an even row (``x``) the lane
  runs EAST, along an odd one WEST; along an even column (``y``) NORTH, along an
  odd one SOUTH. A move against its lane costs one step more.

Guidance is a pure function of the map, so every robot computes the same tables
from its own copy, without a message.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> extra = crisscross(Grid(2, 2))
>>> extra[0:4]   # entering (0, 0): NORTH with column 0's lane; EAST with row 0's; SOUTH and WEST against
[0.0, 0.0, 1.0, 1.0]
>>> extra[4 * 3: 4 * 4]   # entering (1, 1): against column 1 (SOUTH) and row 1 (WEST) when NORTH or EAST
[1.0, 1.0, 0.0, 0.0]
"""

from __future__ import annotations

from collections.abc import Callable

from mrmp.core.grid import Grid

__all__ = ["AGAINST_LANE_COST", "GUIDANCE_TABLE", "crisscross", "guidance_costs"]

AGAINST_LANE_COST = 1.0
"""The extra cost, in steps, of a move against its lane."""


def crisscross(grid: Grid) -> list[float]:
    """The extra cost of entering every state of ``grid`` under the crisscross lanes (module docstring)."""
    costs: list[float] = []
    for x in range(grid.x_size):
        for y in range(grid.y_size):
            north_lane = y % 2 == 0
            east_lane = x % 2 == 0
            costs += [
                0.0 if north_lane else AGAINST_LANE_COST,
                0.0 if east_lane else AGAINST_LANE_COST,
                AGAINST_LANE_COST if north_lane else 0.0,
                AGAINST_LANE_COST if east_lane else 0.0,
            ]
    return costs


GUIDANCE_TABLE: dict[str, Callable[[Grid], list[float]] | None] = {"none": None, "crisscross": crisscross}
"""Each guidance by name: the function giving its extra costs per state, or None (module docstring)."""


def guidance_costs(name: str, grid: Grid) -> list[float] | None:
    """The extra cost of entering every state of ``grid`` under guidance ``name`` (None for ``none``).

    >>> guidance_costs("none", Grid(1, 1)) is None
    True
    >>> guidance_costs("lanes", Grid(1, 1))
    Traceback (most recent call last):
    ...
    ValueError: unknown guidance 'lanes'; known: none, crisscross
    """
    if name not in GUIDANCE_TABLE:
        raise ValueError(f"unknown guidance {name!r}; known: {', '.join(GUIDANCE_TABLE)}")
    make = GUIDANCE_TABLE[name]
    return None if make is None else make(grid)
