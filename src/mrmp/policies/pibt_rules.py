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


DEAD_END_BONUS = 10
"""Steps of priority a robot whose body turns in place gains, besides the step, for each step it ends in a dead end
away from its goal: the League of Robot Runners' Start-Kit rule (``default_planner/planner.cpp``, ``p[i] + 10``)."""


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


# -- bodies that turn in place (``turning``, LoRR's MAPF_T) ---------------------------------------

_STEPS = {1: (1, 0), 2: (0, 1), 3: (-1, 0), 4: (0, -1)}
"""The change of ``(x, y)`` of a move in heading ``1`` to ``4`` (NORTH, EAST, SOUTH, WEST)."""


def ahead_cell(neighbours: Sequence[tuple[int, ...]], here: int, heading: int, y_size: int) -> int:
    """The free flat cell straight ahead of ``here`` in ``heading``, or :data:`NO_CELL`.

    >>> ahead_cell([(1,), (0, 2), (1,)], 1, int(Heading.EAST), 3), ahead_cell([(1,), (0, 2), (1,)], 2, int(Heading.EAST), 3)
    (2, -1)
    """
    dx, dy = _STEPS[heading]
    cell = here + dx * y_size + dy
    return cell if cell in neighbours[here] else NO_CELL


def turned(heading: int, quarters: int) -> int:
    """``heading`` after ``quarters`` quarter turns clockwise (negative: counter-clockwise).

    >>> turned(int(Heading.NORTH), 1), turned(int(Heading.NORTH), -1)
    (2, 4)
    """
    return (heading - 1 + quarters) % 4 + 1


def heading_toward(neighbours: Sequence[tuple[int, ...]], here: int, cell: int, y_size: int) -> int:
    """The heading (1-4) in which ``cell``, a neighbour of ``here``, lies.

    >>> heading_toward([(1,), (0, 2), (1,)], 1, 2, 3), heading_toward([(1,), (0, 2), (1,)], 1, 0, 3)
    (2, 4)
    """
    for facing in (1, 2, 3, 4):
        if ahead_cell(neighbours, here, facing, y_size) == cell:
            return facing
    raise ValueError(f"cell {cell} is not a neighbour of {here}")


def turning_candidates(
    neighbours: Sequence[tuple[int, ...]],
    here: int,
    heading: int,
    table: Sequence[float],
    y_size: int,
    cell_costs: Sequence[float] | None = None,
    noise: Callable[[], float] | None = None,
) -> list[int]:
    """PIBT's candidate cells for a body that turns in place, best first: its neighbours and its own cell.

    A ``turning`` body (LoRR's ``MAPF_T``; :mod:`mrmp.core.body`) drives only
    to the cell ahead; PIBT (Okumura et al., IJCAI 2019) still chooses among
    all its neighbours, as the PIBT of the League of Robot Runners' Start-Kit
    does (MAPF-Competition/Start-Kit, ``default_planner``: next *locations*,
    then a forward move or a turn toward them): a robot given a cell it does not
    face turns toward it and stays this tick
    (:func:`turning_action`). Here the ranking counts the turns: a neighbour in
    heading ``d`` costs the quarter turns from ``heading`` to ``d``, plus its
    entry cost, plus ``table[4 * cell + d - 1]`` (``table`` the robot's
    ``(cell, heading)`` distances in ticks,
    :func:`~mrmp.search.heading_distance.heading_distances` with
    ``both_ways`` and a turn costing one tick); staying costs one tick plus
    ``table`` at ``(here, heading)``. Ties go to fewer turns (the cell ahead
    first), then to staying; ``noise`` breaks the rest as in
    :func:`sorted_candidates`.

    >>> corridor = [(1,), (0, 2), (1,)]                 # 0-1-2 along y, goal 2
    >>> table = [9.0] * 12
    >>> table[4 * 2: 4 * 3] = [0.0] * 4                 # on the goal, any heading
    >>> table[4 * 1: 4 * 2] = [2.0, 1.0, 2.0, 3.0]       # at 1: facing EAST one tick
    >>> turning_candidates(corridor, 1, int(Heading.EAST), table, 3)
    [2, 1, 0]
    >>> turning_candidates(corridor, 1, int(Heading.NORTH), table, 3)   # turn toward 2 first
    [2, 1, 0]
    >>> turning_candidates(corridor, 2, int(Heading.NORTH), table, 3)   # on the goal: stay
    [2, 1]
    """
    ranked: list[tuple[float, int, float, int]] = [(round(1.0 + table[4 * here + heading - 1], 9), 1, 0.0, here)]
    for facing in (1, 2, 3, 4):
        cell = ahead_cell(neighbours, here, facing, y_size)
        if cell == NO_CELL:
            continue
        quarters = (facing - heading) % 4
        turns = min(quarters, 4 - quarters)
        entry = cell_costs[cell] if cell_costs is not None else 1.0
        ranked.append((round(turns + entry + table[4 * cell + facing - 1], 9), 2 * turns, 0.0, cell))
    if noise is not None:
        ranked = [(cost, turns, noise(), cell) for cost, turns, _, cell in ranked]
    ranked.sort()
    return [cell for *_, cell in ranked]


def turning_action(
    neighbours: Sequence[tuple[int, ...]],
    here: int,
    heading: int,
    chosen: int,
    table: Sequence[float],
    y_size: int,
) -> int:
    """The heading a ``turning`` body that PIBT gave ``chosen`` ends its tick with; it drives on only when it keeps it.

    ``chosen`` ahead: it keeps ``heading`` and drives there. ``chosen`` another
    neighbour: it turns a quarter toward it, and stays (for a cell behind it,
    the way whose heading ``table`` ranks better, clockwise on ties).
    ``chosen == here``: it waits, or turns a quarter when that brings its goal
    nearer by ``table`` (waiting on ties, then clockwise). This is the Start-Kit's
    ``getAction`` (MAPF-Competition/Start-Kit, ``default_planner``), with the
    turns of a stay added.

    >>> corridor = [(1,), (0, 2), (1,)]
    >>> table = [9.0] * 12
    >>> table[4 * 1: 4 * 2] = [2.0, 1.0, 2.0, 3.0]       # at 1: EAST is best, WEST worst
    >>> turning_action(corridor, 1, int(Heading.EAST), 2, table, 3)   # ahead: keeps EAST and drives
    2
    >>> turning_action(corridor, 1, int(Heading.NORTH), 1, table, 3)  # stays: a quarter toward EAST
    2
    >>> turning_action(corridor, 1, int(Heading.EAST), 0, table, 3)   # 0 is behind: SOUTH (clockwise) first
    3
    """
    if chosen == here:
        options = (heading, turned(heading, 1), turned(heading, -1))
        return min(options, key=lambda facing: round(table[4 * here + facing - 1], 9))
    wanted = heading_toward(neighbours, here, chosen, y_size)
    quarters = (wanted - heading) % 4
    if quarters == 0:
        return heading
    if quarters == 2:
        clockwise, counter = turned(heading, 1), turned(heading, -1)
        return counter if table[4 * here + counter - 1] < table[4 * here + clockwise - 1] else clockwise
    return turned(heading, 1 if quarters == 1 else -1)

