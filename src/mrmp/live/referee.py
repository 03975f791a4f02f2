"""The live referee: judges ground-truth occupancy intervals of robots moving in real time.

Bodies report when they start to enter a cell and when they have left one
(:class:`~mrmp.live.body.OccupancyRecorder`). A robot therefore *covers* a cell
over an interval of time, and covers two cells while it moves between them. The
referee reports, as the lockstep referee does (:mod:`mrmp.sim.referee`):

* ``vertex``: two robots covering one cell over overlapping intervals;
* ``swap``: two robots each moving into the cell the other is leaving, at overlapping times;
* ``obstacle`` / ``off_grid``: a robot entering a blocked cell or leaving the grid.

For bodies that may follow while driving (``follows``: ``turning`` bodies,
:attr:`mrmp.core.body.BodyModel.follows_while_driving`), two robots on one cell
are no collision when one *follows* the other: the follower started driving
into the cell strictly after the leader started driving out of it, and not from
the cell the leader drives to; the leader was out of the cell by the time the
follower arrived; and, both moving in straight lines over their recorded times,
their centres never came closer than :data:`FOOTPRINT` cells
(``docs/protocol.md``, "Following while driving").

For bodies that turn in place, the referee process judges their actions too
(``action``: :mod:`mrmp.live.action_referee`). In a lifelong run, the errands
the task desk counted are judged on the same ground truth
(:func:`errands_not_visited`): a robot reached an errand only if its body
entered the errand's cell.

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

Following: A drives from (0, 1) to (0, 2) over [1, 2]; B follows from (0, 0), starting at 1.2:

>>> follows = IntervalReferee(Grid(1, 3), ["A", "B"], starts=[(0, 1), (0, 0)], start_time=0.0, follows=True)
>>> for robot, event, cell, t in [(0, "enter", (0, 2), 1.0), (1, "enter", (0, 1), 1.2), (0, "leave", (0, 1), 2.0),
...                               (1, "leave", (0, 0), 2.2)]:
...     follows.feed(robot, event, cell, t)
>>> follows.collisions()
[]
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.result import Collision

FOOTPRINT = 1 / math.sqrt(2)
"""Cells: the least distance between the centres of a follower and its leader (the diameter of a body that may
be followed; ``docs/protocol.md``, "Why ``turning`` may follow")."""

_ROUNDING = 1e-9


@dataclass
class Interval:
    """Robot ``robot`` covers ``cell`` from ``start`` until ``end`` (inf while it is there).

    ``source`` is the cell it drove from into ``cell`` (None for its start) and ``arrived`` when that drive
    ended (inf while it goes on); ``exit_at`` is when it started driving out of ``cell``, to ``exit_to``.
    """

    robot: int
    cell: Cell
    start: float
    end: float = math.inf
    source: Cell | None = None
    arrived: float = math.inf
    exit_at: float = math.inf
    exit_to: Cell | None = None


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
    follows:
        Whether the bodies may follow while driving (module docstring).
    """

    def __init__(
        self, grid: Grid, robot_ids: Sequence[str], starts: Sequence[Cell], start_time: float, follows: bool = False
    ) -> None:
        self.grid = grid
        self.robot_ids = list(robot_ids)
        self.start_time = start_time
        self.follows = follows
        self.intervals: list[Interval] = [Interval(index, cell, start_time) for index, cell in enumerate(starts)]
        self._open: dict[tuple[int, Cell], Interval] = {(index, cell): self.intervals[index] for index, cell in enumerate(starts)}
        self._latest: dict[int, Interval] = dict(enumerate(self.intervals))
        """Per robot, the cell it entered last (the one it drives out of when it enters another)."""
        self._arriving: dict[tuple[int, Cell], Interval] = {}
        """Per robot and cell it drives out of, the interval of the cell it drives into (arrived once it has left)."""

    def feed(self, robot: int, event: str, cell: Cell, t: float) -> None:
        """Take one event: ``"enter"`` (starts covering ``cell``) or ``"leave"`` (stops covering it)."""
        key = (robot, cell)
        if event == "enter":
            if key not in self._open:
                interval = Interval(robot, cell, t)
                previous = self._latest.get(robot)
                if previous is not None and previous.end == math.inf:
                    interval.source = previous.cell
                    previous.exit_at, previous.exit_to = t, cell
                    self._arriving[robot, previous.cell] = interval
                self.intervals.append(interval)
                self._open[key] = interval
                self._latest[robot] = interval
        elif event == "leave":
            leaving = self._open.pop(key, None)
            if leaving is not None:
                leaving.end = t
                arriving = self._arriving.pop(key, None)
                if arriving is not None:
                    arriving.arrived = t

    def _tick(self, t: float) -> int:
        return round((t - self.start_time) * 1000)

    def _static_violation(self, cell: Cell) -> str | None:
        """``"off_grid"`` or ``"obstacle"`` when covering ``cell`` is a violation by itself, else ``None``."""
        if not self.grid.in_bounds(cell):
            return "off_grid"
        return "obstacle" if self.grid.is_blocked(cell) else None

    def collisions(self) -> list[Collision]:
        """Every violation found so far, in time order."""
        found: list[tuple[float, Collision]] = []
        ids = self.robot_ids
        by_cell: dict[Cell, list[Interval]] = {}
        for interval in self.intervals:
            by_cell.setdefault(interval.cell, []).append(interval)
            kind = self._static_violation(interval.cell)
            if kind is not None:
                collision = Collision(kind, self._tick(interval.start), (ids[interval.robot],), (interval.cell,))
                found.append((interval.start, collision))
        overlaps: dict[tuple[int, int], list[tuple[float, float, Interval, Interval]]] = {}
        for _cell, intervals in by_cell.items():
            intervals.sort(key=lambda interval: interval.start)
            for i, first in enumerate(intervals):
                for second in intervals[i + 1 :]:
                    if second.start >= first.end:
                        break
                    if first.robot != second.robot and not (self.follows and _follows(first, second)):
                        a, b = sorted((first, second), key=lambda interval: interval.robot)
                        start, end = max(a.start, b.start), min(a.end, b.end)
                        overlaps.setdefault((a.robot, b.robot), []).append((start, end, a, b))
        for (robot_a, robot_b), spans in overlaps.items():
            for episode in _episodes(spans):
                t = episode[0][0]
                cells = sorted({span[2].cell for span in episode})
                kind = "swap" if _exchanged(episode) else "vertex"
                shown = tuple(cells) if kind == "swap" else (episode[0][2].cell,)
                found.append((t, Collision(kind, self._tick(t), (ids[robot_a], ids[robot_b]), shown)))
        found.sort(key=lambda item: item[0])
        return [collision for _, collision in found]


def errands_not_visited(
    events: Sequence[tuple[int, int, int, int]],
    errands: Mapping[int, Sequence[Cell]],
    intervals: Sequence[Mapping[str, Any]],
) -> list[tuple[int, int, int, int]]:
    """The task desk's ``events`` (``(step, robot, task, errands done)``) whose errand the robot's body never
    covered, by its ground-truth ``intervals`` (``referee.json``'s: ``robot``, ``cell``, ``start``, ``end``);
    ``errands``: each task's errand cells, by task id.

    >>> intervals = [{"robot": 0, "cell": [0, 1], "start": 0.0, "end": None}]
    >>> errands_not_visited([(3, 0, 7, 1), (5, 0, 7, 2)], {7: [(0, 1), (0, 2)]}, intervals)
    [(5, 0, 7, 2)]
    """
    covered = {(int(interval["robot"]), (int(interval["cell"][0]), int(interval["cell"][1]))) for interval in intervals}
    return [event for event in events if (event[1], tuple(errands[event[2]][event[3] - 1])) not in covered]


def _follows(leader: Interval, follower: Interval) -> bool:
    """Whether ``follower``, on the cell ``leader`` stood on first, followed it in (module docstring).

    >>> leader = Interval(0, (0, 1), 0.0, end=2.0, exit_at=1.0, exit_to=(1, 1))   # drives north over [1, 2]
    >>> _follows(leader, Interval(1, (0, 1), 1.1, source=(0, 0), arrived=2.1))   # from the west, just after
    True
    >>> _follows(leader, Interval(1, (0, 1), 1.0, source=(0, 0), arrived=2.0))   # started with it: no leader
    False
    >>> _follows(leader, Interval(1, (0, 1), 1.1, source=(1, 1), arrived=2.1))   # from the cell it drives to
    False
    >>> _follows(leader, Interval(1, (0, 1), 1.5, source=(0, 0), arrived=1.9))   # faster: it closes in
    False
    """
    if follower.source is None or follower.source == leader.exit_to or leader.exit_to is None:
        return False
    if not leader.exit_at < follower.start or not leader.end <= follower.arrived:
        return False
    if leader.end == math.inf:
        return True  # both still drive (traces judged as they grow): judged again once the leader is out
    return _closest_approach(leader, follower) >= FOOTPRINT - _ROUNDING


def _closest_approach(leader: Interval, follower: Interval) -> float:
    """The least distance between the centres of ``leader`` driving out of its cell and ``follower`` driving in,
    each along a straight line at its own constant speed over its recorded times, while both cover the cell."""
    assert leader.exit_to is not None and follower.source is not None

    def at(source: Cell, target: Cell, start: float, end: float, t: float) -> tuple[float, float]:
        share = 1.0 if end <= start else min(1.0, max(0.0, (t - start) / (end - start)))
        return source[0] + share * (target[0] - source[0]), source[1] + share * (target[1] - source[1])

    begin, finish = follower.start, leader.end  # the leader drives all along; the follower has not arrived yet
    drive = (leader.cell, leader.exit_to, leader.exit_at, leader.end)
    arrival = follower.arrived if follower.arrived < math.inf else follower.start + leader.end - leader.exit_at
    entry = (follower.source, leader.cell, follower.start, arrival)  # still driving: taken at the leader's speed
    (lx, ly), (fx, fy) = at(*drive, begin), at(*entry, begin)
    (lx2, ly2), (fx2, fy2) = at(*drive, finish), at(*entry, finish)
    dx, dy = lx - fx, ly - fy  # the gap at ``begin``, then changing linearly to its value at ``finish``
    vx, vy = (lx2 - fx2) - dx, (ly2 - fy2) - dy
    speed = vx * vx + vy * vy
    share = 0.0 if speed == 0 else min(1.0, max(0.0, -(dx * vx + dy * vy) / speed))
    return math.hypot(dx + share * vx, dy + share * vy)


Span = tuple[float, float, Interval, Interval]


def _episodes(spans: list[Span]) -> list[list[Span]]:
    """Group one pair's overlaps into episodes: overlaps that touch in time belong together."""
    episodes: list[list[Span]] = []
    end = -math.inf
    for span in sorted(spans, key=lambda span: span[0]):
        if span[0] > end or not episodes:
            episodes.append([span])
            end = span[1]
        else:
            episodes[-1].append(span)
            end = max(end, span[1])
    return episodes


def _exchanged(episode: list[Span]) -> bool:
    """Whether, in this episode, each robot moved into the cell the other was leaving (a swap)."""
    cells = {span[2].cell for span in episode}
    if len(cells) != 2:
        return False
    first: dict[int, dict[Cell, float]] = {}
    for _, _, a, b in episode:
        for interval in (a, b):
            first.setdefault(interval.robot, {})[interval.cell] = interval.start
    if len(first) != 2 or any(len(entered) != 2 for entered in first.values()):
        return False
    (_robot_a, cells_a), (_robot_b, cells_b) = first.items()
    x, y = sorted(cells)
    return (cells_a[x] < cells_a[y]) == (cells_b[y] < cells_b[x])
