"""The ROS 2 message types the node speaks, declared by hand for Cyclone DDS.

Each class is the DDS type ROS 2's `rosidl` generates for the message: the ROS type
`pkg/msg/Name` is the DDS type `pkg::msg::dds_::Name_` (the Python binding writes `.` for
`::`), its fields in the order of the `.msg` file, `float64` as `float64`, a fixed array as
`array[T, N]`, an unbounded array as `sequence[T]`, `byte` as `uint8` (IDL `octet`).

`ROS_NAME` maps each class to its ROS name (`geometry_msgs/msg/Twist`), the name the
independent encoder (`rosbags`) knows it by.
"""

# No `from __future__ import annotations`: the binding resolves the field types at run time.
import math
from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float32, float64, int32, sequence, uint8, uint32


def _zeros(n: int):
    return field(default_factory=lambda: [0.0] * n)


# builtin_interfaces


@dataclass
class Time_(IdlStruct, typename="builtin_interfaces.msg.dds_.Time_"):
    """`builtin_interfaces/msg/Time`: seconds and nanoseconds."""

    sec: int32 = 0
    nanosec: uint32 = 0


# std_msgs


@dataclass
class Header_(IdlStruct, typename="std_msgs.msg.dds_.Header_"):
    """`std_msgs/msg/Header`: a stamp and a frame."""

    stamp: Time_ = field(default_factory=Time_)
    frame_id: str = ""


# geometry_msgs


@dataclass
class Vector3_(IdlStruct, typename="geometry_msgs.msg.dds_.Vector3_"):
    """`geometry_msgs/msg/Vector3`."""

    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Point_(IdlStruct, typename="geometry_msgs.msg.dds_.Point_"):
    """`geometry_msgs/msg/Point`."""

    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Quaternion_(IdlStruct, typename="geometry_msgs.msg.dds_.Quaternion_"):
    """`geometry_msgs/msg/Quaternion` (the identity by default, as in ROS)."""

    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
class Pose_(IdlStruct, typename="geometry_msgs.msg.dds_.Pose_"):
    """`geometry_msgs/msg/Pose`."""

    position: Point_ = field(default_factory=Point_)
    orientation: Quaternion_ = field(default_factory=Quaternion_)


@dataclass
class PoseWithCovariance_(IdlStruct, typename="geometry_msgs.msg.dds_.PoseWithCovariance_"):
    """`geometry_msgs/msg/PoseWithCovariance`: a pose and its 6×6 covariance, row-major."""

    pose: Pose_ = field(default_factory=Pose_)
    covariance: array[float64, 36] = _zeros(36)


@dataclass
class Twist_(IdlStruct, typename="geometry_msgs.msg.dds_.Twist_"):
    """`geometry_msgs/msg/Twist`: linear (m/s) and angular (rad/s) velocity."""

    linear: Vector3_ = field(default_factory=Vector3_)
    angular: Vector3_ = field(default_factory=Vector3_)


@dataclass
class TwistStamped_(IdlStruct, typename="geometry_msgs.msg.dds_.TwistStamped_"):
    """`geometry_msgs/msg/TwistStamped`."""

    header: Header_ = field(default_factory=Header_)
    twist: Twist_ = field(default_factory=Twist_)


@dataclass
class TwistWithCovariance_(IdlStruct, typename="geometry_msgs.msg.dds_.TwistWithCovariance_"):
    """`geometry_msgs/msg/TwistWithCovariance`."""

    twist: Twist_ = field(default_factory=Twist_)
    covariance: array[float64, 36] = _zeros(36)


@dataclass
class Transform_(IdlStruct, typename="geometry_msgs.msg.dds_.Transform_"):
    """`geometry_msgs/msg/Transform`."""

    translation: Vector3_ = field(default_factory=Vector3_)
    rotation: Quaternion_ = field(default_factory=Quaternion_)


@dataclass
class TransformStamped_(IdlStruct, typename="geometry_msgs.msg.dds_.TransformStamped_"):
    """`geometry_msgs/msg/TransformStamped`: the transform from `header.frame_id` to
    `child_frame_id`."""

    header: Header_ = field(default_factory=Header_)
    child_frame_id: str = ""
    transform: Transform_ = field(default_factory=Transform_)


# nav_msgs


@dataclass
class Odometry_(IdlStruct, typename="nav_msgs.msg.dds_.Odometry_"):
    """`nav_msgs/msg/Odometry`: pose in `header.frame_id`, twist in `child_frame_id`."""

    header: Header_ = field(default_factory=Header_)
    child_frame_id: str = ""
    pose: PoseWithCovariance_ = field(default_factory=PoseWithCovariance_)
    twist: TwistWithCovariance_ = field(default_factory=TwistWithCovariance_)


# tf2_msgs


@dataclass
class TFMessage_(IdlStruct, typename="tf2_msgs.msg.dds_.TFMessage_"):
    """`tf2_msgs/msg/TFMessage`."""

    transforms: sequence[TransformStamped_] = field(default_factory=list)


# sensor_msgs


@dataclass
class Imu_(IdlStruct, typename="sensor_msgs.msg.dds_.Imu_"):
    """`sensor_msgs/msg/Imu`."""

    header: Header_ = field(default_factory=Header_)
    orientation: Quaternion_ = field(default_factory=Quaternion_)
    orientation_covariance: array[float64, 9] = _zeros(9)
    angular_velocity: Vector3_ = field(default_factory=Vector3_)
    angular_velocity_covariance: array[float64, 9] = _zeros(9)
    linear_acceleration: Vector3_ = field(default_factory=Vector3_)
    linear_acceleration_covariance: array[float64, 9] = _zeros(9)


@dataclass
class BatteryState_(IdlStruct, typename="sensor_msgs.msg.dds_.BatteryState_"):
    """`sensor_msgs/msg/BatteryState` (as since Foxy: with `cell_temperature`)."""

    header: Header_ = field(default_factory=Header_)
    voltage: float32 = 0.0
    temperature: float32 = 0.0
    current: float32 = 0.0
    charge: float32 = 0.0
    capacity: float32 = 0.0
    design_capacity: float32 = 0.0
    percentage: float32 = 0.0
    power_supply_status: uint8 = 0
    power_supply_health: uint8 = 0
    power_supply_technology: uint8 = 0
    present: bool = False
    cell_voltage: sequence[float32] = field(default_factory=list)
    cell_temperature: sequence[float32] = field(default_factory=list)
    location: str = ""
    serial_number: str = ""


# diagnostic_msgs


@dataclass
class KeyValue_(IdlStruct, typename="diagnostic_msgs.msg.dds_.KeyValue_"):
    """`diagnostic_msgs/msg/KeyValue`."""

    key: str = ""
    value: str = ""


@dataclass
class DiagnosticStatus_(IdlStruct, typename="diagnostic_msgs.msg.dds_.DiagnosticStatus_"):
    """`diagnostic_msgs/msg/DiagnosticStatus` (`level` is a ROS `byte`: 0 OK, 1 WARN, 2 ERROR,
    3 STALE)."""

    level: uint8 = 0
    name: str = ""
    message: str = ""
    hardware_id: str = ""
    values: sequence[KeyValue_] = field(default_factory=list)


@dataclass
class DiagnosticArray_(IdlStruct, typename="diagnostic_msgs.msg.dds_.DiagnosticArray_"):
    """`diagnostic_msgs/msg/DiagnosticArray`."""

    header: Header_ = field(default_factory=Header_)
    status: sequence[DiagnosticStatus_] = field(default_factory=list)


ROS_NAME: dict[type, str] = {
    Time_: "builtin_interfaces/msg/Time",
    Header_: "std_msgs/msg/Header",
    Vector3_: "geometry_msgs/msg/Vector3",
    Point_: "geometry_msgs/msg/Point",
    Quaternion_: "geometry_msgs/msg/Quaternion",
    Pose_: "geometry_msgs/msg/Pose",
    PoseWithCovariance_: "geometry_msgs/msg/PoseWithCovariance",
    Twist_: "geometry_msgs/msg/Twist",
    TwistStamped_: "geometry_msgs/msg/TwistStamped",
    TwistWithCovariance_: "geometry_msgs/msg/TwistWithCovariance",
    Transform_: "geometry_msgs/msg/Transform",
    TransformStamped_: "geometry_msgs/msg/TransformStamped",
    Odometry_: "nav_msgs/msg/Odometry",
    TFMessage_: "tf2_msgs/msg/TFMessage",
    Imu_: "sensor_msgs/msg/Imu",
    BatteryState_: "sensor_msgs/msg/BatteryState",
    KeyValue_: "diagnostic_msgs/msg/KeyValue",
    DiagnosticStatus_: "diagnostic_msgs/msg/DiagnosticStatus",
    DiagnosticArray_: "diagnostic_msgs/msg/DiagnosticArray",
}
"""Each declared type's ROS 2 name."""


def dds_type_name(cls: type) -> str:
    """The DDS type name ROS 2 gives `cls` (`geometry_msgs::msg::dds_::Twist_`)."""
    package, _, name = ROS_NAME[cls].partition("/msg/")
    return f"{package}::msg::dds_::{name}_"


def yaw_of(q: Quaternion_) -> float:
    """The heading (rotation about z, radians, CCW) of a quaternion."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
