//! The v1.0.0 checks, in the order [`super::bring_up`] runs them: the plan's part of the
//! sequence ([`Sequence`]), and what they share.

use super::drive::drive_for;
use super::{Failure, Link, Plan, Report, Why};
use super::{MIN_TELEMETRY_PER_10S, RAMP_MS, STILL_MM_S, STILL_MRAD_S};
use super::{STOP_SETTLE_MS, STOP_WATCH_MS};
use crate::sequence::Sequence;
use crate::{Check, Note, Timing, failure, per_10s};
use chassis_protocol::driver::v1::Event;
use chassis_protocol::v1::{BodyVelocity, Readback};

/// What the v1.0.0 checks work on.
pub(super) type Run<'a, L> = crate::sequence::Run<'a, L, Plan>;

#[maybe_async::maybe_async(AFIT)]
impl<L: Link> Sequence<L> for Plan {
    type Report = Report;
    type Why = Why;
    type Counts = u32;
    const NAMED: &'static str = " (v1.0.0)";
    const STOP: &'static str = "forced stop";
    const MOVING: &'static [Check] = &[Check::Forward, Check::Strafe, Check::Turn, Check::Stop];

    fn timing(&self) -> &Timing {
        &self.timing
    }

    /// 1. Link: the telemetry frames counted over the listening time.
    fn count(frames: &mut u32, event: Event) {
        if let Event::Telemetry(_) = event {
            *frames = frames.saturating_add(1);
        }
    }

    /// 1. The telemetry rate.
    fn link(run: &mut Run<'_, L>, frames: u32, elapsed_ms: u64) -> Result<(), Failure> {
        let report = &mut run.report;
        report.telemetry_per_10s = per_10s(frames, elapsed_ms);
        if report.telemetry_per_10s < MIN_TELEMETRY_PER_10S {
            log!(
                warn,
                "[link] {} frames; parser {}",
                frames,
                run.link.core().parser_stats()
            );
            return Err(failure(Check::Link, Why::Rate(report.telemetry_per_10s)));
        }
        log!(
            info,
            "[link] up: telemetry {} frames per 10 s",
            report.telemetry_per_10s
        );
        Ok(())
    }

    /// 2. Settings: the system, geometry and PID readbacks, logged; never written.
    async fn settings(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let (link, report) = (&mut *run.link, &mut run.report);
        let settings = Failure::driver(Check::Settings);
        let no_reply =
            |r: Readback| settings(chassis_protocol::driver::Error::Core(no_readback(r)));
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
        Ok(())
    }

    /// 3. Forward (vy), then sideways (vx): the measured velocity of the second half of each
    /// drive follows the command.
    async fn straight(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let v = run.plan.speed_mm_s;
        let drive_ms = run.plan.timing.drive_ms;
        // (check, command, the velocity component that must follow, its slot in the report)
        for (check, velocity, axis, slot) in [
            (Check::Forward, BodyVelocity::new(0, v, 0), 1usize, 0usize),
            (Check::Strafe, BodyVelocity::new(v, 0, 0), 0, 1),
        ] {
            run.link.note(Note::Start(check));
            let half = drive_ms / 2;
            let drive = Some(velocity);
            let seen = drive_for(run, drive, drive_ms, half, check).await?;
            let measured = seen.mean(axis).ok_or(failure(check, Why::NoTelemetry))?;
            if !near(
                i32::from(measured),
                i32::from(v),
                run.plan.tolerance_percent,
            ) {
                return Err(failure(check, Why::NotFollowed(v, measured)));
            }
            if let Some(m) = run.report.measured_mm_s.get_mut(slot) {
                *m = measured;
            }
            log!(
                info,
                "[{}] commanded {} mm/s, measured {} mm/s",
                check,
                v,
                measured
            );
            run.link.note(Note::Passed(check));
        }
        Ok(())
    }

    /// 4. The rotation at a rate: the quaternion's yaw turns by wz × t (after [`RAMP_MS`]).
    async fn turn(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let wz = run.plan.turn_rate_mrad_s;
        let rotate = Some(BodyVelocity::new(0, 0, wz));
        let (ms, check) = (run.plan.turn_ms, Check::Turn);
        let seen = drive_for(run, rotate, ms, RAMP_MS, check).await?;
        let span = match (seen.first_at, seen.frames) {
            (Some(first), 2..) => seen.last_at.saturating_sub(first),
            _ => return Err(failure(Check::Turn, Why::NoTelemetry)),
        };
        // |wz| ≤ 32 767 and the span clamped to 60 s: the product fits an i32.
        let span = i32::try_from(span.min(60_000)).unwrap_or(60_000);
        let expected = i32::from(wz).saturating_mul(span) / 1_000;
        let report = &mut run.report;
        report.yaw_expected_mrad = expected;
        report.yaw_measured_mrad = seen.turned_mrad;
        report.gyro_z_peak = seen.gyro_z_peak;
        if !near(seen.turned_mrad, expected, run.plan.tolerance_percent) {
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
        Ok(())
    }

    /// 5. The forced stop: still once it settles.
    async fn stop(run: &mut Run<'_, L>) -> Result<(), Failure> {
        run.link.note(Note::Start(Check::Stop));
        run.link
            .stop()
            .await
            .map_err(Failure::driver(Check::Stop))?;
        let ms = STOP_SETTLE_MS.saturating_add(STOP_WATCH_MS);
        let (settle, check) = (STOP_SETTLE_MS, Check::Stop);
        let seen = drive_for(run, None, ms, settle, check).await?;
        if seen.frames == 0 {
            return Err(failure(Check::Stop, Why::NoTelemetry));
        }
        run.report.still_peak = seen.peak;
        let [vx, vy, wz] = seen.peak;
        if vx > STILL_MM_S || vy > STILL_MM_S || wz > STILL_MRAD_S {
            return Err(failure(Check::Stop, Why::StillMoving(seen.peak)));
        }
        log!(info, "[stop] forced stop: still ({} at most)", seen.peak);
        run.link.note(Note::Passed(Check::Stop));
        Ok(())
    }

    /// 6. The battery of the latest frame is above the cut-off (a frame carries a BCC: one
    /// reading is judged).
    async fn battery(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let (min_millivolts, report) = (run.plan.min_millivolts, &mut run.report);
        let Some(latest) = run.link.core().telemetry() else {
            return Err(failure(Check::Battery, Why::NoTelemetry));
        };
        report.battery_mv = latest.value.battery_mv;
        if i32::from(report.battery_mv) <= i32::from(min_millivolts) {
            return Err(failure(
                Check::Battery,
                Why::LowBattery(report.battery_mv, min_millivolts),
            ));
        }
        log!(
            info,
            "[battery] {} mV, cut-off {} mV",
            report.battery_mv,
            min_millivolts
        );
        Ok(())
    }

    /// 7. The steady control loop: half the speed forward, re-sent every command period; no
    /// failsafe stop, telemetry keeps coming; then the forced stop.
    async fn control_loop(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let check = Check::ControlLoop;
        let cruise = Some(BodyVelocity::new(0, run.plan.speed_mm_s / 2, 0));
        let loop_ms = run.plan.timing.loop_ms;
        let seen = drive_for(run, cruise, loop_ms, 0, check).await?;
        run.link.stop().await.map_err(Failure::driver(check))?;
        run.report.loop_per_10s = per_10s(seen.frames, loop_ms);
        if run.report.loop_per_10s < MIN_TELEMETRY_PER_10S {
            return Err(failure(check, Why::Rate(run.report.loop_per_10s)));
        }
        log!(
            info,
            "[control-loop] {} ms, telemetry {} frames per 10 s, no failsafe stop",
            loop_ms,
            run.report.loop_per_10s
        );
        Ok(())
    }

    /// The whole frames the driver's parser refused over the bring-up.
    fn tally(run: &mut Run<'_, L>) {
        let stats = run.link.core().parser_stats();
        run.report.bad_frames = stats
            .bad_checksum
            .saturating_add(stats.bad_end)
            .saturating_add(stats.refused);
    }
}

const fn no_readback(readback: Readback) -> chassis_protocol::driver::CoreError {
    chassis_protocol::driver::CoreError::NoReadback(readback)
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
