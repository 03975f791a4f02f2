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
DEAD_END_PENALTY = 0.5
"""Added, among equally near cells, to a dead end (a cell with one free neighbour)."""
SETTLED_PENALTY = 0.25
"""Added, among equally near cells, to a cell where a robot stands on its own goal."""
NOISE_SCALE = 0.2
"""Scale of the random tie-break when tie penalties are on (penalties and noise stay below one move)."""


def sorted_candidates(
    neighbours: Sequence[tuple[int, ...]],
    here: int,
    distances: Sequence[float],
    noise: Callable[[], float] | None = None,
    settled: Container[int] | None = None,
) -> list[int]:
    """A robot's candidate cells at ``here``: its free neighbours, then ``here``, nearest to its goal first.

    Without ``noise`` the sort is stable, so equally near cells keep the order
    NORTH, EAST, SOUTH, WEST, then staying (as in the reference
    implementations, and in :class:`mrmp.centralized.pibt_step.PIBT`). With
    ``noise`` (a random number in [0, 1) per call, as pypibt shuffles
    candidates before sorting) equally near cells come in random order; the
    noise adds less than one to a distance counted in whole moves, so a nearer
    cell always comes first and PIBT's progress argument holds.

    Given ``settled`` (the cells where a robot stands on its own goal), *tie
    penalties* rank equally near cells first: a dead end (one free neighbour)
    comes after other cells, since a robot pushed into one blocks it and must
    come back out the same way; and, unless the robot is within one move of
    its own goal, a settled cell comes after a free one, since taking it pushes
    a robot off its goal. Staying is never penalised. The exception near the
    goal keeps two neighbours from trading places for ever: a robot next to its
    goal must be free to push the robot sitting on it. Penalties plus noise
    (scaled by :data:`NOISE_SCALE`) stay below one move, so the progress
    argument holds.

    >>> sorted_candidates([(1,), (0, 2), (1,)], 1, [2, 1, 0])
    [2, 1, 0]
    >>> import random
    >>> sorted(sorted_candidates([(1, 2), (0,), (0,)], 0, [1, 0, 0], random.Random(3).random)[:2])
    [1, 2]
    >>> star = [(1, 2, 3), (0,), (0, 3), (0, 2)]      # 1 is a dead end, 2 is settled
    >>> sorted_candidates(star, 0, [2, 1, 1, 1], settled={2})
    [3, 2, 1, 0]
    >>> sorted_candidates(star, 0, [1, 0, 0, 0], settled={2})  # within one move of the goal: 2 is fair game
    [2, 3, 1, 0]
    """
    candidates = [*neighbours[here], here]
    if settled is not None:
        avoid_settled = distances[here] > 1

        def key(cell: int) -> float:
            value = distances[cell]
            if cell != here:
                if len(neighbours[cell]) == 1:
                    value += DEAD_END_PENALTY
                if avoid_settled and cell in settled:
                    value += SETTLED_PENALTY
            return value + NOISE_SCALE * noise() if noise is not None else value

        candidates.sort(key=key)
    elif noise is None:
        candidates.sort(key=distances.__getitem__)
    else:
        candidates.sort(key=lambda cell: distances[cell] + noise())
    return candidates


def heading_candidates(
    neighbours: Sequence[tuple[int, ...]],
    here: int,
    table: Sequence[float],
    heading: Heading,
    y_size: int,
    turn_cost: float,
    cell_costs: Sequence[float] | None = None,
    noise: Callable[[], float] | None = None,
) -> list[int]:
    """PIBT's candidate order when turning costs time: by the heading-aware cost to the goal.

    ``table`` is a heading-aware distance table
    (:func:`mrmp.search.heading_distance.heading_distances`: entry ``4 * cell +
    heading - 1``). A move into ``n`` in direction ``d`` while facing ``heading``
    ranks by what the whole way costs through it: ``right_turns(heading, d) *
    turn_cost + cost(n) + table[n, d]``; staying ranks by ``1 + table[here,
    heading]`` (a tick of waiting, in cells). The best move's rank is exactly
    ``table[here, heading]``, less than staying's, so the highest-priority robot,
    which always gets its first candidate, moves along a cheapest heading-aware way
    and its cost to the goal drops by at least one cell's cost per step: PIBT's
    progress argument holds with distances measured in this cost. ``noise`` breaks
    ties (it must stay below the smallest difference of two costs, as in
    :func:`sorted_candidates`).

    >>> from mrmp.core.grid import Grid
    >>> from mrmp.search.flat_map import FlatMap
    >>> from mrmp.search.heading_distance import heading_distances
    >>> flat = FlatMap(Grid(2, 3))
    >>> table = heading_distances(flat.grid, (1, 2), turn_cost=0.5)    # goal: the north-east corner
    >>> [flat.cell(c) for c in heading_candidates(flat.neighbours, flat.index((0, 1)), table, Heading.EAST, 3, 0.5)]
    [(0, 2), (1, 1), (0, 1), (0, 0)]
    >>> [flat.cell(c) for c in heading_candidates(flat.neighbours, flat.index((0, 1)), table, Heading.NORTH, 3, 0.5)]
    [(1, 1), (0, 1), (0, 2), (0, 0)]

    Facing NORTH, going EAST first (one turn now, three later) costs more than waiting.
    """

    origin = divmod(here, y_size)

    def rank(cell: int) -> tuple[float, float]:
        tie = noise() if noise is not None else 0.0
        if cell == here:
            return round(1.0 + table[4 * here + heading - 1], 9), tie
        moving = Heading.between(origin, divmod(cell, y_size))
        entry = cell_costs[cell] if cell_costs is not None else 1.0
        # rounded, so that equal costs summed in another order still tie
        return round(right_turns(heading, moving) * turn_cost + entry + table[4 * cell + moving - 1], 9), tie

    candidates = [*neighbours[here], here]
    candidates.sort(key=rank)
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
