"""The live referee: judges ground-truth occupancy intervals of robots moving in real time.

Bodies report when they start to enter a cell and when they have left one
(:class:`~mrmp.live.body.OccupancyRecorder`). A robot therefore *covers* a cell
over an interval of time, and covers two cells while it moves between them. The
referee reports, as the lockstep referee does (:mod:`mrmp.sim.referee`):

* ``vertex``: two robots covering one cell over overlapping intervals;
* ``swap``: two robots each moving into the cell the other is leaving, at overlapping times;
* ``obstacle`` / ``off_grid``: a robot entering a blocked cell or leaving the grid.

Times are seconds on the clock every process of the run shares
(``time.monotonic`` on one machine); collisions carry the time in milliseconds
since the run's start as their ``tick``.

Examples
--------
>>> from mrmp.core.grid import Grid
>>> referee = IntervalReferee(Grid(1, 3), ["A", "B"], starts=[(0, 0), (0, 2)], start_time=0.0)
>>> referee.feed(0, "enter", (0, 1), 1.0)
>>> referee.feed(1, "enter", (0, 1), 1.5)   # B enters while A is still there
>>> [c.describe() for c in referee.collisions()]
['tick 1500: vertex collision of A, B at (0, 1)']
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.result import Collision


@dataclass
class Interval:
    """Robot ``robot`` covers ``cell`` from ``start`` until ``end`` (inf while it is there)."""

    robot: int
    cell: Cell
    start: float
    end: float = math.inf


class IntervalReferee:
    """Collects occupancy events and finds every violation among them.

    Parameters
    ----------
    grid:
        The map.
    robot_ids:
        Names of the robots, by index.
    starts:
        Where each robot stands at ``start_time``.
    start_time:
        The run's start on the shared clock.
    """

    def __init__(self, grid: Grid, robot_ids: Sequence[str], starts: Sequence[Cell], start_time: float) -> None:
        self.grid = grid
        self.robot_ids = list(robot_ids)
        self.start_time = start_time
        self.intervals: list[Interval] = [Interval(index, cell, start_time) for index, cell in enumerate(starts)]
        self._open: dict[tuple[int, Cell], Interval] = {(index, cell): self.intervals[index] for index, cell in enumerate(starts)}

    def feed(self, robot: int, event: str, cell: Cell, t: float) -> None:
        """Take one event: ``"enter"`` (starts covering ``cell``) or ``"leave"`` (stops covering it)."""
        key = (robot, cell)
        if event == "enter":
            if key not in self._open:
                interval = Interval(robot, cell, t)
                self.intervals.append(interval)
                self._open[key] = interval
        elif event == "leave":
            interval = self._open.pop(key, None)
            if interval is not None:
                interval.end = t

    def cells_at(self, t: float) -> list[list[Cell]]:
        """For each robot, the cells it covers at time ``t``."""
        covered: list[list[Cell]] = [[] for _ in self.robot_ids]
        for interval in self.intervals:
            if interval.start <= t < interval.end:
                covered[interval.robot].append(interval.cell)
        return covered

    def _tick(self, t: float) -> int:
        return int(round((t - self.start_time) * 1000))

    def collisions(self) -> list[Collision]:
        """Every violation found so far, in time order."""
        found: list[tuple[float, Collision]] = []
        ids = self.robot_ids
        by_cell: dict[Cell, list[Interval]] = {}
        for interval in self.intervals:
            by_cell.setdefault(interval.cell, []).append(interval)
            if not self.grid.in_bounds(interval.cell):
                found.append((interval.start, Collision("off_grid", self._tick(interval.start), (ids[interval.robot],), (interval.cell,))))
            elif self.grid.is_blocked(interval.cell):
                found.append((interval.start, Collision("obstacle", self._tick(interval.start), (ids[interval.robot],), (interval.cell,))))
        overlaps: dict[tuple[int, int], list[tuple[float, Cell]]] = {}
        for cell, intervals in by_cell.items():
            intervals.sort(key=lambda interval: interval.start)
            for i, first in enumerate(intervals):
                for second in intervals[i + 1 :]:
                    if second.start >= first.end:
                        break
                    if first.robot != second.robot:
                        pair = tuple(sorted((first.robot, second.robot)))
                        overlaps.setdefault(pair, []).append((max(first.start, second.start), cell))  # type: ignore[arg-type]
        for (a, b), cells in overlaps.items():
            cells.sort()
            distinct = sorted({cell for _, cell in cells})
            t = cells[0][0]
            kind = "swap" if len(distinct) == 2 and self._exchanged(a, b, distinct) else "vertex"
            shown = tuple(distinct) if kind == "swap" else (cells[0][1],)
            found.append((t, Collision(kind, self._tick(t), (ids[a], ids[b]), shown)))
        found.sort(key=lambda item: item[0])
        return [collision for _, collision in found]

    def _exchanged(self, a: int, b: int, cells: list[Cell]) -> bool:
        """Whether robots ``a`` and ``b`` each moved from one of ``cells`` into the other."""
        first: dict[int, list[Cell]] = {a: [], b: []}
        for interval in sorted(self.intervals, key=lambda interval: interval.start):
            if interval.robot in first and interval.cell in cells:
                first[interval.robot].append(interval.cell)
        return all(len(order) >= 2 and order[-2] != order[-1] for order in first.values()) and first[a][-1] != first[b][-1]
