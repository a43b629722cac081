//! The v1.0.0 checks, one function each, in the order [`super::bring_up`] runs them; each
//! notes its start and its end ([`Common::note`](crate::link::Common::note)).

use super::drive::drive_for;
use super::{Failure, Link, Plan, Report, Why};
use super::{MIN_TELEMETRY_PER_10S, RAMP_MS, STILL_MM_S, STILL_MRAD_S};
use super::{STOP_SETTLE_MS, STOP_WATCH_MS};
use crate::link::listen;
use crate::{Check, Note, failure, per_10s};
use chassis_protocol::driver::v1::Event;
use chassis_protocol::v1::{BodyVelocity, Readback};

/// 1. Link: the telemetry rate over the listening time.
#[maybe_async::maybe_async]
pub(super) async fn link<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Link));
    let listen_ms = plan.timing.listen_ms;
    log!(info, "[link] listening to telemetry for {} ms", listen_ms);
    let mut frames = 0u32;
    let count = |event| {
        if let Event::Telemetry(_) = event {
            frames = frames.saturating_add(1);
        }
    };
    let elapsed = listen(link, listen_ms, count).await;
    report.telemetry_per_10s = per_10s(frames, elapsed.map_err(Failure::driver(Check::Link))?);
    if report.telemetry_per_10s < MIN_TELEMETRY_PER_10S {
        log!(
            warn,
            "[link] {} frames; parser {}",
            frames,
            link.core().parser_stats()
        );
        return Err(failure(Check::Link, Why::Rate(report.telemetry_per_10s)));
    }
    log!(
        info,
        "[link] up: telemetry {} frames per 10 s",
        report.telemetry_per_10s
    );
    link.note(Note::Passed(Check::Link));
    Ok(())
}

/// 2. Settings: the system, geometry and PID readbacks, logged; never written.
#[maybe_async::maybe_async]
pub(super) async fn settings<L: Link>(link: &mut L, report: &mut Report) -> Result<(), Failure> {
    link.note(Note::Start(Check::Settings));
    let settings = Failure::driver(Check::Settings);
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
    Ok(())
}

const fn no_readback(readback: Readback) -> chassis_protocol::driver::CoreError {
    chassis_protocol::driver::CoreError::NoReadback(readback)
}

/// 3. Forward (vy), then sideways (vx): the measured velocity of the second half of each
/// drive follows the command.
#[maybe_async::maybe_async]
pub(super) async fn straight<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    let v = plan.speed_mm_s;
    let drive_ms = plan.timing.drive_ms;
    // (check, command, the velocity component that must follow, its slot in the report)
    for (check, velocity, axis, slot) in [
        (Check::Forward, BodyVelocity::new(0, v, 0), 1usize, 0usize),
        (Check::Strafe, BodyVelocity::new(v, 0, 0), 0, 1),
    ] {
        link.note(Note::Start(check));
        let half = drive_ms / 2;
        let drive = Some(velocity);
        let seen = drive_for(link, plan, drive, drive_ms, half, check, failsafe_before).await?;
        let measured = seen.mean(axis).ok_or(failure(check, Why::NoTelemetry))?;
        if !near(i32::from(measured), i32::from(v), plan.tolerance_percent) {
            return Err(failure(check, Why::NotFollowed(v, measured)));
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
    Ok(())
}

/// 4. The rotation at a rate: the quaternion's yaw turns by wz × t (after [`RAMP_MS`]).
#[maybe_async::maybe_async]
pub(super) async fn turn<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Turn));
    let wz = plan.turn_rate_mrad_s;
    let rotate = Some(BodyVelocity::new(0, 0, wz));
    let (ms, check) = (plan.turn_ms, Check::Turn);
    let seen = drive_for(link, plan, rotate, ms, RAMP_MS, check, failsafe_before).await?;
    let span = match (seen.first_at, seen.frames) {
        (Some(first), 2..) => seen.last_at.saturating_sub(first),
        _ => return Err(failure(Check::Turn, Why::NoTelemetry)),
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
            Why::YawOff(expected, seen.turned_mrad),
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
    Ok(())
}

/// 5. The forced stop: still once it settles.
#[maybe_async::maybe_async]
pub(super) async fn stop<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Stop));
    link.stop().await.map_err(Failure::driver(Check::Stop))?;
    let ms = STOP_SETTLE_MS.saturating_add(STOP_WATCH_MS);
    let (settle, check) = (STOP_SETTLE_MS, Check::Stop);
    let seen = drive_for(link, plan, None, ms, settle, check, failsafe_before).await?;
    if seen.frames == 0 {
        return Err(failure(Check::Stop, Why::NoTelemetry));
    }
    report.still_peak = seen.peak;
    let [vx, vy, wz] = seen.peak;
    if vx > STILL_MM_S || vy > STILL_MM_S || wz > STILL_MRAD_S {
        return Err(failure(Check::Stop, Why::StillMoving(seen.peak)));
    }
    log!(info, "[stop] forced stop: still ({} at most)", seen.peak);
    link.note(Note::Passed(Check::Stop));
    Ok(())
}

/// 6. The battery of the latest frame is above the cut-off (a frame carries a BCC: one reading
/// is judged).
#[maybe_async::maybe_async]
pub(super) async fn battery<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Battery));
    let Some(latest) = link.core().telemetry() else {
        return Err(failure(Check::Battery, Why::NoTelemetry));
    };
    report.battery_mv = latest.value.battery_mv;
    if i32::from(report.battery_mv) <= i32::from(plan.min_millivolts) {
        return Err(failure(
            Check::Battery,
            Why::LowBattery(report.battery_mv, plan.min_millivolts),
        ));
    }
    log!(
        info,
        "[battery] {} mV, cut-off {} mV",
        report.battery_mv,
        plan.min_millivolts
    );
    link.note(Note::Passed(Check::Battery));
    Ok(())
}

/// 7. The steady control loop: half the speed forward, re-sent every command period; no
/// failsafe stop, telemetry keeps coming; then the forced stop.
#[maybe_async::maybe_async]
pub(super) async fn control_loop<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::ControlLoop));
    let check = Check::ControlLoop;
    let cruise = Some(BodyVelocity::new(0, plan.speed_mm_s / 2, 0));
    let loop_ms = plan.timing.loop_ms;
    let seen = drive_for(link, plan, cruise, loop_ms, 0, check, failsafe_before).await?;
    link.stop().await.map_err(Failure::driver(check))?;
    report.loop_per_10s = per_10s(seen.frames, loop_ms);
    if report.loop_per_10s < MIN_TELEMETRY_PER_10S {
        return Err(failure(check, Why::Rate(report.loop_per_10s)));
    }
    log!(
        info,
        "[control-loop] {} ms, telemetry {} frames per 10 s, no failsafe stop",
        loop_ms,
        report.loop_per_10s
    );
    link.note(Note::Passed(check));
    Ok(())
}

/// `value` within `percent` % of `target` (and so of the same sign).
fn near(value: i32, target: i32, percent: u8) -> bool {
    let off = i64::from(value).abs_diff(i64::from(target));
    off.saturating_mul(100)
        <= i64::from(target)
            .unsigned_abs()
            .saturating_mul(u64::from(percent))
}

#[cfg(test)]
mod tests {
    use super::near;

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
