"""The animated GIF: frames, size, orientation and what is drawn where."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image
from pixels import Colour, close, share_near

from mrmp.core import Grid, RunResult
from mrmp.viz import write_gif
from mrmp.viz.layout import darker, make_layout, robot_colours
from mrmp.viz.raster import frame_times


def frames_of(path: Path) -> list[Image.Image]:
    with Image.open(path) as gif:
        frames = []
        for index in range(gif.n_frames):
            gif.seek(index)
            frames.append(gif.convert("RGB"))
        return frames


def test_frame_count_size_and_timing(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    path = write_gif(grid, result, tmp_path / "swap.gif", frames_per_tick=4, fps=10)
    layout = make_layout(grid, len(result.robots))
    with Image.open(path) as gif:
        assert gif.format == "GIF"
        assert gif.n_frames == 6 * 4 + 1
        assert gif.size == (layout.width, layout.height)
        assert gif.info.get("loop") == 0
        assert gif.info["duration"] == 100
        gif.seek(gif.n_frames - 1)
        assert gif.info["duration"] >= 1000, "the last frame is held longer"


def test_north_is_up_robots_start_and_end_where_their_paths_say(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    frames = frames_of(write_gif(grid, result, tmp_path / "swap.gif"))
    layout = make_layout(grid, len(result.robots))
    first, last = frames[0], frames[-1]
    for robot, colour in zip(result.robots, robot_colours(2)):
        start, end = layout.centre(robot.path[0]), layout.centre(robot.path[-1])
        assert share_near(first, start, layout.cell * 0.22, colour) > 0.5, f"{robot.id} not at its start"
        assert share_near(last, end, layout.cell * 0.22, colour) > 0.5, f"{robot.id} not at its end"
    # A starts at the bottom (x = 0) and ends at the top (x = 4): north is up.
    blue = robot_colours(1)[0]
    bottom_middle = (layout.left + 2.5 * layout.cell, layout.top + 4.5 * layout.cell)
    top_middle = (layout.left + 2.5 * layout.cell, layout.top + 0.5 * layout.cell)
    assert share_near(first, bottom_middle, layout.cell * 0.22, blue) > 0.5
    assert share_near(last, top_middle, layout.cell * 0.22, blue) > 0.5


def test_heading_marker_points_the_way_the_robot_faces(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    frames = frames_of(write_gif(grid, result, tmp_path / "swap.gif"))
    layout = make_layout(grid, len(result.robots))
    edge = darker(robot_colours(1)[0], 0.4)
    reach = layout.cell * 0.4

    def marker_at(image: Image.Image, cell: tuple[int, int], dx: float, dy: float) -> bool:
        cx, cy = layout.centre(cell)
        return close(image.getpixel((round(cx + dx * reach), round(cy + dy * reach))), edge, 40)

    # Tick 0: A at (0, 2) faces NORTH (up on the picture).
    assert marker_at(frames[0], (0, 2), 0, -1)
    assert not any(marker_at(frames[0], (0, 2), dx, dy) for dx, dy in ((0, 1), (1, 0), (-1, 0)))
    # Last tick: A at (4, 2) faces WEST (left).
    assert marker_at(frames[-1], (4, 2), -1, 0)
    assert not any(marker_at(frames[-1], (4, 2), dx, dy) for dx, dy in ((0, 1), (1, 0), (0, -1)))


def test_obstacles_costs_and_collisions(walled: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = walled
    frames = frames_of(write_gif(grid, result, tmp_path / "walled.gif", frames_per_tick=2))
    layout = make_layout(grid, len(result.robots))
    for cell in grid.blocked_cells():
        assert sum(frames[0].getpixel(tuple(map(round, layout.centre(cell))))) < 250, f"blocked {cell} not dark"
    red, _green, blue = frames[0].getpixel(tuple(map(round, layout.centre((2, 4)))))
    assert red > blue + 40, "a costly cell is tinted amber"
    left, top, _, _ = layout.cell_box((0, 2))
    corner = (left + round(layout.cell * 0.08), top + round(layout.cell * 0.08))

    def is_red(pixel: Colour) -> bool:
        return pixel[0] > 180 and pixel[1] < 110 and pixel[2] < 120

    assert not is_red(frames[0].getpixel(corner))
    assert is_red(frames[2 * 2].getpixel(corner)), "the collision cell flashes at its tick"


def test_frame_cap_reduces_frames_per_tick_then_samples(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    with Image.open(write_gif(grid, result, tmp_path / "one.gif", max_frames=10)) as gif:
        assert gif.n_frames == 7
    with Image.open(write_gif(grid, result, tmp_path / "few.gif", max_frames=4)) as gif:
        assert gif.n_frames == 4


def test_a_gif_over_the_size_limit_is_drawn_again_with_fewer_frames(
    swap: tuple[Grid, RunResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from mrmp.viz import gif

    grid, result = swap
    monkeypatch.setattr(gif, "SIZE_LIMIT", 1)
    target = tmp_path / "swap.gif"
    target.write_bytes(b"previous")
    write_gif(grid, result, target, frames_per_tick=8)  # 6 ticks: 49 frames, then at most 40
    with Image.open(target) as drawn:
        assert drawn.n_frames == 6 * 6 + 1
    assert [path.name for path in tmp_path.iterdir()] == ["swap.gif"]


def test_frame_times() -> None:
    assert frame_times(3, 2, 100) == [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
    assert frame_times(10, 4, 11) == [float(t) for t in range(11)]
    spread = frame_times(100, 4, 20)
    assert len(spread) == 20 and spread[0] == 0.0 and spread[-1] == 100.0
    assert frame_times(0, 4, 50) == [0.0]


@pytest.mark.slow
def test_large_fleet_stays_small_and_quick(crowd, tmp_path: Path) -> None:
    grid, result = crowd(200, 32, 20, seed=1)
    path = write_gif(grid, result, tmp_path / "crowd.gif")
    assert path.stat().st_size < 10_000_000
    with Image.open(path) as gif:
        assert 2 <= gif.n_frames <= 20 * 4 + 1


def test_bad_options_are_refused(swap: tuple[Grid, RunResult], tmp_path: Path) -> None:
    grid, result = swap
    with pytest.raises(ValueError, match="frames_per_tick"):
        write_gif(grid, result, tmp_path / "x.gif", frames_per_tick=0)
    with pytest.raises(ValueError, match="fps"):
        write_gif(grid, result, tmp_path / "x.gif", fps=0)
    with pytest.raises(ValueError, match="max_frames"):
        write_gif(grid, result, tmp_path / "x.gif", max_frames=0)


def test_a_run_without_ticks_is_one_frame(tmp_path: Path) -> None:
    from mrmp.core import RobotResult

    robot = RobotResult("A", (0, 0), (0, 0), path=[(0, 0)])
    result = RunResult("still", "thesis", 0, [robot], [], "done", 0, 0, 0.0)
    with Image.open(write_gif(Grid(3, 3), result, tmp_path / "still.gif")) as gif:
        assert gif.n_frames == 1
