"""Heading-aware distance tables: the cost to a goal from every (cell, heading) state.

The Khepera III turns only to the right (thesis section 3.5), so a robot's cost to
reach its goal depends on where it faces: facing NORTH, a move WEST first costs
three right turns. :func:`heading_distances` computes, for one goal, the least cost
from every state ``(cell, heading)`` — the heading being the direction the robot
faces on that cell — to the goal cell in any heading, where a move from ``c`` in
direction ``d`` while facing ``h`` costs ``right_turns(h, d) * turn_cost`` plus the
entry cost of the cell entered (the same model as heading-aware A*,
:mod:`mrmp.search.best_first_engine`).

The search runs backwards from the goal's four states over the state graph,
wavefront by wavefront, as a label-correcting shortest-path search (Bellman 1958,
"On a routing problem"; Moore 1959, "The shortest path through a maze"): the states
improved in one wave offer their cost to their predecessors in the next, until no
state improves. With non-negative costs this gives Dijkstra's distances (Dijkstra
1959, "A note on two problems in connexion with graphs"), to the last bit: every
candidate cost is summed as a heap-based search sums it (the entry cost, then the
turns). As in :mod:`mrmp.search.distance`, a small wave is expanded in a
plain Python loop and a large one with a few numpy operations over the whole wave:
the 280,000 states of a 500 x 140 warehouse map take tens of milliseconds, where a
heap-based search in Python took a third of a second.

The table is a flat ``array('d')``: the state of flat cell ``i`` (``x * y_size + y``) facing
heading ``h`` (1-4) is entry ``4 * i + h - 1``; blocked and unreachable states are
``inf``. Policy ``pibt`` with ``heading_aware`` ranks its candidate cells with it
(:func:`mrmp.policies.pibt_rules.heading_candidates`).

With ``both_ways`` a body turns a quarter either way (the ``turning`` body of
:mod:`mrmp.core.body`, LoRR's ``MAPF_T``), so a change of heading costs
``min(r, 4 - r)`` quarter turns instead of ``r`` right turns; with
``turn_cost=1`` the table counts the ticks of MAPF_T's actions (forward, turn,
wait), the distance of the ``(cell, heading)`` search that LoRR's planners use.

Examples
--------
A 1x3 corridor, goal at its east end (0, 2); a right turn costs half a cell:

>>> from mrmp.core.grid import Grid
>>> from mrmp.core.heading import Heading
>>> table = heading_distances(Grid(1, 3), (0, 2), turn_cost=0.5)
>>> def at(cell, heading):
...     return table[4 * (cell[0] * 3 + cell[1]) + int(heading) - 1]
>>> at((0, 0), Heading.EAST), at((0, 0), Heading.NORTH), at((0, 0), Heading.WEST)
(2.0, 2.5, 3.0)
>>> at((0, 2), Heading.SOUTH)
0.0

Turning either way, facing WEST costs two quarter turns, facing NORTH one:

>>> table = heading_distances(Grid(1, 3), (0, 2), turn_cost=1.0, both_ways=True)
>>> at((0, 0), Heading.EAST), at((0, 0), Heading.NORTH), at((0, 0), Heading.WEST)
(2.0, 3.0, 4.0)
"""

from __future__ import annotations

import threading
from array import array
from collections import OrderedDict

import numpy as np

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import HEADINGS, quarter_turns, right_turns
from mrmp.search.flat_grid import flat_grid
from mrmp.search.guidance import guidance_costs
from mrmp.search.wavefront import IndexArray, dedupe

__all__ = ["heading_distances"]

_TURNS = [[right_turns(facing, moving) for moving in HEADINGS] for facing in HEADINGS]
"""``_TURNS[h - 1][d - 1]``: right turns from facing ``h`` to facing ``d``."""
_QUARTERS = [[quarter_turns(facing, moving) for moving in HEADINGS] for facing in HEADINGS]
"""``_QUARTERS[h - 1][d - 1]``: quarter turns either way from facing ``h`` to facing ``d``."""
_VECTOR_THRESHOLD = 32
"""Waves of more states than this are expanded with numpy; smaller ones in Python."""
_GRID_CACHE_SIZE = 8
"""How many grids keep their state graph cached."""



class _StateGraph:
    """What every reverse search on one grid needs, built once (module docstring).

    State ``s = 4 * i + d`` is flat cell ``i`` entered moving in direction ``d``
    (0 to 3: NORTH, EAST, SOUTH, WEST). Its predecessors are the four states of the
    cell behind it, ``behind[s]``, or none when that cell is blocked or off the
    grid (``behind[s] == size``, the padding cell). ``costs[s]`` is the cost of
    entering state ``s``: its cell's entry cost, plus the guidance's extra cost
    (:mod:`mrmp.search.guidance`).
    """

    def __init__(self, grid: Grid, guidance: str) -> None:
        x_size, y_size = grid.x_size, grid.y_size
        size = x_size * y_size
        self.size = size
        per_state = [cost for cost in flat_grid(grid).costs for _ in range(4)]
        extra = guidance_costs(guidance, grid)
        if extra is not None:
            per_state = [cost + more for cost, more in zip(per_state, extra, strict=True)]
        self.costs = per_state + [0.0] * 4
        behind = [size] * (4 * size + 4)
        for x in range(x_size):
            for y in range(y_size):
                if not grid.is_free((x, y)):
                    continue
                state = 4 * (x * y_size + y)
                for direction, heading in enumerate(HEADINGS):
                    dx, dy = heading.delta
                    before = (x - dx, y - dy)
                    if grid.is_free(before):
                        behind[state + direction] = before[0] * y_size + before[1]
        self.behind = behind
        self.behind_array: IndexArray = np.array(behind, dtype=np.intp)
        self.cost_array = np.array(self.costs)
        self.ranks: IndexArray = np.arange(16 * size + 16, dtype=np.intp)


_GRAPHS: OrderedDict[tuple[Grid, str], _StateGraph] = OrderedDict()
_GRAPHS_LOCK = threading.Lock()


def _state_graph(grid: Grid, guidance: str) -> _StateGraph:
    """The state graph of ``grid`` under ``guidance``, kept for the last few (grids are immutable)."""
    key = (grid, guidance)
    with _GRAPHS_LOCK:
        graph = _GRAPHS.get(key)
        if graph is not None:
            _GRAPHS.move_to_end(key)
            return graph
    graph = _StateGraph(grid, guidance)
    with _GRAPHS_LOCK:
        _GRAPHS[key] = graph
        while len(_GRAPHS) > _GRID_CACHE_SIZE:
            _GRAPHS.popitem(last=False)
    return graph


def heading_distances(
    grid: Grid, goal: Cell, turn_cost: float, both_ways: bool = False, guidance: str = "none"
) -> array[float]:
    """The least cost from every ``(cell, heading)`` state of ``grid`` to ``goal`` (module docstring).

    The table is an ``array('d')``: 8 bytes a state, indexed as a list.

    Parameters
    ----------
    grid:
        The map (entry costs respected).
    goal:
        The goal cell; any heading on it counts as arrived.
    turn_cost:
        The cost of one right turn, in the unit of entry costs (``turn_time / cell_time``).
    both_ways:
        The body turns a quarter either way at ``turn_cost`` each (module docstring).
    guidance:
        A name of :data:`~mrmp.search.guidance.GUIDANCE_TABLE`: moves against the
        map's lanes cost that much more (``none``: nothing more).

    Raises
    ------
    ValueError
        If ``goal`` is not a free cell of the grid, ``turn_cost`` is negative, or ``guidance`` unknown.

    >>> from mrmp.core.heading import Heading
    >>> row = Grid(2, 3)   # from (1, 0) to (1, 2), facing EAST: row 1's lane runs WEST
    >>> state = 4 * 3 + int(Heading.EAST) - 1
    >>> heading_distances(row, (1, 2), 1.0, True)[state], heading_distances(row, (1, 2), 1.0, True, "crisscross")[state]
    (2.0, 4.0)
    """
    if not grid.is_free(goal):
        raise ValueError(f"goal {goal} is not a free cell of the grid")
    if turn_cost < 0:
        raise ValueError(f"turn_cost must not be negative, got {turn_cost}")
    graph = _state_graph(grid, guidance)
    counts = _QUARTERS if both_ways else _TURNS
    turns = [[counts[facing][moving] * turn_cost for moving in range(4)] for facing in range(4)]
    table = _search(graph, goal[0] * grid.y_size + goal[1], turns)
    return table[: 4 * graph.size]


def _search(graph: _StateGraph, goal: int, turns: list[list[float]]) -> array[float]:
    """The wavefront label-correcting search of the module docstring, from flat cell ``goal``.

    ``turns[facing][moving]`` is the cost of the turns before a move. The padding
    cell's states hold ``-inf``, so no offer improves them and they are never queued.
    """
    size, behind, costs = graph.size, graph.behind, graph.costs
    table = array("d", [float("inf")]) * (4 * size) + array("d", [float("-inf")]) * 4
    view = np.frombuffer(table, dtype=np.float64)
    by_moving = [[turns[facing][moving] for facing in range(4)] for moving in range(4)]
    by_moving_array = np.array(by_moving)
    facings = np.arange(4, dtype=np.intp)
    queued = bytearray(4 * size + 4)  # 1 for a state already in the wave being built
    owner: IndexArray | None = None
    frontier: list[int] | IndexArray = [4 * goal + heading for heading in range(4)]
    for state in frontier:
        table[state] = 0.0
    while True:
        if isinstance(frontier, list):
            wave: list[int] = []
            append = wave.append
            for state in frontier:
                before = 4 * behind[state]
                entered = table[state] + costs[state]
                for facing, turn in enumerate(by_moving[state & 3]):
                    offer = entered + turn
                    if offer < table[before + facing]:
                        table[before + facing] = offer
                        if not queued[before + facing]:
                            queued[before + facing] = 1
                            append(before + facing)
            for state in wave:
                queued[state] = 0
            if not wave:
                return table
            frontier = wave if len(wave) <= _VECTOR_THRESHOLD else np.array(wave, dtype=np.intp)
        else:
            entered = view[frontier] + graph.cost_array[frontier]
            candidates = (4 * graph.behind_array[frontier])[:, None] + facings
            offers = entered[:, None] + by_moving_array[frontier & 3]
            candidates, offers = candidates.ravel(), offers.ravel()
            better = offers < view[candidates]
            candidates, offers = candidates[better], offers[better]
            if not candidates.size:
                return table
            np.minimum.at(view, candidates, offers)
            if owner is None:
                owner = np.empty(4 * size + 4, dtype=np.intp)
            candidates = dedupe(candidates, owner, graph.ranks)
            frontier = candidates if candidates.size > _VECTOR_THRESHOLD else candidates.tolist()
