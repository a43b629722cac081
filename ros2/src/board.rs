//! The board, of either firmware generation, as the node sees it: velocities in (REP-103, SI
//! units) and [`Reading`]s out, each generation's frames and units turned into the node's
//! once here. The port, the detection, the stop and the words for what happened are the
//! `chassis` tool's ([`chassis_cli`]): the node opens and stops a board exactly as every
//! `chassis` command does.

use crate::odom::{RawScale, Twist2, v1_twist, v1_yaw};
use chassis_cli::port;
use chassis_cli::stopping::{self, HostDriver, Spoken, Stopped};
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::driver::{DriverCore, Error, v1};
use chassis_protocol::{Downlink, Stream, Velocity};

/// The period at which the velocity commanded is sent again, ms: the `chassis drive` period,
/// well inside both generations' failsafe times.
pub const COMMAND_PERIOD_MS: u64 = 50;

/// What came from the board, in the node's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reading {
    /// A 2020 encoder frame: each wheel's count, as the board sends it.
    Encoders {
        /// The four counts.
        ticks: [i16; 4],
        /// When it came, ms (the driver's clock).
        at_ms: u64,
    },
    /// A v1.0.0 telemetry frame's measured body velocity (REP-103) and the yaw of its
    /// quaternion.
    Body {
        /// The velocity.
        twist: Twist2,
        /// Yaw, rad (counter-clockwise), when the quaternion is a rotation.
        yaw: Option<f32>,
        /// When it came, ms.
        at_ms: u64,
    },
    /// The IMU's raw counts, in the IMU's own axes, and an orientation where the board gives
    /// one (v1.0.0's quaternion, x, y, z, w).
    Imu {
        /// Accelerometer counts.
        accel: [i16; 3],
        /// Gyro counts.
        gyro: [i16; 3],
        /// The orientation, normalised.
        orientation: Option<[f64; 4]>,
    },
    /// The battery.
    Battery {
        /// V.
        volts: f32,
        /// The charge, 0 to 1, where the board reports one.
        fraction: Option<f32>,
    },
}

/// What the driver knows of the link, for `/diagnostics`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Link {
    /// A frame came within the driver's failsafe time.
    pub alive: bool,
    /// Anything at all has come.
    pub heard: bool,
    /// Each telemetry stream's rate, Hz, by name.
    pub rates: Vec<(&'static str, f64)>,
    /// Telemetry frames lost: missing by their counts (2020), refused for a bad checksum or
    /// end byte (v1.0.0).
    pub dropped: u32,
    /// Bytes that made no frame.
    pub discarded: u32,
    /// Times the driver's failsafe stopped the chassis.
    pub failsafe_stops: u32,
}

/// A firmware generation, as the node drives it.
pub trait Generation: Spoken + Sized {
    /// The firmware's name in `ready:` and the diagnostics ("2020", "v1.0.0").
    const NAME: &'static str;
    /// Opens the board's port with the host defaults.
    fn open(path: &str) -> Result<HostDriver<Self>, String>;
    /// Sends the velocity `twist` (REP-103), through `scale` where the board's unit is raw.
    fn send(
        driver: &mut HostDriver<Self>,
        twist: Twist2,
        scale: &RawScale,
    ) -> Result<(), Error<SerialError>>;
    /// What `event` says that the node publishes (nothing, or one reading per kind).
    fn readings(event: &Self::Event, driver: &HostDriver<Self>) -> Vec<Reading>;
    /// The link's state at the driver's last clock reading.
    fn link(driver: &HostDriver<Self>) -> Link;
}

/// A rate in mHz as Hz.
fn hz(millihertz: u32) -> f64 {
    f64::from(millihertz) / 1000.0
}

impl Generation for DriverCore {
    const NAME: &'static str = "2020";

    fn open(path: &str) -> Result<HostDriver<Self>, String> {
        port::open(path, None)
    }

    fn send(
        driver: &mut HostDriver<Self>,
        twist: Twist2,
        scale: &RawScale,
    ) -> Result<(), Error<SerialError>> {
        let (x, y, z) = scale.to_raw(twist);
        driver.set_velocity(Velocity::new(i32::from(x), i32::from(y), i32::from(z)))
    }

    fn readings(event: &Self::Event, driver: &HostDriver<Self>) -> Vec<Reading> {
        let chassis_protocol::driver::Event::Telemetry(frame) = event else {
            return Vec::new();
        };
        let reading = match frame {
            Downlink::Encoders(e) => Reading::Encoders {
                ticks: e.ticks,
                at_ms: driver.uart().now_ms(),
            },
            Downlink::Imu(imu) => Reading::Imu {
                accel: imu.accel,
                gyro: imu.gyro,
                orientation: None,
            },
            Downlink::Battery(b) => Reading::Battery {
                volts: f32::from(b.centivolts) / 100.0,
                fraction: Some(f32::from(b.percent.min(100)) / 100.0),
            },
            Downlink::Reply(_) => return Vec::new(),
        };
        vec![reading]
    }

    fn link(driver: &HostDriver<Self>) -> Link {
        let core = driver.core();
        let now = driver.uart().now_ms();
        let streams = [
            ("imu", Stream::Imu),
            ("encoders", Stream::Encoders),
            ("battery", Stream::Battery),
        ];
        let stats = core.parser_stats();
        Link {
            alive: core.link_alive(now),
            heard: core.last_heard_ms().is_some(),
            rates: streams
                .iter()
                .map(|(name, s)| (*name, hz(core.stream(*s).rate_millihertz)))
                .collect(),
            dropped: streams
                .iter()
                .fold(0u32, |n, (_, s)| n.saturating_add(core.stream(*s).missed)),
            discarded: stats.discarded,
            failsafe_stops: core.failsafe_stops(),
        }
    }
}

/// m/s or rad/s as the v1.0.0 board's thousandths, saturated.
fn milli(v: f32) -> i16 {
    let m = (v * 1000.0).round();
    if m.is_nan() {
        0
    } else {
        m.clamp(f32::from(i16::MIN), f32::from(i16::MAX)) as i16
    }
}

/// The v1.0.0 quaternion (w, x, y, z × 1000) as a unit one (x, y, z, w), if it is a rotation
/// at all (its norm within 20 % of 1000).
fn unit_quaternion(q: [i16; 4]) -> Option<[f64; 4]> {
    let [w, x, y, z] = q.map(|v| f64::from(v) / 1000.0);
    let norm = (w * w + x * x + y * y + z * z).sqrt();
    (0.8..=1.2)
        .contains(&norm)
        .then(|| [x / norm, y / norm, z / norm, w / norm])
}

impl Generation for v1::DriverCore {
    const NAME: &'static str = "v1.0.0";

    fn open(path: &str) -> Result<HostDriver<Self>, String> {
        port::open_v1(path, None)
    }

    /// The board's vx is sideways to the right and vy forward (the simulated board's axes, as
    /// [`v1_twist`] reads them back): REP-103's x forward is its vy, y to the left its −vx.
    fn send(
        driver: &mut HostDriver<Self>,
        twist: Twist2,
        _scale: &RawScale,
    ) -> Result<(), Error<SerialError>> {
        driver.set_velocity(chassis_protocol::v1::BodyVelocity::new(
            milli(-twist.vy),
            milli(twist.vx),
            milli(twist.wz),
        ))
    }

    fn readings(event: &Self::Event, driver: &HostDriver<Self>) -> Vec<Reading> {
        let v1::Event::Telemetry(t) = event else {
            return Vec::new();
        };
        vec![
            Reading::Body {
                twist: v1_twist(t),
                yaw: v1_yaw(t),
                at_ms: driver.uart().now_ms(),
            },
            Reading::Imu {
                accel: t.accel,
                gyro: t.gyro,
                orientation: unit_quaternion(t.quaternion),
            },
            Reading::Battery {
                volts: f32::from(t.battery_mv) / 1000.0,
                fraction: None,
            },
        ]
    }

    fn link(driver: &HostDriver<Self>) -> Link {
        let core = driver.core();
        let now = driver.uart().now_ms();
        let stats = core.parser_stats();
        let stream = core.stream();
        Link {
            alive: core.link_alive(now),
            heard: core.last_heard_ms().is_some(),
            rates: vec![("telemetry", hz(stream.rate_millihertz))],
            dropped: stream.missed.saturating_add(
                stats
                    .bad_checksum
                    .saturating_add(stats.bad_end)
                    .saturating_add(stats.refused),
            ),
            discarded: stats.discarded,
            failsafe_stops: core.failsafe_stops(),
        }
    }
}

/// Stops the chassis as every `chassis` command does on its way out: what the stop did.
pub fn stop<K: Spoken>(driver: &mut HostDriver<K>) -> Stopped {
    stopping::stop(driver)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn milli_rounds_and_saturates() {
        assert_eq!(milli(0.3), 300);
        assert_eq!(milli(-0.0005), -1); // half away from zero
        assert_eq!(milli(40.0), i16::MAX);
        assert_eq!(milli(-40.0), i16::MIN);
        assert_eq!(milli(f32::NAN), 0);
        assert_eq!(milli(f32::INFINITY), i16::MAX);
    }

    #[test]
    fn the_v1_quaternion_is_normalised() {
        // 90° about z: (cos 45°, 0, 0, sin 45°) × 1000 = (707, 0, 0, 707), norm 0.99985.
        let q = unit_quaternion([707, 0, 0, 707]).unwrap();
        assert!((q[2] - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        assert_eq!(q[2], q[3]);
        assert_eq!((q[0], q[1]), (0.0, 0.0));
        assert_eq!(unit_quaternion([1000, 0, 0, 0]), Some([0.0, 0.0, 0.0, 1.0]));
        assert_eq!(unit_quaternion([0, 0, 0, 0]), None);
        assert_eq!(unit_quaternion([i16::MAX; 4]), None);
    }
}
