"""Readable pictures: colourings, legend, axes, lines to goals, scalable SVG, live runs at their real speed."""

from __future__ import annotations

import itertools
import re
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import pytest
from PIL import Image
from pixels import close, share_near
from typer.testing import CliRunner

from mrmp.cli import app
from mrmp.core import Grid, Heading, RobotResult, RunResult
from mrmp.viz import write_gif, write_svg
from mrmp.viz.colouring import HEADING_COLOURS, check_colouring, colour_at, colour_changes, progress_colour
from mrmp.viz.layout import (
    LEGEND_ROBOTS,
    clock_text,
    make_layout,
    pose_at,
    track,
    trim_idle,
)
from mrmp.viz.legend import GOAL_NEUTRAL, axis_labels, compass, legend_items, place_legend
from mrmp.viz.raster import FramePainter, Style

SVG = "{http://www.w3.org/2000/svg}"
ROOT = Path(__file__).resolve().parents[3]
N, E = Heading.NORTH, Heading.EAST


def by_class(root: ET.Element, name: str) -> list[ET.Element]:
    return [element for element in root.iter() if element.get("class") == name]


# -- colourings ----------------------------------------------------------------------------


def test_a_crowd_is_coloured_by_progress_and_a_few_robots_by_robot() -> None:
    assert check_colouring(None, 5) == "robot"
    assert check_colouring(None, 50) == "progress"
    with pytest.raises(ValueError, match="colour_by"):
        check_colouring("rainbow", 5)


def test_progress_goes_from_red_to_blue_as_the_path_is_done() -> None:
    robot = RobotResult("A", (0, 0), (0, 4), path=[(0, 0), (0, 1), (0, 2), (0, 2), (0, 3), (0, 4)])
    changes = colour_changes(robot, 5, "progress", (0, 0, 0))
    assert colour_at(changes, 0) == progress_colour(0.0)
    assert colour_at(changes, 2.5) == progress_colour(0.5), "two of four moves done"
    assert colour_at(changes, 5) == progress_colour(1.0)
    assert progress_colour(0.0) != progress_colour(1.0)


def test_heading_colours_follow_the_robots_turns() -> None:
    robot = RobotResult("A", (0, 0), (1, 1), path=[(0, 0), (0, 1), (1, 1)], headings=[E, E, N])
    changes = colour_changes(robot, 2, "heading", (0, 0, 0))
    assert [colour for _, colour in changes] == [HEADING_COLOURS[E], HEADING_COLOURS[N]]


# -- legend and axes -----------------------------------------------------------------------


def test_axes_number_x_upwards_and_y_rightwards_with_their_names() -> None:
    layout = make_layout(Grid(5, 7), 2)
    labels = {label.text: label for label in axis_labels(layout) if label.text in ("x", "y")}
    numbers = [label for label in axis_labels(layout) if label.text not in ("x", "y")]
    x_numbers = [label for label in numbers if label.anchor == "end"]
    y_numbers = [label for label in numbers if label.anchor == "middle"]
    assert [label.text for label in x_numbers] == ["0", "1", "2", "3", "4"]
    assert x_numbers[0].y > x_numbers[-1].y, "x grows up the picture (north)"
    assert all(label.x < layout.left for label in x_numbers)
    assert [label.text for label in y_numbers] == [str(y) for y in range(7)]
    assert y_numbers[0].x < y_numbers[-1].x, "y grows to the right (east)"
    assert all(label.y > layout.top + layout.grid_height for label in y_numbers)
    assert labels["x"].y < layout.top and labels["y"].x > layout.left + layout.grid_width
    point = compass(layout)
    assert point.north_tip[1] < point.corner[1] and point.east_tip[0] > point.corner[0]
    assert point.corner[1] > layout.legend_top


def test_big_grids_number_their_axes_sparsely() -> None:
    layout = make_layout(Grid(256, 256))
    numbers = [label for label in axis_labels(layout) if label.anchor == "middle"]
    assert 5 <= len(numbers) <= 30
    gaps = {int(b.text) - int(a.text) for a, b in itertools.pairwise(numbers)}
    assert len(gaps) == 1 and gaps.pop() in (10, 20, 25, 50)


def test_the_legend_lists_a_few_robots_with_their_start_and_goal(swap: tuple[Grid, RunResult]) -> None:
    grid, result = swap
    items = legend_items(result, "robot", False, [(1, 2, 3), (4, 5, 6)])
    assert [item.label for item in items[:2]] == ["A: (0, 2) → (4, 2)", "B: (4, 2) → (0, 2)"]
    assert [item.kind for item in items] == ["robot", "robot", "goal", "trail"]
    layout = make_layout(grid, 2)
    for place in place_legend(items, layout):
        assert layout.legend_top < place.y < layout.height
        assert place.x + place.width <= layout.width


def test_a_crowd_legend_explains_the_colours_not_every_robot(crowd) -> None:
    _, result = crowd(LEGEND_ROBOTS + 40, 16, 4)
    kinds = [item.kind for item in legend_items(result, "progress", True, [])]
    assert kinds == ["ramp", "goal", "trail", "goal-line"]
    assert legend_items(result, "robot", False, [(0, 0, 0)])[0].kind == "robot", "one entry says what a robot is"


# -- SVG -------------------------------------------------------------------------------------


def test_the_svg_scales_and_its_long_title_is_squeezed_not_cut(tmp_path: Path) -> None:
    robot = RobotResult("A", (0, 0), (0, 1), path=[(0, 0), (0, 1)])
    name = "a scenario with a very long name indeed, longer than any picture of a tiny grid is wide"
    result = RunResult(name, "thesis", 0, [robot], [], "done", 1, 1, 0.0)
    root = ET.parse(write_svg(Grid(2, 2), result, tmp_path / "long.svg")).getroot()
    assert root.get("width") == "100%" and root.get("height") is None
    layout = make_layout(Grid(2, 2), 1)
    assert root.get("viewBox") == f"0 0 {layout.width} {layout.height}"
    [title] = by_class(root, "title")
    assert title.text == f"{name} · thesis", "every character kept"
    assert float(title.get("textLength", "0")) <= layout.width - 24
    assert title.get("lengthAdjust") == "spacingAndGlyphs"


def test_svg_goals_and_robots_carry_their_ids_as_titles(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    root = ET.parse(write_svg(grid, result, tmp_path / "swap.svg")).getroot()
    goals = by_class(root, "goal")
    assert [goal.findtext(f"{SVG}title") for goal in goals] == ["goal of robot A: (4, 2)", "goal of robot B: (0, 2)"]
    assert [label.text for label in by_class(root, "goal-label")] == ["A", "B"], "big goal squares name their robot"
    robots = by_class(root, "robot")
    assert [group.findtext(f"{SVG}title") for group in robots] == [
        "robot A: start (0, 2), goal (4, 2)",
        "robot B: start (4, 2), goal (0, 2)",
    ]
    legend = root.find(f".//{SVG}g[@id='legend']")
    assert legend is not None
    texts = [text.text for text in legend.iter(f"{SVG}text")]
    assert "A: (0, 2) → (4, 2)" in texts and "N (x)" in texts and "E (y)" in texts
    axes = root.find(f".//{SVG}g[@id='axes']")
    assert axes is not None and {"x ↑", "y →", "0", "4"} <= {text.text for text in axes.iter(f"{SVG}text")}


def test_svg_goal_lines_follow_their_robot_to_its_goal(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    plain = ET.parse(write_svg(grid, result, tmp_path / "plain.svg")).getroot()
    assert not by_class(plain, "goal-line"), "lines to goals only when asked"
    root = ET.parse(write_svg(grid, result, tmp_path / "lines.svg", goal_lines=True)).getroot()
    layout = make_layout(grid, 2, goal_lines=True)
    lines = by_class(root, "goal-line")
    assert [line.get("data-robot") for line in lines] == ["A", "B"]
    for line, robot in zip(lines, result.robots):
        assert (float(line.get("x2", "0")), float(line.get("y2", "0"))) == pytest.approx(layout.centre(robot.goal))
        moving = {animation.get("attributeName"): animation for animation in line.iter(f"{SVG}animate")}
        assert {"x1", "y1"} <= set(moving)
        last_x = float(moving["x1"].get("values", "").split(";")[-1])
        last_y = float(moving["y1"].get("values", "").split(";")[-1])
        assert (last_x, last_y) == pytest.approx(layout.centre(robot.path[-1]))


def test_svg_colour_by_progress_animates_each_robots_fill(crowd, tmp_path: Path) -> None:
    grid, result = crowd(30, 12, 10, seed=4)
    root = ET.parse(write_svg(grid, result, tmp_path / "crowd.svg")).getroot()
    assert root.get("data-colour-by") == "progress"
    for group, robot in zip(by_class(root, "robot"), result.robots):
        circle = group.find(f"{SVG}circle")
        assert circle is not None
        moved = any(a != b for a, b in itertools.pairwise(robot.path))
        start = progress_colour(0.0) if moved or robot.path[0] != robot.goal else progress_colour(1.0)
        assert circle.get("fill") == "#{:02x}{:02x}{:02x}".format(*start)
        fills = [a for a in circle.iter(f"{SVG}animate") if a.get("attributeName") == "fill"]
        if moved:
            assert fills and fills[0].get("calcMode") == "discrete"
            assert fills[0].get("values", "").split(";")[-1] == "#{:02x}{:02x}{:02x}".format(*progress_colour(1.0))
    goals = by_class(root, "goal")
    assert {goal.get("stroke") for goal in goals} == {"#{:02x}{:02x}{:02x}".format(*GOAL_NEUTRAL)}


# -- GIF and live runs -------------------------------------------------------------------------


def live_swap(swap: tuple[Grid, RunResult], lead: int = 20, tail: int = 10) -> tuple[Grid, RunResult]:
    """The swap as a live run samples it: four samples per move, a still lead-in and tail."""
    grid, result = swap
    robots = []
    for robot in result.robots:
        path = [robot.path[0]] * lead + [cell for cell in robot.path for _ in range(4)] + [robot.path[-1]] * tail
        headings = [robot.headings[0]] * lead + [h for h in robot.headings for _ in range(4)] + [robot.headings[-1]] * tail
        robots.append(replace(robot, path=path, headings=headings))
    ticks = len(robots[0].path) - 1
    return grid, replace(result, robots=robots, ticks=ticks, mode="live", tick_seconds=0.05)


def test_a_live_run_is_shown_from_its_first_move_with_a_clock_in_seconds(swap: tuple[Grid, RunResult]) -> None:
    _, live = live_swap(swap)
    trimmed = trim_idle(live)
    first_move = min(
        tick for robot in live.robots for tick in range(1, len(robot.path)) if robot.path[tick] != robot.path[tick - 1]
    )
    assert trimmed.robots[0].path[0] == live.robots[0].path[0]
    assert trimmed.robots[0].path[1:] == live.robots[0].path[first_move : first_move + len(trimmed.robots[0].path) - 1]
    assert trimmed.ticks < live.ticks - 20
    assert clock_text(trimmed, 4) == "0.20 s / " + f"{trimmed.ticks * 0.05:.2f} s"
    assert clock_text(swap[1], 4) == "tick 4 / 6"


def test_a_live_move_sampled_four_times_is_drawn_over_four_ticks(swap: tuple[Grid, RunResult]) -> None:
    _, live = live_swap(swap)
    robot = trim_idle(live).robots[1]  # B: four moves south, one every four samples
    frames = track(robot, len(robot.path) - 1, move_ticks=4)
    assert [pose_at(frames, t)[0] for t in (4.0, 6.0, 8.0, 16.0)] == [3.0, 2.5, 2.0, 0.0], "a steady walk south"
    jumpy = track(robot, len(robot.path) - 1)
    assert [pose_at(jumpy, t)[0] for t in (1.0, 2.0, 4.0)] == [3.0, 3.0, 3.0], "one tick a move, then still"


def test_a_live_gif_plays_at_its_real_speed(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, live = live_swap(swap)
    seconds = trim_idle(live).ticks * 0.05
    with Image.open(write_gif(grid, live, tmp_path / "live.gif")) as gif:
        durations = []
        for index in range(gif.n_frames):
            gif.seek(index)
            durations.append(gif.info["duration"])
    assert sum(durations[:-1]) == pytest.approx(seconds * 1000, rel=0.05), "real time, the last frame held"
    assert 20 <= durations[0] <= 60
    with Image.open(write_gif(grid, live, tmp_path / "slow.gif", speed=0.5)) as gif:
        slow = []
        for index in range(gif.n_frames):
            gif.seek(index)
            slow.append(gif.info["duration"])
    assert sum(slow[:-1]) == pytest.approx(2 * seconds * 1000, rel=0.05), "half speed takes twice as long"
    with pytest.raises(ValueError, match="speed"):
        write_gif(grid, live, tmp_path / "x.gif", speed=0)


def test_gif_goal_lines_and_legend_are_drawn(swap: tuple[Grid, RunResult]) -> None:
    grid, result = swap
    painter = FramePainter(grid, result, style=Style(goal_lines=True))
    plain = FramePainter(grid, result)
    layout = painter.layout
    first, without = painter.frame(0.0), plain.frame(0.0)
    midway = layout.centre((2, 2))  # A starts at (0, 2), its goal is (4, 2): its line crosses (2, 2)
    assert share_near(first, midway, 2, (250, 249, 245), 10) < 0.5, "a line crosses the middle cell"
    assert share_near(without, midway, 2, (250, 249, 245), 10) > 0.9
    legend = [first.getpixel((x, y)) for x in range(0, layout.width, 3) for y in range(layout.legend_top, layout.height, 3)]
    colours = painter.colours
    assert any(close(pixel, colours[0], 12) for pixel in legend) and any(close(pixel, colours[1], 12) for pixel in legend)


# -- the command line ---------------------------------------------------------------------------


def test_goal_lines_flag_of_run_and_animate(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    runner = CliRunner()
    monkeypatch.chdir(ROOT)
    svg = tmp_path / "swap.svg"
    saved = tmp_path / "swap.json"
    done = runner.invoke(app, ["run", "examples/thesis-swap.yaml", "--animate", str(svg), "--goal-lines", "--json", str(saved)])
    assert done.exit_code == 0, done.output
    assert len(re.findall(r'class="goal-line"', svg.read_text())) == 2
    again = tmp_path / "again.svg"
    done = runner.invoke(app, ["animate", str(saved), "--out", str(again), "--goal-lines"])
    assert done.exit_code == 0, done.output
    assert len(re.findall(r'class="goal-line"', again.read_text())) == 2
