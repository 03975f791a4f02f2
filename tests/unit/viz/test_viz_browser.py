"""The SVG animation as a browser plays it: headless Chromium screenshots at two moments.

The SVG is wrapped in a page that pauses its SMIL clock and seeks it
(``pauseAnimations``, ``setCurrentTime``), so each screenshot shows one
moment of the run; the robot's colour must be at the cell its path gives.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from PIL import Image, ImageChops
from pixels import share_near

from mrmp.io import load_scenario
from mrmp.sim.simulator import simulate
from mrmp.viz import write_svg
from mrmp.viz.layout import make_layout, robot_colours

SWAP = Path(__file__).resolve().parents[3] / "examples" / "thesis-swap.yaml"
SECONDS_PER_TICK = 0.4
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
]


def chromium() -> str:
    for name in ("/usr/bin/chromium", "chromium", "chromium-browser"):
        found = shutil.which(name)
        if found:
            return found
    pytest.skip("chromium is not installed (apt-get install chromium): the SVG is not checked in a browser")


def page(svg: str, seconds: float) -> str:
    """A page showing ``svg`` frozen at ``seconds`` into its animation."""
    body = svg.split("?>", 1)[1] if svg.startswith("<?xml") else svg
    return (
        "<!DOCTYPE html><html><head><style>html, body { margin: 0; padding: 0; overflow: hidden; }"
        " svg { display: block; }</style></head><body>"
        + body
        + "<script>const svg = document.querySelector('svg'); svg.pauseAnimations();"
        f" svg.setCurrentTime({seconds});</script></body></html>"
    )


def screenshot(program: str, svg: str, seconds: float, size: tuple[int, int], folder: Path) -> Image.Image:
    name = f"at-{seconds:g}"
    html = folder / f"{name}.html"
    html.write_text(page(svg, seconds), encoding="utf-8")
    shot = folder / f"{name}.png"
    profile = folder / f"profile-{name}"
    profile.mkdir()
    command = [
        program,
        *CHROMIUM_FLAGS,
        f"--user-data-dir={profile}",
        f"--screenshot={shot}",
        f"--window-size={size[0]},{size[1]}",
        html.as_uri(),
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert shot.exists(), f"chromium wrote no screenshot (exit {done.returncode}): {done.stderr[-500:]}"
    return Image.open(shot).convert("RGB")


def test_the_browser_shows_robot_a_where_its_path_says(tmp_path: Path) -> None:
    program = chromium()
    scenario = load_scenario(SWAP)
    result = simulate(scenario)
    svg = write_svg(scenario.grid, result, tmp_path / "swap.svg", seconds_per_tick=SECONDS_PER_TICK).read_text()
    layout = make_layout(scenario.grid, len(result.robots))
    size = (layout.width, layout.height)
    blue = robot_colours(len(result.robots))[0]
    robot = result.robots[0]
    ticks = (0, 3)
    cells = [robot.path[tick] for tick in ticks]
    assert cells[0] != cells[1], "the test needs robot A to have moved"
    shots = [screenshot(program, svg, tick * SECONDS_PER_TICK, size, tmp_path) for tick in ticks]
    for shot, cell, other in zip(shots, cells, reversed(cells)):
        assert shot.size == size
        assert share_near(shot, layout.centre(cell), layout.cell * 0.25, blue, 30) > 0.5, f"robot A is not drawn at {cell}"
        assert share_near(shot, layout.centre(other), layout.cell * 0.25, blue, 30) < 0.1, f"robot A is still drawn at {other}"
    difference = ImageChops.difference(shots[0], shots[1]).getbbox()
    assert difference is not None, "the two moments look the same"


EMPTY_MAP = Path(__file__).resolve().parents[3] / "maps" / "empty-32-32.map"
EMPTY_SCEN = Path(__file__).resolve().parents[3] / "maps" / "empty-32-32-random-1.scen"


def crowd_of_fifty():
    """Fifty robots crossing an empty 32x32 map by PIBT: the MovingAI instance's first fifty agents."""
    from dataclasses import replace

    from mrmp.io import load_movingai_scenario

    scenario = load_movingai_scenario(EMPTY_MAP, EMPTY_SCEN, 50)
    scenario = replace(scenario, policy=replace(scenario.policy, name="pibt"))
    return scenario, simulate(scenario)


def test_a_crowd_of_fifty_in_a_browser_has_a_legend_axes_goals_and_ids(tmp_path: Path) -> None:
    import xml.etree.ElementTree as ET

    from pixels import close

    from mrmp.viz.colouring import progress_colour
    from mrmp.viz.layout import cell_at
    from mrmp.viz.legend import AXIS_TEXT, GOAL_NEUTRAL, LEGEND_TEXT, compass

    program = chromium()
    scenario, result = crowd_of_fifty()
    assert len(result.robots) == 50 and result.ticks > 10
    svg = write_svg(scenario.grid, result, tmp_path / "crowd.svg", seconds_per_tick=SECONDS_PER_TICK, goal_lines=True)
    text = svg.read_text()
    layout = make_layout(scenario.grid, 50, colouring="progress", goal_lines=True)
    tick = 10
    shot = screenshot(program, text, tick * SECONDS_PER_TICK, (layout.width, layout.height), tmp_path)
    assert shot.size == (layout.width, layout.height)

    def pixels(box: tuple[float, float, float, float]) -> list[tuple[int, int, int]]:
        left, top, right, bottom = (int(value) for value in box)
        return [shot.getpixel((x, y)) for x in range(left, right) for y in range(top, bottom)]

    def has(box: tuple[float, float, float, float], colour: tuple[int, int, int], tolerance: int = 18) -> int:
        return sum(close(pixel, colour, tolerance) for pixel in pixels(box))

    legend = (0, layout.legend_top, layout.width, layout.height)
    assert has(legend, progress_colour(0.0), 8) > 30 and has(legend, progress_colour(1.0), 8) > 30, "the progress ramp"
    point = compass(layout)
    corner = (point.corner[0] - 3, point.north_tip[1], point.east_tip[0] + 1, point.corner[1] + 3)
    assert has(corner, LEGEND_TEXT, 40) > 20, "the compass's N and E arrows"
    x_axis = (0, layout.top, layout.left - 1, layout.top + layout.grid_height)
    y_axis = (layout.left, layout.top + layout.grid_height + 2, layout.left + layout.grid_width, layout.legend_top)
    assert has(x_axis, AXIS_TEXT, 40) > 40 and has(y_axis, AXIS_TEXT, 40) > 40, "the axes' numbers"

    occupied = {cell_at(robot, tick) for robot in result.robots}
    rings = []
    for robot in result.robots:
        if robot.goal in occupied:
            continue
        left, top, right, bottom = layout.cell_box(robot.goal)
        ring = [pixel for pixel in pixels((left, top, right, bottom)) if close(pixel, GOAL_NEUTRAL, 40)]
        rings.append(len(ring) / layout.cell**2)
    assert len(rings) >= 10 and sorted(rings)[len(rings) // 2] > 0.15, "free goals show their square"
    discs = [share_near(shot, layout.centre(cell_at(robot, tick)), layout.cell * 0.2, GOAL_NEUTRAL, 30) for robot in result.robots]
    assert max(discs) < 0.3, "robots are not drawn in the goals' colour"

    root = ET.fromstring(text.split("?>", 1)[1])
    svg_ns = "{http://www.w3.org/2000/svg}"
    titles = [group.findtext(f"{svg_ns}title") or "" for group in root.iter(f"{svg_ns}g") if group.get("class") == "robot"]
    assert [title.split(":")[0] for title in titles] == [f"robot {robot.id}" for robot in result.robots]
    goal_titles = [rect.findtext(f"{svg_ns}title") for rect in root.iter(f"{svg_ns}rect") if rect.get("class") == "goal"]
    assert goal_titles == [f"goal of robot {robot.id}: {robot.goal}" for robot in result.robots]


def test_the_svg_scales_to_the_window(tmp_path: Path) -> None:
    program = chromium()
    scenario = load_scenario(SWAP)
    result = simulate(scenario)
    svg = write_svg(scenario.grid, result, tmp_path / "swap.svg", seconds_per_tick=SECONDS_PER_TICK).read_text()
    layout = make_layout(scenario.grid, len(result.robots))
    double = (2 * layout.width, 2 * layout.height)
    shot = screenshot(program, svg, 0.0, double, tmp_path)
    blue = robot_colours(len(result.robots))[0]
    x, y = layout.centre(result.robots[0].path[0])
    assert share_near(shot, (2 * x, 2 * y), layout.cell * 0.5, blue, 30) > 0.5, "robot A where it is, twice as big"
