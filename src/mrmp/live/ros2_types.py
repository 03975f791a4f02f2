"""The ROS 2 message types a live robot publishes, as DDS types (cyclonedds), named as ROS 2 names them on the wire.

ROS 2 puts a message type ``pkg/msg/Name`` on DDS as the IDL struct
``pkg::msg::dds_::Name_`` (the ``rmw`` type-name mangling; ROS 2 design,
"Topic and Service name mapping to DDS"), with CDR encoding. These
dataclasses give those structs field for field (``builtin_interfaces/Time``,
``std_msgs/Header``, ``std_msgs/String``, ``geometry_msgs/Point``,
``Quaternion``, ``Pose``, ``PoseStamped``), so that ``ros2 topic echo`` reads
what a robot writes. This module imports ``cyclonedds`` (the optional extra
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

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import float64, int32, uint32

__all__ = ["Header", "Point", "Pose", "PoseStamped", "Quaternion", "String", "Time"]


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
