"""The legend, the axes and the compass of a picture: what to write where, shared by every renderer.

Everything here is pure geometry and text, in the picture's pixels
(:class:`mrmp.viz.layout.Layout`): the renderers only draw it.

* The **legend** band under the grid lists what the colours and marks mean
  (:func:`legend_items`), laid out in rows of :data:`~mrmp.viz.layout.LEGEND_SLOT`
  pixel slots (:func:`place_legend`).
* The **axes** are the thesis's: ``x`` grows NORTH (up the picture), ``y``
  grows EAST (to the right); the x numbers run up the grid's left side and
  the y numbers along its foot, every :func:`axis_step` cells
  (:func:`axis_labels`).
* The **compass**, at the legend's right, shows the N and E arrows with the
  axis each one is (:func:`compass`).

Examples
--------
>>> from mrmp.core import Grid, RobotResult, RunResult
>>> from mrmp.viz.layout import make_layout, robot_colours
>>> a = RobotResult("A", (0, 2), (4, 2), path=[(0, 2)])
>>> run = RunResult("swap", "thesis", 0, [a], [], "done", 0, 0, 0.0)
>>> [item.label for item in legend_items(run, "robot", False, robot_colours(1))]
['A: (0, 2) → (4, 2)', 'goal: its colour', 'trail: path so far']
>>> layout = make_layout(Grid(5, 5), 1)
>>> [label.text for label in axis_labels(layout)][:6]
['0', '1', '2', '3', '4', 'x']
"""

from __future__ import annotations

from dataclasses import dataclass

from mrmp.core.heading import Heading
from mrmp.core.result import RunResult
from mrmp.viz.colouring import HEADING, HEADING_COLOURS, PROGRESS, progress_colour
from mrmp.viz.layout import (
    COMPASS_WIDTH,
    LEGEND_PAD,
    LEGEND_ROBOTS,
    LEGEND_ROW,
    LEGEND_SLOT,
    RGB,
    Layout,
    shorten,
)

GOAL_NEUTRAL: RGB = (88, 96, 116)
"""Outline of goals when robots are coloured by progress or heading (the colour no longer says whose)."""
TRAIL_NEUTRAL: RGB = (120, 128, 146)
"""Legend swatch of a trail whose colour follows its robot's."""
AXIS_TEXT: RGB = (110, 116, 130)
"""Colour of the axes' numbers and names, and of the legend's text."""
LEGEND_TEXT: RGB = (52, 58, 72)
"""Colour of the legend's text."""


@dataclass(frozen=True)
class LegendItem:
    """One entry of the legend: a swatch of ``kind`` in ``colour`` and its ``label``.

    ``kind`` is ``"robot"`` (a disc), ``"goal"`` (a hollow square),
    ``"trail"`` or ``"goal-line"`` (a line), ``"ramp"`` (the progress colours,
    two slots wide) or ``"heading"`` (a disc with its nose). ``detail`` is a
    longer text for a tooltip; ``angle`` the heading's, in degrees clockwise
    from north.
    """

    kind: str
    label: str
    colour: RGB
    detail: str = ""
    angle: float = 0.0

    @property
    def slots(self) -> int:
        """How many legend slots the entry takes.

        >>> LegendItem("ramp", "share of path done", (0, 0, 0)).slots
        2
        """
        return 2 if self.kind == "ramp" else 1


def legend_items(result: RunResult, colouring: str, goal_lines: bool, colours: list[RGB]) -> list[LegendItem]:
    """The legend of a run: what the robots' colours say, then goals, trails and lines to goals.

    ``colours`` are the robots' own colours. A run of a few robots coloured
    by robot lists each: ``A: (0, 2) → (4, 2)``, its start then its goal.

    >>> from mrmp.core import RunResult
    >>> run = RunResult("crowd", "pibt", 0, [], [], "done", 0, 0, 0.0)
    >>> [item.kind for item in legend_items(run, "progress", True, [])]
    ['ramp', 'goal', 'trail', 'goal-line']
    """
    items: list[LegendItem] = []
    robots = result.robots
    if colouring == PROGRESS:
        items.append(LegendItem("ramp", "share of path done", progress_colour(0.5), "0% red, 50% amber, 100% blue"))
        goal_colour = GOAL_NEUTRAL
        goal_text = "goal"
    elif colouring == HEADING:
        for heading, name in zip(Heading, ("north", "east", "south", "west")):
            items.append(LegendItem("heading", f"facing {name}", HEADING_COLOURS[heading], angle=90.0 * (int(heading) - 1)))
        goal_colour = GOAL_NEUTRAL
        goal_text = "goal"
    else:
        if 0 < len(robots) <= LEGEND_ROBOTS:
            for robot, colour in zip(robots, colours):
                start, goal = _cell_text(robot.start), _cell_text(robot.goal)
                items.append(
                    LegendItem("robot", f"{robot.id}: {start} → {goal}", colour, f"robot {robot.id}: start {start}, goal {goal}")
                )
        else:
            items.append(LegendItem("robot", "robot (hover: id)", colours[0] if colours else GOAL_NEUTRAL))
        goal_colour = colours[0] if colours else GOAL_NEUTRAL
        goal_text = "goal: its colour"
    items.append(LegendItem("goal", goal_text, goal_colour))
    trail_colour = goal_colour if colouring not in (PROGRESS, HEADING) else TRAIL_NEUTRAL
    items.append(LegendItem("trail", "trail: path so far", trail_colour))
    if goal_lines:
        items.append(LegendItem("goal-line", "line to its goal", trail_colour))
    return items


def _cell_text(cell: tuple[int, int]) -> str:
    return f"({cell[0]}, {cell[1]})"


@dataclass(frozen=True)
class LegendPlace:
    """Where a legend entry goes: its swatch is centred at ``(x + row_height / 2, y)``, its text starts at ``text_x``."""

    item: LegendItem
    x: float
    y: float
    width: float
    text_x: float
    text: str


def place_legend(items: list[LegendItem], layout: Layout) -> list[LegendPlace]:
    """Lay the entries out in rows of slots, left to right, from the legend band's top-left corner.

    An entry's text is cut (:func:`~mrmp.viz.layout.shorten`) to its slot;
    its whole text is in :attr:`LegendItem.detail` or its label.

    >>> from mrmp.core import Grid
    >>> from mrmp.viz.layout import make_layout
    >>> layout = make_layout(Grid(5, 5), 2)
    >>> places = place_legend([LegendItem("goal", "goal", (0, 0, 0))] * 3, layout)
    >>> [(round(p.x - places[0].x), round(p.y - places[0].y)) for p in places]
    [(0, 0), (150, 0), (0, 20)]
    """
    scale = layout.small_font / 11
    pad, slot, row = LEGEND_PAD * scale, LEGEND_SLOT * scale, LEGEND_ROW * scale
    columns = max(1, int((layout.width - 2 * pad - COMPASS_WIDTH * scale) // slot))
    places: list[LegendPlace] = []
    column = line = 0
    for item in items:
        if column + item.slots > columns and column > 0:
            column, line = 0, line + 1
        x = pad + column * slot
        y = layout.legend_top + pad + (line + 0.5) * row
        width = slot * min(item.slots, columns)
        swatch = row * (2.4 if item.kind == "ramp" else 1.0)
        text_x = x + swatch + 4 * scale
        room = x + width - text_x - 6 * scale
        places.append(LegendPlace(item, x, y, width, text_x, shorten(item.label, room, layout.small_font)))
        column += item.slots
    return places


@dataclass(frozen=True)
class AxisLabel:
    """A number or a name of an axis: ``text`` at ``(x, y)``, anchored ``"end"``, ``"middle"`` or ``"start"``."""

    text: str
    x: float
    y: float
    anchor: str


def axis_step(cell: float, widest: int, font: float) -> int:
    """Every how many cells an axis is numbered: 1, 2, 5, 10, 20, 50... so numbers do not touch.

    ``widest`` is the number of characters of the largest number.

    >>> axis_step(72, 1, 11), axis_step(11, 2, 11), axis_step(2, 3, 11)
    (1, 2, 20)
    """
    need = max(font * 1.25, font * 0.62 * widest + font * 0.6)
    step, factors = 1, (2, 2.5, 2)  # 1, 2, 5, 10, 20, 50, ...
    index = 0
    while step * cell < need:
        step = round(step * factors[index % 3])
        index += 1
    return step


def axis_labels(layout: Layout) -> list[AxisLabel]:
    """The x numbers up the left side (0 at the bottom), the y numbers along the foot, and each axis's name.

    The x axis's name sits above its numbers, the y axis's at the right of
    its numbers, each with its arrow: ``x ↑`` and ``y →``.
    """
    font = layout.small_font
    labels: list[AxisLabel] = []
    x_step = axis_step(layout.cell, 1, font)  # x numbers are stacked: only their height matters
    right = layout.left - font * 0.45
    for x in range(0, layout.x_size, x_step):
        _, centre_y = layout.point(x, 0)
        labels.append(AxisLabel(str(x), right, centre_y, "end"))
    labels.append(AxisLabel("x", right, layout.top - font * 0.55, "end"))
    y_step = axis_step(layout.cell, len(str(max(layout.y_size - 1, 0))), font)
    below = layout.top + layout.grid_height + font * 0.95
    for y in range(0, layout.y_size, y_step):
        centre_x, _ = layout.point(0, y)
        labels.append(AxisLabel(str(y), centre_x, below, "middle"))
    labels.append(AxisLabel("y", layout.left + layout.grid_width + font * 0.5, below, "start"))
    return labels


@dataclass(frozen=True)
class Compass:
    """The N arrow (up) and the E arrow (right) from one corner, each with its name and axis."""

    corner: tuple[float, float]
    north_tip: tuple[float, float]
    east_tip: tuple[float, float]
    north_text: tuple[float, float]
    east_text: tuple[float, float]
    head: float
    width: float


def compass(layout: Layout) -> Compass:
    """Where the compass goes: at the legend band's right, its arrows as long as a legend row and a half.

    >>> from mrmp.core import Grid
    >>> from mrmp.viz.layout import make_layout
    >>> point = compass(make_layout(Grid(5, 5)))
    >>> point.north_tip[0] == point.corner[0] and point.north_tip[1] < point.corner[1]
    True
    """
    scale = layout.small_font / 11
    length = LEGEND_ROW * 1.5 * scale
    corner_x = layout.width - COMPASS_WIDTH * scale + 8 * scale
    corner_y = layout.legend_top + LEGEND_PAD * scale + LEGEND_ROW * 1.75 * scale
    return Compass(
        corner=(corner_x, corner_y),
        north_tip=(corner_x, corner_y - length),
        east_tip=(corner_x + length, corner_y),
        north_text=(corner_x + 4 * scale, corner_y - length + 3 * scale),
        east_text=(corner_x + length + 3 * scale, corner_y),
        head=5 * scale,
        width=max(1.0, 1.6 * scale),
    )


NORTH_LABEL = "N (x)"
"""Written beside the compass's north arrow: north is where x grows."""
EAST_LABEL = "E (y)"
"""Written beside the compass's east arrow: east is where y grows."""
