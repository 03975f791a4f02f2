"""A run drawn in the terminal as it goes, with rich.

The grid is drawn north up and east to the right, two characters per cell
(terminal characters are about twice as tall as wide):

* ``· `` a free cell, ``██`` an obstacle;
* a robot as one character and an arrow for its heading, for example
  ``A→`` (bold, in the robot's colour, as in the animations): its id when
  every id is one character, else a letter or digit of its own
  (:func:`short_labels`), which the legend under the grid maps to the full
  ids (``A r0  B r1 ...``);
* a robot's goal as the character of its robot (lower case when that tells
  robots apart still) and ``◦``, for example ``a◦`` (dim, in the robot's colour);
* a robot's trail, the last :data:`TRAIL_CELLS` cells it left, as ``• `` in
  its colour.

A grid too big for the terminal is shrunk: each ``k x k`` block of cells is
drawn as one, showing the robot in it (or how many robots: ``3×``), else a
goal in it, else ``██`` when the block is all obstacles, ``▒▒`` when it is
partly blocked, else free. The caption says ``1:k``.

:func:`render_grid` is pure (the same picture for the same arguments);
:class:`TerminalView` redraws it with :class:`rich.live.Live` after every tick
of a simulation (its :meth:`~TerminalView.on_tick` is the simulator's
``on_tick`` observer) and paces the drawing at ``fps`` ticks per second.

Examples
--------
>>> from mrmp.core import Grid, Heading
>>> grid = Grid.from_rows(["..@", "..."])
>>> picture = render_grid(grid, ["A", "B"], [(0, 0), (1, 1)], [Heading.EAST, Heading.NORTH], [(1, 0), (0, 2)])
>>> print(picture.plain)
a◦B↑██
A→· b◦
"""

from __future__ import annotations

import contextlib
import math
import time
from collections import deque
from collections.abc import Callable, Sequence
from types import TracebackType

from rich.console import Console
from rich.live import Live
from rich.text import Text

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import Scenario
from mrmp.viz.layout import hex_colour, robot_colours

ARROWS: dict[Heading, str] = {Heading.NORTH: "↑", Heading.EAST: "→", Heading.SOUTH: "↓", Heading.WEST: "←"}
"""The arrow drawn after a robot's letter for each heading (north is up)."""
FREE = "· "
"""A free cell."""
BLOCKED = "██"
"""An obstacle (or a block of obstacles)."""
PARTLY_BLOCKED = "▒▒"
"""A shrunk block with some obstacles in it."""
GOAL_MARK = "◦"
"""Drawn after the lower-case letter of a goal's robot."""
TRAIL = "• "
"""A cell among the last :data:`TRAIL_CELLS` a robot left."""
TRAIL_CELLS = 3
"""How many cells a robot's trail shows in the terminal view."""
LABELS = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"
"""The characters given to robots whose ids are not one character each (then :data:`MANY` past these)."""
MANY = "+"
"""The character of robots past the :data:`LABELS` (the legend says how many)."""
FREE_STYLE = "grey42"
BLOCKED_STYLE = "grey62"
RESERVED_LINES = 3
"""Terminal lines kept for the caption and the prompt."""
LEGEND_LINES = 4
"""Most terminal lines the legend of labels may take."""


def short_labels(ids: Sequence[str]) -> list[str]:
    """One character per robot: the ids themselves when each is one distinct character, else :data:`LABELS` in order.

    Robots past :data:`LABELS` share :data:`MANY`.

    >>> short_labels(["A", "B"]), short_labels(["r3", "r13", "r23"])
    (['A', 'B'], ['A', 'B', 'C'])
    """
    if all(len(robot_id) == 1 for robot_id in ids) and len({robot_id.lower() for robot_id in ids}) == len(ids):
        return list(ids)
    return [LABELS[index] if index < len(LABELS) else MANY for index in range(len(ids))]


def legend_text(ids: Sequence[str], labels: Sequence[str], columns: int | None, lines: int) -> list[str]:
    """The lines that map labels to ids (none when every label is its id), at most ``lines`` of ``columns``.

    >>> legend_text(["r3", "r13", "r23"], ["A", "B", "C"], 40, 2)
    ['A r3  B r13  C r23']
    >>> legend_text(["A"], ["A"], 40, 2)
    []
    >>> legend_text([f"r{n}" for n in range(40)], short_labels([f"r{n}" for n in range(40)]), 30, 2)[-1]
    'F r5  G r6  H r7 … (40 robots)'
    """
    if list(ids) == list(labels) or lines <= 0:
        return []
    width = columns if columns is not None else 10**6
    entries = [f"{label} {robot_id}" for label, robot_id in zip(labels, ids) if label != MANY]
    rest = f" … ({len(ids)} robots)"
    rows: list[str] = []
    current = ""
    for entry in entries:
        candidate = f"{current}  {entry}" if current else entry
        if len(candidate) <= width:
            current = candidate
        elif len(rows) + 1 < lines:
            rows.append(current)
            current = entry
        else:  # the last line is full: it says how many robots there are
            while current and len(current) + len(rest) > width:
                current = current.rsplit("  ", 1)[0] if "  " in current else ""
            return [*rows, current + rest]
    if current:
        rows.append(current + (rest if len(entries) < len(ids) else ""))
    return rows


def scale_for(grid: Grid, columns: int | None, lines: int | None) -> int:
    """The smallest ``k`` such that ``k x k`` blocks of cells fit in ``columns`` x ``lines`` characters.

    >>> scale_for(Grid(10, 10), 80, 24), scale_for(Grid(64, 64), 80, 24), scale_for(Grid(64, 64), None, None)
    (1, 3, 1)
    """
    k = 1
    if columns is not None:
        k = max(k, math.ceil(2 * grid.y_size / max(2, columns)))
    if lines is not None:
        k = max(k, math.ceil(grid.x_size / max(1, lines)))
    return k


def render_grid(
    grid: Grid,
    ids: Sequence[str],
    cells: Sequence[Cell],
    headings: Sequence[Heading],
    goals: Sequence[Cell] | None = None,
    *,
    columns: int | None = None,
    lines: int | None = None,
    colours: Sequence[str] | None = None,
    labels: Sequence[str] | None = None,
    trails: Sequence[Sequence[Cell]] | None = None,
) -> Text:
    """The grid with its robots (their goals and trails) as styled text, one line per row, northmost first.

    Parameters
    ----------
    grid:
        The grid.
    ids, cells, headings:
        Each robot's id, cell and heading, in the same order.
    goals:
        Each robot's goal (``None``: goals are not drawn).
    columns, lines:
        The room, in characters; the grid is shrunk by blocks to fit (``None``: no limit).
    colours:
        Each robot's rich colour (default: the animations' colours).
    labels:
        Each robot's character (default: :func:`short_labels` of ``ids``).
    trails:
        Each robot's recent cells, drawn on free cells (``None``: no trails).

    Returns
    -------
    rich.text.Text
        The picture; its ``plain`` is the characters alone.

    Examples
    --------
    >>> from mrmp.core import Grid, Heading
    >>> crowd = render_grid(Grid(4, 4), ["A", "B", "C"], [(0, 0), (0, 1), (3, 3)], [Heading.NORTH] * 3, lines=2)
    >>> crowd.plain.splitlines()
    ['· C↑', '2×· ']
    >>> render_grid(Grid(1, 3), ["A"], [(0, 2)], [Heading.EAST], trails=[[(0, 0), (0, 1)]]).plain
    '• • A→'
    """
    count = len(ids)
    if not (len(cells) == count and len(headings) == count and (goals is None or len(goals) == count)):
        raise ValueError("ids, cells, headings and goals must have one entry per robot")
    styles = list(colours) if colours is not None else [hex_colour(colour) for colour in robot_colours(count)]
    k = scale_for(grid, columns, lines)
    rows, wide = math.ceil(grid.x_size / k), math.ceil(grid.y_size / k)
    robots_in: dict[tuple[int, int], list[int]] = {}
    for index, cell in enumerate(cells):
        robots_in.setdefault(_block(grid, cell, k), []).append(index)
    goal_in: dict[tuple[int, int], int] = {}
    for goal_index, goal in enumerate(goals or ()):
        goal_in.setdefault(_block(grid, goal, k), goal_index)
    trail_in: dict[tuple[int, int], int] = {}
    for trail_index, trail in enumerate(trails or ()):
        for cell in trail:
            trail_in[_block(grid, cell, k)] = trail_index
    marks = list(labels) if labels is not None else short_labels(ids)
    lower = len({mark.lower() for mark in marks}) == len(marks)  # goals in lower case tell robots apart still
    text = Text(no_wrap=True, overflow="crop")
    for row in range(rows):
        if row:
            text.append("\n")
        for column in range(wide):
            here = robots_in.get((row, column))
            if here:
                if len(here) == 1:
                    alone = here[0]
                    text.append(marks[alone] + ARROWS[Heading(headings[alone])], style=f"bold {styles[alone]}")
                else:
                    shown = f"{len(here)}×" if len(here) < 10 else "9+"
                    text.append(shown, style="bold")
                continue
            owner = goal_in.get((row, column))
            if owner is not None:
                text.append((marks[owner].lower() if lower else marks[owner]) + GOAL_MARK, style=f"dim {styles[owner]}")
                continue
            walker = trail_in.get((row, column))
            blocked, total = _blocked_share(grid, row, column, k)
            if blocked == total:
                text.append(BLOCKED, style=BLOCKED_STYLE)
            elif blocked:
                text.append(PARTLY_BLOCKED, style=BLOCKED_STYLE)
            elif walker is not None:
                text.append(TRAIL, style=styles[walker])
            else:
                text.append(FREE, style=FREE_STYLE)
    return text


def _block(grid: Grid, cell: Cell, k: int) -> tuple[int, int]:
    """The ``(row from the top, column)`` of the block holding ``cell``."""
    return ((grid.x_size - 1 - cell[0]) // k, cell[1] // k)


def _blocked_share(grid: Grid, row: int, column: int, k: int) -> tuple[int, int]:
    """Obstacles and cells in the block at ``(row, column)``."""
    top = grid.x_size - 1 - row * k
    blocked = total = 0
    for x in range(top, max(top - k, -1), -1):
        for y in range(column * k, min((column + 1) * k, grid.y_size)):
            total += 1
            blocked += not grid.is_free((x, y))
    return blocked, total


class TerminalView:
    """Redraws a running scenario in the terminal after every tick.

    Use it as a context manager around the run and pass :meth:`on_tick` to the
    simulator::

        with TerminalView(scenario, console) as view:
            result = simulate(scenario, on_tick=view.on_tick)

    Headings are read from the moves (a robot faces the way it last moved,
    starting with its scenario heading). In a lifelong run goals change as
    robots reach them, so goals are not drawn.

    Parameters
    ----------
    scenario:
        What is being run.
    console:
        Where to draw.
    fps:
        Ticks drawn per second: after drawing a tick the view waits until
        ``1 / fps`` seconds have passed since the previous one.
    clock, sleep:
        Time source and waiting (replaceable in tests).
    """

    def __init__(
        self,
        scenario: Scenario,
        console: Console,
        fps: float = 10.0,
        *,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        if not fps > 0:
            raise ValueError(f"fps must be positive, got {fps}")
        self.scenario = scenario
        self.console = console
        self.period = 1.0 / fps
        self.clock = clock
        self.sleep = sleep
        self.ids = [spec.id for spec in scenario.robots]
        self.goals = None if scenario.lifelong else [spec.goal for spec in scenario.robots]
        self.cells: list[Cell] = [spec.start for spec in scenario.robots]
        self.headings: list[Heading] = [spec.heading for spec in scenario.robots]
        self.colours = [hex_colour(colour) for colour in robot_colours(len(self.ids))]
        self.labels = short_labels(self.ids)
        self.recent: list[deque[Cell]] = [deque(maxlen=TRAIL_CELLS) for _ in self.ids]
        self.tick = 0
        self._live: Live | None = None
        self._last = 0.0

    def picture(self) -> Text:
        """The caption and the grid as they are now, fitted to the console."""
        width, height = self.console.size
        grid = self.scenario.grid
        legend = legend_text(self.ids, self.labels, width, LEGEND_LINES)
        room = max(1, height - RESERVED_LINES - len(legend))
        k = scale_for(grid, width, room)
        caption = Text(f"{self.scenario.name or 'run'} · {self.scenario.policy.name} · tick {self.tick}", style="bold")
        if k > 1:
            caption.append(f"  (1:{k})", style="dim")
        if self.goals is None:
            caption.append("  lifelong: goals not shown", style="dim")
        body = render_grid(
            grid,
            self.ids,
            self.cells,
            self.headings,
            self.goals,
            columns=width,
            lines=room,
            colours=self.colours,
            labels=self.labels,
            trails=[[cell for cell in recent if cell != here] for recent, here in zip(self.recent, self.cells)],
        )
        parts = [caption, body, *(Text(line, style="dim") for line in legend)]
        return Text("\n", no_wrap=True, overflow="crop").join(parts)

    def on_tick(self, tick: int, cells: list[Cell]) -> None:
        """Take the robots' cells after ``tick``, redraw, then wait out the frame's time."""
        for index, (before, after) in enumerate(zip(self.cells, cells)):
            if after != before:
                self.recent[index].append(before)
                with contextlib.suppress(ValueError):  # not a single step: the heading cannot be told
                    self.headings[index] = Heading.between(before, after)
        self.cells = list(cells)
        self.tick = tick
        if self._live is not None:
            self._live.update(self.picture(), refresh=True)
        wait = self.period - (self.clock() - self._last)
        if wait > 0:
            self.sleep(wait)
        self._last = self.clock()

    def __enter__(self) -> TerminalView:
        self._live = Live(self.picture(), console=self.console, auto_refresh=False, transient=False)
        self._live.__enter__()
        self._last = self.clock()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        if self._live is not None:
            self._live.__exit__(kind, error, traceback)
            self._live = None
            if not self.console.is_terminal:
                self.console.line()  # not a terminal: the last picture was written without its line end
