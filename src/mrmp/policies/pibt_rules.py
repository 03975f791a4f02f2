"""PIBT's local rules, shared by the central generator and the robots that run PIBT themselves.

Both :class:`mrmp.centralized.pibt_step.PIBT` (one process plans every robot)
and :class:`mrmp.robot.pibt_robot.PibtRobot` (each robot decides for itself
from its messages) order candidate cells and test the *swap* situation with
the functions here, so that the two agree cell for cell.

Cells are flat indices (``x * y_size + y``); ``neighbours[cell]`` lists the
free 4-neighbours of a cell; a distance list gives, for every flat cell, the
cost to one goal (``inf`` or a large number where it cannot be reached).

Sources: candidate order and priority inheritance are PIBT's (Okumura,
Machida, Défago and Tamura, IJCAI 2019 / AIJ 2022); the swap test follows
``is_swap_required`` and ``is_swap_possible`` of LaCAM* engineering (Okumura,
AAMAS 2024, ``Kei18/lacam3/src/pibt.cpp``).

Examples
--------
A corridor of four cells ``0-1-2-3``: a robot at 1 heading for 0 faces a robot
at 0 heading for 3. They cannot pass anywhere in a corridor:

>>> corridor = [(1,), (0, 2), (1, 3), (2,)]
>>> to_zero, to_three = [0, 1, 2, 3], [3, 2, 1, 0]
>>> swap_required(corridor, frozenset(), to_zero, to_three, 1, 0)
True
>>> swap_possible(corridor, frozenset(), 1, 0)
False
"""

from __future__ import annotations

from collections.abc import Callable, Container, Sequence

from mrmp.core.heading import Heading, right_turns

NO_CELL = -1
"""No cell (a walk that found no way on)."""


def sorted_candidates(
    neighbours: Sequence[tuple[int, ...]],
    here: int,
    distances: Sequence[float],
    noise: Callable[[], float] | None = None,
) -> list[int]:
    """A robot's candidate cells at ``here``: its free neighbours, then ``here``, nearest to its goal first.

    Without ``noise`` the sort is stable, so equally near cells keep the order
    NORTH, EAST, SOUTH, WEST, then staying (as in the reference
    implementations, and in :class:`mrmp.centralized.pibt_step.PIBT`). With
    ``noise`` (a random number in [0, 1) per call, as pypibt shuffles
    candidates before sorting) equally near cells come in random order; the
    noise adds less than one to a distance counted in whole moves, so a nearer
    cell always comes first and PIBT's progress argument holds.

    >>> sorted_candidates([(1,), (0, 2), (1,)], 1, [2, 1, 0])
    [2, 1, 0]
    >>> import random
    >>> sorted(sorted_candidates([(1, 2), (0,), (0,)], 0, [1, 0, 0], random.Random(3).random)[:2])
    [1, 2]
    """
    candidates = [*neighbours[here], here]
    if noise is None:
        candidates.sort(key=distances.__getitem__)
    else:
        candidates.sort(key=lambda cell: distances[cell] + noise())
    return candidates


def turn_aware_candidates(
    neighbours: Sequence[tuple[int, ...]],
    here: int,
    distances: Sequence[float],
    heading: Heading,
    y_size: int,
    noise: Callable[[], float] | None = None,
) -> list[int]:
    """Like :func:`sorted_candidates`, with fewer right turns first among equally near cells.

    The robot turns only to the right (thesis section 3.5), so facing NORTH a
    move WEST costs three turns. Distance to the goal stays the first key, so
    PIBT's progress argument (the top robot always takes a cell nearer its
    goal) is unchanged.

    >>> grid = [(3, 1), (4, 2, 0), (5, 1), (4, 0), (5, 1, 3), (2, 4)]   # Grid(2, 3), flat x * 3 + y
    >>> to_corner = [3, 2, 1, 2, 1, 0]                                  # goal (1, 2) = flat 5
    >>> sorted_candidates(grid, 1, to_corner)                         # NORTH (x + 1) listed first
    [4, 2, 1, 0]
    >>> turn_aware_candidates(grid, 1, to_corner, Heading.EAST, 3)    # facing EAST: go EAST at once
    [2, 4, 1, 0]
    """

    def key(cell: int) -> tuple[float, int, float]:
        tie = noise() if noise is not None else 0.0
        if cell == here:
            return distances[cell], 0, tie
        hx, hy = divmod(here, y_size)
        cx, cy = divmod(cell, y_size)
        return distances[cell], right_turns(heading, Heading.between((hx, hy), (cx, cy))), tie

    candidates = [*neighbours[here], here]
    candidates.sort(key=key)
    return candidates


def open_neighbours(
    neighbours: Sequence[tuple[int, ...]], settled: Container[int], cell: int, behind: int
) -> tuple[int, int]:
    """How many ways lead on from ``cell`` (not back to ``behind``, not into a settled dead end), and one of them.

    A *settled dead end* is a cell with a single neighbour on which a robot
    stands on its own goal: it will not make way, so it does not count.

    >>> open_neighbours([(1,), (0, 2), (1,)], frozenset(), 1, 0)
    (1, 2)
    >>> open_neighbours([(1,), (0, 2), (1,)], {2}, 1, 0)
    (0, -1)
    """
    row = neighbours[cell]
    count = len(row)
    onward = NO_CELL
    for next_cell in row:
        if next_cell == behind or (len(neighbours[next_cell]) == 1 and next_cell in settled):
            count -= 1
        else:
            onward = next_cell
    return count, onward


def swap_required(
    neighbours: Sequence[tuple[int, ...]],
    settled: Container[int],
    pusher_distances: Sequence[float],
    puller_distances: Sequence[float],
    pusher_cell: int,
    puller_cell: int,
) -> bool:
    """Whether the pusher (at ``pusher_cell``) and the puller (at ``puller_cell``) are head-on in a corridor.

    Walks on from the puller's cell, away from the pusher, while the pusher's
    goal keeps getting nearer; they must pass each other when no place along
    the way lets them, and the puller wants to go where the pusher comes from.

    >>> swap_required([(1,), (0, 2), (1,)], frozenset(), [2, 1, 0], [0, 1, 2], 0, 1)
    True
    """
    dist = pusher_distances
    for _ in range(len(neighbours)):
        if not dist[puller_cell] < dist[pusher_cell]:
            break
        count, onward = open_neighbours(neighbours, settled, puller_cell, pusher_cell)
        if count >= 2:
            return False  # they can pass at puller_cell
        if count <= 0:
            break
        pusher_cell, puller_cell = puller_cell, onward
    back = puller_distances
    return back[pusher_cell] < back[puller_cell] and (dist[pusher_cell] == 0 or dist[puller_cell] < dist[pusher_cell])


def swap_possible(
    neighbours: Sequence[tuple[int, ...]], settled: Container[int], pusher_origin: int, puller_origin: int
) -> bool:
    """Whether walking back from ``puller_origin`` (away from ``pusher_origin``) reaches a passing place.

    >>> swap_possible([(1,), (0, 2, 3), (1,), (1,)], frozenset(), 0, 1)
    True
    """
    pusher_cell, puller_cell = pusher_origin, puller_origin
    for _ in range(len(neighbours)):
        if puller_cell == pusher_origin:
            return False  # went round a loop
        count, onward = open_neighbours(neighbours, settled, puller_cell, pusher_cell)
        if count >= 2:
            return True
        if count <= 0:
            return False
        pusher_cell, puller_cell = puller_cell, onward
    return False
