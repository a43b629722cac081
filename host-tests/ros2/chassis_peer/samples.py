"""One sample of each published type with values that exercise the encoding: strings of every
length modulo 4 before 8-byte fields (CDR alignment), empty and non-empty sequences, floats at
the edges (subnormal, largest, negative zero, infinity, NaN), unsigned and signed extremes."""

import math

from . import msgs

_EDGES = [0.0, -0.0, 1e-300, -1.797e308, 5e-324, math.inf, -math.inf, math.nan, 1.0 / 3.0]


def _cov(n: int, offset: int) -> list[float]:
    return [_EDGES[(i + offset) % len(_EDGES)] for i in range(n)]


def header(frame: str, sec: int = 1_700_000_000, nanosec: int = 999_999_999) -> msgs.Header_:
    """A header with `frame` and a stamp."""
    return msgs.Header_(msgs.Time_(sec, nanosec), frame)


def odometry() -> msgs.Odometry_:
    """An `Odometry` with every covariance slot set and an odd-length child frame."""
    return msgs.Odometry_(
        header=header("odom", -2_147_483_648, 4_294_967_295),
        child_frame_id="base_link",
        pose=msgs.PoseWithCovariance_(
            msgs.Pose_(msgs.Point_(1.25, -0.5, 0.0), msgs.Quaternion_(0.0, 0.0, 0.6, 0.8)),
            _cov(36, 0),
        ),
        twist=msgs.TwistWithCovariance_(
            msgs.Twist_(msgs.Vector3_(0.3, -0.0, 0.0), msgs.Vector3_(0.0, 0.0, -1.5)),
            _cov(36, 3),
        ),
    )


def tf() -> msgs.TFMessage_:
    """A `TFMessage` of two transforms with frames of lengths 1 to 3 (alignment)."""
    return msgs.TFMessage_(
        [
            msgs.TransformStamped_(
                header("o"),
                "ba",
                msgs.Transform_(msgs.Vector3_(1.0, 2.0, 3.0), msgs.Quaternion_(0, 0, 0, 1)),
            ),
            msgs.TransformStamped_(
                header("odo", 7, 8),
                "b",
                msgs.Transform_(msgs.Vector3_(-1e-300, 0, 1), msgs.Quaternion_(0.5, 0.5, 0.5, 0.5)),
            ),
        ]
    )


def imu() -> msgs.Imu_:
    """An `Imu` with the orientation unknown (covariance[0] = -1, as REP-145 says)."""
    return msgs.Imu_(
        header=header("imu_link"),
        orientation=msgs.Quaternion_(0, 0, 0, 1),
        orientation_covariance=[-1.0] + [0.0] * 8,
        angular_velocity=msgs.Vector3_(0.01, -0.02, 0.5),
        angular_velocity_covariance=_cov(9, 1),
        linear_acceleration=msgs.Vector3_(0.0, 0.0, 9.80665),
        linear_acceleration_covariance=_cov(9, 5),
    )


def battery() -> msgs.BatteryState_:
    """A `BatteryState` with one cell voltage, no temperatures, NaN where unknown (the values
    exact in `float32`, so that they decode to themselves)."""
    return msgs.BatteryState_(
        header=header("base_link"),
        voltage=12.375,
        temperature=math.nan,
        current=math.nan,
        charge=math.nan,
        capacity=math.nan,
        design_capacity=math.nan,
        percentage=math.nan,
        power_supply_status=2,
        power_supply_health=0,
        power_supply_technology=0,
        present=True,
        cell_voltage=[4.125],
        cell_temperature=[],
        location="chassis",
        serial_number="",
    )


def diagnostics() -> msgs.DiagnosticArray_:
    """A `DiagnosticArray` of two statuses, with and without key-values (UTF-8 included)."""
    return msgs.DiagnosticArray_(
        header=header(""),
        status=[
            msgs.DiagnosticStatus_(
                level=1,
                name="chassis: link",
                message="late replies",
                hardware_id="OminiBot HV",
                values=[msgs.KeyValue_("frames", "1234"), msgs.KeyValue_("v", "12,4 V — ok")],
            ),
            msgs.DiagnosticStatus_(level=3, name="x", message="", hardware_id="", values=[]),
        ],
    )


def twist() -> msgs.Twist_:
    """A `Twist` with extreme components."""
    return msgs.Twist_(msgs.Vector3_(1e-300, -1.797e308, -0.0), msgs.Vector3_(math.inf, 0, 2.5))


def twist_stamped() -> msgs.TwistStamped_:
    """A `TwistStamped`."""
    return msgs.TwistStamped_(header("base_link", 3, 4), twist())


ALL = {
    "Odometry": odometry,
    "TFMessage": tf,
    "Imu": imu,
    "BatteryState": battery,
    "DiagnosticArray": diagnostics,
    "Twist": twist,
    "TwistStamped": twist_stamped,
}
"""A sample maker for each top-level type."""

BY_TOPIC = {
    "/odom": odometry,
    "/tf": tf,
    "/imu/data_raw": imu,
    "/battery_state": battery,
    "/diagnostics": diagnostics,
}
"""The sample of each topic the node publishes."""
