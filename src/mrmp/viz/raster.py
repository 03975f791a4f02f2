"""Frames of a run drawn with Pillow: the pictures the GIF and MP4 writers encode.

The picture, north up and east to the right: a warm-white grid with dark
obstacles and amber costly cells; each robot's goal as a hollow square in the
robot's colour; each robot as a disc with a pointed nose showing its heading
and, in big enough cells, its id; a fading trail of the cells it visited;
optionally the messages of each tick as arrows from sender to recipient
(:func:`mrmp.viz.layout.message_arrows`); a caption band with the scenario,
the tick and a progress bar; collision cells flashed red at their tick (and
faintly marked afterwards).

Motion between ticks is interpolated (:func:`mrmp.viz.layout.track`); a robot
that changes heading turns (rightwards, as the robots do) before it moves.
Big cells are drawn at two or three times the size and shrunk, for smooth edges.

Examples
--------
>>> from mrmp.core import Grid, Heading, RobotResult, RunResult
>>> robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)], headings=[Heading.EAST, Heading.EAST])
>>> run = RunResult("demo", "thesis", 0, [robot], [], "arrived", 1, 1, 0.0)
>>> painter = FramePainter(Grid(2, 2), run)
>>> image = painter.frame(0.5)
>>> image.mode, image.size
('RGB', (340, 309))
"""

from __future__ import annotations

import itertools
import math
from bisect import bisect_right
from dataclasses import dataclass
from functools import lru_cache

from PIL import Image, ImageDraw, ImageFont

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.result import RobotResult, RunResult
from mrmp.viz.colouring import ROBOT, check_colouring, colour_at, colour_changes, colouring_caption, progress_ramp
from mrmp.viz.layout import (
    BACKGROUND,
    BAD_NEWS,
    COLLISION,
    COST_TEXT,
    GOAL_INSET,
    GOAL_LABEL_CELL,
    GOAL_WIDTH,
    GRID_LINE,
    HEADER,
    HEADER_DIM,
    HEADER_TEXT,
    LEGEND_ROW,
    MESSAGE_LABEL_CELL,
    OBSTACLE,
    OBSTACLE_EDGE,
    PALETTE,
    ROBOT_EDGE,
    ROBOT_RADIUS,
    SUCCESS,
    Keyframe,
    Layout,
    MessageArrow,
    arrow_head,
    arrow_shape,
    cell_at,
    check_speed,
    clock_text,
    cost_tint,
    darker,
    goal_label_place,
    is_live,
    label_size,
    make_layout,
    marker_points,
    message_arrows,
    message_label_place,
    message_width,
    mix,
    move_ticks_of,
    pose_at,
    robot_colours,
    robot_label,
    run_caption,
    run_subtitle,
    run_ticks,
    run_verdict,
    text_colour_on,
    track,
    trim_idle,
)
from mrmp.viz.legend import (
    AXIS_TEXT,
    EAST_LABEL,
    GOAL_NEUTRAL,
    LEGEND_TEXT,
    NORTH_LABEL,
    LegendPlace,
    axis_labels,
    compass,
    legend_items,
    place_legend,
)


def frame_times(ticks: int, frames_per_tick: int, max_frames: int) -> list[float]:
    """Times (in ticks) of the frames to draw, first ``0`` and last ``ticks``.

    ``frames_per_tick`` frames per tick when that fits in ``max_frames``; else
    fewer per tick; else ``max_frames`` times spread evenly over the run.

    >>> frame_times(2, 2, 100)
    [0.0, 0.5, 1.0, 1.5, 2.0]
    >>> frame_times(4, 4, 9)
    [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]
    >>> frame_times(8, 4, 5)
    [0.0, 2.0, 4.0, 6.0, 8.0]
    >>> frame_times(0, 4, 10)
    [0.0]
    """
    if ticks <= 0:
        return [0.0]
    per_tick = min(frames_per_tick, (max_frames - 1) // ticks)
    if per_tick >= 1:
        return [step / per_tick for step in range(ticks * per_tick + 1)]
    count = max(2, max_frames)
    return [ticks * index / (count - 1) for index in range(count)]


def check_frame_options(frames_per_tick: int, fps: float, max_frames: int | None) -> None:
    """Refuse frame settings of a GIF or MP4 writer that are not positive.

    >>> check_frame_options(4, 10.0, None)
    >>> check_frame_options(4, 0.0, None)
    Traceback (most recent call last):
    ...
    ValueError: fps must be positive, got 0.0
    """
    if frames_per_tick < 1:
        raise ValueError(f"frames_per_tick must be at least 1, got {frames_per_tick}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    if max_frames is not None and max_frames < 1:
        raise ValueError(f"max_frames must be at least 1, got {max_frames}")


def live_frame_times(result: RunResult, fps: float, speed: float, max_frames: int) -> tuple[list[float], float]:
    """Times (in ticks) of the frames of a live run played at ``speed`` times its real speed, and each frame's seconds.

    A live run's tick lasts ``tick_seconds``; frames come ``1 / fps`` seconds
    apart at most, fewer when ``max_frames`` says so (each then lasts longer:
    the animation still plays at ``speed``).

    >>> from mrmp.core import RobotResult, RunResult
    >>> robot = RobotResult("A", (0, 0), (0, 0), path=[(0, 0)] * 11)
    >>> run = RunResult("s", "p", 0, [robot], [], "done", 10, 0, 0.0, mode="live", tick_seconds=0.05)
    >>> times, seconds = live_frame_times(run, 10.0, 1.0, 100)   # 0.5 s at 10 frames a second
    >>> len(times), times[1], seconds
    (6, 2.0, 0.1)
    >>> live_frame_times(run, 10.0, 0.5, 100)[0][1]              # half speed: twice the frames
    1.0
    """
    ticks = run_ticks(result)
    seconds = ticks * float(result.tick_seconds or 0.0) / speed
    if ticks <= 0 or seconds <= 0:
        return [0.0], 1.0 / fps
    count = max(2, min(max_frames, math.ceil(seconds * fps - 1e-9) + 1))
    return [ticks * index / (count - 1) for index in range(count)], seconds / (count - 1)


@dataclass(frozen=True)
class Style:
    """What a picture shows beyond the run itself (see :func:`mrmp.viz.gif.write_gif`)."""

    show_messages: bool = False
    colour_by: str | None = None
    goal_lines: bool = False
    speed: float = 1.0


def frames_of_run(
    grid: Grid,
    result: RunResult,
    layout: Layout,
    frames_per_tick: int,
    max_frames: int,
    style: Style | None = None,
    fps: float = 10.0,
) -> tuple[list[float], float, FramePainter]:
    """The times of the frames to draw, each frame's seconds, and a painter that flashes collisions at their spacing.

    A simulated run has ``frames_per_tick`` frames a tick (:func:`frame_times`),
    each ``1 / fps`` seconds; a live run plays at its real speed times
    ``style.speed`` (:func:`live_frame_times`).

    >>> from mrmp.core import Grid, RobotResult, RunResult
    >>> robot = RobotResult("A", (0, 0), (1, 1), path=[(0, 0), (0, 1), (1, 1)])
    >>> run = RunResult("demo", "thesis", 0, [robot], [], "arrived", 2, 2, 0.0)
    >>> times, seconds, painter = frames_of_run(Grid(2, 2), run, make_layout(Grid(2, 2), 1), 2, 100)
    >>> times, seconds
    ([0.0, 0.5, 1.0, 1.5, 2.0], 0.1)
    """
    style = style if style is not None else Style()
    check_speed(style.speed)
    result = trim_idle(result)
    if is_live(result):
        times, seconds = live_frame_times(result, fps, style.speed, max_frames)
    else:
        times, seconds = frame_times(run_ticks(result), frames_per_tick, max_frames), 1.0 / fps
    painter = FramePainter(grid, result, layout, step=times[1] - times[0] if len(times) > 1 else 1.0, style=style)
    return times, seconds, painter


@lru_cache(maxsize=64)
def _font(size: int, bold: bool = False) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    name = "DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf"
    try:
        return ImageFont.truetype(name, size)
    except OSError:
        return ImageFont.load_default(size)


def _supersampling(layout: Layout) -> int:
    """Draw at 3x or 2x and shrink (smooth edges) when the picture is cheap enough."""
    if layout.robots <= 30 and layout.cell >= 40:
        return 3
    if layout.robots <= 300 and layout.cell >= 14:
        return 2
    return 1


class FramePainter:
    """Draws the frames of one run: a static background once, then moving parts.

    Parameters
    ----------
    grid:
        The grid the run took place on.
    result:
        The run to draw.
    layout:
        Where things go (default: :func:`~mrmp.viz.layout.make_layout` of ``grid``).
    step:
        Time between two frames, in ticks (a collision is flashed on at least one frame).
    show_messages:
        Draw the messages of the run's message log as arrows (nothing if it has none).
    """

    def __init__(
        self,
        grid: Grid,
        result: RunResult,
        layout: Layout | None = None,
        step: float = 1.0,
        *,
        show_messages: bool = False,
        style: Style | None = None,
    ) -> None:
        style = style if style is not None else Style(show_messages=show_messages)
        self.style = style
        result = trim_idle(result)
        self.colouring = check_colouring(style.colour_by, len(result.robots))
        if layout is None:
            layout = make_layout(grid, len(result.robots), colouring=self.colouring, goal_lines=style.goal_lines)
        ticks = run_ticks(result)
        self.grid = grid
        self.flash = max(0.75, 0.55 * step)  # ticks either side of a collision it is flashed: at least one frame
        self.result = result
        self.layout = layout
        self.ticks = ticks
        self.ss = _supersampling(layout)
        self.big = layout.scaled(self.ss)
        self.colours = robot_colours(len(result.robots))
        self.own = self.colouring == ROBOT
        self.edges = [darker(colour, 0.4) if self.own else ROBOT_EDGE for colour in self.colours]
        self.changes = [
            colour_changes(robot, ticks, self.colouring, colour) for robot, colour in zip(result.robots, self.colours)
        ]
        self.tracks: list[list[Keyframe]] = [track(robot, ticks, move_ticks_of(result)) for robot in result.robots]
        self.moves: list[list[tuple[int, Cell]]] = [_moves(robot, ticks) for robot in result.robots]
        self.title = run_caption(result)
        self.verdict, self.good = run_verdict(result)
        self.arrows: list[MessageArrow] = message_arrows(result, self.big) if style.show_messages else []
        self.background = self._background()

    # -- static parts ----------------------------------------------------------------------

    def _background(self) -> Image.Image:
        big, ss = self.big, self.ss
        image = Image.new("RGB", (big.width, big.height), BACKGROUND)
        draw = ImageDraw.Draw(image)
        draw.rectangle((0, 0, big.width - 1, big.header - 1), fill=HEADER)
        costs = self.grid.costs()
        cost_values = list(costs.values())
        cost_font = _font(max(8, round(big.cell * 0.2)), bold=False) if self.layout.cell >= 36 else None
        for cell, cost in costs.items():
            box = big.cell_box(cell)
            draw.rectangle((box[0], box[1], box[2] - 1, box[3] - 1), fill=cost_tint(cost, cost_values))
            if cost_font is not None:
                label = f"{cost:g}"
                draw.text(
                    (box[2] - big.cell * 0.08, box[3] - big.cell * 0.06),
                    label,
                    fill=COST_TEXT,
                    font=cost_font,
                    anchor="rd",
                )
        line = max(1, round(ss * (1 if self.layout.cell < 40 else 1.5)))
        left, top = big.left, big.top
        right, bottom = left + big.grid_width, top + big.grid_height
        if self.layout.cell >= 4:
            for column in range(self.grid.y_size + 1):
                x = left + column * big.cell
                draw.line((x, top, x, bottom), fill=GRID_LINE, width=line)
            for row in range(self.grid.x_size + 1):
                y = top + row * big.cell
                draw.line((left, y, right, y), fill=GRID_LINE, width=line)
        radius = round(big.cell * 0.12) if self.layout.cell >= 12 else 0
        gap = round(big.cell * 0.04)
        for cell in self.grid.blocked_cells():
            box = big.cell_box(cell)
            draw.rounded_rectangle(
                (box[0] + gap, box[1] + gap, box[2] - 1 - gap, box[3] - 1 - gap),
                radius=radius,
                fill=OBSTACLE,
                outline=OBSTACLE_EDGE,
                width=max(1, ss),
            )
        draw.rectangle((left, top, right, bottom), outline=mix(GRID_LINE, OBSTACLE, 0.5), width=line)
        self._goals(draw)
        self._axes(draw)
        self._legend(draw)
        return image

    def _goals(self, draw: ImageDraw.ImageDraw) -> None:
        """Goal squares: in their robot's colour (with its id in big cells), else neutral."""
        big = self.big
        inset = big.cell * GOAL_INSET
        width = max(1, round(big.cell * GOAL_WIDTH))
        labelled = self.own and self.layout.cell >= GOAL_LABEL_CELL
        font = _font(max(6, round(big.cell * 0.17)), bold=True)
        for robot, colour in zip(self.result.robots, self.colours):
            shown = colour if self.own else GOAL_NEUTRAL
            box = big.cell_box(robot.goal)
            draw.rounded_rectangle(
                (box[0] + inset, box[1] + inset, box[2] - inset, box[3] - inset),
                radius=big.cell * 0.1,
                outline=shown,
                fill=mix(shown, BACKGROUND, 0.12),
                width=width,
            )
            if labelled:
                place = goal_label_place(big, robot.goal)
                draw.text(place, robot_label(robot.id), fill=darker(colour, 0.25), font=font, anchor="ls")

    def _axes(self, draw: ImageDraw.ImageDraw) -> None:
        """The axes' numbers and names (:func:`mrmp.viz.legend.axis_labels`)."""
        font = _font(round(self.big.small_font))
        bold = _font(round(self.big.small_font), bold=True)
        anchors = {"end": "rm", "middle": "mm", "start": "lm"}
        for label in axis_labels(self.big):
            named = label.text in ("x", "y")
            text = (f"{label.text} ↑" if label.text == "x" else f"{label.text} →") if named else label.text
            draw.text((label.x, label.y), text, fill=AXIS_TEXT, font=bold if named else font, anchor=anchors[label.anchor])

    def _legend(self, draw: ImageDraw.ImageDraw) -> None:
        """The legend band: what colours and marks mean, and the compass."""
        big = self.big
        draw.rectangle((0, big.legend_top, big.width, big.height), fill=mix(GRID_LINE, BACKGROUND, 0.35))
        font = _font(round(big.small_font))
        row = big.small_font / 11 * LEGEND_ROW
        for place in place_legend(legend_items(self.result, self.colouring, self.style.goal_lines, self.colours), big):
            self._swatch(draw, place, row)
            label = _fit(draw, place.item.label, font, place.width - (place.text_x - place.x) - 4 * self.ss)
            draw.text((place.text_x, place.y), label, fill=LEGEND_TEXT, font=font, anchor="lm")
        point = compass(big)
        bold = _font(round(big.small_font), bold=True)
        arrows = ((point.north_tip, point.north_text, NORTH_LABEL), (point.east_tip, point.east_text, EAST_LABEL))
        for tip, text_at, text in arrows:
            draw.line((point.corner, tip), fill=LEGEND_TEXT, width=max(1, round(point.width)))
            draw.polygon(arrow_head(MessageArrow(0, 0, 0, (), point.corner, tip), point.head), fill=LEGEND_TEXT)
            draw.text(text_at, text, fill=LEGEND_TEXT, font=bold, anchor="lm")

    def _swatch(self, draw: ImageDraw.ImageDraw, place: LegendPlace, row: float) -> None:
        item = place.item
        x, y = place.x + row / 2, place.y
        size = row * 0.7
        if item.kind in ("robot", "heading"):
            radius = size * 0.45
            disc = (x - radius, y - radius, x + radius, y + radius)
            draw.ellipse(disc, fill=item.colour, outline=darker(item.colour, 0.4), width=max(1, self.ss))
            if item.kind == "heading":
                draw.polygon(marker_points((x, y), item.angle, size, _SMALL_MARKER), fill=darker(item.colour, 0.45))
        elif item.kind == "goal":
            half = size / 2
            draw.rounded_rectangle(
                (x - half, y - half, x + half, y + half),
                radius=size * 0.15,
                outline=item.colour,
                fill=mix(item.colour, BACKGROUND, 0.12),
                width=max(1, round(size * 0.14)),
            )
        elif item.kind == "ramp":
            ramp = progress_ramp()
            step = (row * 2.4 - 4 * self.ss) / len(ramp)
            for number, shade in enumerate(ramp):
                left = place.x + 2 * self.ss + number * step
                draw.rectangle((left, y - size / 2, left + step, y + size / 2), fill=shade)
        else:
            share = 0.6 if item.kind == "trail" else 0.8
            width = max(1, round(row * (0.18 if item.kind == "trail" else 0.1)))
            ends = (place.x + 2 * self.ss, y, place.x + row - 2 * self.ss, y)
            draw.line(ends, fill=mix(item.colour, BACKGROUND, share), width=width)

    # -- moving parts ----------------------------------------------------------------------

    def frame(self, t: float) -> Image.Image:
        """The picture at time ``t`` (in ticks), at output size."""
        image = self.background.copy()
        draw = ImageDraw.Draw(image)
        flashes = self._collisions(t)
        for box, strength in flashes:
            fill = (
                mix(COLLISION, BACKGROUND, 0.2 + 0.6 * strength) if strength > 0 else mix(COLLISION, BACKGROUND, 0.12)
            )
            draw.rectangle(box, fill=fill)
        self._trails(draw, t)
        if self.style.goal_lines:
            self._goal_lines(draw, t)
        self._robots(draw, t)
        if self.arrows:
            self._messages(draw, t)
        for box, strength in flashes:
            width = max(1, round(self.big.cell * (0.1 if strength > 0 else 0.05)))
            colour = COLLISION if strength > 0 else mix(COLLISION, BACKGROUND, 0.55)
            draw.rectangle(box, outline=colour, width=width)
        self._caption(draw, t)
        if self.ss > 1:
            image = image.reduce(self.ss)
        return image

    def _collisions(self, t: float) -> list[tuple[tuple[float, float, float, float], float]]:
        """Boxes of collision cells to mark at ``t`` with a flash strength (0: faint reminder)."""
        big = self.big
        window = self.flash
        marks: list[tuple[tuple[float, float, float, float], float]] = []
        for collision in self.result.collisions:
            distance = t - collision.tick
            if abs(distance) < window:
                strength = 1.0 - abs(distance) / window * 0.7
            elif distance > 0:
                strength = 0.0
            else:
                continue
            for cell in collision.cells:
                box = big.cell_box(cell)
                marks.append(((box[0], box[1], box[2] - 1, box[3] - 1), strength))
        return marks

    def _trails(self, draw: ImageDraw.ImageDraw, t: float) -> None:
        big = self.big
        width = max(1, round(self.layout.trail_width * self.ss))
        keep = self.layout.trail_ticks
        fade = float(keep) if keep is not None else max(8.0, self.ticks * 0.75)
        floor = 0.0 if keep is not None else 0.35
        now = min(math.floor(t + 1e-9), self.ticks)
        first = 0 if keep is None else max(0, now - keep)
        for index in range(len(self.result.robots)):
            colour = colour_at(self.changes[index], t)
            x, y, _ = pose_at(self.tracks[index], t)
            moves = self.moves[index]
            begin = max(0, bisect_right(moves, first, key=_tick_of) - 1)
            stop = bisect_right(moves, now, key=_tick_of)
            points = [(big.centre(cell), float(max(tick, first))) for tick, cell in moves[begin:stop]]
            here = big.point(x, y)
            if points and here != points[-1][0]:
                points.append((here, t))
            if len(points) < 2:
                continue
            half = width / 2
            for number, ((start, _), (end, reached)) in enumerate(itertools.pairwise(points)):
                age = t - reached
                share = max(floor, (0.85 if self.own else 0.45) * (1.0 - age / fade))
                if share <= 0.02:
                    continue
                shade = mix(colour, BACKGROUND, share)
                if width >= 3 and number == 0:
                    draw.ellipse((start[0] - half, start[1] - half, start[0] + half, start[1] + half), fill=shade)
                draw.line((start, end), fill=shade, width=width)
                if width >= 3:  # round joint, half hidden under the next, younger, segment
                    draw.ellipse((end[0] - half, end[1] - half, end[0] + half, end[1] + half), fill=shade)

    def _goal_lines(self, draw: ImageDraw.ImageDraw, t: float) -> None:
        """A line from each robot to its goal, in the robot's colour at ``t``."""
        big = self.big
        width = max(1, round(big.cell * 0.05))
        for index, robot in enumerate(self.result.robots):
            x, y, _ = pose_at(self.tracks[index], t)
            here, goal = big.point(x, y), big.centre(robot.goal)
            if math.dist(here, goal) > big.cell * ROBOT_RADIUS:
                draw.line((here, goal), fill=mix(colour_at(self.changes[index], t), BACKGROUND, 0.7), width=width)

    def _robots(self, draw: ImageDraw.ImageDraw, t: float) -> None:
        big = self.big
        radius = big.cell * ROBOT_RADIUS
        outline = max(1, round(big.cell * 0.045))
        labels = self.layout.show_labels
        nose_outside = self.layout.cell >= 18
        for index, robot in enumerate(self.result.robots):
            colour, edge = colour_at(self.changes[index], t), self.edges[index]
            x, y, angle = pose_at(self.tracks[index], t)
            centre = big.point(x, y)
            disc = (centre[0] - radius, centre[1] - radius, centre[0] + radius, centre[1] + radius)
            if nose_outside:
                draw.polygon(marker_points(centre, angle, big.cell), fill=edge)
                draw.ellipse(disc, fill=colour, outline=edge, width=outline)
            else:
                draw.ellipse(disc, fill=colour)
                draw.polygon(marker_points(centre, angle, big.cell, _SMALL_MARKER), fill=edge)
            if labels:
                text = robot_label(robot.id)
                size = round(label_size(text, big.cell))
                font = _font(size, bold=True)
                while size > 6 * self.ss and draw.textlength(text, font=font) > 2 * radius * 0.9:
                    size -= 1
                    font = _font(size, bold=True)
                draw.text(centre, text, fill=text_colour_on(colour), font=font, anchor="mm")

    def _messages(self, draw: ImageDraw.ImageDraw, t: float) -> None:
        """Arrows of the messages sent during the tick under way at ``t``, in the senders' colours."""
        big = self.big
        width = max(1, round(message_width(self.layout) * self.ss))
        font = _font(max(6, round(big.cell * 0.12))) if self.layout.cell >= MESSAGE_LABEL_CELL else None
        for arrow in self.arrows:
            if not arrow.shown_at(t):
                continue
            colour = self.colours[arrow.sender]  # exact: it is in the GIF's palette
            base, tip = arrow_shape(arrow, big.cell)
            draw.line((arrow.start, base), fill=colour, width=width)
            draw.polygon(tip, fill=colour)
            if font is not None:
                place, side = message_label_place(arrow, big.cell)
                anchor = {"start": "lm", "middle": "mm", "end": "rm"}[side]
                draw.text(place, arrow.label, fill=colour, font=font, anchor=anchor, stroke_width=self.ss, stroke_fill=BACKGROUND)

    def _caption(self, draw: ImageDraw.ImageDraw, t: float) -> None:
        """Two lines: the title (in a smaller font when too long, never cut), then size, colouring and clock."""
        big, ss = self.big, self.ss
        size = self.layout.font_size * ss
        small = round(self.layout.font_size * 0.82) * ss
        tick_font = _font(small)
        first, second = big.header * 0.3, big.header * 0.68
        pad = 12 * ss
        title_font = _font(size, bold=True)
        while size > 7 * ss and draw.textlength(self.title, font=title_font) > big.width - 2 * pad:
            size -= 1
            title_font = _font(size, bold=True)
        draw.text((pad, first), self.title, fill=HEADER_TEXT, font=title_font, anchor="lm")
        tick = min(math.floor(t + 1e-9), self.ticks)
        finished = t >= self.ticks
        right = clock_text(self.result, tick)
        if finished:
            right += f"  ·  {self.verdict}"
        right_colour = (SUCCESS if self.good else BAD_NEWS) if finished else HEADER_TEXT
        draw.text((big.width - pad, second), right, fill=right_colour, font=tick_font, anchor="rm")
        longest = f"{clock_text(self.result, self.ticks)}  ·  {self.verdict}"  # the same subtitle on every frame
        room = big.width - 3 * pad - draw.textlength(longest, font=tick_font)
        subtitle = _fit(draw, run_subtitle(self.result, colouring_caption(self.colouring), self.style.speed), tick_font, room)
        if subtitle:
            draw.text((pad, second), subtitle, fill=HEADER_DIM, font=tick_font, anchor="lm")
        bar = max(2, 3 * ss)
        share = t / self.ticks if self.ticks else 1.0
        draw.rectangle((0, big.header - bar, big.width, big.header - 1), fill=mix(HEADER_DIM, HEADER, 0.35))
        accent = (SUCCESS if self.good else BAD_NEWS) if finished else PALETTE[0]
        draw.rectangle(
            (0, big.header - bar, round(big.width * share), big.header - 1), fill=mix(accent, HEADER_TEXT, 0.85)
        )


def _moves(robot: RobotResult, ticks: int) -> list[tuple[int, Cell]]:
    """``(tick, cell)`` for tick 0 and each tick at which ``robot`` reached a new cell."""
    moves = [(0, cell_at(robot, 0))]
    for tick in range(1, ticks + 1):
        cell = cell_at(robot, tick)
        if cell != moves[-1][1]:
            moves.append((tick, cell))
    return moves


def _tick_of(move: tuple[int, Cell]) -> int:
    return move[0]


_SMALL_MARKER: tuple[tuple[float, float], ...] = ((0.0, -0.46), (-0.2, -0.04), (0.2, -0.04))
"""Heading triangle for small cells: drawn over the disc, from near its centre to beyond its edge."""


def _fit(draw: ImageDraw.ImageDraw, text: str, font: ImageFont.FreeTypeFont | ImageFont.ImageFont, room: float) -> str:
    """``text``, cut short with an ellipsis if it is wider than ``room`` pixels."""
    if draw.textlength(text, font=font) <= room:
        return text
    while text and draw.textlength(text + "…", font=font) > room:
        text = text[:-1]
    return text + "…" if text else ""

