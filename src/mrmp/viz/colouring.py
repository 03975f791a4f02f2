"""What a robot's colour says: who it is, how much of its path it has done, or where it faces.

Three colourings, shared by every picture of a run:

* ``"robot"``: each robot keeps its own colour (:func:`mrmp.viz.layout.robot_colours`),
  the clearest for a few robots, whose goals and legend entries share it;
* ``"progress"``: the share of its path a robot has done, from red (nothing
  yet) through amber to blue (all of it), in steps of a tenth: a crowd shows
  at a glance who is stuck;
* ``"heading"``: the way the robot faces, one colour per heading.

Up to :data:`CROWD` robots the default is ``"robot"``; past that 50 similar
colours cannot be told apart, and the default is ``"progress"``.

The progress ramp follows ColorBrewer's red-yellow-blue scheme, which stays
readable with the common colour-vision deficiencies (C. A. Brewer, *Color Use
Guidelines for Mapping and Visualization*, 1994; colorbrewer2.org); the
heading colours are Okabe and Ito's colour-blind-safe palette (*Color
Universal Design*, 2002).

Examples
--------
>>> from mrmp.core import RobotResult
>>> default_colouring(2), default_colouring(50)
('robot', 'progress')
>>> robot = RobotResult("A", (0, 0), (0, 2), path=[(0, 0), (0, 1), (0, 1), (0, 2)])
>>> [share for _, share in progress_steps(robot, 3)]
[0.0, 0.5, 1.0]
>>> [tick for tick, _ in colour_changes(robot, 3, "progress", (0, 0, 0))]
[0.0, 1.0, 3.0]
"""

from __future__ import annotations

import contextlib
from bisect import bisect_right
from collections.abc import Sequence
from itertools import pairwise

from mrmp.core.heading import Heading
from mrmp.core.result import RobotResult

RGB = tuple[int, int, int]

ROBOT = "robot"
PROGRESS = "progress"
HEADING = "heading"
COLOURINGS: tuple[str, ...] = (ROBOT, PROGRESS, HEADING)
"""The colourings a picture can use."""
CROWD = 12
"""Runs with more robots than this are coloured by progress unless told otherwise."""

PROGRESS_STOPS: tuple[tuple[float, RGB], ...] = (
    (0.0, (215, 48, 39)),
    (0.25, (244, 109, 67)),
    (0.5, (230, 175, 45)),
    (0.75, (116, 173, 209)),
    (1.0, (49, 84, 170)),
)
"""Colour of a share of the path done, at five stops (ColorBrewer RdYlBu, the middle darkened to read on white)."""
PROGRESS_STEPS = 10
"""The share of the path is shown in steps of ``1 / PROGRESS_STEPS``."""

HEADING_COLOURS: dict[Heading, RGB] = {
    Heading.NORTH: (0, 114, 178),
    Heading.EAST: (230, 159, 0),
    Heading.SOUTH: (0, 158, 115),
    Heading.WEST: (204, 121, 167),
}
"""Colour of each heading (Okabe-Ito blue, orange, bluish green, reddish purple)."""


def default_colouring(robots: int) -> str:
    """``"robot"`` for up to :data:`CROWD` robots, else ``"progress"``.

    >>> default_colouring(12), default_colouring(13)
    ('robot', 'progress')
    """
    return ROBOT if robots <= CROWD else PROGRESS


def check_colouring(colouring: str | None, robots: int) -> str:
    """``colouring``, or the default for ``robots`` when ``None``; refuses an unknown name.

    >>> check_colouring(None, 3), check_colouring("heading", 3)
    ('robot', 'heading')
    >>> check_colouring("rainbow", 3)
    Traceback (most recent call last):
    ...
    ValueError: colour_by must be one of robot, progress, heading, got 'rainbow'
    """
    if colouring is None:
        return default_colouring(robots)
    if colouring not in COLOURINGS:
        raise ValueError(f"colour_by must be one of {', '.join(COLOURINGS)}, got {colouring!r}")
    return colouring


def progress_colour(share: float) -> RGB:
    """The colour of having done ``share`` (0..1) of the path, rounded to a tenth.

    >>> progress_colour(0.0), progress_colour(1.0), progress_colour(0.52) == progress_colour(0.5)
    ((215, 48, 39), (49, 84, 170), True)
    """
    share = round(min(1.0, max(0.0, share)) * PROGRESS_STEPS) / PROGRESS_STEPS
    for (low, low_colour), (high, high_colour) in pairwise(PROGRESS_STOPS):
        if share <= high:
            part = (share - low) / (high - low)
            return tuple(round(a + (b - a) * part) for a, b in zip(low_colour, high_colour))  # type: ignore[return-value]
    return PROGRESS_STOPS[-1][1]


def progress_ramp() -> list[RGB]:
    """Every colour :func:`progress_colour` gives, from 0 to 1.

    >>> len(progress_ramp()), progress_ramp()[0] == progress_colour(0.0)
    (11, True)
    """
    return [progress_colour(step / PROGRESS_STEPS) for step in range(PROGRESS_STEPS + 1)]


def progress_steps(robot: RobotResult, ticks: int) -> list[tuple[int, float]]:
    """``(tick, share of the path done)`` at tick 0 and at each tick the shown share changes.

    The share is the robot's moves so far over all its moves until ``ticks``
    (a robot that never moves has done all of its path when it starts on its
    goal, none of it otherwise).

    >>> from mrmp.core import RobotResult
    >>> progress_steps(RobotResult("A", (1, 1), (1, 1), path=[(1, 1)] * 3), 2)
    [(0, 1.0)]
    """
    path = [robot.path[min(tick, len(robot.path) - 1)] for tick in range(ticks + 1)] if robot.path else [robot.start]
    total = sum(1 for before, after in pairwise(path) if before != after)
    if total == 0:
        return [(0, 1.0 if path[0] == robot.goal else 0.0)]
    steps = [(0, 0.0)]
    done = 0
    for tick in range(1, len(path)):
        if path[tick] != path[tick - 1]:
            done += 1
            share = round(done / total * PROGRESS_STEPS) / PROGRESS_STEPS
            if share != steps[-1][1]:
                steps.append((tick, share))
    return steps


def _heading_steps(robot: RobotResult, ticks: int) -> list[tuple[int, Heading]]:
    """``(tick, heading)`` at tick 0 and at each change of heading (headings read from the moves when absent)."""
    steps: list[tuple[int, Heading]] = []
    heading = Heading.NORTH
    for tick in range(ticks + 1):
        if robot.headings:
            heading = Heading(robot.headings[min(tick, len(robot.headings) - 1)])
        elif robot.path and 0 < tick < len(robot.path) and robot.path[tick] != robot.path[tick - 1]:
            with contextlib.suppress(ValueError):  # not a single step: the heading stays
                heading = Heading.between(robot.path[tick - 1], robot.path[tick])
        if not steps or steps[-1][1] != heading:
            steps.append((tick, heading))
    return steps


def colour_changes(robot: RobotResult, ticks: int, colouring: str, identity: RGB) -> list[tuple[float, RGB]]:
    """``(time in ticks, colour)`` of ``robot`` at time 0 and at each change, under ``colouring``.

    ``identity`` is the robot's own colour, used by ``"robot"``.

    >>> from mrmp.core import Heading, RobotResult
    >>> robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)], headings=[Heading.NORTH, Heading.EAST])
    >>> colour_changes(robot, 1, "robot", (1, 2, 3))
    [(0.0, (1, 2, 3))]
    >>> north, east = HEADING_COLOURS[Heading.NORTH], HEADING_COLOURS[Heading.EAST]
    >>> colour_changes(robot, 1, "heading", (1, 2, 3)) == [(0.0, north), (1.0, east)]
    True
    """
    if colouring == PROGRESS:
        return [(float(tick), progress_colour(share)) for tick, share in progress_steps(robot, ticks)]
    if colouring == HEADING:
        return [(float(tick), HEADING_COLOURS[heading]) for tick, heading in _heading_steps(robot, ticks)]
    return [(0.0, identity)]


def _time_of(change: tuple[float, RGB]) -> float:
    return change[0]


def colour_at(changes: Sequence[tuple[float, RGB]], t: float) -> RGB:
    """The colour of :func:`colour_changes` at time ``t`` (ticks): the last change at or before it.

    >>> colour_at([(0.0, (0, 0, 0)), (2.0, (9, 9, 9))], 1.99), colour_at([(0.0, (0, 0, 0)), (2.0, (9, 9, 9))], 2.0)
    ((0, 0, 0), (9, 9, 9))
    """
    index = bisect_right(changes, t + 1e-9, key=_time_of) - 1
    return changes[max(0, index)][1]


def colouring_caption(colouring: str) -> str:
    """What the colour of a robot means, for the picture's caption.

    >>> colouring_caption("progress")
    'colour: share of path done'
    """
    return {ROBOT: "colour: robot", PROGRESS: "colour: share of path done", HEADING: "colour: heading"}[colouring]
