//! The bring-up of a board running firmware **v1.0.0** (`7B … BCC 7D` frames, see
//! `docs/firmware-generations.md`): [`bring_up_v1`] over a [`LinkV1`], the v1.0.0 driver
//! (`Blocking::new_v1`, `Async::new_v1` of [`crate::link`]).
//!
//! Written once for both shells, as the 2020 bring-up is (`maybe-async`), and sharing with it
//! what is not the generation's: the [`Check`]s and their exit codes, [`Note`], [`Failure`]
//! (with the v1.0.0 reasons, [`WhyV1`]) and the [`Plan`]. The sequence:
//!
//! 1. [`Check::Link`]: telemetry frames (one 32-byte frame, 20–24 Hz) are counted over
//!    [`Plan::listen_ms`]: at least 70 % of 20 Hz.
//! 2. [`Check::Settings`]: the system, geometry and PID readbacks (`0x33`, `0x34`, `0x50`),
//!    logged. **Nothing is written**: the settings frames would overwrite what the owner tuned.
//! 3. [`Check::Forward`], [`Check::Strafe`]: vy, then vx, at [`Plan::speed`] mm/s for
//!    [`Plan::drive_ms`], re-sent every [`Plan::command_period_ms`]; the measured body velocity
//!    in the telemetry of the second half must follow (its mean within
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
//! 7. [`Check::ControlLoop`]: a steady loop, [`Plan::speed`] / 2 forward re-sent every period
//!    for [`Plan::loop_ms`] (the board drops a few frames while commanded): telemetry keeps
//!    coming (70 % of 20 Hz) and the driver's failsafe never stops the chassis; then the forced
//!    stop.
//!
//! There is no [`Check::DriveType`] on v1.0.0 (no register holds one: every velocity frame
//! carries the vendor's type byte, 4), so its exit code never comes from here. Any failure
//! sends the forced stop (best effort; only if the plan moves the chassis: without motion,
//! only readbacks are sent). A passed bring-up ends with the forced stop. Nothing panics.

use crate::{Check, Failure, LinkError, Note, Plan, Skip};
use chassis_protocol::driver::v1::{DriverCore, Event};
use chassis_protocol::v1::{BodyVelocity, Geometry, Pid, Readback, Reply, SystemSettings};

/// The calls the v1.0.0 bring-up makes; each is the v1.0.0 driver's call of the same name.
///
/// `async` (the futures are not `Send`: a bring-up runs on one core, in one task), or plain
/// functions with feature `blocking`.
#[allow(async_fn_in_trait)]
#[maybe_async::maybe_async(AFIT)]
pub trait LinkV1 {
    /// Milliseconds since boot (the driver's clock).
    fn now_ms(&mut self) -> u64;
    /// The driver's sans-IO core: latest telemetry, parser counters, failsafe stops.
    fn core(&self) -> &DriverCore;
    /// Takes in what has arrived; the blocking shell returns at once, the async one waits a
    /// little for bytes.
    async fn poll(&mut self) -> Result<Option<Event>, LinkError>;
    /// Sets the body velocity (`0x25`).
    async fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError>;
    /// The forced stop.
    async fn stop(&mut self) -> Result<(), LinkError>;
    /// One readback: the board's reply.
    async fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError>;
    /// What the bring-up is doing (a check starts, passes, is skipped). Does nothing unless
    /// implemented.
    fn note(&mut self, note: Note) {
        let _ = note;
    }
}

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

/// Why a check failed on v1.0.0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WhyV1 {
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

/// What a passed v1.0.0 bring-up measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ReportV1 {
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

fn fail(check: Check) -> impl Fn(LinkError) -> Failure<WhyV1> {
    move |e| Failure {
        check,
        why: WhyV1::Driver(e),
    }
}

const fn failure(check: Check, why: WhyV1) -> Failure<WhyV1> {
    Failure { check, why }
}

/// Runs the whole v1.0.0 bring-up on `link`. On a failure the chassis gets the forced stop
/// (best effort, if the plan moves it) and the failed check is returned.
#[maybe_async::maybe_async]
pub async fn bring_up_v1<L: LinkV1>(link: &mut L, plan: &Plan) -> Result<ReportV1, Failure<WhyV1>> {
    let result = steps(link, plan).await;
    if let Err(failure) = &result {
        log!(
            error,
            "bring-up (v1.0.0): {} failed: {}",
            failure.check,
            failure.why
        );
        if plan.motion {
            if let Err(e) = link.stop().await {
                log!(error, "forced stop after the failure: {}", e);
            }
        }
    }
    result
}

#[maybe_async::maybe_async]
async fn steps<L: LinkV1>(link: &mut L, plan: &Plan) -> Result<ReportV1, Failure<WhyV1>> {
    let mut report = ReportV1::default();

    // 1. Link: the telemetry rate.
    link.note(Note::Start(Check::Link));
    log!(
        info,
        "[link] listening to telemetry for {} ms",
        plan.listen_ms
    );
    let start = link.now_ms();
    let mut frames = 0u32;
    while link.now_ms().saturating_sub(start) < plan.listen_ms {
        if let Some(Event::Telemetry(_)) = link.poll().await.map_err(fail(Check::Link))? {
            frames = frames.saturating_add(1);
        }
    }
    report.telemetry_per_10s = per_10s(frames, link.now_ms().saturating_sub(start));
    if report.telemetry_per_10s < MIN_TELEMETRY_PER_10S {
        log!(
            warn,
            "[link] {} frames; parser {}",
            frames,
            link.core().parser_stats()
        );
        return Err(failure(Check::Link, WhyV1::Rate(report.telemetry_per_10s)));
    }
    log!(
        info,
        "[link] up: telemetry {} frames per 10 s",
        report.telemetry_per_10s
    );
    link.note(Note::Passed(Check::Link));

    // 2. Settings: read back, never written.
    link.note(Note::Start(Check::Settings));
    let settings = fail(Check::Settings);
    let no_reply = |r: Readback| settings(chassis_protocol::driver::Error::Core(no_readback(r)));
    let reply = link.readback(Readback::System).await.map_err(&settings)?;
    report.system = reply.system().ok_or_else(|| no_reply(Readback::System))?;
    let reply = link.readback(Readback::Geometry).await.map_err(&settings)?;
    report.geometry = reply
        .geometry()
        .ok_or_else(|| no_reply(Readback::Geometry))?;
    let reply = link.readback(Readback::Pid).await.map_err(&settings)?;
    report.pid = reply.pid().ok_or_else(|| no_reply(Readback::Pid))?;
    log!(info, "[settings] {}", report.system);
    log!(info, "[settings] {}", report.geometry);
    log!(info, "[settings] {}", report.pid);
    link.note(Note::Passed(Check::Settings));

    let failsafe_before = link.core().failsafe_stops();
    if plan.motion {
        motion_checks(link, plan, &mut report, failsafe_before).await?;
    } else {
        for check in [Check::Forward, Check::Strafe, Check::Turn, Check::Stop] {
            link.note(Note::Skipped(check, Skip::NoMotion));
        }
    }

    // 6. Battery.
    link.note(Note::Start(Check::Battery));
    let Some(latest) = link.core().telemetry() else {
        return Err(failure(Check::Battery, WhyV1::NoTelemetry));
    };
    report.battery_mv = latest.value.battery_mv;
    if i32::from(report.battery_mv) <= i32::from(plan.min_millivolts) {
        return Err(failure(
            Check::Battery,
            WhyV1::LowBattery(report.battery_mv, plan.min_millivolts),
        ));
    }
    log!(
        info,
        "[battery] {} mV, cut-off {} mV",
        report.battery_mv,
        plan.min_millivolts
    );
    link.note(Note::Passed(Check::Battery));

    // 7. The steady control loop.
    if plan.motion {
        link.note(Note::Start(Check::ControlLoop));
        let cruise = BodyVelocity::new(0, speed(plan.speed / 2), 0);
        let seen = window(
            link,
            plan,
            Some(cruise),
            plan.loop_ms,
            0,
            Check::ControlLoop,
            failsafe_before,
        )
        .await?;
        link.stop().await.map_err(fail(Check::ControlLoop))?;
        report.loop_per_10s = per_10s(seen.frames, plan.loop_ms);
        if report.loop_per_10s < MIN_TELEMETRY_PER_10S {
            return Err(failure(
                Check::ControlLoop,
                WhyV1::Rate(report.loop_per_10s),
            ));
        }
        log!(
            info,
            "[control-loop] {} ms, telemetry {} frames per 10 s, no failsafe stop",
            plan.loop_ms,
            report.loop_per_10s
        );
        link.note(Note::Passed(Check::ControlLoop));
    } else {
        link.note(Note::Skipped(Check::ControlLoop, Skip::NoMotion));
    }

    let stats = link.core().parser_stats();
    report.bad_frames = stats
        .bad_checksum
        .saturating_add(stats.bad_end)
        .saturating_add(stats.refused);
    Ok(report)
}

/// Checks 3 to 5: forward, sideways, the rotation, the forced stop.
#[maybe_async::maybe_async]
async fn motion_checks<L: LinkV1>(
    link: &mut L,
    plan: &Plan,
    report: &mut ReportV1,
    failsafe_before: u32,
) -> Result<(), Failure<WhyV1>> {
    // 3. Forward (vy) and sideways (vx): the measured velocity follows.
    let v = speed(plan.speed);
    // (check, command, the velocity component that must follow, its slot in the report)
    for (check, velocity, axis, slot) in [
        (Check::Forward, BodyVelocity::new(0, v, 0), 1usize, 0usize),
        (Check::Strafe, BodyVelocity::new(v, 0, 0), 0, 1),
    ] {
        link.note(Note::Start(check));
        let half = plan.drive_ms / 2;
        let seen = window(
            link,
            plan,
            Some(velocity),
            plan.drive_ms,
            half,
            check,
            failsafe_before,
        )
        .await?;
        let measured = seen.mean(axis).ok_or(failure(check, WhyV1::NoTelemetry))?;
        if !near(i32::from(measured), i32::from(v), plan.tolerance_percent) {
            return Err(failure(check, WhyV1::NotFollowed(v, measured)));
        }
        if let Some(m) = report.measured_mm_s.get_mut(slot) {
            *m = measured;
        }
        log!(
            info,
            "[{}] commanded {} mm/s, measured {} mm/s",
            check,
            v,
            measured
        );
        link.note(Note::Passed(check));
    }

    // 4. The rotation at a rate: the quaternion's yaw turns by wz × t.
    link.note(Note::Start(Check::Turn));
    let wz = plan.turn_rate_mrad_s;
    let seen = window(
        link,
        plan,
        Some(BodyVelocity::new(0, 0, wz)),
        plan.turn_ms,
        RAMP_MS,
        Check::Turn,
        failsafe_before,
    )
    .await?;
    let span = match (seen.first_at, seen.frames) {
        (Some(first), 2..) => seen.last_at.saturating_sub(first),
        _ => return Err(failure(Check::Turn, WhyV1::NoTelemetry)),
    };
    // |wz| ≤ 32 767 and the span clamped to 60 s: the product fits an i32.
    let span = i32::try_from(span.min(60_000)).unwrap_or(60_000);
    let expected = i32::from(wz).saturating_mul(span) / 1_000;
    report.yaw_expected_mrad = expected;
    report.yaw_measured_mrad = seen.turned_mrad;
    report.gyro_z_peak = seen.gyro_z_peak;
    if !near(seen.turned_mrad, expected, plan.tolerance_percent) {
        return Err(failure(
            Check::Turn,
            WhyV1::YawOff(expected, seen.turned_mrad),
        ));
    }
    log!(
        info,
        "[turn] rotated at {} mrad/s: yaw turned {} mrad in {} ms ({} expected), gyro z peak {}",
        wz,
        seen.turned_mrad,
        span,
        expected,
        seen.gyro_z_peak
    );
    link.note(Note::Passed(Check::Turn));

    // 5. The forced stop: still after it settles.
    link.note(Note::Start(Check::Stop));
    link.stop().await.map_err(fail(Check::Stop))?;
    let seen = window(
        link,
        plan,
        None,
        STOP_SETTLE_MS.saturating_add(STOP_WATCH_MS),
        STOP_SETTLE_MS,
        Check::Stop,
        failsafe_before,
    )
    .await?;
    if seen.frames == 0 {
        return Err(failure(Check::Stop, WhyV1::NoTelemetry));
    }
    report.still_peak = seen.peak;
    let [vx, vy, wz] = seen.peak;
    if vx > STILL_MM_S || vy > STILL_MM_S || wz > STILL_MRAD_S {
        return Err(failure(Check::Stop, WhyV1::StillMoving(seen.peak)));
    }
    log!(info, "[stop] forced stop: still ({} at most)", seen.peak);
    link.note(Note::Passed(Check::Stop));
    Ok(())
}

/// What the telemetry of a window showed, from its judged part on.
#[derive(Clone, Copy, Debug, Default)]
struct Seen {
    frames: u32,
    /// Sum of each measured velocity component.
    sum: [i32; 3],
    /// The largest |component|.
    peak: [u16; 3],
    /// When the first and the last frame judged came.
    first_at: Option<u64>,
    last_at: u64,
    /// The yaw of the last frame, and the changes from frame to frame added up, mrad.
    yaw_mrad: Option<i32>,
    turned_mrad: i32,
    gyro_z_peak: u16,
}

impl Seen {
    fn take(&mut self, t: &chassis_protocol::v1::Telemetry, at_ms: u64) {
        self.frames = self.frames.saturating_add(1);
        for ((sum, peak), v) in self.sum.iter_mut().zip(&mut self.peak).zip(t.velocity) {
            *sum = sum.saturating_add(i32::from(v));
            *peak = (*peak).max(v.unsigned_abs());
        }
        self.first_at.get_or_insert(at_ms);
        self.last_at = at_ms;
        let yaw = yaw_mrad(t.quaternion);
        if let Some(previous) = self.yaw_mrad {
            self.turned_mrad = self
                .turned_mrad
                .saturating_add(wrap_mrad(yaw.saturating_sub(previous)));
        }
        self.yaw_mrad = Some(yaw);
        let [_, _, gz] = t.gyro;
        self.gyro_z_peak = self.gyro_z_peak.max(gz.unsigned_abs());
    }

    /// The mean of component `axis`, if a frame came.
    fn mean(&self, axis: usize) -> Option<i16> {
        let sum = *self.sum.get(axis)?;
        let n = i32::try_from(self.frames).ok().filter(|n| *n > 0)?;
        i16::try_from(sum.checked_div(n)?).ok()
    }
}

/// Sends `velocity` (if any) every command period for `ms`, taking telemetry in; frames that
/// come `judge_after_ms` or more after the start are judged. The driver's failsafe stopping the
/// chassis ends it at once: never command motion past that.
#[maybe_async::maybe_async]
async fn window<L: LinkV1>(
    link: &mut L,
    plan: &Plan,
    velocity: Option<BodyVelocity>,
    ms: u64,
    judge_after_ms: u64,
    check: Check,
    failsafe_before: u32,
) -> Result<Seen, Failure<WhyV1>> {
    let start = link.now_ms();
    let mut next_send = start;
    let mut seen = Seen::default();
    loop {
        let now = link.now_ms();
        if now.saturating_sub(start) >= ms {
            return Ok(seen);
        }
        if link.core().failsafe_stops() != failsafe_before {
            return Err(failure(check, WhyV1::FailsafeStop));
        }
        if let Some(velocity) = velocity {
            if now >= next_send {
                next_send = now.saturating_add(plan.command_period_ms);
                link.set_velocity(velocity).await.map_err(fail(check))?;
            }
        }
        if let Some(Event::Telemetry(t)) = link.poll().await.map_err(fail(check))? {
            if now.saturating_sub(start) >= judge_after_ms {
                seen.take(&t, now);
            }
        }
    }
}

/// Frames per 10 s of `frames` in `ms` (32-bit: a Cortex-M divides that in hardware).
fn per_10s(frames: u32, ms: u64) -> u32 {
    let ms = u32::try_from(ms.max(1)).unwrap_or(u32::MAX);
    frames.saturating_mul(10_000).checked_div(ms).unwrap_or(0)
}

/// `value` within `percent` % of `target` (and so of the same sign).
fn near(value: i32, target: i32, percent: u8) -> bool {
    let off = i64::from(value).abs_diff(i64::from(target));
    off.saturating_mul(100)
        <= i64::from(target)
            .unsigned_abs()
            .saturating_mul(u64::from(percent))
}

/// A plan's speed as a velocity component, mm/s.
fn speed(v: i32) -> i16 {
    i16::try_from(v.clamp(i32::from(i16::MIN), i32::from(i16::MAX))).unwrap_or(0)
}

const fn no_readback(readback: Readback) -> chassis_protocol::driver::CoreError {
    chassis_protocol::driver::CoreError::NoReadback(readback)
}

/// π in mrad (rounded).
const PI_MRAD: i32 = 3_142;

/// A change of yaw back into (-π, π], mrad.
const fn wrap_mrad(d: i32) -> i32 {
    if d > PI_MRAD {
        d.saturating_sub(2 * PI_MRAD)
    } else if d <= -PI_MRAD {
        d.saturating_add(2 * PI_MRAD)
    } else {
        d
    }
}

/// The yaw (rotation about z) of the quaternion w, x, y, z (× 1000), mrad in (-π, π]:
/// atan2(2 (w z + x y), w² + x² − y² − z²), which needs no normalised quaternion.
fn yaw_mrad([w, x, y, z]: [i16; 4]) -> i32 {
    let (w, x, y, z) = (f32::from(w), f32::from(x), f32::from(y), f32::from(z));
    let sin = 2.0 * (w * z + x * y);
    let cos = w * w + x * x - y * y - z * z;
    // `as` saturates: |atan2| ≤ π, so it never needs to.
    (atan2(sin, cos) * 1_000.0) as i32
}

/// atan2 in single precision without `libm`: the polynomial of Abramowitz and Stegun 4.4.49
/// on [0, 1] (error ≤ 1e-5 rad), moved to the right octant.
fn atan2(y: f32, x: f32) -> f32 {
    use core::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    if ax == 0.0 && ay == 0.0 {
        return 0.0;
    }
    let steep = ay > ax;
    let a = if steep { ax / ay } else { ay / ax };
    let s = a * a;
    let mut r =
        a * (0.999_866 + s * (-0.330_299_5 + s * (0.180_141 + s * (-0.085_133 + s * 0.020_835_1))));
    if steep {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 { -r } else { r }
}

#[cfg(feature = "blocking")]
#[maybe_async::sync_impl]
impl<U, C> LinkV1 for crate::link::Blocking<U, C, DriverCore>
where
    U: embedded_io::Read + embedded_io::Write + embedded_io::ReadReady,
    C: chassis_protocol::driver::Clock + Clone,
{
    fn now_ms(&mut self) -> u64 {
        self.clock.now_ms()
    }
    fn core(&self) -> &DriverCore {
        self.driver.core()
    }
    fn poll(&mut self) -> Result<Option<Event>, LinkError> {
        self.driver.poll().map_err(crate::link::kind)
    }
    fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.driver
            .set_velocity(velocity)
            .map_err(crate::link::kind)
    }
    fn stop(&mut self) -> Result<(), LinkError> {
        self.driver.stop().map_err(crate::link::kind)
    }
    fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.driver.readback(readback).map_err(crate::link::kind)
    }
}

#[cfg(feature = "async")]
#[maybe_async::async_impl(AFIT)]
impl<U, C, D> LinkV1 for crate::link::Async<U, C, D, DriverCore>
where
    U: embedded_io_async::Read + embedded_io_async::Write,
    C: chassis_protocol::driver::Clock + Clone,
    D: embedded_hal_async::delay::DelayNs,
{
    fn now_ms(&mut self) -> u64 {
        self.clock.now_ms()
    }
    fn core(&self) -> &DriverCore {
        self.driver.core()
    }
    async fn poll(&mut self) -> Result<Option<Event>, LinkError> {
        self.driver.poll().await.map_err(crate::link::kind)
    }
    async fn set_velocity(&mut self, velocity: BodyVelocity) -> Result<(), LinkError> {
        self.driver
            .set_velocity(velocity)
            .await
            .map_err(crate::link::kind)
    }
    async fn stop(&mut self) -> Result<(), LinkError> {
        self.driver.stop().await.map_err(crate::link::kind)
    }
    async fn readback(&mut self, readback: Readback) -> Result<Reply, LinkError> {
        self.driver
            .readback(readback)
            .await
            .map_err(crate::link::kind)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    fn about_z(yaw_rad: f64) -> [i16; 4] {
        let (s, c) = (yaw_rad / 2.0).sin_cos();
        [
            (c * 1000.0).round() as i16,
            0,
            0,
            (s * 1000.0).round() as i16,
        ]
    }

    #[test]
    fn the_yaw_of_a_rotation_about_z_is_its_angle() {
        for deg in (-179..=180).step_by(7) {
            let rad = f64::from(deg).to_radians();
            let yaw = yaw_mrad(about_z(rad));
            let want = (rad * 1000.0).round() as i32;
            // A quaternion in thousandths: about 2 mrad of resolution.
            assert!((yaw - want).abs() <= 3, "{deg}°: {yaw} mrad, not {want}");
        }
        assert_eq!(yaw_mrad([0, 0, 0, 0]), 0, "no quaternion: no yaw, no panic");
    }

    #[test]
    fn atan2_agrees_with_std() {
        for i in -50..=50 {
            for j in -50..=50 {
                let (y, x) = (i as f32 / 7.0, j as f32 / 3.0);
                if x == 0.0 && y == 0.0 {
                    continue;
                }
                assert!((atan2(y, x) - y.atan2(x)).abs() < 2e-5, "atan2({y}, {x})");
            }
        }
    }

    #[test]
    fn yaw_changes_are_added_up_across_the_half_turn() {
        let mut seen = Seen::default();
        // 0.1 rad a frame, 40 frames: 4 rad, more than π.
        for k in 0..=40u32 {
            let t = chassis_protocol::v1::Telemetry {
                quaternion: about_z(wrap(f64::from(k) * 0.1)),
                ..Default::default()
            };
            seen.take(&t, u64::from(k) * 45);
        }
        assert!(
            (seen.turned_mrad - 4_000).abs() <= 10,
            "{}",
            seen.turned_mrad
        );
        assert_eq!(seen.last_at - seen.first_at.unwrap(), 40 * 45);
    }

    fn wrap(rad: f64) -> f64 {
        let two_pi = std::f64::consts::TAU;
        let r = rad.rem_euclid(two_pi);
        if r > std::f64::consts::PI {
            r - two_pi
        } else {
            r
        }
    }

    #[test]
    fn near_is_a_tolerance_around_the_target_with_its_sign() {
        assert!(near(300, 300, 25));
        assert!(near(226, 300, 25));
        assert!(!near(224, 300, 25));
        assert!(!near(-300, 300, 25));
        assert!(near(0, 0, 25));
        assert!(!near(1, 0, 25));
        assert!(near(i32::MIN, i32::MIN, 0), "no overflow");
    }
}
