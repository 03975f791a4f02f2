"""Geometry, colours and motion shared by the renderers."""

from __future__ import annotations

import pytest

from mrmp.core import Grid, Heading, RobotResult
from mrmp.viz.layout import (
    PALETTE,
    Keyframe,
    make_layout,
    pose_at,
    robot_colours,
    simplify,
    text_colour_on,
    track,
)

N, E, S, W = Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST


@pytest.mark.parametrize("size, cell", [(5, 72), (8, 72), (32, 22), (64, 11), (500, 2)])
def test_cell_size_shrinks_with_the_grid_and_is_capped(size: int, cell: int) -> None:
    layout = make_layout(Grid(size, size))
    assert layout.cell == cell
    assert layout.grid_width <= max(720, 2 * size)


def test_wide_grid_is_limited_by_its_longer_side() -> None:
    layout = make_layout(Grid(4, 90))
    assert layout.grid_width <= 720
    assert layout.width >= layout.grid_width


def test_north_is_up_and_east_is_right() -> None:
    layout = make_layout(Grid(3, 4))
    north_west = layout.centre((2, 0))
    south_west = layout.centre((0, 0))
    south_east = layout.centre((0, 3))
    assert north_west[1] < south_west[1], "larger x must be drawn higher"
    assert south_east[0] > south_west[0], "larger y must be drawn further right"
    assert north_west == (layout.left + layout.cell / 2, layout.top + layout.cell / 2)
    box = layout.cell_box((0, 3))
    assert (box[2], box[3]) == (layout.left + layout.grid_width, layout.top + layout.grid_height)


def test_scaled_layout_multiplies_every_length() -> None:
    layout = make_layout(Grid(5, 5), robots=3)
    big = layout.scaled(3)
    assert (big.cell, big.width, big.height, big.left, big.top) == (
        3 * layout.cell,
        3 * layout.width,
        3 * layout.height,
        3 * layout.left,
        3 * layout.top,
    )
    assert big.centre((1, 1)) == tuple(3 * value for value in layout.centre((1, 1)))


def test_labels_and_trails_thin_out_for_big_fleets() -> None:
    small = make_layout(Grid(5, 5), robots=2)
    crowded = make_layout(Grid(32, 32), robots=200)
    assert small.show_labels and not crowded.show_labels
    assert small.trail_ticks is None and crowded.trail_ticks is not None
    assert crowded.trail_width < small.trail_width


def test_palette_colours_are_distinct_for_any_fleet() -> None:
    assert robot_colours(len(PALETTE)) == list(PALETTE)
    for count in (1, 11, 200, 1500):
        colours = robot_colours(count)
        assert len(colours) == count
        assert len(set(colours)) == count
        assert all(0 <= channel <= 255 for colour in colours for channel in colour)


def test_text_colour_contrasts() -> None:
    assert text_colour_on((255, 255, 255)) != (255, 255, 255)
    assert text_colour_on((0, 0, 80)) == (255, 255, 255)


def test_track_turns_before_moving_and_only_to_the_right() -> None:
    robot = RobotResult(
        "A",
        (0, 2),
        (4, 2),
        path=[(0, 2), (1, 2), (1, 3), (2, 3), (3, 3), (4, 3), (4, 2)],
        headings=[N, N, E, N, N, N, W],
    )
    frames = track(robot, 6)
    assert frames[0] == Keyframe(0.0, 0.0, 2.0, 0.0)
    assert frames[-1].t == 6.0 and (frames[-1].x, frames[-1].y) == (4.0, 2.0)
    angles = [frame.angle for frame in frames]
    assert angles == sorted(angles), "robots only turn right: angles never decrease"
    assert angles[-1] % 360 == 270.0  # WEST
    # Tick 1 -> 2: turn to EAST in the first half, then move.
    assert pose_at(frames, 1.5) == (1.0, 2.0, 90.0)
    assert pose_at(frames, 1.75) == (1.0, 2.5, 90.0)
    # Tick 2 -> 3: EAST to NORTH is three right turns.
    assert pose_at(frames, 2.5)[2] == 360.0


def test_track_of_a_robot_that_only_turns_takes_the_whole_tick() -> None:
    robot = RobotResult("A", (1, 1), (1, 1), path=[(1, 1), (1, 1)], headings=[N, S])
    frames = track(robot, 1)
    assert pose_at(frames, 0.5) == (1.0, 1.0, 90.0)
    assert pose_at(frames, 1.0)[2] == 180.0


def test_track_copes_with_short_paths_and_missing_headings() -> None:
    robot = RobotResult("A", (0, 0), (0, 2), path=[(0, 0), (0, 1), (0, 2)])
    frames = track(robot, 5)
    assert frames[-1].t == 5.0
    assert pose_at(frames, 4.0)[:2] == (0.0, 2.0)
    assert pose_at(frames, 4.0)[2] % 360 == 90.0  # faces EAST, the way it moved
    empty = RobotResult("B", (3, 3), (3, 3))
    assert pose_at(track(empty, 2), 1.0)[:2] == (3.0, 3.0)


def test_simplify_keeps_ends_and_changes_of_pace() -> None:
    frames = [Keyframe(float(t), float(min(t, 3)), 0.0, 0.0) for t in range(7)]
    kept = simplify(frames)
    assert [frame.t for frame in kept] == [0.0, 3.0, 6.0]
    for t in (0.5, 2.2, 4.0):
        assert pose_at(kept, t) == pose_at(frames, t)
