"""The thesis's line-counting body on a differential-drive robot, as ``--drive ros2`` drives it, on a virtual clock.

A driver that integrates the wheel speeds (:class:`~mrmp.live.diff_drive.DiffDrive`)
and sees lines from the odometry, exactly as :class:`~mrmp.live.ros2_driver.Ros2Driver`
does over DDS, but in process: the body's geometry (:func:`~mrmp.live.diff_drive.body_geometry`)
must bring the robot to the middle of every cell of a path, facing the way it moved.
"""

from __future__ import annotations

import math

import pytest

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.io.ros_messages import cell_position, heading_yaw
from mrmp.live.body import LineCountingBody, OccupancyRecorder, OdometryLineBody
from mrmp.live.diff_drive import DiffDrive, body_geometry, odometry_in_map, on_grid_line, wheel_twist, yaw_heading

STEP = 0.0005  # seconds of virtual time per control step


class IntegratingDriver:
    """Wheel speeds in, lines out: the robot's motion integrated on a virtual clock."""

    def __init__(self, start: Cell, heading: Heading, wheel_base: float, line_width: float = 0.1) -> None:
        self.robot = DiffDrive()
        self.start, self.heading, self.wheel_base, self.line_width = start, heading, wheel_base, line_width
        self.twist = (0.0, 0.0)

    def set_speeds(self, left: float, right: float) -> None:
        self.twist = wheel_twist(left, right, self.wheel_base)

    def stop(self) -> None:
        self.twist = (0.0, 0.0)

    def line_detected(self) -> bool:
        return on_grid_line(*self.pose(), 1.0, self.line_width)

    def pose(self) -> tuple[float, float, float]:
        return odometry_in_map(self.start, self.heading, self.robot.x, self.robot.y, self.robot.yaw)

    map_pose = pose


def drive(
    path: list[Cell],
    heading: Heading,
    cell_seconds: float,
    turn_seconds: float,
    kind: type = LineCountingBody,
    control_every: float = STEP,
    tolerance: float = 0.05,
) -> tuple[IntegratingDriver, list]:
    """Drive ``path``; the body's control loop runs every ``control_every`` seconds (the robot moves in between).

    After every move the robot must be within ``tolerance`` metres of the cell's middle (a twentieth of a cell).
    """
    speed, wheel_base, settle = body_geometry(cell_seconds, turn_seconds, 1.0, 0.1)
    driver = IntegratingDriver(path[0], heading, wheel_base)
    recorder = OccupancyRecorder()
    body = kind(driver, path[0], heading, speed, turn_seconds, settle, recorder)
    now = 0.0
    for target in path[1:]:
        body.start_move(target, now)
        while True:
            driver.robot.advance(*driver.twist, control_every)
            now += control_every
            if body.poll(now):
                break
            assert now < 100 * len(path), "the body never reached its cell"
        east, north, yaw = driver.pose()
        assert (east, north) == pytest.approx(cell_position(target)[:2], abs=tolerance)
        assert yaw_heading(yaw) == body.heading
    return driver, recorder.events


@pytest.mark.parametrize("kind", [LineCountingBody, OdometryLineBody])
@pytest.mark.parametrize(("cell_seconds", "turn_seconds"), [(2.0, 1.0), (0.5, 0.25), (1.0, 0.1)])
def test_the_body_reaches_the_middle_of_every_cell_of_the_thesis_path(cell_seconds: float, turn_seconds: float, kind: type) -> None:
    path = [(x, 0) for x in range(5)] + [(4, y) for y in range(1, 5)]  # x first, one right turn, then y
    driver, events = drive(path, Heading.NORTH, cell_seconds, turn_seconds, kind)
    assert [cell for event, cell, _ in events if event == "enter"] == path[1:]
    assert math.isclose(driver.pose()[2], heading_yaw(Heading.EAST), abs_tol=0.02)


@pytest.mark.parametrize("kind", [LineCountingBody, OdometryLineBody])
def test_a_left_turn_is_three_right_turns_and_still_lands_in_the_cell(kind: type) -> None:
    path = [(0, 1), (1, 1), (1, 0)]  # north, then west: from NORTH three right turns
    driver, events = drive(path, Heading.NORTH, 0.5, 0.25, kind)
    assert yaw_heading(driver.pose()[2]) == Heading.WEST
    assert [event for event, _, _ in events] == ["enter", "leave", "enter", "leave"]


def test_a_late_control_loop_turns_a_timed_body_off_its_row_and_not_one_that_measures_its_turns() -> None:
    path = [(x, 0) for x in range(5)] + [(4, y) for y in range(1, 5)]
    late = 0.02  # a busy machine: the body's control loop runs every 20 ms, so it stops a turn up to 20 ms late
    with pytest.raises(AssertionError):  # the turn overshoots, and the robot drifts off its row cell by cell
        drive(path, Heading.NORTH, 0.5, 0.25, LineCountingBody, control_every=late, tolerance=0.15)
    drive(path, Heading.NORTH, 0.5, 0.25, OdometryLineBody, control_every=late, tolerance=0.15)
