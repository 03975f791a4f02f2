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
