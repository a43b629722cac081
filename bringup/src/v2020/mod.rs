//! The bring-up of a board running the **2020** firmware (`FF FE` frames): [`bring_up`] over a
//! [`Link`], the 2020 driver (`Blocking`, `Async`, each made with `new`). Its twin for
//! v1.0.0 is [`crate::v1`], the same parts under the same names.
//!
//! The sequence, each step a named [`Check`] (run in this order by the one sequence both
//! generations share; what each does here is in `checks.rs`):
//!
//! 1. [`Check::Link`]: telemetry arrives; each stream's rate is measured over
//!    [`Timing::listen_ms`] and must be near its nominal one (IMU 100 Hz, encoders 25 Hz,
//!    battery 1 Hz).
//! 2. [`Check::Settings`]: every register and the pending angle are read (each register read
//!    twice until two replies agree: there is no checksum) into a [`Snapshot`], logged and
//!    encoded with postcard (what a firmware would keep in flash to restore later). With
//!    motion, a turn left pending (by a program that was killed) is then cancelled.
//! 3. [`Check::DriveType`]: the build's drive type ([`Plan::drive`]) is written to the system
//!    mode register if the board has another one, and read back.
//! 4. [`Check::Forward`], [`Check::Strafe`]: a short drive each, re-sent every
//!    [`Timing::command_period_ms`]; the encoders must count.
//! 5. [`Check::Turn`]: one 90° turn, sent **once** (the board adds turns up); the gyro must see
//!    it and the pending angle must reach 0.
//! 6. [`Check::Stop`]: after a stop, the encoders stand still (most encoder frames in a row
//!    agree: one frame with a changed byte is not motion).
//! 7. [`Check::Battery`]: the battery is above its cut-off (a reading at or below it is judged
//!    again on the next battery frame: one frame can carry a changed byte).
//! 8. [`Check::ControlLoop`]: a steady control loop (slow forward, the velocity re-sent each
//!    period, a verified register read every [`Plan::loop_read_every_ms`] while moving): no
//!    failsafe stop; then stop.
//!
//! Without [`Timing::motion`], only checks 1, 2 and 7 run, and nothing but reads is sent. Any
//! failure stops the chassis (best effort) and names its check.
//!
//! [`Snapshot`]: chassis_protocol::registers::Snapshot

mod checks;
mod drive;
#[cfg(any(feature = "blocking", feature = "async"))]
mod link;

pub use checks::{SNAPSHOT_POSTCARD_MAX, encode_snapshot};

#[cfg(doc)]
use crate::Check;
use crate::link::Common;
use crate::{LinkError, Timing};
use chassis_protocol::driver::{DriverCore, Event};
use chassis_protocol::registers::Snapshot;
use chassis_protocol::{DriveType, Register, Stream, Turn, Velocity, Write};

/// The shared blocking wrapper over the 2020 driver: a [`Link`] (feature `blocking`).
#[cfg(feature = "blocking")]
pub type Blocking<U, C> = crate::link::Blocking<U, C, DriverCore>;

/// The shared async wrapper over the 2020 driver: a [`Link`] (feature `async`).
#[cfg(feature = "async")]
pub type Async<U, C, D> = crate::link::Async<U, C, D, DriverCore>;

/// What the 2020 bring-up does, and how long each step takes.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plan {
    /// Whether the chassis may move; how long listening, each drive and the control loop
    /// last; how often motion is re-sent.
    pub timing: Timing,
    /// The chassis's drive type, as built: written to the board if it has another. `None`:
    /// the board's own is kept (and reported).
    pub drive: Option<DriveType>,
    /// Speed of the motion checks, in the velocity frame's raw units.
    pub speed: i32,
    /// The one-shot turn, 0.1°.
    pub turn_deci_degrees: i32,
    /// The turn must be done within this, ms.
    pub turn_timeout_ms: u64,
    /// A register read every this many ms during the control loop.
    pub loop_read_every_ms: u64,
    /// The gyro Z reading (raw counts) a turn must exceed at least once: well above the
    /// sensor's noise at rest.
    pub gyro_threshold: u16,
    /// Battery voltage below which the bring-up fails when the board uses its built-in table
    /// (0.01 V).
    pub min_centivolts: u16,
}

impl Plan {
    /// The bring-up every board runs by default: about 6 s end to end.
    pub const DEFAULT: Plan = Plan {
        timing: Timing::DEFAULT,
        drive: Some(DriveType::Mecanum),
        speed: 300,
        turn_deci_degrees: 900,
        turn_timeout_ms: 3_000,
        loop_read_every_ms: 250,
        gyro_threshold: 20,
        min_centivolts: 1_050,
    };
}

/// Why a check failed on the 2020 firmware.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Why {
    /// The driver failed (transport error, timeout, unconfirmed read…).
    Driver(LinkError),
    /// A stream sent nothing, or too few frames: (stream, frames per 10 s measured).
    Rate(Stream, u32),
    /// The encoders did not move.
    EncodersStill,
    /// The encoders kept moving after a stop.
    EncodersMoving,
    /// The gyro saw no rotation.
    GyroStill,
    /// The turn was not done in time: the angle still pending, 0.1°.
    TurnPending(i32),
    /// The drive type read back is not the one written.
    DriveTypeNotSet(DriveType),
    /// The battery is at or below the limit: (centivolts, limit).
    LowBattery(u16, u16),
    /// No battery frame to judge.
    NoBattery,
    /// The driver's failsafe stopped the chassis: the board went quiet.
    FailsafeStop,
    /// No encoder frame came during a drive: the board went quiet (before the failsafe's
    /// time was up: it allows a board more after a settings frame).
    NoEncoderFrames,
}

/// A driver error: [`Why::Driver`].
impl From<LinkError> for Why {
    fn from(e: LinkError) -> Self {
        Why::Driver(e)
    }
}

/// A failed 2020 check and why.
pub type Failure = crate::Failure<Why>;

/// What a passed 2020 bring-up measured.
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Frames per 10 s of each stream: IMU, encoders, battery.
    pub rates_per_10s: [u32; 3],
    /// Every register.
    pub snapshot: Snapshot,
    /// The angle pending before the turn, 0.1°.
    pub pending_before: i32,
    /// Encoder ticks counted during forward and sideways (sum of |Δ| over the wheels).
    pub ticks: [u32; 2],
    /// The largest |gyro Z| seen during the turn.
    pub gyro_peak: u16,
    /// Battery voltage, 0.01 V, and percent.
    pub battery: (u16, u16),
    /// Register reads done while moving in the control loop.
    pub loop_reads: u32,
    /// Telemetry frames the parser counted as missed over the whole bring-up.
    pub missed: u32,
}

/// The calls the 2020 bring-up makes: [`Common`]'s (over the 2020 core) and these; each is
/// the 2020 driver's call of the same name.
///
/// `async` (the futures are not `Send`: a bring-up runs on one core, in one task), or plain
/// functions with feature `blocking`.
#[allow(async_fn_in_trait)]
#[maybe_async::maybe_async(AFIT)]
pub trait Link: Common<Core = DriverCore, Event = Event> {
    /// Sets the body velocity.
    async fn set_velocity(&mut self, velocity: Velocity) -> Result<(), LinkError>;
    /// Sends a turn, once.
    async fn turn(&mut self, turn: Turn) -> Result<(), LinkError>;
    /// The angle still to turn, 0.1°.
    async fn turn_remaining(&mut self) -> Result<i32, LinkError>;
    /// Every register, each read verified.
    async fn read_settings(&mut self) -> Result<Snapshot, LinkError>;
    /// One register, untyped, read until two replies agree (there is no checksum: one reply
    /// can carry a changed byte).
    async fn read_verified(&mut self, register: Register) -> Result<u32, LinkError>;
    /// One register write.
    async fn write(&mut self, write: Write) -> Result<(), LinkError>;
}

crate::sequence::entry_points!(
    /// Runs the whole 2020 bring-up on `link`. On a failure the chassis is stopped (best
    /// effort) and the failed check returned.
);
