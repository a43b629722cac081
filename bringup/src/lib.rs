//! The chassis bring-up, written once: every board under `boards/` runs [`bring_up`] over its
//! own UART, through the blocking or the async driver (see [`link`]).
//!
//! Two firmware generations, two sequences of the same [`Check`]s (same names, same exit
//! codes): [`bring_up`] for the 2020 firmware (`FF FE` frames, below), and
//! [`v1::bring_up_v1`] for v1.0.0 (`7B … BCC 7D` frames: the measured velocity instead of the
//! encoders, a rotation at a rate instead of the turn by an angle, the forced stop, nothing
//! written; see [`v1`]). A board that may meet either finds out first with
//! `chassis_protocol::detect::detect` (the QEMU board does). [`Note`], [`Plan`] and
//! [`Failure`] are shared; a failure's reason is the generation's ([`Why`], [`v1::WhyV1`]).
//!
//! It is written as `async` code and compiled one of two ways: as is (feature `async`, for an
//! executor such as embassy's), or as plain blocking code (feature `blocking`: the
//! `maybe-async` macro removes every `async` and `.await`), so that a board without an executor
//! runs it as ordinary function calls, and its firmware has no future that could be polled
//! after it finished (a panic path the no-panic proof would find).
//!
//! The 2020 sequence, each step a named [`Check`]:
//!
//! 1. [`Check::Link`]: telemetry arrives; each stream's rate is measured over
//!    [`Plan::listen_ms`] and must be near its nominal one (IMU 100 Hz, encoders 25 Hz,
//!    battery 1 Hz).
//! 2. [`Check::Settings`]: every register and the pending angle are read (each register read
//!    twice until two replies agree: there is no checksum) into a [`Snapshot`], logged and
//!    encoded with postcard (what a firmware would keep in flash to restore later).
//! 3. [`Check::DriveType`]: the build's drive type ([`Plan::drive`]) is written to the system
//!    mode register if the board has another one, and read back.
//! 4. [`Check::Forward`], [`Check::Strafe`]: a short drive each, re-sent every
//!    [`Plan::command_period_ms`]; the encoders must count.
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
//! Any failure stops the chassis (best effort) and names its check. Nothing here panics: the
//! boards' release builds prove it at link time.

#![no_std]
#![warn(missing_docs)]

#[cfg(all(feature = "blocking", feature = "async"))]
compile_error!("features `blocking` and `async` exclude each other: a board picks one");

/// The bring-up's log: defmt with feature `defmt`; without it, nothing (a PC follows the
/// bring-up through [`Link::note`] instead).
#[cfg(feature = "defmt")]
macro_rules! log {
    ($level:ident, $($t:tt)*) => {
        defmt::$level!($($t)*)
    };
}

/// The bring-up's log: defmt with feature `defmt`; without it, nothing (a PC follows the
/// bring-up through [`Link::note`] instead).
#[cfg(not(feature = "defmt"))]
macro_rules! log {
    ($level:ident, $fmt:literal $(, $arg:expr)* $(,)?) => {{
        $(let _ = &$arg;)*
    }};
}

pub mod link;
pub mod v1;

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

use chassis_protocol::driver::Event;
use chassis_protocol::registers::Snapshot;
use chassis_protocol::{Downlink, DriveType, Kind, Register, Stream, Turn, Velocity, Write};
pub use link::{Link, LinkError};

/// What the bring-up does, and how long each step takes.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plan {
    /// The chassis's drive type, as built: written to the board if it has another. `None`:
    /// the board's own is kept (and reported).
    pub drive: Option<DriveType>,
    /// Whether the chassis may move. `false`: only [`Check::Link`], [`Check::Settings`] and
    /// [`Check::Battery`] run (nothing is written, nothing moves); the others are skipped.
    /// Both generations.
    pub motion: bool,
    /// How long telemetry is listened to before rates are judged, ms (at least 1 s: 2020
    /// battery frames come at 1 Hz). Both generations.
    pub listen_ms: u64,
    /// Speed of the motion tests (the velocity frame's units: raw on 2020, mm/s on v1.0.0).
    pub speed: i32,
    /// How long each straight motion lasts, ms. Both generations.
    pub drive_ms: u64,
    /// The motion commands are re-sent this often, ms (well inside the driver's failsafe).
    /// Both generations.
    pub command_period_ms: u64,
    /// The one-shot turn, 0.1° (2020: v1.0.0 has no turn by an angle).
    pub turn_deci_degrees: i32,
    /// The turn must be done within this, ms.
    pub turn_timeout_ms: u64,
    /// How long the steady control loop runs, ms. Both generations.
    pub loop_ms: u64,
    /// A register read every this many ms during the control loop (2020).
    pub loop_read_every_ms: u64,
    /// The gyro Z reading (raw counts) a turn must exceed at least once: well above the
    /// sensor's noise at rest.
    pub gyro_threshold: u16,
    /// Battery voltage below which the bring-up fails when the board uses its built-in table
    /// (0.01 V).
    pub min_centivolts: u16,
    /// v1.0.0 (which has no turn by an angle): the rate of the rotation check, mrad/s.
    pub turn_rate_mrad_s: i16,
    /// v1.0.0: how long the rotation check rotates, ms (its first
    /// [`v1::RAMP_MS`] are not judged).
    pub turn_ms: u64,
    /// v1.0.0: the battery voltage at or below which the bring-up fails, mV.
    pub min_millivolts: u16,
    /// v1.0.0: how far a measured velocity, and the yaw turned, may be from what was
    /// commanded, % of it.
    pub tolerance_percent: u8,
}

impl Plan {
    /// The bring-up every board runs by default: about 6 s end to end.
    pub const DEFAULT: Plan = Plan {
        drive: Some(DriveType::Mecanum),
        motion: true,
        listen_ms: 1_200,
        speed: 300,
        drive_ms: 400,
        command_period_ms: 40,
        turn_deci_degrees: 900,
        turn_timeout_ms: 3_000,
        loop_ms: 1_500,
        loop_read_every_ms: 250,
        gyro_threshold: 20,
        min_centivolts: 1_050,
        turn_rate_mrad_s: 1_000,
        turn_ms: 1_200,
        min_millivolts: 9_000,
        tolerance_percent: 25,
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
    /// [`Plan::motion`] is `false`).
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

/// What the bring-up is doing, for a program that shows its progress ([`Link::note`]).
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
    /// [`Plan::motion`] is `false`.
    NoMotion,
    /// [`Plan::drive`] is `None`: the board's drive type is kept.
    DriveTypeKept,
    /// A differential chassis does not move sideways (X is unused).
    NoSideways,
    /// A chassis without encoders (open-loop differential): nothing to count.
    NoEncoders,
}

/// Why a check failed.
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

/// A failed check and why: [`Why`] on the 2020 firmware, [`v1::WhyV1`] on v1.0.0 (the checks
/// and their exit codes are shared, the reasons are the generation's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Failure<W = Why> {
    /// The check that failed.
    pub check: Check,
    /// Why.
    pub why: W,
}

/// What a passed bring-up measured.
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

/// The longest postcard encoding of a [`Snapshot`] (varints: 3 bytes per u16, 5 per u32).
pub const SNAPSHOT_POSTCARD_MAX: usize = 3 + 5 + 5 + 5 + 5 + 3 + 3 + 3 + 3;

/// Encodes `snapshot` with postcard into `buf`; the bytes written.
pub fn encode_snapshot<'a>(
    snapshot: &Snapshot,
    buf: &'a mut [u8; SNAPSHOT_POSTCARD_MAX],
) -> &'a [u8] {
    match postcard::to_slice(snapshot, buf) {
        Ok(bytes) => bytes,
        Err(_) => &[],
    }
}

fn fail(check: Check) -> impl Fn(LinkError) -> Failure {
    move |e| Failure {
        check,
        why: Why::Driver(e),
    }
}

/// Runs the whole bring-up on `link`. On a failure the chassis is stopped (best effort) and
/// the failed check returned.
#[maybe_async::maybe_async]
pub async fn bring_up<L: Link>(link: &mut L, plan: &Plan) -> Result<Report, Failure> {
    let result = steps(link, plan).await;
    if let Err(failure) = &result {
        log!(error, "bring-up: {} failed: {}", failure.check, failure.why);
        // Without motion nothing was set moving: nothing but reads is sent.
        if plan.motion {
            if let Err(e) = link.stop().await {
                log!(error, "stop after the failure: {}", e);
            }
        }
    }
    result
}

/// What a board on real hardware does: runs the bring-up, logs its verdict, then keeps reading
/// telemetry for ever (the chassis stopped, so the failsafe has nothing to do).
#[maybe_async::maybe_async]
pub async fn bring_up_and_park<L: Link>(link: &mut L, plan: &Plan) -> ! {
    match bring_up(link, plan).await {
        Ok(report) => log!(info, "PASS: every check passed: {}", report),
        Err(failure) => log!(error, "FAIL: {} ({})", failure.check, failure.why),
    }
    loop {
        if let Err(e) = link.poll().await {
            log!(warn, "link: {}", e);
        }
    }
}

#[maybe_async::maybe_async]
async fn steps<L: Link>(link: &mut L, plan: &Plan) -> Result<Report, Failure> {
    let mut report = Report::default();

    // 1. Link up: count each stream's frames over the listening time.
    link.note(Note::Start(Check::Link));
    log!(
        info,
        "[link] listening to telemetry for {} ms",
        plan.listen_ms
    );
    let mut counts = [0u32; 3];
    let start = link.now_ms();
    while link.now_ms().saturating_sub(start) < plan.listen_ms {
        if let Some(Event::Telemetry(frame)) = link.poll().await.map_err(fail(Check::Link))? {
            if let Kind::Telemetry(stream) = frame.kind() {
                if let Some(c) = counts.get_mut(stream.index()) {
                    *c = c.saturating_add(1);
                }
            }
        }
    }
    // 32-bit arithmetic: a Cortex-M divides it in hardware (64-bit division is a library
    // routine of nearly 1 KB); a listening time fits, and so do its frames × 10 000.
    let elapsed = u32::try_from(link.now_ms().saturating_sub(start).max(1)).unwrap_or(u32::MAX);
    for stream in Stream::ALL {
        let i = stream.index();
        let frames = counts.get(i).copied().unwrap_or(0);
        let per_10s = frames
            .saturating_mul(10_000)
            .checked_div(elapsed)
            .unwrap_or(0);
        if let Some(r) = report.rates_per_10s.get_mut(i) {
            *r = per_10s;
        }
        // At least 70 % of the nominal rate (battery: one frame in the window).
        let nominal_per_10s = u32::from(stream.rate_hz()) * 10;
        let enough = match stream {
            Stream::Battery => frames >= 1,
            _ => per_10s >= nominal_per_10s * 7 / 10,
        };
        if !enough {
            log!(
                warn,
                "[link] frames {} in {} ms; parser {}",
                counts,
                elapsed,
                link.core().parser_stats()
            );
            return Err(Failure {
                check: Check::Link,
                why: Why::Rate(stream, per_10s),
            });
        }
    }
    log!(
        info,
        "[link] up: IMU {} Hz, encoders {} Hz, battery {} frame(s)",
        report.rates_per_10s[0] / 10,
        report.rates_per_10s[1] / 10,
        counts[2]
    );

    link.note(Note::Passed(Check::Link));

    // 2. Every register, and the pending angle.
    link.note(Note::Start(Check::Settings));
    let snapshot = link.read_settings().await.map_err(fail(Check::Settings))?;
    report.pending_before = pending_angle(link).await.map_err(fail(Check::Settings))?;
    report.snapshot = snapshot;
    log!(info, "[settings] {}", snapshot);
    log!(
        info,
        "[settings] pending angle {} (0.1°)",
        report.pending_before
    );
    let mut buf = [0u8; SNAPSHOT_POSTCARD_MAX];
    let encoded = encode_snapshot(&snapshot, &mut buf);
    log!(
        info,
        "[settings] postcard ({} bytes): {=[u8]:02x}",
        encoded.len(),
        encoded
    );

    link.note(Note::Passed(Check::Settings));

    let failsafe_before = link.core().failsafe_stops();
    if plan.motion && report.pending_before.unsigned_abs() > 10 {
        // A turn left pending (by a program that was killed): cancelled before anything moves.
        log!(
            warn,
            "[settings] a turn of {} (0.1°) was pending: cancelled",
            report.pending_before
        );
        link.stop().await.map_err(fail(Check::Settings))?;
    }
    if plan.motion {
        motion_checks(link, plan, &snapshot, &mut report, failsafe_before).await?;
    } else {
        for check in [
            Check::DriveType,
            Check::Forward,
            Check::Strafe,
            Check::Turn,
            Check::Stop,
        ] {
            link.note(Note::Skipped(check, Skip::NoMotion));
        }
    }

    // 7. Battery: above the cut-off. One frame can carry a changed byte (no checksum), so a
    // reading at or below the limit is judged again on the next frame before it fails.
    link.note(Note::Start(Check::Battery));
    battery(link, plan, &snapshot, &mut report).await?;
    link.note(Note::Passed(Check::Battery));

    // 8. The steady control loop, reads while moving.
    if plan.motion {
        link.note(Note::Start(Check::ControlLoop));
        control_loop(link, plan, &mut report, failsafe_before).await?;
        link.note(Note::Passed(Check::ControlLoop));
    } else {
        link.note(Note::Skipped(Check::ControlLoop, Skip::NoMotion));
    }

    let missed = Stream::ALL
        .into_iter()
        .map(|s| link.core().stream(s).missed)
        .fold(0u32, u32::saturating_add);
    report.missed = missed;
    Ok(report)
}

/// Checks 3 to 6: the drive type, forward, sideways, the turn, the stop.
#[maybe_async::maybe_async]
async fn motion_checks<L: Link>(
    link: &mut L,
    plan: &Plan,
    snapshot: &Snapshot,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    // 3. The build's drive type.
    let Some(drive) = plan.drive else {
        log!(
            info,
            "[drive-type] kept: {}",
            snapshot.system_mode.drive_type()
        );
        link.note(Note::Skipped(Check::DriveType, Skip::DriveTypeKept));
        let kept = snapshot.system_mode.drive_type();
        return moving_checks(link, plan, kept, report, failsafe_before).await;
    };
    link.note(Note::Start(Check::DriveType));
    if snapshot.system_mode.drive_type() == drive {
        log!(info, "[drive-type] already {}", drive);
    } else {
        let mode = snapshot.system_mode.with_drive_type(drive);
        link.write(Write::SystemMode(mode))
            .await
            .map_err(fail(Check::DriveType))?;
        let raw = link
            .read_verified(Register::SystemMode)
            .await
            .map_err(fail(Check::DriveType))?;
        let read_back = chassis_protocol::SystemMode::from_bits(raw).drive_type();
        if read_back != drive {
            return Err(Failure {
                check: Check::DriveType,
                why: Why::DriveTypeNotSet(read_back),
            });
        }
        log!(
            info,
            "[drive-type] {} -> {}",
            snapshot.system_mode.drive_type(),
            drive
        );
    }
    link.note(Note::Passed(Check::DriveType));
    moving_checks(link, plan, drive, report, failsafe_before).await
}

/// Checks 4 to 6: forward, sideways, the turn, the stop.
#[maybe_async::maybe_async]
async fn moving_checks<L: Link>(
    link: &mut L,
    plan: &Plan,
    drive: DriveType,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    // 4. Forward and sideways: the encoders must count.
    for (check, velocity, slot) in [
        (Check::Forward, Velocity::new(0, plan.speed, 0), 0usize),
        (Check::Strafe, Velocity::new(plan.speed, 0, 0), 1),
    ] {
        // A differential chassis has no sideways (X unused); without encoders nothing counts.
        let skip = match drive {
            DriveType::DifferentialOpenLoop => Some(Skip::NoEncoders),
            DriveType::Differential if check == Check::Strafe => Some(Skip::NoSideways),
            _ => None,
        };
        if let Some(why) = skip {
            link.note(Note::Skipped(check, why));
            continue;
        }
        link.note(Note::Start(check));
        let moved = drive_for(link, plan, velocity, plan.drive_ms, check).await?;
        if link.core().failsafe_stops() != failsafe_before {
            return Err(Failure {
                check,
                why: Why::FailsafeStop,
            });
        }
        if moved.ticks == 0 {
            return Err(Failure {
                check,
                why: Why::EncodersStill,
            });
        }
        if let Some(t) = report.ticks.get_mut(slot) {
            *t = moved.ticks;
        }
        log!(info, "[{}] encoders counted {} ticks", check, moved.ticks);
        link.note(Note::Passed(check));
    }

    // 5. One turn, sent once; wait for the pending angle to reach 0.
    link.note(Note::Start(Check::Turn));
    link.stop().await.map_err(fail(Check::Turn))?;
    link.turn(Turn::by_deci_degrees(plan.turn_deci_degrees))
        .await
        .map_err(fail(Check::Turn))?;
    log!(info, "[turn] {} (0.1°) sent once", plan.turn_deci_degrees);
    let start = link.now_ms();
    let mut next_read = start.saturating_add(200);
    let mut gyro_peak = 0u16;
    let mut pending = plan.turn_deci_degrees;
    loop {
        if link.core().failsafe_stops() != failsafe_before {
            return Err(Failure {
                check: Check::Turn,
                why: Why::FailsafeStop,
            });
        }
        let now = link.now_ms();
        if let Some(Event::Telemetry(Downlink::Imu(imu))) =
            link.poll().await.map_err(fail(Check::Turn))?
        {
            gyro_peak = gyro_peak.max(imu.gyro[2].unsigned_abs());
        }
        if now >= next_read {
            next_read = now.saturating_add(200);
            // A reply lost on the line is read again at the next turn of the loop; the
            // timeout bounds the wait. The transport failing ends the check.
            match link.turn_remaining().await {
                Ok(left) => pending = left,
                Err(e @ chassis_protocol::driver::Error::Core(_)) => {
                    log!(warn, "[turn] pending angle unread: {}", e);
                }
                Err(e) => return Err(fail(Check::Turn)(e)),
            }
            if pending.unsigned_abs() <= 10 {
                break;
            }
            if now.saturating_sub(start) > plan.turn_timeout_ms {
                return Err(Failure {
                    check: Check::Turn,
                    why: Why::TurnPending(pending),
                });
            }
        }
    }
    report.gyro_peak = gyro_peak;
    if gyro_peak < plan.gyro_threshold {
        return Err(Failure {
            check: Check::Turn,
            why: Why::GyroStill,
        });
    }
    log!(
        info,
        "[turn] done in {} ms, gyro Z peak {}",
        link.now_ms().saturating_sub(start),
        gyro_peak
    );

    link.note(Note::Passed(Check::Turn));

    // 6. Stop: the encoders stand still (after 100 ms to settle).
    if drive == DriveType::DifferentialOpenLoop {
        link.stop().await.map_err(fail(Check::Stop))?;
        link.note(Note::Skipped(Check::Stop, Skip::NoEncoders));
        return Ok(());
    }
    link.note(Note::Start(Check::Stop));
    link.stop().await.map_err(fail(Check::Stop))?;
    let _ = drive_for(link, plan, Velocity::new(0, 0, 0), 100, Check::Stop).await?;
    let still = drive_for(link, plan, Velocity::new(0, 0, 0), 200, Check::Stop).await?;
    // Still: the counters of most frames in a row agree. One frame can carry a changed byte
    // (no checksum), which changes the two pairs it is in; a chassis still moving changes
    // every pair.
    if still.pairs == 0 {
        return Err(Failure {
            check: Check::Stop,
            why: Why::NoEncoderFrames,
        });
    }
    if still.changed_pairs.saturating_mul(2) > still.pairs {
        return Err(Failure {
            check: Check::Stop,
            why: Why::EncodersMoving,
        });
    }
    log!(info, "[stop] encoders still");
    link.note(Note::Passed(Check::Stop));
    Ok(())
}

/// Check 7: the battery is above its cut-off.
#[maybe_async::maybe_async]
async fn battery<L: Link>(
    link: &mut L,
    plan: &Plan,
    snapshot: &Snapshot,
    report: &mut Report,
) -> Result<(), Failure> {
    let limit = if snapshot.battery_cutoff_centivolts == 0x7FFF {
        plan.min_centivolts
    } else {
        snapshot.battery_cutoff_centivolts
    };
    let Some(first) = link.core().battery() else {
        return Err(Failure {
            check: Check::Battery,
            why: Why::NoBattery,
        });
    };
    let mut battery = first.value;
    if battery.centivolts <= limit {
        let start = link.now_ms();
        while link.now_ms().saturating_sub(start) < 1_500 {
            link.poll().await.map_err(fail(Check::Battery))?;
            if let Some(next) = link.core().battery() {
                if next.at_ms > first.at_ms {
                    battery = next.value;
                    break;
                }
            }
        }
    }
    report.battery = (battery.centivolts, battery.percent);
    if battery.centivolts <= limit {
        return Err(Failure {
            check: Check::Battery,
            why: Why::LowBattery(battery.centivolts, limit),
        });
    }
    log!(
        info,
        "[battery] {} cV ({} %), cut-off {} cV",
        battery.centivolts,
        battery.percent,
        limit
    );
    Ok(())
}

/// Check 8: the steady control loop (reads while moving), then stop.
#[maybe_async::maybe_async]
async fn control_loop<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    let cruise = Velocity::new(0, plan.speed / 2, 0);
    let start = link.now_ms();
    let mut next_send = start;
    let mut next_read = start.saturating_add(plan.loop_read_every_ms);
    let mut reads = 0u32;
    while link.now_ms().saturating_sub(start) < plan.loop_ms {
        let now = link.now_ms();
        if now >= next_send {
            next_send = now.saturating_add(plan.command_period_ms);
            link.set_velocity(cruise)
                .await
                .map_err(fail(Check::ControlLoop))?;
        }
        if now >= next_read {
            next_read = now.saturating_add(plan.loop_read_every_ms);
            let _ = link
                .read_verified(Register::MotorVoltage)
                .await
                .map_err(fail(Check::ControlLoop))?;
            reads = reads.saturating_add(1);
        }
        link.poll().await.map_err(fail(Check::ControlLoop))?;
        // The driver stopped a board that went quiet: never command motion past that.
        if link.core().failsafe_stops() != failsafe_before {
            return Err(Failure {
                check: Check::ControlLoop,
                why: Why::FailsafeStop,
            });
        }
    }
    link.stop().await.map_err(fail(Check::ControlLoop))?;
    report.loop_reads = reads;
    log!(
        info,
        "[control-loop] {} ms, {} reads while moving, no failsafe stop",
        plan.loop_ms,
        reads
    );
    Ok(())
}

/// The angle still pending, read until a reply comes (three reads at most): one reply lost
/// on the line is no reason to fail a check. The transport failing ends it at once.
#[maybe_async::maybe_async]
async fn pending_angle<L: Link>(link: &mut L) -> Result<i32, LinkError> {
    let mut tries = 0u8;
    loop {
        tries = tries.saturating_add(1);
        match link.turn_remaining().await {
            Err(chassis_protocol::driver::Error::Core(_)) if tries < 3 => {}
            other => return other,
        }
    }
}

/// What a timed drive saw.
struct Moved {
    /// Sum over the wheels of |ticks at the end − ticks at the start|.
    ticks: u32,
    /// Encoder frames in a row (pairs) seen, and how many of them differ.
    pairs: u32,
    changed_pairs: u32,
}

/// Drives at `velocity` for `ms`, re-sending it every command period, taking telemetry in.
#[maybe_async::maybe_async]
async fn drive_for<L: Link>(
    link: &mut L,
    plan: &Plan,
    velocity: Velocity,
    ms: u64,
    check: Check,
) -> Result<Moved, Failure> {
    let start = link.now_ms();
    let mut next_send = start;
    let mut first: Option<[i16; 4]> = None;
    let mut last: Option<[i16; 4]> = None;
    let (mut pairs, mut changed_pairs) = (0u32, 0u32);
    let failsafe_before = link.core().failsafe_stops();
    while link.now_ms().saturating_sub(start) < ms {
        // The driver stopped a board that went quiet: never command motion past that.
        if link.core().failsafe_stops() != failsafe_before {
            return Err(Failure {
                check,
                why: Why::FailsafeStop,
            });
        }
        let now = link.now_ms();
        if now >= next_send && velocity != Velocity::new(0, 0, 0) {
            next_send = now.saturating_add(plan.command_period_ms);
            link.set_velocity(velocity).await.map_err(fail(check))?;
        }
        if let Some(Event::Telemetry(Downlink::Encoders(e))) =
            link.poll().await.map_err(fail(check))?
        {
            first.get_or_insert(e.ticks);
            if let Some(previous) = last {
                pairs = pairs.saturating_add(1);
                if previous != e.ticks {
                    changed_pairs = changed_pairs.saturating_add(1);
                }
            }
            last = Some(e.ticks);
        }
    }
    if velocity != Velocity::new(0, 0, 0) && first.is_none() {
        return Err(Failure {
            check,
            why: Why::NoEncoderFrames,
        });
    }
    let ticks = match (first, last) {
        (Some(a), Some(b)) => a
            .iter()
            .zip(b.iter())
            .map(|(a, b)| u32::from(b.wrapping_sub(*a).unsigned_abs()))
            .fold(0u32, u32::saturating_add),
        _ => 0,
    };
    Ok(Moved {
        ticks,
        pairs,
        changed_pairs,
    })
}
