"""Geometry, colours and motion shared by the GIF and SVG renderers.

Everything here is pure: no file is written and Pillow is not imported, so the
two renderers draw exactly the same picture from the same numbers.

Drawing convention: NORTH is up and EAST is to the right. The cell ``(x, y)``
(x grows NORTH, y grows EAST) is drawn at column ``y`` and at row
``x_size - 1 - x`` counted from the top.

Motion: a robot's :func:`track` lists keyframes ``(t, x, y, angle)`` where
``t`` is in ticks, ``(x, y)`` is a (fractional) cell and ``angle`` is the
heading in degrees clockwise from north. Robots only turn right (see
:func:`mrmp.core.heading.right_turns`), so angles only grow; when a robot both
turns and moves during a tick it turns in the first half and moves in the
second.

Examples
--------
>>> from mrmp.core import Grid, Heading, RobotResult
>>> layout = make_layout(Grid(5, 5))
>>> layout.cell
72
>>> layout.centre((4, 0)) == (layout.left + 36.0, layout.top + 36.0)   # NW corner cell
True
>>> robot = RobotResult("A", (0, 2), (1, 3), path=[(0, 2), (0, 3), (1, 3)],
...                     headings=[Heading.NORTH, Heading.EAST, Heading.NORTH])
>>> [tuple(frame) for frame in track(robot, 2)]
[(0.0, 0.0, 2.0, 0.0), (0.5, 0.0, 2.0, 90.0), (1.0, 0.0, 3.0, 90.0), (1.5, 0.0, 3.0, 360.0), (2.0, 1.0, 3.0, 360.0)]
>>> pose_at(track(robot, 2), 0.75)
(0.0, 2.5, 90.0)
"""

from __future__ import annotations

import colorsys
import math
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import NamedTuple

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading, right_turns
from mrmp.core.result import RobotResult, RunResult
from mrmp.viz.colouring import HEADING, PROGRESS, check_colouring

RGB = tuple[int, int, int]
"""A colour as 0-255 red, green, blue."""

# -- theme ---------------------------------------------------------------------------

BACKGROUND: RGB = (250, 249, 245)
"""Page and free-cell colour (warm white)."""
GRID_LINE: RGB = (222, 220, 212)
"""Thin lines between cells."""
OBSTACLE: RGB = (52, 58, 72)
"""Blocked cells (dark slate)."""
OBSTACLE_EDGE: RGB = (38, 42, 53)
"""Outline of blocked cells."""
HEADER: RGB = (36, 41, 54)
"""Caption band above the grid."""
HEADER_TEXT: RGB = (236, 238, 244)
"""Caption text."""
HEADER_DIM: RGB = (150, 158, 178)
"""Secondary caption text (policy, progress track)."""
SUCCESS: RGB = (102, 204, 128)
"""Caption colour of a successful run."""
BAD_NEWS: RGB = (255, 128, 128)
"""Caption colour of a failed run."""
COLLISION: RGB = (228, 26, 48)
"""Collision flash."""
COST_HIGH: RGB = (240, 180, 90)
"""Tint of the most expensive cells (amber)."""
COST_LOW: RGB = (150, 214, 180)
"""Tint of cells cheaper than 1 (mint)."""
COST_TEXT: RGB = (170, 120, 50)
"""Cost figures written in big cells."""
FONT_FAMILY = "DejaVu Sans, Verdana, Helvetica, Arial, sans-serif"
"""CSS font family for SVG text (the GIF uses DejaVu Sans too when installed)."""

PALETTE: tuple[RGB, ...] = (
    (78, 121, 167),  # blue
    (242, 142, 43),  # orange
    (89, 161, 79),  # green
    (176, 122, 161),  # purple
    (237, 201, 72),  # yellow
    (118, 183, 178),  # teal
    (255, 157, 167),  # pink
    (156, 117, 95),  # brown
    (225, 87, 89),  # red
    (73, 152, 148),  # sea green
)
"""A qualitative palette (Tableau 10, reordered, grey dropped): the first robots' colours."""

# -- robot body, in cell units, pointing NORTH (up, towards -y on screen) ---------------------

ROBOT_RADIUS = 0.31
"""Radius of a robot's disc, as a fraction of a cell."""
HEADING_MARKER: tuple[tuple[float, float], ...] = ((0.0, -0.49), (-0.17, -0.2), (0.17, -0.2))
"""Triangle showing a robot's heading, in cell units around the robot's centre, for NORTH."""
GOAL_INSET = 0.13
"""Gap between a goal square and its cell's edge, as a fraction of a cell."""
GOAL_WIDTH = 0.075
"""Stroke of a goal square, as a fraction of a cell."""
GOAL_LABEL_CELL = 40
"""Goal squares in cells at least this many pixels wide carry their robot's id in a corner."""
ROBOT_EDGE: RGB = (45, 50, 62)
"""Outline and nose of robots whose colour changes (coloured by progress or heading)."""
TURN_SHARE = 0.5
"""Fraction of a tick spent turning when a robot turns and moves in the same tick."""


# -- layout --------------------------------------------------------------------------


@dataclass(frozen=True)
class Layout:
    """Where a grid goes in a picture: cell size, margins and the caption band.

    Use :func:`make_layout` rather than building one by hand. Pixel coordinates
    have their origin at the top-left corner of the picture, y growing down.
    """

    x_size: int
    y_size: int
    cell: int
    left: int
    top: int
    width: int
    height: int
    header: int
    robots: int = 0
    legend: int = 0
    axis_left: int = 0
    axis_bottom: int = 0

    @property
    def legend_top(self) -> int:
        """Where the legend band begins (it runs to the bottom of the picture)."""
        return self.height - self.legend

    @property
    def grid_width(self) -> int:
        """Width of the drawn grid in pixels."""
        return self.y_size * self.cell

    @property
    def grid_height(self) -> int:
        """Height of the drawn grid in pixels."""
        return self.x_size * self.cell

    def point(self, x: float, y: float) -> tuple[float, float]:
        """Pixel position of the centre of a (possibly fractional) cell ``(x, y)``.

        >>> make_layout(Grid(3, 4)).point(2, 0) == make_layout(Grid(3, 4)).centre((2, 0))
        True
        """
        return (self.left + (y + 0.5) * self.cell, self.top + (self.x_size - 0.5 - x) * self.cell)

    def centre(self, cell: Cell) -> tuple[float, float]:
        """Pixel centre of ``cell``: column ``y``, row ``x_size - 1 - x`` from the top.

        >>> layout = make_layout(Grid(5, 5))
        >>> left, top = layout.left, layout.top
        >>> layout.centre((0, 0)) == (left + 36.0, top + 4.5 * 72)   # SW corner: bottom left
        True
        """
        return self.point(cell[0], cell[1])

    def cell_box(self, cell: Cell) -> tuple[int, int, int, int]:
        """Pixel box ``(left, top, right, bottom)`` of ``cell``, right and bottom exclusive.

        >>> layout = make_layout(Grid(2, 2))
        >>> box = layout.cell_box((1, 0))   # north-west cell
        >>> (box[0] - layout.left, box[1] - layout.top, box[2] - box[0])
        (0, 0, 72)
        """
        left = self.left + cell[1] * self.cell
        top = self.top + (self.x_size - 1 - cell[0]) * self.cell
        return (left, top, left + self.cell, top + self.cell)

    def scaled(self, factor: int) -> Layout:
        """The same layout with every pixel length multiplied by ``factor`` (for supersampling).

        >>> make_layout(Grid(2, 2)).scaled(2).cell
        144
        """
        return Layout(
            self.x_size,
            self.y_size,
            self.cell * factor,
            self.left * factor,
            self.top * factor,
            self.width * factor,
            self.height * factor,
            self.header * factor,
            self.robots,
            self.legend * factor,
            self.axis_left * factor,
            self.axis_bottom * factor,
        )

    @property
    def show_labels(self) -> bool:
        """Whether robots are big enough, and few enough, to carry their id."""
        return self.cell >= 26 and self.robots <= 80

    @property
    def trail_width(self) -> float:
        """Stroke width of trails in pixels (thin for crowded runs)."""
        share = 0.14 if self.robots <= 20 else 0.1 if self.robots <= 80 else 0.08
        return max(1.0, self.cell * share)

    @property
    def trail_ticks(self) -> int | None:
        """How many ticks of trail to keep (``None``: the whole path)."""
        if self.robots <= 20:
            return None
        return 12 if self.robots <= 80 else 5

    @property
    def font_size(self) -> int:
        """Caption font size in pixels (the title's; the line under it is a little smaller)."""
        return max(12, min(16, self.width // 28))

    @property
    def small_font(self) -> float:
        """Font size of the legend and the axes' numbers, in pixels."""
        return self.header * SMALL_FONT / HEADER_HEIGHT


def make_layout(
    grid: Grid,
    robots: int = 0,
    *,
    colouring: str | None = None,
    goal_lines: bool = False,
    max_side: int = 720,
    max_cell: int = 72,
    min_cell: int = 2,
    min_width: int = 340,
) -> Layout:
    """Choose the cell size and margins for drawing ``grid``, with its axes and legend.

    The cell size is the largest that keeps the longer side of the grid within
    ``max_side`` pixels, between ``min_cell`` and ``max_cell``. The grid has
    the x numbers on its left and the y numbers under it; a narrow grid is
    centred in a picture at least ``min_width`` wide. The caption band (two
    lines) is at the top, the legend band (:func:`legend_slots` entries of
    :data:`LEGEND_SLOT` pixels beside the compass) at the bottom.

    Parameters
    ----------
    grid:
        The grid to draw.
    robots:
        Number of robots, which decides labels, trail styles and the legend.
    colouring, goal_lines:
        What robots' colours say (default: :func:`mrmp.viz.colouring.default_colouring`)
        and whether lines join robots to their goals: both change the legend.
    max_side, max_cell, min_cell, min_width:
        Size limits in pixels.

    Examples
    --------
    >>> make_layout(Grid(32, 32)).cell, make_layout(Grid(64, 64)).cell
    (22, 11)
    >>> layout = make_layout(Grid(1, 2))
    >>> layout.width >= 340 and layout.left > layout.cell // 2
    True
    >>> layout = make_layout(Grid(5, 5), 2)
    >>> layout.top + layout.grid_height + layout.axis_bottom <= layout.legend_top < layout.height
    True
    """
    cell = max(min_cell, min(max_cell, max_side // max(grid.x_size, grid.y_size)))
    margin = max(6, min(18, cell // 3))
    header = HEADER_HEIGHT
    digits = len(str(max(grid.x_size - 1, 0)))
    axis_left = round(SMALL_FONT * (0.62 * digits + 0.9))
    axis_bottom = round(SMALL_FONT * 1.7)
    right_margin = max(margin, round(SMALL_FONT * 2.4))  # room for the y axis's name
    top_margin = max(margin, round(SMALL_FONT * 1.5))  # room for the x axis's name
    grid_width = grid.y_size * cell
    block = axis_left + grid_width + right_margin
    width = max(block + 2 * margin, min_width)
    left = (width - block) // 2 + axis_left
    top = header + top_margin
    slots = legend_slots(robots, check_colouring(colouring, robots), goal_lines)
    columns = max(1, (width - 2 * LEGEND_PAD - COMPASS_WIDTH) // LEGEND_SLOT)
    rows = max(2, -(-slots // columns))
    legend = LEGEND_PAD + rows * LEGEND_ROW + LEGEND_PAD
    height = top + grid.x_size * cell + axis_bottom + legend
    return Layout(grid.x_size, grid.y_size, cell, left, top, width, height, header, robots, legend, axis_left, axis_bottom)


HEADER_HEIGHT = 52
"""Height of the caption band: the title, then the run's size, colouring and clock."""
SMALL_FONT = 11
"""Font size of the legend and the axes, in pixels, in a picture of :data:`HEADER_HEIGHT`."""
LEGEND_SLOT = 150
"""Width of one legend entry, in pixels."""
LEGEND_ROW = 20
"""Height of one row of legend entries, in pixels."""
LEGEND_PAD = 8
"""Space around the legend's entries, in pixels."""
COMPASS_WIDTH = 78
"""Width kept at the legend's right for the compass (N and E arrows, with x and y)."""
LEGEND_ROBOTS = 10
"""Runs of up to this many robots coloured by robot list each robot in the legend, with its start and goal."""


def legend_slots(robots: int, colouring: str, goal_lines: bool) -> int:
    """How many legend entries a run has (the progress ramp counts two).

    Entries: each robot (coloured by robot, up to :data:`LEGEND_ROBOTS`) or
    one entry saying what a robot is, or the ramp, or the four headings; then
    the goal, the trail and, when drawn, the line to the goal.

    >>> legend_slots(2, "robot", False), legend_slots(50, "progress", True), legend_slots(50, "heading", False)
    (4, 5, 6)
    """
    if colouring == PROGRESS:
        colours = 2
    elif colouring == HEADING:
        colours = 4
    else:
        colours = robots if 0 < robots <= LEGEND_ROBOTS else 1
    return colours + 2 + (1 if goal_lines else 0)


# -- colours --------------------------------------------------------------------------


def robot_colours(count: int) -> list[RGB]:
    """Distinct colours for ``count`` robots.

    The first ten come from :data:`PALETTE`; after that the palette repeats,
    each round with its own lightness and a slight hue shift (low-discrepancy
    sequences, so rounds differ as much as they can). No two robots get the
    same colour, however many there are.

    >>> colours = robot_colours(1000)
    >>> colours[:2] == [PALETTE[0], PALETTE[1]], len(set(colours))
    (True, 1000)
    """
    colours: list[RGB] = []
    seen: set[RGB] = set()
    for index in range(count):
        round_, slot = divmod(index, len(PALETTE))
        colour = PALETTE[slot]
        if round_:
            hue, lightness, saturation = colorsys.rgb_to_hls(*(channel / 255 for channel in colour))
            lightness = min(0.8, max(0.3, lightness + ((round_ * 0.618034 + 0.5) % 1.0 - 0.5) * 0.5))
            hue = (hue + ((round_ * 0.414214) % 1.0 - 0.5) * 0.09) % 1.0
            saturation *= 0.8 if round_ % 3 == 2 else 1.0
            red, green, blue = colorsys.hls_to_rgb(hue, lightness, saturation)
            colour = (round(red * 255), round(green * 255), round(blue * 255))
        while colour in seen:  # nudge a clash by one step of blue, then green
            red, green, blue = colour
            colour = (red, green, blue + 1) if blue < 255 else (red, (green + 1) % 256, 0)
        seen.add(colour)
        colours.append(colour)
    return colours


def mix(colour: RGB, other: RGB, share: float) -> RGB:
    """``share`` of ``colour`` over ``1 - share`` of ``other``.

    >>> mix((255, 0, 0), (0, 0, 255), 0.5)
    (128, 0, 128)
    """
    share = min(1.0, max(0.0, share))
    return tuple(round(a * share + b * (1 - share)) for a, b in zip(colour, other))  # type: ignore[return-value]


def darker(colour: RGB, amount: float = 0.35) -> RGB:
    """``colour`` darkened towards black by ``amount``.

    >>> darker((200, 100, 0), 0.5)
    (100, 50, 0)
    """
    return mix((0, 0, 0), colour, amount)


def text_colour_on(colour: RGB) -> RGB:
    """Black or white, whichever reads better on ``colour``.

    >>> text_colour_on((250, 250, 250)), text_colour_on((20, 20, 60))
    ((28, 28, 34), (255, 255, 255))
    """
    red, green, blue = colour
    luminance = (0.299 * red + 0.587 * green + 0.114 * blue) / 255
    return (28, 28, 34) if luminance > 0.62 else (255, 255, 255)


def hex_colour(colour: RGB) -> str:
    """CSS hex form of a colour.

    >>> hex_colour((78, 121, 167))
    '#4e79a7'
    """
    return "#{:02x}{:02x}{:02x}".format(*colour)


def cost_tint(cost: float, costs: Sequence[float]) -> RGB:
    """Fill of a cell whose entry cost is ``cost``, given every cost on the grid.

    Costlier cells are more amber, the costliest at full tint; cells cheaper
    than 1 are mint.

    >>> cost_tint(1.0, [1.0, 5.0]) == BACKGROUND
    True
    >>> cost_tint(5.0, [2.0, 5.0]) == mix(COST_HIGH, BACKGROUND, 0.85)
    True
    """
    if cost == 1.0:
        return BACKGROUND
    if cost < 1.0:
        return mix(COST_LOW, BACKGROUND, 0.3 + 0.5 * (1.0 - cost))
    highest = max([1.0, *costs])
    share = 0.3 + 0.55 * (cost - 1.0) / (highest - 1.0) if highest > 1.0 else 0.6
    return mix(COST_HIGH, BACKGROUND, share)


# -- motion --------------------------------------------------------------------------


class Keyframe(NamedTuple):
    """A robot's pose at time ``t`` (ticks): fractional cell ``(x, y)`` and heading ``angle``."""

    t: float
    x: float
    y: float
    angle: float


def heading_angle(heading: Heading | int) -> float:
    """Degrees clockwise from north (screen up) for ``heading``.

    >>> [heading_angle(h) for h in Heading]
    [0.0, 90.0, 180.0, 270.0]
    """
    return 90.0 * (int(heading) - 1)


def run_ticks(result: RunResult) -> int:
    """The last tick of a run: one less than the longest path (0 for an empty run).

    >>> from mrmp.core import RobotResult, RunResult
    >>> run = RunResult("s", "p", 0, [RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)])], [], "done", 1, 1, 0.0)
    >>> run_ticks(run)
    1
    """
    return max((len(robot.path) - 1 for robot in result.robots), default=0) if result.robots else 0


def cell_at(robot: RobotResult, tick: int) -> Cell:
    """Where ``robot`` is at ``tick``; past the end of its path it stays put.

    >>> cell_at(RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)]), 7)
    (0, 1)
    """
    if not robot.path:
        return robot.start
    return robot.path[min(max(tick, 0), len(robot.path) - 1)]


def _heading_at(robot: RobotResult, tick: int) -> Heading:
    if not robot.headings:
        if robot.path and 0 < tick < len(robot.path) and robot.path[tick] != robot.path[tick - 1]:
            try:
                return Heading.between(robot.path[tick - 1], robot.path[tick])
            except ValueError:
                pass
        return Heading.NORTH if tick <= 0 else _heading_at(robot, tick - 1)
    return Heading(robot.headings[min(max(tick, 0), len(robot.headings) - 1)])


def track(robot: RobotResult, ticks: int, move_ticks: int = 1) -> list[Keyframe]:
    """Keyframes of ``robot``'s motion over ticks ``0 .. ticks``.

    Between two ticks a robot that changes heading first turns right (as many
    quarter turns as :func:`~mrmp.core.heading.right_turns` says) and then
    moves; one that only turns takes the whole tick to turn. Keyframes where
    nothing changes pace are dropped, so the list is short for robots that wait.
    The first keyframe is at ``t = 0`` and the last at ``t = ticks``.

    ``move_ticks`` is how many ticks a move may take: a live run samples its
    robots several times per cell (:func:`move_ticks_of`), and a move seen at
    one sample goes on while the robot stays in the new cell, up to
    ``move_ticks`` ticks, rather than jumping in one.

    >>> still = RobotResult("A", (1, 1), (1, 1), path=[(1, 1)] * 5)
    >>> track(still, 4)
    [Keyframe(t=0.0, x=1.0, y=1.0, angle=0.0), Keyframe(t=4.0, x=1.0, y=1.0, angle=0.0)]
    >>> sampled = RobotResult("A", (0, 0), (1, 0), path=[(0, 0), (1, 0), (1, 0), (1, 0), (1, 0), (1, 0)])
    >>> [(frame.t, frame.x) for frame in track(sampled, 5, move_ticks=4)]
    [(0.0, 0.0), (4.0, 1.0), (5.0, 1.0)]
    """
    heading = _heading_at(robot, 0)
    angle = heading_angle(heading)
    here = cell_at(robot, 0)
    frames = [Keyframe(0.0, float(here[0]), float(here[1]), angle)]
    tick = 0
    while tick < ticks:
        there = cell_at(robot, tick + 1)
        next_heading = _heading_at(robot, tick + 1)
        span = 1
        if there != here:
            while (
                span < move_ticks
                and tick + span < ticks
                and cell_at(robot, tick + span + 1) == there
                and _heading_at(robot, tick + span + 1) == next_heading
            ):
                span += 1
        turns = right_turns(heading, next_heading)
        if turns:
            angle += 90.0 * turns
            turn_end = tick + (TURN_SHARE * span if there != here else 1.0)
            frames.append(Keyframe(float(turn_end), float(here[0]), float(here[1]), angle))
        frames.append(Keyframe(float(tick + span), float(there[0]), float(there[1]), angle))
        here, heading = there, next_heading
        tick += span
    return simplify(frames)


LIVE_SAMPLES_PER_MOVE = 4
"""Ground-truth samples of a live run per cell move: its ``tick_seconds`` is a quarter of a move's time
(:mod:`mrmp.live.launcher`)."""


def move_ticks_of(result: RunResult) -> int:
    """How many ticks a move may take when drawn: :data:`LIVE_SAMPLES_PER_MOVE` for a live run, else 1.

    >>> move_ticks_of(RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0))
    1
    """
    return LIVE_SAMPLES_PER_MOVE if is_live(result) else 1


def trim_idle(result: RunResult) -> RunResult:
    """A live run without its still lead-in and tail: from a tick before the first move to the last move's end.

    A live run's ground truth starts when its processes start and ends after
    the last one stops; the picture shows the motion, its clock counting from
    the tick before the first move. A simulated run is returned as it is.

    >>> from dataclasses import replace
    >>> robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0)] * 5 + [(0, 1)] * 10)
    >>> run = RunResult("s", "p", 0, [robot], [], "done", 14, 1, 0.0, mode="live", tick_seconds=0.05)
    >>> trimmed = trim_idle(run)
    >>> trimmed.robots[0].path[:2], run_ticks(trimmed)
    ([(0, 0), (0, 1)], 5)
    >>> simulated = replace(run, tick_seconds=None)
    >>> trim_idle(simulated) is simulated
    True
    """
    if not is_live(result) or not result.robots:
        return result
    changes = [
        tick
        for robot in result.robots
        for tick in range(1, len(robot.path))
        if robot.path[tick] != robot.path[tick - 1]
    ]
    if not changes:
        return result
    first = max(0, min(changes) - 1)
    last = min(run_ticks(result), max(changes) + LIVE_SAMPLES_PER_MOVE)
    robots = [
        replace(
            robot,
            path=robot.path[first : last + 1],
            headings=robot.headings[first : last + 1] if robot.headings else [],
        )
        for robot in result.robots
    ]
    collisions = [
        replace(collision, tick=collision.tick - first) for collision in result.collisions if first <= collision.tick <= last
    ]
    log = result.message_log[first : last + 1] if result.message_log is not None else None
    return replace(result, robots=robots, collisions=collisions, ticks=last - first, message_log=log)


def simplify(frames: Sequence[Keyframe], fields: Sequence[str] = ("x", "y", "angle")) -> list[Keyframe]:
    """Drop keyframes that lie on the straight line between their neighbours.

    Only ``fields`` are compared, so a renderer animating just the position can
    pass ``("x", "y")`` to get the position's own, shorter, keyframes.

    >>> frames = [Keyframe(0, 0, 0, 0), Keyframe(1, 1, 0, 0), Keyframe(2, 2, 0, 0), Keyframe(3, 2, 0, 90)]
    >>> [frame.t for frame in simplify(frames)]
    [0, 2, 3]
    >>> [frame.t for frame in simplify(frames, ("x", "y"))]
    [0, 2, 3]
    """
    if len(frames) <= 2:
        return list(frames)
    kept = [frames[0]]
    for index in range(1, len(frames) - 1):
        before, here, after = kept[-1], frames[index], frames[index + 1]
        span = after.t - before.t
        share = (here.t - before.t) / span if span else 0.0
        on_line = all(
            abs(getattr(before, name) + (getattr(after, name) - getattr(before, name)) * share - getattr(here, name))
            < 1e-9
            for name in fields
        )
        if not on_line:
            kept.append(here)
    kept.append(frames[-1])
    return kept


def _time_of(frame: Keyframe) -> float:
    return frame.t


def pose_at(frames: Sequence[Keyframe], t: float) -> tuple[float, float, float]:
    """Interpolated ``(x, y, angle)`` of a track at time ``t`` (clamped to the track).

    >>> frames = [Keyframe(0, 0, 0, 0), Keyframe(2, 2, 0, 90)]
    >>> pose_at(frames, 1.0), pose_at(frames, 5.0)
    ((1.0, 0.0, 45.0), (2, 0, 90))
    """
    if t <= frames[0].t:
        first = frames[0]
        return (first.x, first.y, first.angle)
    if t >= frames[-1].t:
        last = frames[-1]
        return (last.x, last.y, last.angle)
    index = bisect_right(frames, t, key=_time_of)
    before, after = frames[index - 1], frames[index]
    share = (t - before.t) / (after.t - before.t)
    return (
        before.x + (after.x - before.x) * share,
        before.y + (after.y - before.y) * share,
        before.angle + (after.angle - before.angle) * share,
    )


def marker_points(
    centre: tuple[float, float], angle: float, size: float, shape: Sequence[tuple[float, float]] = HEADING_MARKER
) -> list[tuple[float, float]]:
    """``shape`` (cell units, pointing north) turned ``angle`` degrees clockwise, scaled by ``size`` pixels.

    >>> [(round(x), round(y)) for x, y in marker_points((0, 0), 90.0, 100, [(0.0, -0.5)])]
    [(50, 0)]
    """
    radians = math.radians(angle)
    cos, sin = math.cos(radians), math.sin(radians)
    cx, cy = centre
    return [(cx + size * (px * cos - py * sin), cy + size * (px * sin + py * cos)) for px, py in shape]


def robot_label(robot_id: str) -> str:
    """The text written on a robot: its id, cut to four characters.

    >>> robot_label("B"), robot_label("r123"), robot_label("robot-7")
    ('B', 'r123', 'rob…')
    """
    return robot_id if len(robot_id) <= 4 else robot_id[:3] + "…"


def label_size(label: str, cell: float) -> float:
    """Font size (pixels) that fits ``label`` inside a robot's disc in a cell of ``cell`` pixels.

    >>> label_size("A", 72), round(label_size("r123", 72), 1)
    (17.28, 15.5)
    """
    fits = 1.8 * ROBOT_RADIUS * cell / (0.65 * max(1, len(label)))
    return min(0.24 * cell, fits)


def goal_label_place(layout: Layout, goal: Cell) -> tuple[float, float]:
    """Where a goal square's id is written: inside its top-left corner (the text's baseline start).

    >>> layout = make_layout(Grid(5, 5))
    >>> x, y = goal_label_place(layout, (4, 0))
    >>> layout.left < x < layout.left + layout.cell / 3 and layout.top < y < layout.top + layout.cell / 3
    True
    """
    left, top, _, _ = layout.cell_box(goal)
    return (left + layout.cell * (GOAL_INSET + 0.05), top + layout.cell * (GOAL_INSET + 0.19))


def text_width(text: str, font_size: float, bold: bool = False) -> float:
    """Estimated width in pixels of ``text`` in DejaVu Sans (for SVG, whose text the browser measures).

    >>> text_width("abcd", 10)
    22.0
    """
    return (0.62 if bold else 0.55) * font_size * len(text)


def shorten(text: str, room: float, font_size: float, bold: bool = False) -> str:
    """``text`` cut with an ellipsis to about ``room`` pixels, estimating DejaVu Sans widths.

    For SVG, whose text is measured by the browser; the GIF measures exactly.

    >>> shorten("swap · thesis", 400, 14)
    'swap · thesis'
    >>> shorten("a very long scenario name indeed", 100, 14)
    'a very long…'
    """
    width = (0.62 if bold else 0.55) * font_size
    most = int(room // width)
    if len(text) <= most:
        return text
    return text[: max(0, most - 1)].rstrip() + "…" if most > 1 else ""


def run_caption(result: RunResult) -> str:
    """Title shown above the grid: scenario and policy.

    >>> run_caption(RunResult("swap", "thesis", 0, [], [], "done", 0, 0, 0.0))
    'swap · thesis'
    """
    parts = [part for part in (result.scenario, result.policy) if part]
    return " · ".join(parts) if parts else "mrmp run"


def is_live(result: RunResult) -> bool:
    """Whether ``result`` is a live run sampled every ``tick_seconds`` (its clock is shown in seconds).

    >>> is_live(RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0, mode="live", tick_seconds=0.05))
    True
    """
    return result.tick_seconds is not None and result.tick_seconds > 0


def clock_text(result: RunResult, tick: int) -> str:
    """The clock shown at ``tick``: ``tick 3 / 7`` for a simulated run, ``0.15 s / 0.35 s`` for a live one.

    >>> run = RunResult("s", "p", 0, [RobotResult("A", (0, 0), (0, 0), path=[(0, 0)] * 8)], [], "done", 7, 0, 0.0)
    >>> clock_text(run, 3)
    'tick 3 / 7'
    >>> from dataclasses import replace
    >>> clock_text(replace(run, mode="live", tick_seconds=0.05), 3)
    '0.15 s / 0.35 s'
    """
    ticks = run_ticks(result)
    if is_live(result):
        seconds = float(result.tick_seconds or 0.0)
        return f"{tick * seconds:.2f} s / {ticks * seconds:.2f} s"
    return f"tick {tick} / {ticks}"


def speed_text(speed: float) -> str:
    """How fast a live run's animation plays: ``real time`` or, say, ``played at 0.5x``.

    >>> speed_text(1.0), speed_text(0.25)
    ('real time', 'played at 0.25x')
    """
    return "real time" if speed == 1.0 else f"played at {speed:g}x"


def run_subtitle(result: RunResult, colouring_caption: str, speed: float = 1.0) -> str:
    """The caption's second line: how many robots, what their colour says, and for a live run its speed.

    >>> run_subtitle(RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0), "colour: robot")
    '0 robots · colour: robot'
    """
    count = len(result.robots)
    parts = [f"{count} robot{'' if count == 1 else 's'}", colouring_caption]
    if is_live(result):
        parts.append(f"live, {speed_text(speed)}")
    return " · ".join(parts)


def check_speed(speed: float) -> float:
    """Refuse a playing speed that is not positive.

    >>> check_speed(0)
    Traceback (most recent call last):
    ...
    ValueError: speed must be positive, got 0
    """
    if not speed > 0:
        raise ValueError(f"speed must be positive, got {speed}")
    return speed


def run_verdict(result: RunResult) -> tuple[str, bool]:
    """Short end-of-run verdict for the caption and whether it is good news.

    >>> run_verdict(RunResult("s", "p", 0, [], [], "done", 0, 0, 0.0))
    ('all arrived', True)
    """
    if result.collisions:
        count = len(result.collisions)
        return (f"{count} collision{'s' if count != 1 else ''}", False)
    missing = len(result.not_arrived)
    if missing:
        return (f"{missing} not arrived", False)
    return ("all arrived", True)


# -- messages ------------------------------------------------------------------------

MAX_MESSAGE_ARROWS = 200
"""Most sender-to-recipient arrows drawn per tick (the shortest); crowded runs broadcast far more."""
MESSAGE_OFFSET = 0.09
"""Sideways shift of a message arrow, in cells, so that A to B and B to A show as two parallel arrows."""
MESSAGE_LABEL_CELL = 48
"""Cells at least this many pixels wide write the kinds of message on each arrow."""


@dataclass(frozen=True)
class MessageArrow:
    """Messages one robot sent another during ``tick``, drawn as an arrow.

    The arrow joins the edges of the two robots' discs where they stood when
    the tick began (tick ``tick - 1``, when they spoke) and is shown from time
    ``tick - 1`` until ``tick``, while the robots make that tick's move.
    ``start`` and ``end`` (the tip) are pixels; ``sender`` and ``recipient``
    are robot indices; ``kinds`` are the kinds of the messages, in the order
    first sent.
    """

    tick: int
    sender: int
    recipient: int
    kinds: tuple[str, ...]
    start: tuple[float, float]
    end: tuple[float, float]

    @property
    def label(self) -> str:
        """The kinds, joined: written on the arrow in big cells.

        >>> MessageArrow(1, 0, 1, ("state", "claim"), (0, 0), (1, 0)).label
        'state+claim'
        """
        return "+".join(self.kinds)

    def shown_at(self, t: float) -> bool:
        """Whether the arrow is on screen at time ``t`` (ticks): ``tick - 1 <= t < tick``.

        >>> arrow = MessageArrow(2, 0, 1, ("state",), (0, 0), (1, 0))
        >>> arrow.shown_at(0.9), arrow.shown_at(1.0), arrow.shown_at(1.99), arrow.shown_at(2.0)
        (False, True, True, False)
        """
        return self.tick - 1 <= t < self.tick


def message_arrows(result: RunResult, layout: Layout, limit: int = MAX_MESSAGE_ARROWS) -> list[MessageArrow]:
    """The arrows that draw ``result``'s message log (none if it has no log), tick by tick.

    Messages of one tick between the same two robots make one arrow; at most
    ``limit`` arrows per tick, the shortest (then the first logged), so a
    crowd that broadcasts shows who talks to its neighbours. An arrow starts just outside the sender's disc
    and ends just outside the recipient's, shifted sideways by
    :data:`MESSAGE_OFFSET` cells to the right of its direction.

    >>> from mrmp.core import Grid, RobotResult, RunResult
    >>> a = RobotResult("A", (0, 0), (0, 2), path=[(0, 0), (0, 1)])
    >>> b = RobotResult("B", (0, 2), (0, 2), path=[(0, 2), (0, 2)])
    >>> log = [[], [("A", "B", "state"), ("B", "A", "state"), ("A", "B", "claim")]]
    >>> run = RunResult("s", "p", 0, [a, b], [], "done", 1, 0, 0.0, message_log=log)
    >>> layout = make_layout(Grid(1, 3))
    >>> arrows = message_arrows(run, layout)
    >>> [(arrow.tick, arrow.sender, arrow.recipient, arrow.label) for arrow in arrows]
    [(1, 0, 1, 'state+claim'), (1, 1, 0, 'state')]
    >>> first = arrows[0]   # A (west) to B (east): points east, below the centre line (to its right)
    >>> first.end[0] > first.start[0], first.start[1] == first.end[1] > layout.centre((0, 0))[1]
    (True, True)
    """
    if not result.message_log:
        return []
    index_of = {robot.id: index for index, robot in enumerate(result.robots)}
    reach = layout.cell * ROBOT_RADIUS * 1.15
    shift = layout.cell * MESSAGE_OFFSET
    arrows: list[MessageArrow] = []
    for tick, entries in enumerate(result.message_log):
        if tick == 0 or not entries:
            continue
        kinds_of: dict[tuple[int, int], list[str]] = {}
        for sender_id, recipient_id, kind in entries:
            sender, recipient = index_of.get(sender_id), index_of.get(recipient_id)
            if sender is None or recipient is None or sender == recipient:
                continue
            kinds = kinds_of.setdefault((sender, recipient), [])
            if kind not in kinds:
                kinds.append(kind)
        pairs = []
        for (sender, recipient), kinds in kinds_of.items():
            here = layout.centre(cell_at(result.robots[sender], tick - 1))
            there = layout.centre(cell_at(result.robots[recipient], tick - 1))
            length = math.dist(here, there)
            if length > 2 * reach:
                pairs.append((length, sender, recipient, kinds, here, there))
        if len(pairs) > limit:
            pairs = sorted(pairs, key=_length_of)[:limit]  # a stable sort: ties stay in logged order
        for length, sender, recipient, kinds, here, there in pairs:
            ux, uy = (there[0] - here[0]) / length, (there[1] - here[1]) / length
            nx, ny = -uy * shift, ux * shift  # screen y grows down: (-uy, ux) is to the right of travel
            start = (here[0] + ux * reach + nx, here[1] + uy * reach + ny)
            end = (there[0] - ux * reach + nx, there[1] - uy * reach + ny)
            arrows.append(MessageArrow(tick, sender, recipient, tuple(kinds), start, end))
    return arrows


def _length_of(pair: tuple[float, int, int, list[str], tuple[float, float], tuple[float, float]]) -> float:
    return pair[0]


def _direction(arrow: MessageArrow) -> tuple[float, float]:
    """The unit vector from an arrow's start to its tip (``(0, 0)`` for an arrow of no length)."""
    (x0, y0), (x1, y1) = arrow.start, arrow.end
    length = math.dist(arrow.start, arrow.end) or 1.0
    return (x1 - x0) / length, (y1 - y0) / length


def arrow_head(arrow: MessageArrow, size: float) -> list[tuple[float, float]]:
    """Triangle of an arrow's tip, ``size`` pixels long, as three points (the tip first).

    >>> arrow = MessageArrow(1, 0, 1, ("state",), (0.0, 0.0), (10.0, 0.0))
    >>> arrow_head(arrow, 4.0)
    [(10.0, 0.0), (6.0, -2.0), (6.0, 2.0)]
    """
    x1, y1 = arrow.end
    ux, uy = _direction(arrow)
    back_x, back_y = x1 - ux * size, y1 - uy * size
    half = size / 2
    return [(x1, y1), (back_x + uy * half, back_y - ux * half), (back_x - uy * half, back_y + ux * half)]


def arrow_shape(arrow: MessageArrow, cell: float) -> tuple[tuple[float, float], list[tuple[float, float]]]:
    """Where an arrow's shaft ends and its head (:func:`arrow_head`), for cells ``cell`` pixels wide.

    The head is 0.16 of a cell long, at least 3 pixels; the shaft stops at
    the middle of the head's base.

    >>> arrow = MessageArrow(1, 0, 1, ("state",), (0.0, 0.0), (50.0, 0.0))
    >>> arrow_shape(arrow, 10.0)
    ((47.0, 0.0), [(50.0, 0.0), (47.0, -1.5), (47.0, 1.5)])
    """
    tip = arrow_head(arrow, max(3.0, cell * 0.16))
    return ((tip[1][0] + tip[2][0]) / 2, (tip[1][1] + tip[2][1]) / 2), tip


def message_width(layout: Layout) -> float:
    """Stroke width of message arrows in pixels.

    >>> message_width(make_layout(Grid(5, 5)))
    2.88
    """
    return max(1.0, layout.cell * 0.04)


def message_label_place(arrow: MessageArrow, cell: float) -> tuple[tuple[float, float], str]:
    """Where an arrow's :attr:`~MessageArrow.label` goes and how it is anchored: ``"start"``, ``"middle"`` or ``"end"``.

    The label sits beside the arrow, on its right (the side it is shifted
    to), a third of the way from the sender, so the labels of A to B and of
    B to A never overlap. ``"start"`` means the text begins at the point (it
    extends to the right), ``"end"`` that it ends there.

    >>> north = MessageArrow(1, 0, 1, ("state",), (50.0, 100.0), (50.0, 10.0))   # drawn upwards
    >>> message_label_place(north, 60.0)
    ((59.0, 70.0), 'start')
    >>> south = MessageArrow(1, 1, 0, ("state",), (40.0, 10.0), (40.0, 100.0))
    >>> message_label_place(south, 60.0)[1]
    'end'
    """
    (x0, y0), (x1, y1) = arrow.start, arrow.end
    ux, uy = _direction(arrow)
    nx, ny = -uy, ux
    gap = cell * 0.15
    x, y = x0 + (x1 - x0) / 3 + nx * gap, y0 + (y1 - y0) / 3 + ny * gap
    if nx > 0.35:
        return ((x, y), "start")
    if nx < -0.35:
        return ((x, y), "end")
    return ((x, y + ny * gap * 0.5), "middle")
