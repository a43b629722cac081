//! The ROS 2 messages the node sends and takes, written by hand as plain serde structs whose
//! fields are in the order of their `.msg` definitions: the order is the CDR layout, so a
//! field out of place is a message the other side decodes wrongly. Each module's tests hold
//! the CDR bytes (little-endian, after the 4-byte encapsulation header) of one value worked out
//! by hand from the CDR rules: every primitive aligned to its own size from the start of the
//! payload, a `string` as a `u32` length counting its terminating NUL, then the bytes and the
//! NUL, a sequence as a `u32` count then its elements, a fixed array as its elements only.

mod builtin;
mod diagnostic;
mod geometry;
mod nav;
mod sensor;
mod tf;

pub use builtin::{Header, Time};
pub use diagnostic::{DiagnosticArray, DiagnosticStatus, KeyValue};
pub use geometry::{
    Point, Pose, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist, TwistStamped,
    TwistWithCovariance, Vector3,
};
pub use nav::Odometry;
pub use sensor::{BatteryState, Imu};
pub use tf::TfMessage;

/// A message type's ROS name: its package and its type (`geometry_msgs`, `Twist`), what
/// ros2-client turns into the DDS type name `geometry_msgs::msg::dds_::Twist_`.
pub trait Message {
    /// The package, e.g. `geometry_msgs`.
    const PACKAGE: &'static str;
    /// The type, e.g. `Twist`.
    const NAME: &'static str;
}

/// Writes `impl Message` for each `type => package`.
macro_rules! message_names {
    ($($ty:ident => $package:literal, $name:literal;)*) => {
        $(impl Message for $ty {
            const PACKAGE: &'static str = $package;
            const NAME: &'static str = $name;
        })*
    };
}

message_names! {
    Twist => "geometry_msgs", "Twist";
    TwistStamped => "geometry_msgs", "TwistStamped";
    Odometry => "nav_msgs", "Odometry";
    TfMessage => "tf2_msgs", "TFMessage";
    Imu => "sensor_msgs", "Imu";
    BatteryState => "sensor_msgs", "BatteryState";
    DiagnosticArray => "diagnostic_msgs", "DiagnosticArray";
}

/// The bytes ros2-client's publisher puts on the wire for `value`: the encapsulation header
/// `00 01 00 00` (CDR, little-endian) and the CDR payload, from the same encoder it uses.
#[cfg(test)]
pub(crate) fn wire<T: serde::Serialize>(value: &T) -> Vec<u8> {
    use ros2_client::dds::rustdds::{CDRSerializerAdapter, RepresentationIdentifier, no_key};
    let payload =
        <CDRSerializerAdapter<T> as no_key::SerializerAdapter<T>>::to_bytes(value).unwrap();
    let mut out = RepresentationIdentifier::CDR_LE.to_bytes().to_vec();
    out.extend_from_slice(&[0, 0]);
    out.extend_from_slice(&payload);
    out
}

/// A header stamped `sec` s and `nanosec` ns, in `frame`.
#[cfg(test)]
pub(crate) fn header(sec: i32, nanosec: u32, frame: &str) -> Header {
    Header {
        stamp: Time { sec, nanosec },
        frame_id: frame.into(),
    }
}

/// Little-endian bytes of the values given, for writing the expected bytes in the tests.
#[cfg(test)]
pub(crate) mod le {
    /// An `f64`'s 8 bytes.
    pub fn f64(v: f64) -> [u8; 8] {
        v.to_le_bytes()
    }
    /// An `f32`'s 4 bytes.
    pub fn f32(v: f32) -> [u8; 4] {
        v.to_le_bytes()
    }
    /// A `u32`'s 4 bytes.
    pub fn u32(v: u32) -> [u8; 4] {
        v.to_le_bytes()
    }
}
