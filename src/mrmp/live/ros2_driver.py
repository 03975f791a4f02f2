"""A robot body over ROS 2: wheel speeds out as ``geometry_msgs/Twist``, odometry in, grid lines seen from it.

``mrmp agent --drive ros2`` gives the robot an
:class:`~mrmp.live.body.OdometryLineBody`, the body of a real Khepera III
(thesis sections 2.3 and 3.6: right turns, then forward until a grid line is
crossed; its turns ended by odometry rather than by a clock), whose driver is
this :class:`Ros2Driver` instead of the robot's own board. It implements :class:`~mrmp.live.body.KheperaDriver` over
DDS, as a ROS 2 node would:

* ``set_speeds(left, right)``: a ``geometry_msgs/msg/Twist`` on
  ``/robot_<id>/cmd_vel`` (linear x and angular z of the two wheel speeds,
  :func:`~mrmp.live.diff_drive.wheel_twist`);
* ``line_detected()``: from the last ``nav_msgs/msg/Odometry`` on
  ``/robot_<id>/odom``, in frame ``odom`` from where the robot started (REP
  105), turned into the map frame (:func:`~mrmp.live.diff_drive.odometry_in_map`):
  whether a line across its way lies under the robot's centre
  (:func:`~mrmp.live.diff_drive.on_grid_line`), or was crossed since the last
  reading (the sensor latches a line it passed between two readings, as a
  sensor sampled faster than the robot's control loop would have seen it);
* ``map_pose()``: the same odometry as a pose, for the body's turns.

So any robot whose ROS 2 driver takes ``cmd_vel`` and publishes ``odom`` can be
the body of an ``mrmp agent``; :mod:`mrmp.live.ros2_robot` is such a robot,
simulated (the tests drive it). The topics' QoS are ROS 2's defaults for them:
reliable, volatile, a history of 10.

Examples
--------
>>> command_topic("A"), odometry_topic("A")
('rt/robot_A/cmd_vel', 'rt/robot_A/odom')
"""

from __future__ import annotations

import math
import time
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.io.ros_messages import robot_topic
from mrmp.live.diff_drive import odometry_in_map, on_grid_line, wheel_twist

__all__ = ["Ros2Driver", "command_topic", "odometry_topic"]

QOS_DEPTH = 10
"""The history of the command and odometry topics (ROS 2's default QoS profile)."""


def command_topic(robot_id: str) -> str:
    """The DDS topic of ``/robot_<id>/cmd_vel``."""
    return "rt" + robot_topic(robot_id, "cmd_vel")


def odometry_topic(robot_id: str) -> str:
    """The DDS topic of ``/robot_<id>/odom``."""
    return "rt" + robot_topic(robot_id, "odom")


def topic_qos() -> Any:
    """ROS 2's default QoS for a topic: reliable, volatile, keep the last :data:`QOS_DEPTH`."""
    from cyclonedds.core import Policy, Qos
    from cyclonedds.util import duration

    return Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile, Policy.History.KeepLast(QOS_DEPTH))


class Ros2Driver:
    """:class:`~mrmp.live.body.KheperaDriver` over ROS 2 topics (module docstring).

    Parameters
    ----------
    robot_id:
        The robot's id (its topics' names).
    start, heading:
        Where the robot stands and faces when its odometry starts (its ``odom`` origin).
    domain:
        The ROS 2 domain id.
    wheel_base:
        Metres between the wheels (turns the wheel speeds into a twist).
    cell_size, line_width:
        Metres per cell and per grid line.
    """

    def __init__(
        self,
        robot_id: str,
        start: Cell,
        heading: Heading,
        *,
        domain: int = 0,
        wheel_base: float,
        cell_size: float = 1.0,
        line_width: float = 0.1,
    ) -> None:
        from cyclonedds.domain import DomainParticipant
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from mrmp.live import ros2_types

        self._types = ros2_types
        self.robot_id = robot_id
        self.start = start
        self.heading = heading
        self.wheel_base = wheel_base
        self.cell_size = cell_size
        self.line_width = line_width
        self.odometry: tuple[float, float, float] | None = None
        """The last odometry pose, ``(x, y, yaw)`` in frame ``odom``; None before the first."""
        self._last_line: tuple[bool, int] | None = None  # the axis and the cell along it at the last line reading
        self.commands = 0
        self._participant: Any = DomainParticipant(domain)
        participant = self._participant
        qos = topic_qos()
        self._commands: Any = DataWriter(participant, Topic(participant, command_topic(robot_id), ros2_types.Twist), qos=qos)
        self._odometry: Any = DataReader(participant, Topic(participant, odometry_topic(robot_id), ros2_types.Odometry), qos=qos)

    # -- KheperaDriver ------------------------------------------------------------------------

    def set_speeds(self, left: float, right: float) -> None:
        """Command the wheel speeds, as a twist."""
        linear, angular = wheel_twist(left, right, self.wheel_base)
        vector = self._types.Vector3
        self._commands.write(self._types.Twist(vector(linear, 0.0, 0.0), vector(0.0, 0.0, angular)))
        self.commands += 1

    def line_detected(self) -> bool:
        """Whether a grid line across the robot's way is under its centre, or was crossed since the last reading."""
        pose = self.map_pose()
        if pose is None:
            return False
        east, north, yaw = pose
        along_east = abs(math.cos(yaw)) >= abs(math.sin(yaw))
        reading = (along_east, math.floor((east if along_east else north) / self.cell_size))
        crossed = self._last_line is not None and self._last_line[0] == along_east and self._last_line[1] != reading[1]
        self._last_line = reading
        return crossed or on_grid_line(east, north, yaw, self.cell_size, self.line_width)

    def stop(self) -> None:
        """Command a zero twist."""
        self.set_speeds(0.0, 0.0)

    # -- odometry ---------------------------------------------------------------------------------

    def map_pose(self) -> tuple[float, float, float] | None:
        """The robot's last reported pose as ``(east, north, yaw)`` in frame ``map``, None before any odometry."""
        for sample in self._odometry.take(N=QOS_DEPTH):
            if isinstance(sample, self._types.Odometry):
                pose = sample.pose.pose
                quaternion = pose.orientation
                yaw = 2.0 * math.atan2(quaternion.z, quaternion.w)
                self.odometry = (pose.position.x, pose.position.y, yaw)
        if self.odometry is None:
            return None
        return odometry_in_map(self.start, self.heading, *self.odometry, self.cell_size)

    def wait_for_odometry(self, seconds: float) -> bool:
        """Wait up to ``seconds`` for the robot's first odometry (its driver runs); whether it came."""
        deadline = time.monotonic() + seconds
        while self.map_pose() is None:
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True

    def close(self) -> None:
        """Stop the robot and let DDS go."""
        if self._participant is not None:
            self.stop()
            self._participant = self._commands = self._odometry = None
