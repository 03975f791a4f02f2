"""The animated SVG: valid XML, one animated group per robot, animations that end where the run ends."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from mrmp.core import Grid, RunResult
from mrmp.viz import write_svg
from mrmp.viz.layout import make_layout

SVG = "{http://www.w3.org/2000/svg}"


def parse(path: Path) -> ET.Element:
    return ET.parse(path).getroot()


def robot_groups(root: ET.Element) -> list[ET.Element]:
    return [group for group in root.iter(f"{SVG}g") if group.get("class") == "robot"]


def value_at(animation: ET.Element, share: float) -> list[float]:
    """Evaluate a linear SMIL animation at ``share`` (0..1) of its duration."""
    keys = [float(key) for key in animation.get("keyTimes", "").split(";")]
    values = [[float(number) for number in value.split(",")] for value in animation.get("values", "").split(";")]
    for index in range(len(keys) - 1):
        if keys[index] <= share <= keys[index + 1]:
            span = keys[index + 1] - keys[index]
            part = (share - keys[index]) / span if span else 1.0
            return [a + (b - a) * part for a, b in zip(values[index], values[index + 1])]
    return values[-1]


def test_svg_parses_with_one_animated_group_per_robot(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    root = parse(write_svg(grid, result, tmp_path / "swap.svg"))
    layout = make_layout(grid, len(result.robots))
    assert root.tag == f"{SVG}svg"
    assert root.get("width") == "100%" and root.get("height") is None, "the picture scales to its container"
    assert root.get("viewBox") == f"0 0 {layout.width} {layout.height}"
    groups = robot_groups(root)
    assert [group.get("data-robot") for group in groups] == ["A", "B"]
    for group in groups:
        kinds = {animation.get("type") for animation in group.iter(f"{SVG}animateTransform")}
        assert kinds == {"translate", "rotate"}
        assert group.find(f"{SVG}circle") is not None
        assert group.find(f".//{SVG}polygon") is not None, "heading marker"


def test_every_animation_is_well_formed_and_loops(walled: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = walled
    root = parse(write_svg(grid, result, tmp_path / "walled.svg", seconds_per_tick=0.5, hold_s=1.0))
    animations = list(root.iter(f"{SVG}animate")) + list(root.iter(f"{SVG}animateTransform"))
    assert animations
    for animation in animations:
        keys = [float(key) for key in animation.get("keyTimes", "").split(";")]
        values = animation.get("values", "").split(";")
        assert len(keys) == len(values) >= 1
        assert keys[0] == 0.0 and keys == sorted(keys) and keys[-1] <= 1.0
        if animation.get("calcMode") != "discrete":
            assert keys[-1] == 1.0
        assert animation.get("dur") == "2.500s"  # 3 ticks x 0.5 s + 1 s held
        assert animation.get("repeatCount") == "indefinite"


def test_robots_move_from_start_to_end(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    root = parse(write_svg(grid, result, tmp_path / "swap.svg"))
    layout = make_layout(grid, len(result.robots))
    for group, robot in zip(robot_groups(root), result.robots):
        move = next(a for a in group.iter(f"{SVG}animateTransform") if a.get("type") == "translate")
        assert value_at(move, 0.0) == pytest.approx(list(layout.centre(robot.path[0])))
        assert value_at(move, 1.0) == pytest.approx(list(layout.centre(robot.path[-1])))
        turn = next(a for a in group.iter(f"{SVG}animateTransform") if a.get("type") == "rotate")
        angles = [float(value) for value in turn.get("values", "").split(";")]
        assert angles == sorted(angles), "robots only turn right"
    # A ends facing WEST, B facing SOUTH (degrees clockwise from north).
    ends = [
        value_at(next(a for a in g.iter(f"{SVG}animateTransform") if a.get("type") == "rotate"), 1.0)[0]
        for g in robot_groups(root)
    ]
    assert [angle % 360 for angle in ends] == [270.0, 180.0]


def test_svg_shows_grid_goals_trails_ticks_and_collisions(walled: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = walled
    root = parse(write_svg(grid, result, tmp_path / "walled.svg"))
    classes = [element.get("class") for element in root.iter()]
    assert classes.count("obstacle") == len(grid.blocked_cells())
    assert classes.count("cost") == 1
    assert classes.count("goal") == len(result.robots)
    assert classes.count("trail") == len(result.robots)
    assert classes.count("tick") == result.ticks + 1
    collisions = [element for element in root.iter() if element.get("class") == "collision"]
    assert len(collisions) == 1 and collisions[0].find(f"{SVG}animate") is not None
    texts = "".join(element.text or "" for element in root.iter(f"{SVG}text"))
    assert "tick 3 / 3" in texts and "1 collision" in texts
    for trail in (element for element in root.iter() if element.get("class") == "trail"):
        animation = trail.find(f"{SVG}animate")
        assert animation is not None and animation.get("attributeName") == "stroke-dashoffset"
        assert value_at(animation, 1.0) == [0.0], "the whole trail is drawn by the end"


def test_special_characters_in_ids_are_escaped(tmp_path: Path) -> None:
    from mrmp.core import RobotResult

    robot = RobotResult('<"R&D">', (0, 0), (0, 1), path=[(0, 0), (0, 1)])
    result = RunResult("a < b & c", "thesis", 0, [robot], [], "done", 1, 1, 0.0)
    root = parse(write_svg(Grid(2, 2), result, tmp_path / "odd.svg"))
    assert robot_groups(root)[0].get("data-robot") == '<"R&D">'


def test_large_fleet_svg(crowd, tmp_path: Path) -> None:
    grid, result = crowd(200, 32, 20, seed=2)
    root = parse(write_svg(grid, result, tmp_path / "crowd.svg"))
    assert len(robot_groups(root)) == 200
    assert not [text for group in robot_groups(root) for text in group.iter(f"{SVG}text")], "no labels in small cells"


def test_bad_options_are_refused(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    with pytest.raises(ValueError, match="seconds_per_tick"):
        write_svg(grid, result, tmp_path / "x.svg", seconds_per_tick=0)
    with pytest.raises(ValueError, match="hold_s"):
        write_svg(grid, result, tmp_path / "x.svg", hold_s=-1)
