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
>>> root.tag, root.get("width"), root.get("height")
('{http://www.w3.org/2000/svg}svg', '300', '220')
"""

from __future__ import annotations

import itertools
import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

from mrmp.core.grid import Grid
from mrmp.core.result import RunResult
from mrmp.viz._atomic import replacing
from mrmp.viz.layout import (
    BACKGROUND,
    COLLISION,
    COST_TEXT,
    FONT_FAMILY,
    GOAL_INSET,
    GOAL_WIDTH,
    GRID_LINE,
    HEADER,
    HEADER_DIM,
    HEADER_TEXT,
    HEADING_MARKER,
    MESSAGE_LABEL_CELL,
    OBSTACLE,
    OBSTACLE_EDGE,
    PALETTE,
    ROBOT_RADIUS,
    SUCCESS,
    Keyframe,
    arrow_shape,
    cell_at,
    cost_tint,
    darker,
    hex_colour,
    label_size,
    make_layout,
    message_arrows,
    message_label_place,
    message_width,
    mix,
    robot_colours,
    robot_label,
    run_caption,
    run_ticks,
    run_verdict,
    shorten,
    simplify,
    text_colour_on,
    track,
)

SVG_NAMESPACE = "http://www.w3.org/2000/svg"
_SMALL_MARKER: tuple[tuple[float, float], ...] = ((0.0, -0.46), (-0.2, -0.04), (0.2, -0.04))
_BAD_NEWS = (255, 128, 128)


def write_svg(
    grid: Grid,
    result: RunResult,
    path: str | os.PathLike[str],
    *,
    seconds_per_tick: float = 0.4,
    hold_s: float = 1.5,
    show_messages: bool = False,
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
        Playing time of one tick.
    hold_s:
        How long the final state stays on screen before the loop restarts.
    show_messages:
        Draw each tick's messages as arrows from sender to recipient (runs
        with a message log).

    Returns
    -------
    Path
        The path written (atomically: a temporary file in the same folder,
        then renamed).

    Raises
    ------
    ValueError
        If ``seconds_per_tick`` is not positive or ``hold_s`` is negative.
    """
    root = _svg_root(grid, result, seconds_per_tick, hold_s, show_messages)
    target = Path(path)
    with replacing(target) as temporary:
        ET.ElementTree(root).write(temporary, encoding="utf-8", xml_declaration=True)
    return target


def svg_text(
    grid: Grid, result: RunResult, *, seconds_per_tick: float = 0.4, hold_s: float = 1.5, show_messages: bool = False
) -> str:
    """The animated SVG of :func:`write_svg` as text, to embed in HTML (no XML declaration).

    >>> from mrmp.core import Grid, RobotSpec, Scenario
    >>> from mrmp.sim.simulator import simulate
    >>> grid = Grid(1, 3)
    >>> text = svg_text(grid, simulate(Scenario(grid, (RobotSpec("A", (0, 0), (0, 2)),))))
    >>> text.startswith("<svg") and text.endswith("</svg>")
    True
    """
    root = _svg_root(grid, result, seconds_per_tick, hold_s, show_messages)
    return ET.tostring(root, encoding="unicode")


def _svg_root(grid: Grid, result: RunResult, seconds_per_tick: float, hold_s: float, show_messages: bool) -> ET.Element:
    """The animation's ``<svg>`` element, indented; checks the timing arguments."""
    if not seconds_per_tick > 0:
        raise ValueError(f"seconds_per_tick must be positive, got {seconds_per_tick}")
    if not hold_s >= 0:
        raise ValueError(f"hold_s must not be negative, got {hold_s}")
    root = _SvgRun(grid, result, seconds_per_tick, hold_s, show_messages).build()
    ET.indent(root, space=" ")
    return root


def _n(value: float) -> str:
    """A compact number for SVG text: at most two decimals, no trailing zeros.

    >>> _n(3.0), _n(2.345), _n(-0.001)
    ('3', '2.35', '0')
    """
    text = f"{value:.2f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


class _SvgRun:
    """Builds the SVG element tree of one run."""

    def __init__(
        self, grid: Grid, result: RunResult, seconds_per_tick: float, hold_s: float, show_messages: bool = False
    ) -> None:
        self.show_messages = show_messages
        self.grid = grid
        self.result = result
        self.layout = make_layout(grid, len(result.robots))
        self.ticks = run_ticks(result)
        self.spt = seconds_per_tick
        self.duration = max(self.ticks * seconds_per_tick + hold_s, 0.1)
        self.dur = f"{self.duration:.3f}s"
        self.colours = robot_colours(len(result.robots))
        self.tracks: list[list[Keyframe]] = [track(robot, self.ticks) for robot in result.robots]

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
                "width": str(layout.width),
                "height": str(layout.height),
                "viewBox": f"0 0 {layout.width} {layout.height}",
                "font-family": FONT_FAMILY,
            },
        )
        ET.SubElement(
            root, "title"
        ).text = f"{run_caption(self.result)}: {self.ticks} ticks, {len(self.result.robots)} robots"
        ET.SubElement(root, "rect", {"width": "100%", "height": "100%", "fill": hex_colour(BACKGROUND)})
        self._grid(ET.SubElement(root, "g", {"id": "grid"}))
        self._goals(ET.SubElement(root, "g", {"id": "goals"}))
        collisions = ET.SubElement(root, "g", {"id": "collisions"})
        self._collision_cells(collisions)
        self._trails(
            ET.SubElement(
                root, "g", {"id": "trails", "fill": "none", "stroke-linecap": "round", "stroke-linejoin": "round"}
            )
        )
        self._robots(ET.SubElement(root, "g", {"id": "robots"}))
        if self.show_messages:
            self._messages(ET.SubElement(root, "g", {"id": "messages"}))
        self._collision_rings(ET.SubElement(root, "g", {"id": "collision-rings", "fill": "none"}))
        self._caption(ET.SubElement(root, "g", {"id": "caption"}))
        return root

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
        layout = self.layout
        inset = layout.cell * GOAL_INSET
        for robot, colour in zip(self.result.robots, self.colours):
            left, top, _, _ = layout.cell_box(robot.goal)
            ET.SubElement(
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
                    "fill": hex_colour(mix(colour, BACKGROUND, 0.12)),
                    "stroke": hex_colour(colour),
                    "stroke-width": _n(max(1.0, layout.cell * GOAL_WIDTH)),
                },
            )

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
                    "stroke": hex_colour(self.colours[index]),
                    "stroke-opacity": "0.5" if keep is None else "0.6",
                    "stroke-width": _n(width),
                    "stroke-dasharray": f"{_n(window)} {_n(gap)}",
                    "stroke-dashoffset": _n(window),
                },
            )
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
        for index, robot in enumerate(self.result.robots):
            colour = self.colours[index]
            edge = darker(colour, 0.4)
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
            ET.SubElement(body, "title").text = f"robot {robot.id}: {robot.start} to {robot.goal}"
            moves = simplify(frames, ("x", "y"))
            self._animate(
                body,
                "transform",
                [(frame.t, "{},{}".format(*map(_n, layout.point(frame.x, frame.y)))) for frame in moves],
                transform="translate",
            )
            disc = {"r": _n(radius), "fill": hex_colour(colour)}
            if nose_outside:  # the nose peeks out from under the disc
                disc.update({"stroke": hex_colour(edge), "stroke-width": _n(max(1.0, layout.cell * 0.045))})
                heading = ET.SubElement(body, "g", {"class": "heading", "transform": f"rotate({_n(frames[0].angle)})"})
                ET.SubElement(body, "circle", disc)
            else:  # small cells: the marker is drawn over the disc
                ET.SubElement(body, "circle", disc)
                heading = ET.SubElement(body, "g", {"class": "heading", "transform": f"rotate({_n(frames[0].angle)})"})
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
                        "fill": hex_colour(text_colour_on(colour)),
                    },
                )
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
        layout = self.layout
        size = layout.font_size
        middle = layout.header / 2 - 1
        pad = 12
        ET.SubElement(
            group, "rect", {"width": str(layout.width), "height": str(layout.header), "fill": hex_colour(HEADER)}
        )
        title = ET.SubElement(
            group,
            "text",
            {
                "x": str(pad),
                "y": _n(middle),
                "font-size": str(size),
                "font-weight": "bold",
                "dy": "0.35em",
                "fill": hex_colour(HEADER_TEXT),
            },
        )
        verdict, good = run_verdict(self.result)
        longest = f"tick {self.ticks} / {self.ticks}  ·  {verdict}"  # the widest tick counter
        room = layout.width - 3 * pad - 0.55 * size * len(longest)
        title.text = shorten(run_caption(self.result), room, size, bold=True)
        ticks = ET.SubElement(group, "g", {"id": "ticks", "font-size": str(size), "text-anchor": "end"})
        for tick in range(self.ticks + 1):
            final = tick == self.ticks
            text = f"tick {tick} / {self.ticks}" + (f"  ·  {verdict}" if final else "")
            colour = (SUCCESS if good else _BAD_NEWS) if final else HEADER_TEXT
            label = ET.SubElement(
                ticks,
                "text",
                {
                    "class": "tick",
                    "x": str(layout.width - pad),
                    "y": _n(middle),
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
            end = hex_colour(mix(SUCCESS if good else _BAD_NEWS, HEADER_TEXT, 0.85))
            self._animate(
                progress,
                "fill",
                [(0.0, hex_colour(mix(PALETTE[0], HEADER_TEXT, 0.85))), (float(self.ticks), end)],
                discrete=True,
            )


def _n_key(key: float) -> str:
    """A keyTime with up to five decimals.

    >>> _n_key(0.0), _n_key(1.0), _n_key(0.333333)
    ('0', '1', '0.33333')
    """
    text = f"{key:.5f}".rstrip("0").rstrip(".")
    return text or "0"
