//! The bring-up of a board running firmware **v1.0.0** (`7B … BCC 7D` frames, see
//! `docs/firmware-generations.md`): [`bring_up`] over a [`Link`], the v1.0.0 driver
//! (`Blocking`, `Async`, each made with `new`). Its twin for the 2020 firmware is
//! [`crate::v2020`], the same parts under the same names.
//!
//! The sequence, each step a named [`Check`] (run in this order by the one sequence both
//! generations share; what each does here is in `checks.rs`):
//!
//! 1. [`Check::Link`]: telemetry frames (one 32-byte frame, 20–24 Hz) are counted over
//!    [`Timing::listen_ms`]: at least 70 % of 20 Hz.
//! 2. [`Check::Settings`]: the system, geometry and PID readbacks (`0x33`, `0x34`, `0x50`),
//!    logged. **Nothing is written**: the settings frames would overwrite what the owner tuned.
//! 3. [`Check::Forward`], [`Check::Strafe`]: vy, then vx, at [`Plan::speed_mm_s`] for
//!    [`Timing::drive_ms`], re-sent every [`Timing::command_period_ms`]; the measured body
//!    velocity in the telemetry of the second half must follow (its mean within
//!    [`Plan::tolerance_percent`] of the command).
//! 4. [`Check::Turn`], here **a rotation at a rate** (v1.0.0 has no turn by an angle): wz at
//!    [`Plan::turn_rate_mrad_s`] for [`Plan::turn_ms`]; after the first [`RAMP_MS`], the yaw
//!    from the telemetry's quaternion must turn by wz × the time between the first and the last
//!    frame judged, within [`Plan::tolerance_percent`] (frame-to-frame changes are added up, so
//!    more than half a turn is measured right too).
//! 5. [`Check::Stop`]: the forced stop (`0x25`, `ctl = 0`, all zeros) while rotating; after
//!    [`STOP_SETTLE_MS`], every frame for [`STOP_WATCH_MS`] shows the chassis still (|vx|,
//!    |vy| ≤ [`STILL_MM_S`], |wz| ≤ [`STILL_MRAD_S`]).
//! 6. [`Check::Battery`]: the latest frame's battery above [`Plan::min_millivolts`] (a frame
//!    carries a BCC: one reading is judged).
//! 7. [`Check::ControlLoop`]: a steady loop, [`Plan::speed_mm_s`] / 2 forward re-sent every
//!    period for [`Timing::loop_ms`] (the board drops a few frames while commanded): telemetry
//!    keeps coming (70 % of 20 Hz) and the driver's failsafe never stops the chassis; then the
//!    forced stop.
//!
//! There is no [`Check::DriveType`] on v1.0.0 (no register holds one: every velocity frame
//! carries the vendor's type byte, 4), so its exit code never comes from here. Without
//! [`Timing::motion`], only checks 1, 2 and 6 run, and only readbacks are sent. Any failure
//! sends the forced stop (best effort, if the plan moves the chassis). A passed bring-up ends
//! with the forced stop. Nothing panics.

mod checks;
mod drive;
#[cfg(any(feature = "blocking", feature = "async"))]
mod link;
mod yaw;

#[cfg(doc)]
use crate::Check;
use crate::link::Common;
use crate::{LinkError, Timing};
use chassis_protocol::driver::v1::{DriverCore, Event};
use chassis_protocol::v1::{BodyVelocity, Geometry, Pid, Readback, Reply, SystemSettings};

/// The shared blocking wrapper over the v1.0.0 driver: a [`Link`] (feature `blocking`).
#[cfg(feature = "blocking")]
pub type Blocking<U, C> = crate::link::Blocking<U, C, DriverCore>;

/// The shared async wrapper over the v1.0.0 driver: a [`Link`] (feature `async`).
#[cfg(feature = "async")]
pub type Async<U, C, D> = crate::link::Async<U, C, D, DriverCore>;

/// The least telemetry rate, frames per 10 s: 70 % of 20 Hz, the low end of what owners
/// measured.
pub const MIN_TELEMETRY_PER_10S: u32 = 140;
/// The first ms of the rotation check that are not judged: the chassis gets up to speed.
pub const RAMP_MS: u64 = 200;
/// After the forced stop, the chassis has this long to stand still, ms.
pub const STOP_SETTLE_MS: u64 = 200;
/// Then every frame for this long must show it still, ms.
pub const STOP_WATCH_MS: u64 = 300;
/// Still: |vx| and |vy| at most this, mm/s.
pub const STILL_MM_S: u16 = 20;
/// Still: |wz| at most this, mrad/s.
pub const STILL_MRAD_S: u16 = 50;

/// What the v1.0.0 bring-up does, and how long each step takes.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plan {
    /// Whether the chassis may move; how long listening, each drive and the control loop
    /// last; how often motion is re-sent.
    pub timing: Timing,
    /// Speed of the straight checks, mm/s (the control loop goes at half of it).
    pub speed_mm_s: i16,
    /// The rate of the rotation check (v1.0.0 has no turn by an angle), mrad/s.
    pub turn_rate_mrad_s: i16,
    /// How long the rotation check rotates, ms (its first [`RAMP_MS`] are not judged).
    pub turn_ms: u64,
    /// The battery voltage at or below which the bring-up fails, mV.
    pub min_millivolts: u16,
    /// How far a measured velocity, and the yaw turned, may be from what was commanded, % of
    /// it.
    pub tolerance_percent: u8,
}

impl Plan {
    /// The bring-up a board runs by default: about 6 s end to end.
    pub const DEFAULT: Plan = Plan {
        timing: Timing::DEFAULT,
        speed_mm_s: 300,
        turn_rate_mrad_s: 1_000,
        turn_ms: 1_200,
        min_millivolts: 9_000,
        tolerance_percent: 25,
    };
}

/// Why a check failed on v1.0.0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Why {
    /// The driver failed (transport error, a readback unanswered…).
    Driver(LinkError),
    /// Telemetry came too slowly: frames per 10 s measured.
    Rate(u32),
    /// No telemetry frame came when one was needed to judge (the board went quiet before the
    /// failsafe's time was up).
    NoTelemetry,
    /// The measured velocity did not follow the command: (commanded, measured mean), mm/s.
    NotFollowed(i16, i16),
    /// The yaw did not turn by what the rotation should have: (expected, measured), mrad.
    YawOff(i32, i32),
    /// The chassis was still moving after the forced stop: the largest |vx|, |vy| (mm/s) and
    /// |wz| (mrad/s) seen.
    StillMoving([u16; 3]),
    /// The battery is at or below the cut-off: (mV, cut-off mV).
    LowBattery(i16, u16),
    /// The driver's failsafe stopped the chassis: the board went quiet.
    FailsafeStop,
}

/// A driver error: [`Why::Driver`].
impl From<LinkError> for Why {
    fn from(e: LinkError) -> Self {
        Why::Driver(e)
    }
}

/// A failed v1.0.0 check and why.
pub type Failure = crate::Failure<Why>;

/// What a passed v1.0.0 bring-up measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Telemetry frames per 10 s while listening.
    pub telemetry_per_10s: u32,
    /// The system settings read back.
    pub system: SystemSettings,
    /// The geometry read back.
    pub geometry: Geometry,
    /// The PID gains read back.
    pub pid: Pid,
    /// The mean measured vy while driving forward, and vx while driving sideways, mm/s.
    pub measured_mm_s: [i16; 2],
    /// The rotation: the yaw turned as wz × t said, and as the quaternion measured, mrad.
    pub yaw_expected_mrad: i32,
    /// The yaw turned as measured, mrad.
    pub yaw_measured_mrad: i32,
    /// The largest |gyro z| seen while rotating (raw: read by one user as mrad/s).
    pub gyro_z_peak: u16,
    /// The largest |vx|, |vy| (mm/s), |wz| (mrad/s) seen once stopped.
    pub still_peak: [u16; 3],
    /// Battery voltage, mV.
    pub battery_mv: i16,
    /// Telemetry frames per 10 s during the control loop.
    pub loop_per_10s: u32,
    /// Whole frames the driver's parser refused over the bring-up (bad BCC, bad end, a
    /// payload that is no frame).
    pub bad_frames: u32,
}

/// The calls the v1.0.0 bring-up makes: [`Common`]'s (over the v1.0.0 core) and these; each
/// is the v1.0.0 driver's call of the same name.
///
/// `async` (the futures are not `Send`: a bring-up runs on one core, in one task), or plain
/// functions with feature `blocking`.
#[allow(async_fn_in_trait)]
#[maybe_async::maybe_async(AFIT)]
pub trait Link: Common<Core = DriverCore, Event = Event> {
    /// Sets the body velocity (`0x25`).
    async fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError>;
    /// One readback: the board's reply.
    async fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError>;
}

crate::sequence::entry_points!(
    /// Runs the whole v1.0.0 bring-up on `link`. On a failure the chassis gets the forced stop
    /// (best effort, if the plan moves it) and the failed check is returned.
);
