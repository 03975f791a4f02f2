"""The thesis's experiment over every orientation: two robots trade places, for every pair of cells.

Chapter 4's scenario 2 (figure 4, labels "S(A) D(A) / D(B) S(B)") has two
robots trade places but gives no cells, and chapter 3 calls the method
successful "under all circumstances". This module runs the thesis's rule
(:class:`~mrmp.policies.thesis.ThesisPolicy`) on every unordered pair of cells
of an empty grid, robot A from the first cell to the second and robot B the
other way, for both of the thesis's resolutions (``divert``, the change of
route; ``wait``, velocity tuning, section 2.1), with and without the safety
layer, and counts the outcomes. ``bench/thesis_pairs.py`` prints the table;
``docs/thesis.md`` discusses it.

Outcomes: ``success`` (both arrived, no collision), ``collision`` (the referee
found one; unguarded runs only), or the simulator's stop reason (``livelock``,
``deadlock``, ``tick limit``).

Examples
--------
>>> from mrmp.core.grid import Grid
>>> len(trade_places_pairs(Grid(5, 5)))
300
>>> outcome(trade_places_scenario(Grid(5, 5), (0, 2), (4, 2), "divert", guarded=True))
'success'
>>> outcome(trade_places_scenario(Grid(5, 5), (2, 0), (2, 4), "divert", guarded=True))
'livelock'
"""

from __future__ import annotations

import itertools
from collections import Counter
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.options import POLICY_DEFAULT_SEARCH, RESOLUTIONS
from mrmp.core.scenario import PolicyOptions, RobotSpec, Scenario
from mrmp.sim.simulator import simulate

OUTCOMES = ("success", "livelock", "deadlock", "collision", "tick limit")
"""Every outcome a trade-places run can have, in table order."""

TICK_LIMIT = 60
"""Ticks per run: on a 5x5 grid a successful trade takes at most 12 (sum of both robots' costs about 20)."""


@dataclass(frozen=True)
class Column:
    """One column of the table: a resolution, with or without the safety layer."""

    resolve: str
    guarded: bool

    @property
    def title(self) -> str:
        """The column's heading.

        >>> Column("wait", guarded=True).title
        'wait, guarded'
        """
        return f"{self.resolve}, {'guarded' if self.guarded else 'unguarded'}"


COLUMNS = tuple(Column(resolve, guarded) for resolve in RESOLUTIONS for guarded in (False, True))
"""The table's columns: ``divert`` and ``wait``, each unguarded then guarded."""


def trade_places_pairs(grid: Grid) -> list[tuple[Cell, Cell]]:
    """Every unordered pair of free cells of ``grid``, cells in row-major ``(x, y)`` order.

    >>> trade_places_pairs(Grid(1, 3))
    [((0, 0), (0, 1)), ((0, 0), (0, 2)), ((0, 1), (0, 2))]
    """
    cells = [(x, y) for x in range(grid.x_size) for y in range(grid.y_size) if grid.is_free((x, y))]
    return list(itertools.combinations(cells, 2))


def trade_places_scenario(
    grid: Grid, first: Cell, second: Cell, resolve: str, guarded: bool, search: str = POLICY_DEFAULT_SEARCH
) -> Scenario:
    """Robot A from ``first`` to ``second``, robot B back, both facing NORTH, under the thesis's rule.

    ``search`` gives Next (``policy.search``; by default the update coordinate method).
    """
    robots = (RobotSpec("A", first, second), RobotSpec("B", second, first))
    return Scenario(
        grid,
        robots,
        name=f"trade {first} {second}",
        policy=PolicyOptions(name="thesis", resolve=resolve, search=search),
        max_ticks=TICK_LIMIT,
        safety=guarded,
    )


def outcome(scenario: Scenario) -> str:
    """How one run of ``scenario`` in the lockstep simulator ends (one of :data:`OUTCOMES`)."""
    result = simulate(scenario)
    if result.collisions:
        return "collision"
    return "success" if result.success else result.stop_reason


def outcome_table(grid: Grid | None = None, search: str = POLICY_DEFAULT_SEARCH) -> dict[Column, Counter[str]]:
    """The outcomes of every trade-places pair of ``grid`` (5x5 when omitted), per column of :data:`COLUMNS`."""
    grid = grid or Grid(5, 5)
    pairs = trade_places_pairs(grid)
    table: dict[Column, Counter[str]] = {}
    for column in COLUMNS:
        table[column] = Counter(
            outcome(trade_places_scenario(grid, first, second, column.resolve, column.guarded, search))
            for first, second in pairs
        )
    return table


def failing_pairs(
    grid: Grid, column: Column, search: str = POLICY_DEFAULT_SEARCH
) -> dict[str, list[tuple[Cell, Cell]]]:
    """The pairs of ``grid`` that do not succeed in ``column``, by outcome.

    >>> failing_pairs(Grid(1, 2), Column("divert", guarded=False))
    {'collision': [((0, 0), (0, 1))]}
    """
    failures: dict[str, list[tuple[Cell, Cell]]] = {}
    for first, second in trade_places_pairs(grid):
        result = outcome(trade_places_scenario(grid, first, second, column.resolve, column.guarded, search))
        if result != "success":
            failures.setdefault(result, []).append((first, second))
    return failures


def table_markdown(table: dict[Column, Counter[str]]) -> str:
    """The table as Markdown: one row per outcome, one column per :class:`Column`, and the total.

    >>> print(table_markdown({Column("divert", False): Counter(success=2, livelock=1)}))
    | outcome | divert, unguarded |
    |---|---:|
    | success | 2 |
    | livelock | 1 |
    | deadlock | 0 |
    | collision | 0 |
    | tick limit | 0 |
    | pairs | 3 |
    """
    columns = list(table)
    lines = [
        "| outcome | " + " | ".join(column.title for column in columns) + " |",
        "|---|" + "---:|" * len(columns),
    ]
    for name in OUTCOMES:
        lines.append(f"| {name} | " + " | ".join(str(table[column][name]) for column in columns) + " |")
    lines.append("| pairs | " + " | ".join(str(sum(table[column].values())) for column in columns) + " |")
    return "\n".join(lines)
