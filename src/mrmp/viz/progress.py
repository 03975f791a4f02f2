"""A one-line progress report on a terminal: of a simulation (ticks, arrivals, collisions, elapsed) or a live run.

:class:`ProgressLine` is a simulator's ``on_tick`` observer; :class:`LiveProgressLine`
shows a live run's progress (robots arrived, messages, faults injected, elapsed)
as its launcher reports it. On a terminal it
keeps one line up to date (at most a few times per second, so a fast run is
not slowed by its own report) and clears it when the run ends; elsewhere
(a pipe, a file, ``--json -``) it prints nothing.

>>> from io import StringIO
>>> from mrmp.core import Grid, RobotSpec, Scenario
>>> scenario = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 2)), RobotSpec("B", (0, 2), (0, 1))))
>>> line = ProgressLine(scenario, Console(file=StringIO()))
>>> line.on_tick(1, [(0, 1), (0, 1)])
>>> line.text()
'tick 1: 1 of 2 robots on their goals, 1 collision so far, 0 s'
>>> line.on_tick(2, [(0, 2), (0, 1)])
>>> line.text()
'tick 2: 2 of 2 robots on their goals, 1 collision so far, 0 s'
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from types import TracebackType
from typing import Self

from rich.console import Console
from rich.live import Live
from rich.text import Text

from mrmp.core.cell import Cell
from mrmp.core.progress import LiveProgress
from mrmp.core.scenario import Scenario

REFRESH_S = 0.25
"""Least time between two redraws of the line."""


class _TerminalLine:
    """One line kept up to date on a terminal while the ``with`` block runs, and cleared after it; nothing elsewhere."""

    console: Console
    live: Live | None

    def __enter__(self) -> Self:
        if self.console.is_terminal:
            self.live = Live(Text(""), console=self.console, auto_refresh=False, transient=True)
            self.live.__enter__()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        if self.live is not None:
            self.live.__exit__(kind, error, trace)


class ProgressLine(_TerminalLine):
    """Ticks done (of the tick limit when the scenario sets one), robots on their goals, collisions, elapsed time.

    In a lifelong run goals change as robots reach them, so the line counts
    ticks, collisions and time only.

    Collisions are counted as the referee defines them (two robots in one
    cell, or two robots trading cells in one tick), from the cells the
    simulator reports each tick; the referee's verdict at the end is the one
    that counts.
    """

    def __init__(self, scenario: Scenario, console: Console) -> None:
        self.goals = None if scenario.lifelong else [robot.goal for robot in scenario.robots]
        self.robots = len(scenario.robots)
        self.limit = scenario.max_ticks
        self.console = console
        self.started = time.monotonic()
        self.tick = 0
        self.arrived = 0
        self.collisions = 0
        self.previous: Sequence[Cell] = [robot.start for robot in scenario.robots]
        self.shown_at = 0.0
        self.live: Live | None = None

    def on_tick(self, tick: int, cells: Sequence[Cell]) -> None:
        """Count tick ``tick``'s arrivals and collisions, and redraw the line if it is time."""
        self.tick = tick
        if self.goals is not None:
            self.arrived = sum(1 for cell, goal in zip(cells, self.goals, strict=True) if cell == goal)
        self.collisions += _vertex_collisions(cells) + _swap_collisions(self.previous, cells)
        self.previous = list(cells)
        now = time.monotonic()
        if self.live is not None and now - self.shown_at >= REFRESH_S:
            self.shown_at = now
            self.live.update(Text(self.text()), refresh=True)

    def text(self) -> str:
        """The line as it stands."""
        ticks = f"tick {self.tick}" + (f" of {self.limit}" if self.limit else "")
        collisions = f"{self.collisions} collision{'' if self.collisions == 1 else 's'} so far"
        elapsed = time.monotonic() - self.started
        arrivals = "" if self.goals is None else f"{self.arrived} of {self.robots} robots on their goals, "
        return f"{ticks}: {arrivals}{collisions}, {elapsed:.0f} s"


class LiveProgressLine(_TerminalLine):
    """A live run's progress on one terminal line, redrawn as the launcher reports it; nothing elsewhere.

    >>> from io import StringIO
    >>> with LiveProgressLine(Console(file=StringIO())) as line:
    ...     line.on_progress(LiveProgress(robots=2, arrived=1, messages=12, elapsed_s=0.5))
    >>> line.shown
    '0.5 s: 1 of 2 robots arrived, 12 messages'
    """

    def __init__(self, console: Console) -> None:
        self.console = console
        self.live: Live | None = None
        self.shown = ""

    def on_progress(self, progress: LiveProgress) -> None:
        """Show ``progress`` (on a terminal)."""
        self.shown = progress.text()
        if self.live is not None:
            self.live.update(Text(self.shown), refresh=True)


def _vertex_collisions(cells: Sequence[Cell]) -> int:
    """Pairs of robots sharing a cell, counted once per extra robot in the cell.

    >>> _vertex_collisions([(0, 0), (0, 0), (1, 1), (0, 0)])
    2
    """
    return len(cells) - len(set(cells))


def _swap_collisions(before: Sequence[Cell], after: Sequence[Cell]) -> int:
    """Pairs of robots that traded cells between two ticks.

    >>> _swap_collisions([(0, 0), (0, 1), (5, 5)], [(0, 1), (0, 0), (5, 5)])
    1
    """
    moves = {(here, there) for here, there in zip(before, after, strict=True) if here != there}
    return sum(1 for here, there in moves if (there, here) in moves) // 2
