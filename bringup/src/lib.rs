//! The chassis bring-up, written once: every board under `boards/` runs it over its own UART,
//! through the blocking or the async driver (see [`link`]).
//!
//! Two firmware generations, the same parts under the same names in a module each:
//!
//! | | 2020 (`FF FE` frames) | v1.0.0 (`7B … BCC 7D` frames) |
//! |---|---|---|
//! | the sequence | [`v2020::bring_up`] | [`v1::bring_up`] |
//! | what it does, how long | [`v2020::Plan`] | [`v1::Plan`] |
//! | what it needs of the driver (and [`link::Common`]) | [`v2020::Link`] | [`v1::Link`] |
//! | the driver as that link (feature `blocking`, `async`) | `v2020::Blocking`, `v2020::Async` | `v1::Blocking`, `v1::Async` |
//! | why a check failed | [`v2020::Why`] | [`v1::Why`] |
//! | what a passed bring-up measured | [`v2020::Report`] | [`v1::Report`] |
//! | a board's whole run | [`v2020::bring_up_and_park`] | [`v1::bring_up_and_park`] |
//!
//! Both run one sequence, written once: the checks in their order, each start and end noted,
//! the checks that move skipped without motion, the stop after a failure, the verdict. Each
//! module holds only what its checks do, and its documentation lists them in order. A board
//! that may meet either generation finds out first with `chassis_protocol::detect::detect`
//! (the QEMU board does), then runs that generation's bring-up. Shared, here: the [`Check`]s
//! (the same names and exit codes on both), [`Note`], [`Skip`], [`Failure`] (a check and the
//! generation's reason), the [`Timing`] both plans hold, and the [`link`] wrappers. Nothing of
//! either generation is re-exported at the root: a board running the 2020 bring-up names it,
//! `chassis_bringup::v2020::{Plan, bring_up_and_park}`.
//!
//! It is written as `async` code and compiled one of two ways: as is (feature `async`, for an
//! executor such as embassy's), or as plain blocking code (feature `blocking`: the
//! `maybe-async` macro removes every `async` and `.await`), so that a board without an executor
//! runs it as ordinary function calls, and its firmware has no future that could be polled
//! after it finished (a panic path the no-panic proof would find). The two features exclude
//! each other: `maybe-async` picks one form for the whole build.
//!
//! Any failure stops the chassis (best effort) and names its check. Nothing here panics: the
//! boards' release builds prove it at link time.

#![no_std]
#![warn(missing_docs)]

#[cfg(all(feature = "blocking", feature = "async"))]
compile_error!("features `blocking` and `async` exclude each other: a board picks one");

/// The bring-up's log: defmt with feature `defmt`; without it, nothing (a PC follows the
/// bring-up through each generation's `Link::note` instead).
#[cfg(feature = "defmt")]
macro_rules! log {
    ($level:ident, $($t:tt)*) => {
        defmt::$level!($($t)*)
    };
}

/// The bring-up's log: defmt with feature `defmt`; without it, nothing (a PC follows the
/// bring-up through each generation's `Link::note` instead).
#[cfg(not(feature = "defmt"))]
macro_rules! log {
    ($level:ident, $fmt:literal $(, $arg:expr)* $(,)?) => {{
        $(let _ = &$arg;)*
    }};
}

pub mod link;
mod sequence;
pub mod v1;
pub mod v2020;

/// embassy-time as the driver's clock (feature `embassy`).
#[cfg(feature = "embassy")]
pub mod embassy {
    /// Milliseconds of `embassy_time::Instant` (a handle: copy it freely).
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Millis;

    impl chassis_protocol::driver::Clock for Millis {
        fn now_ms(&mut self) -> u64 {
            embassy_time::Instant::now().as_millis()
        }
    }
}

pub use link::LinkError;

/// What both generations' plans hold: whether the chassis may move, and how long the steps
/// both run take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Timing {
    /// Whether the chassis may move. `false`: only [`Check::Link`], [`Check::Settings`] and
    /// [`Check::Battery`] run (nothing is written, nothing moves); the others are skipped.
    pub motion: bool,
    /// How long telemetry is listened to before rates are judged, ms (at least 1 s: 2020
    /// battery frames come at 1 Hz).
    pub listen_ms: u64,
    /// How long each straight motion lasts, ms.
    pub drive_ms: u64,
    /// The motion commands are re-sent this often, ms (well inside the driver's failsafe).
    pub command_period_ms: u64,
    /// How long the steady control loop runs, ms.
    pub loop_ms: u64,
}

impl Timing {
    /// What every board runs by default.
    pub const DEFAULT: Timing = Timing {
        motion: true,
        listen_ms: 1_200,
        drive_ms: 400,
        command_period_ms: 40,
        loop_ms: 1_500,
    };
}

/// A step of the bring-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Check {
    /// Telemetry arrives at its rates (v1.0.0: its one frame, at 20–24 Hz).
    Link,
    /// Every register read (v1.0.0: the system, geometry and PID readbacks; nothing written).
    Settings,
    /// The build's drive type is set (2020 only: v1.0.0 has no such register).
    DriveType,
    /// Forward: the encoders count (v1.0.0: the measured velocity follows vy).
    Forward,
    /// Sideways: the encoders count (v1.0.0: the measured velocity follows vx).
    Strafe,
    /// The one-shot turn: the gyro sees it, the pending angle reaches 0 (v1.0.0, which has no
    /// turn by an angle: a rotation at a rate, the quaternion's yaw turns by wz × t).
    Turn,
    /// After a stop the encoders stand still (v1.0.0: after the forced stop, the measured
    /// velocity is 0).
    Stop,
    /// The battery is above its cut-off.
    Battery,
    /// The steady control loop: no failsafe stop while reads go on (v1.0.0: while the
    /// velocity is re-sent; telemetry keeps coming).
    ControlLoop,
}

impl Check {
    /// Every check, in the order the bring-up runs them.
    pub const ALL: [Check; 9] = [
        Check::Link,
        Check::Settings,
        Check::DriveType,
        Check::Forward,
        Check::Strafe,
        Check::Turn,
        Check::Stop,
        Check::Battery,
        Check::ControlLoop,
    ];

    /// Its name in logs and on a PC's screen.
    pub const fn name(self) -> &'static str {
        match self {
            Check::Link => "link",
            Check::Settings => "settings",
            Check::DriveType => "drive-type",
            Check::Forward => "forward",
            Check::Strafe => "strafe",
            Check::Turn => "turn",
            Check::Stop => "stop",
            Check::Battery => "battery",
            Check::ControlLoop => "control-loop",
        }
    }

    /// Whether it moves the chassis or writes to the board (skipped when
    /// [`Timing::motion`] is `false`).
    pub const fn moves(self) -> bool {
        !matches!(self, Check::Link | Check::Settings | Check::Battery)
    }

    /// The process exit code under QEMU when this check fails (0 means every check passed).
    pub const fn exit_code(self) -> i32 {
        match self {
            Check::Link => 10,
            Check::Settings => 11,
            Check::DriveType => 12,
            Check::Forward => 13,
            Check::Strafe => 14,
            Check::Turn => 15,
            Check::Stop => 16,
            Check::Battery => 17,
            Check::ControlLoop => 18,
        }
    }
}

/// What the bring-up is doing, for a program that shows its progress (each generation's
/// `Link::note`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Note {
    /// A check starts.
    Start(Check),
    /// A check passed.
    Passed(Check),
    /// A check is skipped, and why.
    Skipped(Check, Skip),
}

/// Why a check is skipped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Skip {
    /// [`Timing::motion`] is `false`.
    NoMotion,
    /// 2020: [`v2020::Plan::drive`] is `None`: the board's drive type is kept.
    DriveTypeKept,
    /// 2020: a differential chassis does not move sideways (X is unused).
    NoSideways,
    /// 2020: a chassis without encoders (open-loop differential): nothing to count.
    NoEncoders,
}

/// A failed check and why: `W` is the generation's reason ([`v2020::Why`], [`v1::Why`]; each
/// generation names its own as `Failure`: [`v2020::Failure`], [`v1::Failure`]). The checks and
/// their exit codes are shared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Failure<W> {
    /// The check that failed.
    pub check: Check,
    /// Why.
    pub why: W,
}

impl<W: From<LinkError>> Failure<W> {
    /// `check` failed because the driver did (`Why::Driver`): what `map_err` takes.
    fn driver(check: Check) -> impl Fn(LinkError) -> Self {
        move |e| failure(check, W::from(e))
    }
}

/// `check` failed, and why.
const fn failure<W>(check: Check, why: W) -> Failure<W> {
    Failure { check, why }
}

/// A span of ms as the divisor of a rate: 32-bit (a Cortex-M divides that in hardware; 64-bit
/// division is a library routine of nearly 1 KB), at least 1. A listening time fits, and so do
/// its frames × 10 000.
fn divisor_ms(ms: u64) -> u32 {
    u32::try_from(ms.max(1)).unwrap_or(u32::MAX)
}

/// Frames per 10 s of `frames` in `ms`.
fn per_10s(frames: u32, ms: u64) -> u32 {
    frames
        .saturating_mul(10_000)
        .checked_div(divisor_ms(ms))
        .unwrap_or(0)
}
