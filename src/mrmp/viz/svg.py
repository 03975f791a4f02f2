"""Animated SVG of a run, played by any browser with SMIL animation.

The picture is the GIF's (see :mod:`mrmp.viz.gif`), from the same
:mod:`mrmp.viz.layout`: grid, obstacles, costly cells, goals as hollow squares,
robots as discs with a heading nose and their id, growing trails, a tick
counter with a progress bar, and collision cells flashed red at their tick.

How it moves, all looping with ``repeatCount="indefinite"``:

* each robot is a ``<g class="robot">`` whose position is an
  ``<animateTransform type="translate">`` and whose nose turns with an
  ``<animateTransform type="rotate">``, both with ``values`` and ``keyTimes``
  taken from the robot's keyframes (:func:`mrmp.viz.layout.track`);
* a trail is a polyline through the cells visited whose ``stroke-dashoffset``
  is animated so the drawn part ends where the robot is (crowded runs show only
  the last few cells);
* the tick counter is one ``<text>`` per tick whose ``opacity`` switches with a
  discrete ``<animate>``;
* a collision cell's ``opacity`` flashes at its tick and then stays faint;
* with ``show_messages``, each tick's messages are arrows from sender to
  recipient (:func:`mrmp.viz.layout.message_arrows`) whose ``opacity``
  switches on for that tick with a discrete ``<animate>``.

To show one moment (for a screenshot), pause the document's clock and set it:
``svg.pauseAnimations(); svg.setCurrentTime(seconds)``; tick ``t`` plays at
``t * seconds_per_tick`` seconds.

Examples
--------
>>> import tempfile, pathlib
>>> import xml.etree.ElementTree as ET
>>> from mrmp.core import Grid, Heading, RobotResult, RunResult
>>> robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)], headings=[Heading.EAST, Heading.EAST])
>>> run = RunResult("demo", "thesis", 0, [robot], [], "arrived", 1, 1, 0.0)
>>> with tempfile.TemporaryDirectory() as folder:
...     root = ET.parse(write_svg(Grid(2, 2), run, pathlib.Path(folder) / "demo.svg")).getroot()
>>> root.tag, root.get("width"), root.get("viewBox")
('{http://www.w3.org/2000/svg}svg', '100%', '0 0 340 309')
"""

from __future__ import annotations

import itertools
import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.viz._atomic import replacing
from mrmp.viz.colouring import ROBOT, check_colouring, colour_changes, colouring_caption, progress_ramp
from mrmp.viz.layout import (
    BACKGROUND,
    BAD_NEWS,
    COLLISION,
    COST_TEXT,
    FONT_FAMILY,
    GOAL_INSET,
    GOAL_LABEL_CELL,
    GOAL_WIDTH,
    GRID_LINE,
    HEADER,
    HEADER_DIM,
    HEADER_TEXT,
    HEADING_MARKER,
    LEGEND_ROW,
    MESSAGE_LABEL_CELL,
    OBSTACLE,
    OBSTACLE_EDGE,
    PALETTE,
    RGB,
    ROBOT_EDGE,
    ROBOT_RADIUS,
    SUCCESS,
    Keyframe,
    MessageArrow,
    arrow_head,
    arrow_shape,
    cell_at,
    check_speed,
    clock_text,
    cost_tint,
    darker,
    goal_label_place,
    hex_colour,
    is_live,
    label_size,
    make_layout,
    marker_points,
    message_arrows,
    message_label_place,
    message_width,
    mix,
    move_ticks_of,
    robot_colours,
    robot_label,
    run_caption,
    run_subtitle,
    run_ticks,
    run_verdict,
    simplify,
    text_colour_on,
    text_width,
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

SVG_NAMESPACE = "http://www.w3.org/2000/svg"
_SMALL_MARKER: tuple[tuple[float, float], ...] = ((0.0, -0.46), (-0.2, -0.04), (0.2, -0.04))


def write_svg(
    grid: Grid,
    result: RunResult,
    path: str | os.PathLike[str],
    *,
    seconds_per_tick: float | None = None,
    hold_s: float = 1.5,
    show_messages: bool = False,
    colour_by: str | None = None,
    goal_lines: bool = False,
    speed: float = 1.0,
) -> Path:
    """Draw ``result`` on ``grid`` as a looping animated SVG at ``path``.

    Parameters
    ----------
    grid:
        The grid the run took place on.
    result:
        The run: robots' paths and headings (one per tick) and collisions.
    path:
        Where to write the SVG (UTF-8).
    seconds_per_tick:
        Playing time of one tick; by default 0.4 s, and for a live run its
        ``tick_seconds`` over ``speed``, so that it plays at its real speed.
    hold_s:
        How long the final state stays on screen before the loop restarts.
    show_messages:
        Draw each tick's messages as arrows from sender to recipient (runs
        with a message log).
    colour_by:
        What a robot's colour says: ``"robot"``, ``"progress"`` or
        ``"heading"`` (:mod:`mrmp.viz.colouring`; by default ``"robot"`` for
        a few robots, ``"progress"`` for a crowd).
    goal_lines:
        Draw a line from each robot to its goal, until it is there.
    speed:
        A live run plays at ``speed`` times its real speed (the caption says so).

    Returns
    -------
    Path
        The path written (atomically: a temporary file in the same folder,
        then renamed).

    Raises
    ------
    ValueError
        If ``seconds_per_tick`` or ``speed`` is not positive, ``hold_s`` is
        negative or ``colour_by`` unknown.
    """
    root = _svg_root(grid, result, _Style(seconds_per_tick, hold_s, show_messages, colour_by, goal_lines, speed))
    target = Path(path)
    with replacing(target) as temporary:
        ET.ElementTree(root).write(temporary, encoding="utf-8", xml_declaration=True)
    return target


def svg_text(
    grid: Grid,
    result: RunResult,
    *,
    seconds_per_tick: float | None = None,
    hold_s: float = 1.5,
    show_messages: bool = False,
    colour_by: str | None = None,
    goal_lines: bool = False,
    speed: float = 1.0,
) -> str:
    """The animated SVG of :func:`write_svg` as text, to embed in HTML (no XML declaration).

    >>> from mrmp.core import Grid, RobotSpec, Scenario
    >>> from mrmp.sim.simulator import simulate
    >>> grid = Grid(1, 3)
    >>> text = svg_text(grid, simulate(Scenario(grid, (RobotSpec("A", (0, 0), (0, 2)),))))
    >>> text.startswith("<svg") and text.endswith("</svg>")
    True
    """
    root = _svg_root(grid, result, _Style(seconds_per_tick, hold_s, show_messages, colour_by, goal_lines, speed))
    return ET.tostring(root, encoding="unicode")


@dataclass(frozen=True)
class _Style:
    """The options of one SVG picture (see :func:`write_svg`)."""

    seconds_per_tick: float | None = None
    hold_s: float = 1.5
    show_messages: bool = False
    colour_by: str | None = None
    goal_lines: bool = False
    speed: float = 1.0


def _svg_root(grid: Grid, result: RunResult, style: _Style) -> ET.Element:
    """The animation's ``<svg>`` element, indented; checks the options."""
    check_speed(style.speed)
    result = trim_idle(result)
    seconds_per_tick = style.seconds_per_tick
    if seconds_per_tick is None:
        seconds_per_tick = float(result.tick_seconds or 0.0) / style.speed if is_live(result) else DEFAULT_SECONDS_PER_TICK
    if not seconds_per_tick > 0:
        raise ValueError(f"seconds_per_tick must be positive, got {seconds_per_tick}")
    if not style.hold_s >= 0:
        raise ValueError(f"hold_s must not be negative, got {style.hold_s}")
    root = _SvgRun(grid, result, seconds_per_tick, style).build()
    ET.indent(root, space=" ")
    return root


DEFAULT_SECONDS_PER_TICK = 0.4
"""Playing time of a tick of a simulated run."""


def _n(value: float) -> str:
    """A compact number for SVG text: at most two decimals, no trailing zeros.

    >>> _n(3.0), _n(2.345), _n(-0.001)
    ('3', '2.35', '0')
    """
    text = f"{value:.2f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _same(colour: RGB) -> RGB:
    return colour


class _SvgRun:
    """Builds the SVG element tree of one run."""

    def __init__(self, grid: Grid, result: RunResult, seconds_per_tick: float, style: _Style) -> None:
        self.show_messages = style.show_messages
        self.goal_lines = style.goal_lines
        self.speed = style.speed
        self.grid = grid
        self.result = result
        self.colouring = check_colouring(style.colour_by, len(result.robots))
        self.layout = make_layout(grid, len(result.robots), colouring=self.colouring, goal_lines=style.goal_lines)
        self.ticks = run_ticks(result)
        self.spt = seconds_per_tick
        self.duration = max(self.ticks * seconds_per_tick + style.hold_s, 0.1)
        self.dur = f"{self.duration:.3f}s"
        self.colours = robot_colours(len(result.robots))
        self.tracks: list[list[Keyframe]] = [track(robot, self.ticks, move_ticks_of(result)) for robot in result.robots]
        self.changes = [
            colour_changes(robot, self.ticks, self.colouring, colour) for robot, colour in zip(result.robots, self.colours)
        ]

    # -- timing helpers -----------------------------------------------------------------

    def _key(self, tick_time: float) -> float:
        """keyTime (0..1) of a time in ticks."""
        return min(1.0, max(0.0, tick_time * self.spt / self.duration))

    def _animate(
        self,
        parent: ET.Element,
        attribute: str,
        samples: Sequence[tuple[float, str]],
        *,
        transform: str | None = None,
        discrete: bool = False,
    ) -> ET.Element:
        """Add a looping ``<animate>`` (or ``<animateTransform>``) of ``attribute`` through ``samples``.

        ``samples`` are ``(time in ticks, value)`` in time order; the first value
        is stretched back to the start and the last one held to the end.
        """
        keys: list[float] = []
        values: list[str] = []
        for tick_time, value in samples:
            key = round(self._key(tick_time), 5)
            if keys and key <= keys[-1]:
                if discrete:  # a discrete value lasting no time: the later one wins
                    values[-1] = value
                    continue
                key = keys[-1]  # linear: an equal keyTime makes a jump
            keys.append(key)
            values.append(value)
        if not keys:
            keys, values = [0.0], ["0"]
        if keys[0] > 0.0:
            keys.insert(0, 0.0)
            values.insert(0, values[0])
        if not discrete and (keys[-1] < 1.0 or len(keys) == 1):
            keys.append(1.0)
            values.append(values[-1])
        attributes = {
            "attributeName": attribute,
            "values": ";".join(values),
            "keyTimes": ";".join(_n_key(key) for key in keys),
            "dur": self.dur,
            "repeatCount": "indefinite",
        }
        if discrete:
            attributes["calcMode"] = "discrete"
        if transform is not None:
            attributes["type"] = transform
            return ET.SubElement(parent, "animateTransform", attributes)
        return ET.SubElement(parent, "animate", attributes)

    # -- the document ---------------------------------------------------------------------

    def build(self) -> ET.Element:
        layout = self.layout
        root = ET.Element(
            "svg",
            {
                "xmlns": SVG_NAMESPACE,
                "version": "1.1",
                "width": "100%",
                "viewBox": f"0 0 {layout.width} {layout.height}",
                "font-family": FONT_FAMILY,
                "data-width": str(layout.width),
                "data-height": str(layout.height),
                "data-colour-by": self.colouring,
            },
        )
        ET.SubElement(
            root, "title"
        ).text = f"{run_caption(self.result)}: {self.ticks} ticks, {len(self.result.robots)} robots"
        ET.SubElement(root, "rect", {"width": "100%", "height": "100%", "fill": hex_colour(BACKGROUND)})
        self._grid(ET.SubElement(root, "g", {"id": "grid"}))
        self._axes(ET.SubElement(root, "g", {"id": "axes", "font-size": _n(layout.small_font), "fill": hex_colour(AXIS_TEXT)}))
        self._goals(ET.SubElement(root, "g", {"id": "goals"}))
        collisions = ET.SubElement(root, "g", {"id": "collisions"})
        self._collision_cells(collisions)
        self._trails(
            ET.SubElement(
                root, "g", {"id": "trails", "fill": "none", "stroke-linecap": "round", "stroke-linejoin": "round"}
            )
        )
        if self.goal_lines:
            self._goal_lines(ET.SubElement(root, "g", {"id": "goal-lines", "stroke-linecap": "round"}))
        self._robots(ET.SubElement(root, "g", {"id": "robots"}))
        if self.show_messages:
            self._messages(ET.SubElement(root, "g", {"id": "messages"}))
        self._collision_rings(ET.SubElement(root, "g", {"id": "collision-rings", "fill": "none"}))
        self._caption(ET.SubElement(root, "g", {"id": "caption"}))
        self._legend(ET.SubElement(root, "g", {"id": "legend", "font-size": _n(layout.small_font)}))
        return root

    def _colour_samples(self, index: int, paint: Callable[[RGB], RGB] = _same) -> list[tuple[float, str]]:
        """The colour changes of robot ``index`` as ``(tick time, CSS colour)``, each passed through ``paint``."""
        return [(tick_time, hex_colour(paint(colour))) for tick_time, colour in self.changes[index]]

    def _paint(self, element: ET.Element, attribute: str, index: int, paint: Callable[[RGB], RGB] = _same) -> None:
        """Set ``attribute`` of ``element`` to robot ``index``'s colour, animated when the colour changes."""
        samples = self._colour_samples(index, paint)
        element.set(attribute, samples[0][1])
        if len(samples) > 1:
            self._animate(element, attribute, samples, discrete=True)

    def _axes(self, group: ET.Element) -> None:
        """The x numbers up the left side, the y numbers along the foot, and the axes' names."""
        for label in axis_labels(self.layout):
            text = ET.SubElement(
                group,
                "text",
                {"x": _n(label.x), "y": _n(label.y), "dy": "0.35em", "text-anchor": label.anchor, "class": "axis"},
            )
            if label.text in ("x", "y"):
                text.set("font-style", "italic")
                text.set("font-weight", "bold")
                text.text = f"{label.text} ↑" if label.text == "x" else f"{label.text} →"
            else:
                text.text = label.text

    def _goal_lines(self, group: ET.Element) -> None:
        """A line from each robot (moving) to its goal (fixed), in the robot's colour."""
        layout = self.layout
        width = _n(max(1.0, layout.cell * 0.05))
        for index, robot in enumerate(self.result.robots):
            goal_x, goal_y = layout.centre(robot.goal)
            moves = simplify(self.tracks[index], ("x", "y"))
            start_x, start_y = layout.point(moves[0].x, moves[0].y)
            line = ET.SubElement(
                group,
                "line",
                {
                    "class": "goal-line",
                    "data-robot": robot.id,
                    "x1": _n(start_x),
                    "y1": _n(start_y),
                    "x2": _n(goal_x),
                    "y2": _n(goal_y),
                    "stroke-width": width,
                    "stroke-opacity": "0.7",
                },
            )
            ET.SubElement(line, "title").text = f"robot {robot.id} to its goal {robot.goal}"
            self._paint(line, "stroke", index)
            if len(moves) > 1:
                points = [layout.point(frame.x, frame.y) for frame in moves]
                self._animate(line, "x1", [(frame.t, _n(x)) for frame, (x, _) in zip(moves, points)])
                self._animate(line, "y1", [(frame.t, _n(y)) for frame, (_, y) in zip(moves, points)])

    def _legend(self, group: ET.Element) -> None:
        """What the colours and marks mean, and the compass."""
        layout = self.layout
        row = layout.small_font / 11 * LEGEND_ROW
        ET.SubElement(
            group,
            "rect",
            {
                "y": str(layout.legend_top),
                "width": str(layout.width),
                "height": str(layout.legend),
                "fill": hex_colour(mix(GRID_LINE, BACKGROUND, 0.35)),
            },
        )
        items = legend_items(self.result, self.colouring, self.goal_lines, self.colours)
        for place in place_legend(items, layout):
            entry = ET.SubElement(group, "g", {"class": f"legend-{place.item.kind}"})
            if place.item.detail:
                ET.SubElement(entry, "title").text = place.item.detail
            self._swatch(entry, place, row)
            text = ET.SubElement(
                entry, "text", {"x": _n(place.text_x), "y": _n(place.y), "dy": "0.35em", "fill": hex_colour(LEGEND_TEXT)}
            )
            text.text = place.text
        self._compass(ET.SubElement(group, "g", {"id": "compass"}))

    def _swatch(self, entry: ET.Element, place: LegendPlace, row: float) -> None:
        """The mark of a legend entry, in a box ``row`` pixels high at the entry's left."""
        item = place.item
        x, y = place.x + row / 2, place.y
        size = row * 0.7
        colour = hex_colour(item.colour)
        if item.kind in ("robot", "heading"):
            ET.SubElement(
                entry,
                "circle",
                {"cx": _n(x), "cy": _n(y), "r": _n(size * 0.45), "fill": colour, "stroke": hex_colour(darker(item.colour, 0.4))},
            )
            if item.kind == "heading":
                nose = marker_points((x, y), item.angle, size, _SMALL_MARKER)
                ET.SubElement(entry, "polygon", {"points": _points(nose), "fill": hex_colour(darker(item.colour, 0.45))})
        elif item.kind == "goal":
            ET.SubElement(
                entry,
                "rect",
                {
                    "x": _n(x - size / 2),
                    "y": _n(y - size / 2),
                    "width": _n(size),
                    "height": _n(size),
                    "rx": _n(size * 0.15),
                    "fill": hex_colour(mix(item.colour, BACKGROUND, 0.12)),
                    "stroke": colour,
                    "stroke-width": _n(max(1.0, size * 0.14)),
                },
            )
        elif item.kind == "ramp":
            ramp = progress_ramp()
            width = row * 2.4 - 4
            step = width / len(ramp)
            for number, shade in enumerate(ramp):
                ET.SubElement(
                    entry,
                    "rect",
                    {
                        "x": _n(place.x + 2 + number * step),
                        "y": _n(y - size / 2),
                        "width": _n(step + 0.3),
                        "height": _n(size),
                        "fill": hex_colour(shade),
                    },
                )
        else:  # trail, goal-line: a short line
            ET.SubElement(
                entry,
                "line",
                {
                    "x1": _n(place.x + 2),
                    "y1": _n(y),
                    "x2": _n(place.x + row - 2),
                    "y2": _n(y),
                    "stroke": colour,
                    "stroke-width": _n(max(1.5, row * (0.18 if item.kind == "trail" else 0.1))),
                    "stroke-linecap": "round",
                    "stroke-opacity": "0.6" if item.kind == "trail" else "0.8",
                },
            )

    def _compass(self, group: ET.Element) -> None:
        """Arrows to NORTH (where x grows) and EAST (where y grows)."""
        point = compass(self.layout)
        colour = hex_colour(LEGEND_TEXT)
        for tip, text_at, text, anchor in (
            (point.north_tip, point.north_text, NORTH_LABEL, "start"),
            (point.east_tip, point.east_text, EAST_LABEL, "start"),
        ):
            ET.SubElement(
                group,
                "line",
                {
                    "x1": _n(point.corner[0]),
                    "y1": _n(point.corner[1]),
                    "x2": _n(tip[0]),
                    "y2": _n(tip[1]),
                    "stroke": colour,
                    "stroke-width": _n(point.width),
                },
            )
            head = arrow_head(MessageArrow(0, 0, 0, (), point.corner, tip), point.head)
            ET.SubElement(group, "polygon", {"points": _points(head), "fill": colour})
            label = ET.SubElement(
                group,
                "text",
                {
                    "x": _n(text_at[0]),
                    "y": _n(text_at[1]),
                    "dy": "0.35em",
                    "text-anchor": anchor,
                    "fill": colour,
                    "font-weight": "bold",
                },
            )
            label.text = text

    def _grid(self, group: ET.Element) -> None:
        layout, grid = self.layout, self.grid
        costs = grid.costs()
        values = list(costs.values())
        for cell, cost in sorted(costs.items()):
            left, top, _, _ = layout.cell_box(cell)
            ET.SubElement(
                group,
                "rect",
                {
                    "class": "cost",
                    "x": str(left),
                    "y": str(top),
                    "width": str(layout.cell),
                    "height": str(layout.cell),
                    "fill": hex_colour(cost_tint(cost, values)),
                },
            )
            if layout.cell >= 36:
                label = ET.SubElement(
                    group,
                    "text",
                    {
                        "x": _n(left + layout.cell * 0.92),
                        "y": _n(top + layout.cell * 0.92),
                        "font-size": _n(layout.cell * 0.2),
                        "text-anchor": "end",
                        "fill": hex_colour(COST_TEXT),
                    },
                )
                label.text = f"{cost:g}"
        left, top = layout.left, layout.top
        right, bottom = left + layout.grid_width, top + layout.grid_height
        if layout.cell >= 4:
            lines = [f"M{left + column * layout.cell} {top}V{bottom}" for column in range(1, grid.y_size)]
            lines += [f"M{left} {top + row * layout.cell}H{right}" for row in range(1, grid.x_size)]
            if lines:
                ET.SubElement(
                    group,
                    "path",
                    {"d": "".join(lines), "stroke": hex_colour(GRID_LINE), "stroke-width": "1", "fill": "none"},
                )
        gap = layout.cell * 0.04
        radius = layout.cell * 0.12 if layout.cell >= 12 else 0
        for cell in grid.blocked_cells():
            box_left, box_top, _, _ = layout.cell_box(cell)
            ET.SubElement(
                group,
                "rect",
                {
                    "class": "obstacle",
                    "x": _n(box_left + gap),
                    "y": _n(box_top + gap),
                    "width": _n(layout.cell - 2 * gap),
                    "height": _n(layout.cell - 2 * gap),
                    "rx": _n(radius),
                    "fill": hex_colour(OBSTACLE),
                    "stroke": hex_colour(OBSTACLE_EDGE),
                },
            )
        ET.SubElement(
            group,
            "rect",
            {
                "x": str(left),
                "y": str(top),
                "width": str(layout.grid_width),
                "height": str(layout.grid_height),
                "fill": "none",
                "stroke": hex_colour(mix(GRID_LINE, OBSTACLE, 0.5)),
                "stroke-width": "1.5",
            },
        )

    def _goals(self, group: ET.Element) -> None:
        """Each goal as a hollow square: in its robot's colour (with the robot's id in big cells), else neutral."""
        layout = self.layout
        inset = layout.cell * GOAL_INSET
        own = self.colouring == ROBOT
        for robot, colour in zip(self.result.robots, self.colours):
            shown = colour if own else GOAL_NEUTRAL
            left, top, _, _ = layout.cell_box(robot.goal)
            square = ET.SubElement(
                group,
                "rect",
                {
                    "class": "goal",
                    "data-robot": robot.id,
                    "x": _n(left + inset),
                    "y": _n(top + inset),
                    "width": _n(layout.cell - 2 * inset),
                    "height": _n(layout.cell - 2 * inset),
                    "rx": _n(layout.cell * 0.1),
                    "fill": hex_colour(mix(shown, BACKGROUND, 0.12)),
                    "stroke": hex_colour(shown),
                    "stroke-width": _n(max(1.0, layout.cell * GOAL_WIDTH)),
                },
            )
            ET.SubElement(square, "title").text = f"goal of robot {robot.id}: {robot.goal}"
            if own and layout.cell >= GOAL_LABEL_CELL:
                place = goal_label_place(layout, robot.goal)
                label = ET.SubElement(
                    group,
                    "text",
                    {
                        "class": "goal-label",
                        "x": _n(place[0]),
                        "y": _n(place[1]),
                        "font-size": _n(layout.cell * 0.17),
                        "font-weight": "bold",
                        "fill": hex_colour(darker(colour, 0.25)),
                    },
                )
                label.text = robot_label(robot.id)

    def _collision_windows(self) -> list[tuple[tuple[int, int], list[tuple[float, str]]]]:
        """Each collision cell with its opacity samples: flash at the tick, then faint."""
        marks = []
        for collision in self.result.collisions:
            tick = float(collision.tick)
            samples = [(0.0, "0"), (max(0.0, tick - 0.75), "0"), (tick, "1"), (tick + 0.75, "0.3")]
            for cell in collision.cells:
                marks.append((cell, samples))
        return marks

    def _collision_cells(self, group: ET.Element) -> None:
        layout = self.layout
        for cell, samples in self._collision_windows():
            left, top, _, _ = layout.cell_box(cell)
            rect = ET.SubElement(
                group,
                "rect",
                {
                    "class": "collision",
                    "x": str(left),
                    "y": str(top),
                    "width": str(layout.cell),
                    "height": str(layout.cell),
                    "fill": hex_colour(COLLISION),
                    "fill-opacity": "0.7",
                    "opacity": "0",
                },
            )
            self._animate(rect, "opacity", samples)

    def _collision_rings(self, group: ET.Element) -> None:
        layout = self.layout
        width = max(1.0, layout.cell * 0.1)
        for cell, samples in self._collision_windows():
            left, top, _, _ = layout.cell_box(cell)
            rect = ET.SubElement(
                group,
                "rect",
                {
                    "x": _n(left + width / 2),
                    "y": _n(top + width / 2),
                    "width": _n(layout.cell - width),
                    "height": _n(layout.cell - width),
                    "stroke": hex_colour(COLLISION),
                    "stroke-width": _n(width),
                    "opacity": "0",
                },
            )
            self._animate(rect, "opacity", samples)

    def _trails(self, group: ET.Element) -> None:
        layout = self.layout
        width = layout.trail_width
        keep = layout.trail_ticks
        for index, robot in enumerate(self.result.robots):
            points: list[tuple[float, float]] = []
            last = None
            for tick in range(self.ticks + 1):
                cell = cell_at(robot, tick)
                if cell == last:
                    continue
                points.append(layout.centre(cell))
                last = cell
            if len(points) < 2:
                continue
            total = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
            window = total if keep is None else min(total, keep * layout.cell)
            gap = total + window + layout.cell
            samples = [(tick_time, _n(window - travelled)) for tick_time, travelled in self._distances(index)]
            polyline = ET.SubElement(
                group,
                "polyline",
                {
                    "class": "trail",
                    "data-robot": robot.id,
                    "points": " ".join(f"{_n(x)},{_n(y)}" for x, y in points),
                    "stroke-opacity": "0.5" if keep is None else "0.6" if self.colouring == ROBOT else "0.35",
                    "stroke-width": _n(width),
                    "stroke-dasharray": f"{_n(window)} {_n(gap)}",
                    "stroke-dashoffset": _n(window),
                },
            )
            self._paint(polyline, "stroke", index)
            self._animate(polyline, "stroke-dashoffset", samples)

    def _distances(self, index: int) -> list[tuple[float, float]]:
        """``(tick time, pixels travelled)`` at each change of pace of robot ``index``."""
        frames = simplify(self.tracks[index], ("x", "y"))
        travelled = 0.0
        samples = [(frames[0].t, 0.0)]
        for before, after in itertools.pairwise(frames):
            travelled += math.dist(self.layout.point(before.x, before.y), self.layout.point(after.x, after.y))
            samples.append((after.t, travelled))
        return samples

    def _robots(self, group: ET.Element) -> None:
        layout = self.layout
        radius = layout.cell * ROBOT_RADIUS
        nose_outside = layout.cell >= 18
        shape = HEADING_MARKER if nose_outside else _SMALL_MARKER
        nose = " ".join(f"{_n(x * layout.cell)},{_n(y * layout.cell)}" for x, y in shape)
        own = self.colouring == ROBOT
        for index, robot in enumerate(self.result.robots):
            colour = self.colours[index]
            edge = darker(colour, 0.4) if own else ROBOT_EDGE
            frames = self.tracks[index]
            x0, y0 = layout.point(frames[0].x, frames[0].y)
            body = ET.SubElement(
                group,
                "g",
                {
                    "class": "robot",
                    "id": f"robot-{index}",
                    "data-robot": robot.id,
                    "transform": f"translate({_n(x0)},{_n(y0)})",
                },
            )
            ET.SubElement(body, "title").text = f"robot {robot.id}: start {robot.start}, goal {robot.goal}"
            moves = simplify(frames, ("x", "y"))
            self._animate(
                body,
                "transform",
                [(frame.t, "{},{}".format(*map(_n, layout.point(frame.x, frame.y)))) for frame in moves],
                transform="translate",
            )
            disc = {"r": _n(radius)}
            if nose_outside:  # the nose peeks out from under the disc
                disc.update({"stroke": hex_colour(edge), "stroke-width": _n(max(1.0, layout.cell * 0.045))})
                heading = ET.SubElement(body, "g", {"class": "heading", "transform": f"rotate({_n(frames[0].angle)})"})
                circle = ET.SubElement(body, "circle", disc)
            else:  # small cells: the marker is drawn over the disc
                circle = ET.SubElement(body, "circle", disc)
                heading = ET.SubElement(body, "g", {"class": "heading", "transform": f"rotate({_n(frames[0].angle)})"})
            self._paint(circle, "fill", index)
            turns = simplify(frames, ("angle",))
            self._animate(heading, "transform", [(frame.t, _n(frame.angle)) for frame in turns], transform="rotate")
            ET.SubElement(heading, "polygon", {"points": nose, "fill": hex_colour(edge)})
            if layout.show_labels:
                label = ET.SubElement(
                    body,
                    "text",
                    {
                        "text-anchor": "middle",
                        "dy": "0.35em",
                        "font-size": _n(max(6.0, label_size(robot_label(robot.id), layout.cell))),
                        "font-weight": "bold",
                    },
                )
                self._paint(label, "fill", index, text_colour_on)
                label.text = robot_label(robot.id)

    def _messages(self, group: ET.Element) -> None:
        """One ``<g class="message">`` per arrow, visible during its tick only."""
        layout = self.layout
        width = message_width(layout)
        labelled = layout.cell >= MESSAGE_LABEL_CELL
        robots = self.result.robots
        for arrow in message_arrows(self.result, layout):
            colour = hex_colour(self.colours[arrow.sender])
            element = ET.SubElement(
                group,
                "g",
                {
                    "class": "message",
                    "data-tick": str(arrow.tick),
                    "data-from": robots[arrow.sender].id,
                    "data-to": robots[arrow.recipient].id,
                    "data-kinds": arrow.label,
                    "opacity": "1" if arrow.tick == 1 else "0",
                },
            )
            base, tip = arrow_shape(arrow, layout.cell)
            ET.SubElement(
                element,
                "line",
                {
                    "x1": _n(arrow.start[0]),
                    "y1": _n(arrow.start[1]),
                    "x2": _n(base[0]),
                    "y2": _n(base[1]),
                    "stroke": colour,
                    "stroke-width": _n(width),
                },
            )
            ET.SubElement(
                element, "polygon", {"points": " ".join(f"{_n(x)},{_n(y)}" for x, y in tip), "fill": colour}
            )
            if labelled:
                (label_x, label_y), side = message_label_place(arrow, layout.cell)
                label = ET.SubElement(
                    element,
                    "text",
                    {
                        "x": _n(label_x),
                        "y": _n(label_y),
                        "dy": "0.35em",
                        "text-anchor": side,
                        "font-size": _n(layout.cell * 0.12),
                        "fill": colour,
                        "stroke": hex_colour(BACKGROUND),
                        "stroke-width": "2",
                        "paint-order": "stroke",
                    },
                )
                label.text = arrow.label
            samples = [(0.0, "0"), (arrow.tick - 1.0, "1"), (float(arrow.tick), "0")]
            self._animate(element, "opacity", samples, discrete=True)

    def _caption(self, group: ET.Element) -> None:
        """Two lines: the title (squeezed, never cut, when too long), then the run's size, colouring and clock."""
        layout = self.layout
        size = layout.font_size
        small = round(size * 0.82)
        first, second = layout.header * 0.3, layout.header * 0.68
        pad = 12
        ET.SubElement(
            group, "rect", {"width": str(layout.width), "height": str(layout.header), "fill": hex_colour(HEADER)}
        )
        title = ET.SubElement(
            group,
            "text",
            {
                "class": "title",
                "x": str(pad),
                "y": _n(first),
                "font-size": str(size),
                "font-weight": "bold",
                "dy": "0.35em",
                "fill": hex_colour(HEADER_TEXT),
            },
        )
        title.text = run_caption(self.result)
        title_room = layout.width - 2 * pad
        if text_width(title.text, size, bold=True) > title_room:  # squeezed to fit, every character kept
            title.set("textLength", _n(title_room))
            title.set("lengthAdjust", "spacingAndGlyphs")
        verdict, good = run_verdict(self.result)
        subtitle = ET.SubElement(
            group,
            "text",
            {"x": str(pad), "y": _n(second), "font-size": str(small), "dy": "0.35em", "fill": hex_colour(HEADER_DIM)},
        )
        subtitle.text = run_subtitle(self.result, colouring_caption(self.colouring), self.speed)
        longest = f"{clock_text(self.result, self.ticks)}  ·  {verdict}"
        room = layout.width - 3.0 * pad - text_width(longest, small)
        if text_width(subtitle.text, small) > room:
            subtitle.set("textLength", _n(max(room, 10)))
            subtitle.set("lengthAdjust", "spacingAndGlyphs")
        ticks = ET.SubElement(group, "g", {"id": "ticks", "font-size": str(small), "text-anchor": "end"})
        for tick in range(self.ticks + 1):
            final = tick == self.ticks
            text = clock_text(self.result, tick) + (f"  ·  {verdict}" if final else "")
            colour = (SUCCESS if good else BAD_NEWS) if final else HEADER_TEXT
            label = ET.SubElement(
                ticks,
                "text",
                {
                    "class": "tick",
                    "x": str(layout.width - pad),
                    "y": _n(second),
                    "dy": "0.35em",
                    "fill": hex_colour(colour),
                    "opacity": "1" if tick == 0 else "0",
                },
            )
            label.text = text
            if self.ticks == 0:
                continue
            samples = [(0.0, "0"), (float(tick), "1")] if tick else [(0.0, "1")]
            if not final:
                samples.append((tick + 1.0, "0"))
            self._animate(label, "opacity", samples, discrete=True)
        bar = 3
        ET.SubElement(
            group,
            "rect",
            {
                "y": str(layout.header - bar),
                "width": str(layout.width),
                "height": str(bar),
                "fill": hex_colour(mix(HEADER_DIM, HEADER, 0.35)),
            },
        )
        progress = ET.SubElement(
            group,
            "rect",
            {
                "y": str(layout.header - bar),
                "width": "0" if self.ticks else str(layout.width),
                "height": str(bar),
                "fill": hex_colour(mix(PALETTE[0], HEADER_TEXT, 0.85)),
            },
        )
        if self.ticks:
            self._animate(progress, "width", [(0.0, "0"), (float(self.ticks), str(layout.width))])
            end = hex_colour(mix(SUCCESS if good else BAD_NEWS, HEADER_TEXT, 0.85))
            self._animate(
                progress,
                "fill",
                [(0.0, hex_colour(mix(PALETTE[0], HEADER_TEXT, 0.85))), (float(self.ticks), end)],
                discrete=True,
            )


def _points(points: Sequence[tuple[float, float]]) -> str:
    """SVG ``points`` of a polygon."""
    return " ".join(f"{_n(x)},{_n(y)}" for x, y in points)


def _n_key(key: float) -> str:
    """A keyTime with up to five decimals.

    >>> _n_key(0.0), _n_key(1.0), _n_key(0.333333)
    ('0', '1', '0.33333')
    """
    text = f"{key:.5f}".rstrip("0").rstrip(".")
    return text or "0"
