"""The ROS 2 message types a live robot publishes, as DDS types (cyclonedds), named as ROS 2 names them on the wire.

ROS 2 puts a message type ``pkg/msg/Name`` on DDS as the IDL struct
``pkg::msg::dds_::Name_`` (the ``rmw`` type-name mangling; ROS 2 design,
"Topic and Service name mapping to DDS"), with CDR encoding. These
dataclasses give those structs field for field (``builtin_interfaces/Time``,
``std_msgs/Header``, ``std_msgs/String``, ``geometry_msgs/Point``,
``Quaternion``, ``Pose``, ``PoseStamped``, ``Vector3``, ``Twist``,
``PoseWithCovariance``, ``TwistWithCovariance``, ``nav_msgs/Odometry``), so
that ``ros2 topic echo`` reads what a robot writes, and a robot's ROS 2 driver
reads what it answers. This module imports ``cyclonedds`` (the optional extra
``ros2``); only :mod:`mrmp.live.ros2_topics` imports it, when asked to publish.

Examples
--------
>>> PoseStamped.__idl_typename__
'geometry_msgs::msg::dds_::PoseStamped_'
>>> message = String("hello")
>>> String.deserialize(message.serialize()) == message
True
"""

from dataclasses import dataclass  # no postponed annotations: cyclonedds reads the field types themselves
from typing import TYPE_CHECKING

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, int32, uint32

if TYPE_CHECKING:
    Covariance = list[float]
else:
    Covariance = array[float64, 36]  # a row-major 6x6 covariance, as IDL double[36]

__all__ = [
    "Header",
    "Odometry",
    "Point",
    "Pose",
    "PoseStamped",
    "PoseWithCovariance",
    "Quaternion",
    "String",
    "Time",
    "Twist",
    "TwistWithCovariance",
    "Vector3",
    "stamped_header",
]


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    """``builtin_interfaces/msg/Time``: seconds and nanoseconds."""

    sec: int32
    nanosec: uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    """``std_msgs/msg/Header``: a stamp and the frame the data is in."""

    stamp: Time
    frame_id: str


def stamped_header(nanoseconds: int, frame: str) -> Header:
    """A header stamped ``nanoseconds`` of ROS time, in ``frame``.

    >>> stamped_header(3_000_000_007, "map")
    Header(stamp=Time(sec=3, nanosec=7), frame_id='map')
    """
    return Header(Time(nanoseconds // 1_000_000_000, nanoseconds % 1_000_000_000), frame)


@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    """``std_msgs/msg/String``."""

    data: str


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    """``geometry_msgs/msg/Point``, metres."""

    x: float64
    y: float64
    z: float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    """``geometry_msgs/msg/Quaternion``."""

    x: float64
    y: float64
    z: float64
    w: float64


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    """``geometry_msgs/msg/Pose``."""

    position: Point
    orientation: Quaternion


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    """``geometry_msgs/msg/PoseStamped``."""

    header: Header
    pose: Pose


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    """``geometry_msgs/msg/Vector3``."""

    x: float64
    y: float64
    z: float64


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    """``geometry_msgs/msg/Twist``: linear (m/s) and angular (rad/s) velocity, in the body's frame."""

    linear: Vector3
    angular: Vector3


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    """``geometry_msgs/msg/PoseWithCovariance``."""

    pose: Pose
    covariance: Covariance


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    """``geometry_msgs/msg/TwistWithCovariance``."""

    twist: Twist
    covariance: Covariance


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    """``nav_msgs/msg/Odometry``: the pose in ``header.frame_id`` (``odom``), the twist in ``child_frame_id``."""

    header: Header
    child_frame_id: str
    pose: PoseWithCovariance
    twist: TwistWithCovariance
