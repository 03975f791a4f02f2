"""A simulated differential-drive robot as a ROS 2 node: takes ``cmd_vel``, integrates it, publishes ``odom``.

The stand-in for a real robot's ROS 2 driver, so that ``mrmp agent --drive
ros2`` (:mod:`mrmp.live.ros2_driver`) can be tested, and tried, without one.
It reads ``geometry_msgs/msg/Twist`` on ``/robot_<id>/cmd_vel`` and moves a
:class:`~mrmp.live.diff_drive.DiffDrive` exactly along each command from the
moment it arrives to the next (the unicycle model; no slip, no noise), and
publishes ``nav_msgs/msg/Odometry`` on ``/robot_<id>/odom`` (frame ``odom``
from where it started, child frame ``base_link``) every ``1 / rate`` seconds,
in the ROS 2 domain ``ROS_DOMAIN_ID``.

Usage::

    python -m mrmp.live.ros2_robot --robot A [--rate 200] [--out pose.json] [--timeout 600]

It prints ``ready`` once its topics exist, and on SIGTERM or SIGINT (or after
``--timeout`` seconds) writes its last odometry pose, ``{"x", "y", "yaw",
"commands"}``, to ``--out`` and ends. Bad arguments: one line, exit code 2.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

from mrmp.live.diff_drive import DiffDrive
from mrmp.live.ros2_driver import command_topic, odometry_topic, topic_qos
from mrmp.live.ros2_topics import ros2_domain, ros2_problem

if TYPE_CHECKING:
    from mrmp.live.ros2_types import Odometry

__all__ = ["main"]

POLL_SECONDS = 0.0005
"""How often the node looks for new commands: a command takes effect this late at most."""


def _arguments(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m mrmp.live.ros2_robot", description=__doc__.splitlines()[0])
    parser.add_argument("--robot", required=True, help="the robot's id (its topics' names)")
    parser.add_argument("--rate", type=float, default=200.0, help="odometry messages per second")
    parser.add_argument("--out", type=Path, help="where to write the last pose on exit")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds before the node ends by itself")
    arguments = parser.parse_args(argv)
    if not 1.0 <= arguments.rate <= 1000.0:
        parser.error(f"--rate: expected 1 to 1000 messages per second, got {arguments.rate:g}")
    if not 0.0 < arguments.timeout <= 86400.0:
        parser.error(f"--timeout: expected more than 0 and at most 86400 seconds, got {arguments.timeout:g}")
    return arguments


def main(argv: list[str] | None = None) -> int:
    """Run the node until stopped (module docstring); 0 when it ended normally, 2 on bad input."""
    arguments = _arguments(sys.argv[1:] if argv is None else argv)
    missing = ros2_problem()
    try:
        if missing is not None:
            raise ValueError(f"--robot: {missing}")
        domain = ros2_domain(os.environ)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    from mrmp.live import ros2_types as types

    stop = threading.Event()
    for signum in (signal.SIGTERM, signal.SIGINT):
        signal.signal(signum, lambda *_: stop.set())
    participant = DomainParticipant(domain)
    qos = topic_qos()
    commands = DataReader(participant, Topic(participant, command_topic(arguments.robot), types.Twist), qos=qos)
    odometry = DataWriter(participant, Topic(participant, odometry_topic(arguments.robot), types.Odometry), qos=qos)
    robot = DiffDrive()
    linear = angular = 0.0
    received = 0
    period = 1.0 / arguments.rate
    started = last = time.monotonic()
    next_report = last
    print("ready", flush=True)
    while not stop.is_set() and last - started < arguments.timeout:
        now = time.monotonic()
        robot.advance(linear, angular, now - last)
        last = now
        for sample in commands.take(N=64):
            if isinstance(sample, types.Twist):
                linear, angular = sample.linear.x, sample.angular.z
                received += 1
        if now >= next_report:
            odometry.write(_odometry(robot, linear, angular))
            next_report = now + period
        time.sleep(POLL_SECONDS)
    if arguments.out is not None:
        pose = {"x": robot.x, "y": robot.y, "yaw": robot.yaw, "commands": received}
        arguments.out.write_text(json.dumps(pose) + "\n", encoding="utf-8")
    return 0


def _odometry(robot: DiffDrive, linear: float, angular: float) -> Odometry:
    """The ``nav_msgs/msg/Odometry`` of ``robot``'s pose now and its current twist."""
    from mrmp.live import ros2_types as types

    header = types.stamped_header(time.time_ns(), "odom")
    orientation = types.Quaternion(0.0, 0.0, math.sin(robot.yaw / 2.0), math.cos(robot.yaw / 2.0))
    pose = types.PoseWithCovariance(types.Pose(types.Point(robot.x, robot.y, 0.0), orientation), [0.0] * 36)
    twist = types.Twist(types.Vector3(linear, 0.0, 0.0), types.Vector3(0.0, 0.0, angular))
    return types.Odometry(header, "base_link", pose, types.TwistWithCovariance(twist, [0.0] * 36))


if __name__ == "__main__":
    raise SystemExit(main())
