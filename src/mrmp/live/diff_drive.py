"""A differential-drive robot on the grid: its kinematics, its odometry frame, and the grid lines under its sensor.

The Khepera III is a differential-drive robot (thesis section 2.3): two wheels
``wheel_base`` apart, the left at speed ``l`` and the right at ``r`` move it
forward at ``(l + r) / 2`` and turn it counter-clockwise at ``(r - l) /
wheel_base`` (the unicycle model; e.g. Siegwart, Nourbakhsh and Scaramuzza,
*Introduction to Autonomous Mobile Robots*, 2nd ed., section 3.2). Its floor
sensor sees the black lines between cells. A ROS 2 robot reports its motion as
odometry in frame ``odom``, which starts where the robot started, x ahead and y
to its left (REP 105); mrmp's map frame is east, north (``docs/ros2.md``).
Nothing here reads a clock: callers give the times.

Examples
--------
A robot at the centre of cell (0, 0), facing EAST, drives one second at 1 m/s:

>>> robot = DiffDrive()
>>> robot.advance(1.0, 0.0, 1.0)
>>> round(robot.x, 6), round(robot.y, 6), robot.yaw
(1.0, 0.0, 0.0)
>>> [round(value, 6) for value in odometry_in_map((0, 0), Heading.EAST, robot.x, robot.y, robot.yaw)]
[1.5, 0.5, 0.0]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.io.ros_messages import cell_position, heading_yaw

__all__ = ["DiffDrive", "body_geometry", "odometry_in_map", "on_grid_line", "wheel_twist", "yaw_heading"]


@dataclass
class DiffDrive:
    """A differential-drive robot's pose in its odometry frame (metres, radians), advanced exactly between commands."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def advance(self, linear: float, angular: float, seconds: float) -> None:
        """Move for ``seconds`` at ``linear`` m/s ahead and ``angular`` rad/s counter-clockwise (exact arcs).

        >>> robot = DiffDrive()
        >>> robot.advance(0.0, math.pi / 2, 1.0)   # a quarter turn left in place
        >>> round(robot.yaw, 6), robot.x
        (1.570796, 0.0)
        """
        if seconds <= 0:
            return
        if abs(angular) < 1e-12:
            self.x += linear * seconds * math.cos(self.yaw)
            self.y += linear * seconds * math.sin(self.yaw)
            return
        turned = self.yaw + angular * seconds
        radius = linear / angular
        self.x += radius * (math.sin(turned) - math.sin(self.yaw))
        self.y -= radius * (math.cos(turned) - math.cos(self.yaw))
        self.yaw = math.atan2(math.sin(turned), math.cos(turned))


def wheel_twist(left: float, right: float, wheel_base: float) -> tuple[float, float]:
    """The ``(linear, angular)`` velocity of wheel speeds ``left`` and ``right`` (m/s), ``wheel_base`` metres apart.

    >>> wheel_twist(1.0, 1.0, 0.5), wheel_twist(1.0, -1.0, 0.5)   # ahead; a right (clockwise) turn in place
    ((1.0, 0.0), (0.0, -4.0))
    """
    return (left + right) / 2.0, (right - left) / wheel_base


def odometry_in_map(
    start: Cell, heading: Heading, x: float, y: float, yaw: float, cell_size: float = 1.0
) -> tuple[float, float, float]:
    """A pose in frame ``odom`` of a robot that started on ``start`` facing ``heading``, as ``(east, north, yaw)`` in ``map``.

    >>> [round(value, 6) for value in odometry_in_map((2, 0), Heading.NORTH, 1.0, 0.0, 0.0)]   # one metre ahead: north
    [0.5, 3.5, 1.570796]
    """
    east, north, _ = cell_position(start, cell_size)
    base = heading_yaw(heading)
    cos, sin = math.cos(base), math.sin(base)
    turned = base + yaw
    return east + cos * x - sin * y, north + sin * x + cos * y, math.atan2(math.sin(turned), math.cos(turned))


def on_grid_line(east: float, north: float, yaw: float, cell_size: float, line_width: float) -> bool:
    """Whether a floor sensor at ``(east, north)`` sees a line across the way the robot faces (``yaw``).

    Lines lie on every cell boundary, ``line_width`` wide; the sensor looks for
    those across its travel: the east-west boundaries when it faces mostly
    north or south, the north-south ones otherwise.

    >>> on_grid_line(1.02, 0.5, 0.0, 1.0, 0.1), on_grid_line(0.9, 0.5, 0.0, 1.0, 0.1)
    (True, False)
    >>> on_grid_line(0.5, 0.98, 0.0, 1.0, 0.1)   # a line along its way, not across: not seen
    False
    """
    along = east if abs(math.cos(yaw)) >= abs(math.sin(yaw)) else north
    offset = along / cell_size
    return abs(offset - round(offset)) * cell_size < line_width / 2.0


def yaw_heading(yaw: float) -> Heading:
    """The heading nearest ``yaw`` (radians counter-clockwise from east).

    >>> yaw_heading(0.1).name, yaw_heading(math.pi / 2).name, yaw_heading(-3.1).name
    ('EAST', 'NORTH', 'WEST')
    """
    return min(Heading, key=lambda heading: abs(math.remainder(yaw - heading_yaw(heading), 2 * math.pi)))


def body_geometry(cell_seconds: float, turn_seconds: float, cell_size: float, line_width: float) -> tuple[float, float, float]:
    """``(speed, wheel_base, settle_seconds)`` of a body driving a cell in ``cell_seconds``, a right turn in ``turn_seconds``.

    A right turn spins the wheels at ``speed`` and ``-speed``: a quarter turn
    takes ``(pi / 2) / (2 * speed / wheel_base)``, so ``wheel_base = 4 * speed
    * turn_seconds / pi``; after crossing a line the body drives on to the
    cell's middle, ``(cell_size - line_width) / 2`` metres.

    >>> [round(value, 4) for value in body_geometry(0.5, 0.25, 1.0, 0.1)]
    [2.0, 0.6366, 0.225]
    """
    speed = cell_size / cell_seconds
    return speed, 4.0 * speed * turn_seconds / math.pi, (cell_size - line_width) / 2.0 / speed
