"""A live robot on ROS 2 topics: each robot process publishes its pose and state over DDS, as a ROS 2 node would.

With ``--ros2`` (``mrmp agent``, ``mrmp run --live``) every robot process
opens a DDS participant (cyclonedds, the optional extra ``ros2``) in the ROS 2
domain ``ROS_DOMAIN_ID`` (0 when unset) and writes, as ROS 2 does on the wire
(topic ``/x`` is the DDS topic ``rt/x``, types from :mod:`mrmp.live.ros2_types`):

* ``/robot_<id>/pose`` (``geometry_msgs/msg/PoseStamped``, frame ``map``):
  the robot's pose when it starts and each time its body starts to enter a
  cell, at that cell's centre and facing the way it moves, in the axes of
  ``docs/ros2.md`` (REP 103 and 105: east, north, up, metres);
* ``/robot_<id>/state`` (``std_msgs/msg/String``): one JSON object per
  ground-truth event of its body: ``{"robot", "event", "cell", "heading",
  "t"}``, ``event`` one of ``start``, ``enter``, ``leave`` and ``stop`` (the
  process is ending).

Both are reliable, transient-local (a subscriber that joins late gets the
last 64) and stamped with this machine's clock (ROS time). ``ros2 topic echo
/robot_A/pose`` in the same domain and network shows them; so does any DDS
participant, like the test's. What DDS may use of the network is DDS's own
configuration (``CYCLONEDDS_URI``); the tests confine it to loopback.

This is middleware, so it lives in the live layer; the robot's brain knows
nothing of it. It publishes what the body reports to the referee's trace
(:class:`~mrmp.live.body.OccupancyRecorder`).

Examples
--------
>>> pose_topic("A"), state_topic("r-1")
('rt/robot_A/pose', 'rt/robot_r_1/state')
>>> ros2_domain({"ROS_DOMAIN_ID": "7"}), ros2_domain({})
(7, 0)
>>> ros2_domain({"ROS_DOMAIN_ID": "300"})
Traceback (most recent call last):
...
ValueError: ROS_DOMAIN_ID: expected a whole number from 0 to 232, got '300'
"""

from __future__ import annotations

import importlib.util
import json
import time
from collections.abc import Callable, Mapping
from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.io.ros_messages import FRAME, cell_position, heading_quaternion, robot_topic

__all__ = [
    "DOMAIN_VARIABLE",
    "MAX_DOMAIN_ID",
    "Ros2Publisher",
    "pose_topic",
    "published_qos",
    "ros2_domain",
    "ros2_problem",
    "state_topic",
]

DOMAIN_VARIABLE = "ROS_DOMAIN_ID"
"""The environment variable that names the ROS 2 domain, as for every ROS 2 node."""
MAX_DOMAIN_ID = 232
"""The largest ROS 2 domain id (ROS 2 documentation, "The ROS_DOMAIN_ID")."""
HISTORY = 64
"""Samples of each topic a subscriber that joins late still gets (transient-local history)."""
ACK_WAIT_SECONDS = 1.0
"""How long a robot process ending waits for subscribers to acknowledge what it wrote."""


def ros2_problem() -> str | None:
    """Why ``--ros2`` cannot run here (its package is missing), or None.

    >>> ros2_problem() in (None, "needs the ros2 extra (cyclonedds): pip install -e '.[ros2]'")
    True
    """
    if importlib.util.find_spec("cyclonedds") is None:
        return "needs the ros2 extra (cyclonedds): pip install -e '.[ros2]'"
    return None


def ros2_domain(environment: Mapping[str, str]) -> int:
    """The ROS 2 domain id that ``environment`` names (``ROS_DOMAIN_ID``; 0 when unset or empty).

    Raises
    ------
    ValueError
        If it is not a whole number from 0 to :data:`MAX_DOMAIN_ID`.
    """
    text = environment.get(DOMAIN_VARIABLE, "").strip()
    if not text:
        return 0
    if not text.isdigit() or int(text) > MAX_DOMAIN_ID:
        raise ValueError(f"{DOMAIN_VARIABLE}: expected a whole number from 0 to {MAX_DOMAIN_ID}, got {text!r}")
    return int(text)


def pose_topic(robot_id: str) -> str:
    """The DDS topic of ``/robot_<id>/pose`` (ROS 2 prefixes topics with ``rt``)."""
    return "rt" + robot_topic(robot_id, "pose")


def state_topic(robot_id: str) -> str:
    """The DDS topic of ``/robot_<id>/state``."""
    return "rt" + robot_topic(robot_id, "state")


def published_qos() -> Any:
    """The QoS of the pose and state topics (module docstring): reliable, transient-local, the last :data:`HISTORY`."""
    from cyclonedds.core import Policy, Qos
    from cyclonedds.util import duration

    return Qos(
        Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(HISTORY)
    )


class Ros2Publisher:
    """One robot's pose and state on ROS 2 topics (module docstring).

    Parameters
    ----------
    robot_id:
        The robot's id in the scenario (its topics' names).
    start, heading:
        Where its body stands and faces at the start (published at once).
    domain:
        The ROS 2 domain id.
    cell_size:
        Metres per cell.
    clock:
        Nanoseconds of ROS time now (this machine's clock).
    """

    def __init__(
        self,
        robot_id: str,
        start: Cell,
        heading: Heading,
        *,
        domain: int = 0,
        cell_size: float = 1.0,
        clock: Callable[[], int] = time.time_ns,
    ) -> None:
        from cyclonedds.domain import DomainParticipant
        from cyclonedds.pub import DataWriter
        from cyclonedds.topic import Topic

        from mrmp.live import ros2_types

        self._types = ros2_types
        self.robot_id = robot_id
        self.cell = start
        self.heading = heading
        self.cell_size = cell_size
        self.clock = clock
        self.published = 0
        qos = published_qos()
        self._participant: Any = DomainParticipant(domain)
        participant = self._participant
        self._pose: Any = DataWriter(participant, Topic(participant, pose_topic(robot_id), ros2_types.PoseStamped), qos=qos)
        self._state: Any = DataWriter(participant, Topic(participant, state_topic(robot_id), ros2_types.String), qos=qos)
        self._write_pose()
        self._write_state("start", start, 0.0)

    def occupancy(self, event: str, cell: Cell, t: float) -> None:
        """A body's ground-truth event (an :class:`~mrmp.live.body.OccupancyRecorder` sink): publish it."""
        if self._participant is None:
            return
        if event == "enter":
            if cell != self.cell:
                self.heading = Heading.between(self.cell, cell)
            self.cell = cell
            self._write_pose()
        self._write_state(event, cell, t)

    def close(self) -> None:
        """Publish ``stop``, give subscribers a moment to acknowledge what was written, and let DDS go."""
        if self._participant is None:
            return
        from cyclonedds.util import duration

        self._write_state("stop", self.cell, 0.0)
        for writer in (self._pose, self._state):
            writer.wait_for_acks(duration(seconds=ACK_WAIT_SECONDS))
        self._participant = self._pose = self._state = None

    # -- messages ------------------------------------------------------------------------

    def _write_pose(self) -> None:
        types = self._types
        x, y, z = cell_position(self.cell, self.cell_size)
        qx, qy, qz, qw = heading_quaternion(self.heading)
        pose = types.Pose(types.Point(x, y, z), types.Quaternion(qx, qy, qz, qw))
        self._pose.write(types.PoseStamped(types.stamped_header(self.clock(), FRAME), pose))
        self.published += 1

    def _write_state(self, event: str, cell: Cell, t: float) -> None:
        state = {"robot": self.robot_id, "event": event, "cell": list(cell), "heading": self.heading.name, "t": t}
        self._state.write(self._types.String(json.dumps(state)))
        self.published += 1
