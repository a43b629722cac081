//! The 2020 checks, in the order [`super::bring_up`] runs them: the plan's part of the
//! sequence ([`Sequence`]), and what they share.

use super::drive::drive_for;
use super::{Failure, Link, Plan, Report, Why};
use crate::sequence::Sequence;
use crate::{Check, LinkError, Note, Skip, Timing, divisor_ms, failure, per_10s};
use chassis_protocol::driver::Event;
use chassis_protocol::registers::Snapshot;
use chassis_protocol::{Downlink, DriveType, Kind, Register, Stream, Turn, Velocity, Write};

/// What the 2020 checks work on.
pub(super) type Run<'a, L> = crate::sequence::Run<'a, L, Plan>;

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

#[maybe_async::maybe_async(AFIT)]
impl<L: Link> Sequence<L> for Plan {
    type Report = Report;
    type Why = Why;
    type Counts = [u32; 3];
    const NAMED: &'static str = "";
    const STOP: &'static str = "stop";
    const MOVING: &'static [Check] = &[
        Check::DriveType,
        Check::Forward,
        Check::Strafe,
        Check::Turn,
        Check::Stop,
    ];

    fn timing(&self) -> &Timing {
        &self.timing
    }

    /// 1. Link up: each stream's frames counted over the listening time.
    fn count(counts: &mut [u32; 3], event: Event) {
        if let Event::Telemetry(frame) = event {
            if let Kind::Telemetry(stream) = frame.kind() {
                if let Some(c) = counts.get_mut(stream.index()) {
                    *c = c.saturating_add(1);
                }
            }
        }
    }

    /// 1. Each stream at its rate.
    fn link(run: &mut Run<'_, L>, counts: [u32; 3], elapsed_ms: u64) -> Result<(), Failure> {
        let elapsed = divisor_ms(elapsed_ms);
        if let Err(why) = rates(counts, elapsed, &mut run.report.rates_per_10s) {
            log!(
                warn,
                "[link] frames {} in {} ms; parser {}",
                counts,
                elapsed,
                run.link.core().parser_stats()
            );
            return Err(failure(Check::Link, why));
        }
        log!(
            info,
            "[link] up: IMU {} Hz, encoders {} Hz, battery {} frame(s)",
            run.report.rates_per_10s[0] / 10,
            run.report.rates_per_10s[1] / 10,
            counts[2]
        );
        Ok(())
    }

    /// 2. Every register, and the pending angle: logged, and the registers encoded with
    /// postcard.
    async fn settings(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let snapshot = run
            .link
            .read_settings()
            .await
            .map_err(Failure::driver(Check::Settings))?;
        run.report.pending_before = pending_angle(run.link)
            .await
            .map_err(Failure::driver(Check::Settings))?;
        run.report.snapshot = snapshot;
        log!(info, "[settings] {}", snapshot);
        log!(
            info,
            "[settings] pending angle {} (0.1°)",
            run.report.pending_before
        );
        let mut buf = [0u8; SNAPSHOT_POSTCARD_MAX];
        let encoded = encode_snapshot(&snapshot, &mut buf);
        log!(
            info,
            "[settings] postcard ({} bytes): {=[u8]:02x}",
            encoded.len(),
            encoded
        );
        Ok(())
    }

    /// Before anything moves: a turn left pending (by a program that was killed) is
    /// cancelled. Then 3., the drive type.
    async fn before_motion(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let pending = run.report.pending_before;
        if pending.unsigned_abs() > 10 {
            log!(
                warn,
                "[settings] a turn of {} (0.1°) was pending: cancelled",
                pending
            );
            run.link
                .stop()
                .await
                .map_err(Failure::driver(Check::Settings))?;
        }
        drive_type(run).await
    }

    /// 4. Forward, then sideways: the encoders must count. A differential chassis has no
    /// sideways (X unused); without encoders nothing counts.
    async fn straight(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let (speed, drive_ms) = (run.plan.speed, run.plan.timing.drive_ms);
        let drive = drive(run.plan, &run.report.snapshot);
        for (check, velocity, slot) in [
            (Check::Forward, Velocity::new(0, speed, 0), 0usize),
            (Check::Strafe, Velocity::new(speed, 0, 0), 1),
        ] {
            let skip = match drive {
                DriveType::DifferentialOpenLoop => Some(Skip::NoEncoders),
                DriveType::Differential if check == Check::Strafe => Some(Skip::NoSideways),
                _ => None,
            };
            if let Some(why) = skip {
                run.link.note(Note::Skipped(check, why));
                continue;
            }
            run.link.note(Note::Start(check));
            let seen = drive_for(run, velocity, drive_ms, check).await?;
            if run.link.core().failsafe_stops() != run.failsafe_before {
                return Err(failure(check, Why::FailsafeStop));
            }
            if seen.ticks == 0 {
                return Err(failure(check, Why::EncodersStill));
            }
            if let Some(t) = run.report.ticks.get_mut(slot) {
                *t = seen.ticks;
            }
            log!(info, "[{}] encoders counted {} ticks", check, seen.ticks);
            run.link.note(Note::Passed(check));
        }
        Ok(())
    }

    /// 5. One turn, sent once: the pending angle must reach 0 in time, and the gyro see it.
    async fn turn(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let deci_degrees = run.plan.turn_deci_degrees;
        run.link
            .stop()
            .await
            .map_err(Failure::driver(Check::Turn))?;
        run.link
            .turn(Turn::by_deci_degrees(deci_degrees))
            .await
            .map_err(Failure::driver(Check::Turn))?;
        log!(info, "[turn] {} (0.1°) sent once", deci_degrees);
        let start = run.link.now_ms();
        let gyro_peak = until_turned(run, start).await?;
        run.report.gyro_peak = gyro_peak;
        if gyro_peak < run.plan.gyro_threshold {
            return Err(failure(Check::Turn, Why::GyroStill));
        }
        log!(
            info,
            "[turn] done in {} ms, gyro Z peak {}",
            run.link.now_ms().saturating_sub(start),
            gyro_peak
        );
        Ok(())
    }

    /// 6. After a stop, the encoders stand still (after 100 ms to settle). Without encoders
    /// the stop is sent and the check skipped.
    async fn stop(run: &mut Run<'_, L>) -> Result<(), Failure> {
        if drive(run.plan, &run.report.snapshot) == DriveType::DifferentialOpenLoop {
            run.link
                .stop()
                .await
                .map_err(Failure::driver(Check::Stop))?;
            run.link.note(Note::Skipped(Check::Stop, Skip::NoEncoders));
            return Ok(());
        }
        run.link.note(Note::Start(Check::Stop));
        run.link
            .stop()
            .await
            .map_err(Failure::driver(Check::Stop))?;
        let still = Velocity::new(0, 0, 0);
        let _ = drive_for(run, still, 100, Check::Stop).await?;
        let seen = drive_for(run, still, 200, Check::Stop).await?;
        // Still: the counters of most frames in a row agree. One frame can carry a changed
        // byte (no checksum), which changes the two pairs it is in; a chassis still moving
        // changes every pair.
        if seen.pairs == 0 {
            return Err(failure(Check::Stop, Why::NoEncoderFrames));
        }
        if seen.changed_pairs.saturating_mul(2) > seen.pairs {
            return Err(failure(Check::Stop, Why::EncodersMoving));
        }
        log!(info, "[stop] encoders still");
        run.link.note(Note::Passed(Check::Stop));
        Ok(())
    }

    /// 7. The battery is above its cut-off (the board's, or the plan's when the board uses its
    /// built-in table). One frame can carry a changed byte (no checksum), so a reading at or
    /// below the limit is judged again on the next frame before it fails.
    async fn battery(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let snapshot = &run.report.snapshot;
        let limit = if snapshot.battery_cutoff_centivolts == 0x7FFF {
            run.plan.min_centivolts
        } else {
            snapshot.battery_cutoff_centivolts
        };
        let Some(first) = run.link.core().battery() else {
            return Err(failure(Check::Battery, Why::NoBattery));
        };
        let mut battery = first.value;
        if battery.centivolts <= limit {
            let start = run.link.now_ms();
            while run.link.now_ms().saturating_sub(start) < 1_500 {
                run.link
                    .poll()
                    .await
                    .map_err(Failure::driver(Check::Battery))?;
                if let Some(next) = run.link.core().battery() {
                    if next.at_ms > first.at_ms {
                        battery = next.value;
                        break;
                    }
                }
            }
        }
        run.report.battery = (battery.centivolts, battery.percent);
        if battery.centivolts <= limit {
            return Err(failure(
                Check::Battery,
                Why::LowBattery(battery.centivolts, limit),
            ));
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

    /// 8. The steady control loop: slow forward, re-sent every command period, a verified
    /// register read every [`Plan::loop_read_every_ms`] while moving, no failsafe stop; then
    /// stop.
    async fn control_loop(run: &mut Run<'_, L>) -> Result<(), Failure> {
        let check = Check::ControlLoop;
        let (plan, link) = (run.plan, &mut *run.link);
        let cruise = Velocity::new(0, plan.speed / 2, 0);
        let start = link.now_ms();
        let mut next_send = start;
        let mut next_read = start.saturating_add(plan.loop_read_every_ms);
        let mut reads = 0u32;
        while link.now_ms().saturating_sub(start) < plan.timing.loop_ms {
            let now = link.now_ms();
            if now >= next_send {
                next_send = now.saturating_add(plan.timing.command_period_ms);
                link.set_velocity(cruise)
                    .await
                    .map_err(Failure::driver(check))?;
            }
            if now >= next_read {
                next_read = now.saturating_add(plan.loop_read_every_ms);
                let _ = link
                    .read_verified(Register::MotorVoltage)
                    .await
                    .map_err(Failure::driver(check))?;
                reads = reads.saturating_add(1);
            }
            link.poll().await.map_err(Failure::driver(check))?;
            // The driver stopped a board that went quiet: never command motion past that.
            if link.core().failsafe_stops() != run.failsafe_before {
                return Err(failure(check, Why::FailsafeStop));
            }
        }
        link.stop().await.map_err(Failure::driver(check))?;
        run.report.loop_reads = reads;
        log!(
            info,
            "[control-loop] {} ms, {} reads while moving, no failsafe stop",
            plan.timing.loop_ms,
            reads
        );
        Ok(())
    }

    /// The telemetry frames the parser counted as missed over the whole bring-up.
    fn tally(run: &mut Run<'_, L>) {
        run.report.missed = Stream::ALL
            .into_iter()
            .map(|s| run.link.core().stream(s).missed)
            .fold(0u32, u32::saturating_add);
    }
}

/// Each stream's frames per 10 s, from `counts` in `elapsed` ms, into `rates`, in order until
/// one is too slow: at least 70 % of its nominal rate (battery: one frame in the window).
fn rates(counts: [u32; 3], elapsed: u32, rates: &mut [u32; 3]) -> Result<(), Why> {
    for stream in Stream::ALL {
        let i = stream.index();
        let frames = counts.get(i).copied().unwrap_or(0);
        let per_10s = per_10s(frames, u64::from(elapsed));
        if let Some(r) = rates.get_mut(i) {
            *r = per_10s;
        }
        let nominal_per_10s = u32::from(stream.rate_hz()) * 10;
        let enough = match stream {
            Stream::Battery => frames >= 1,
            _ => per_10s >= nominal_per_10s * 7 / 10,
        };
        if !enough {
            return Err(Why::Rate(stream, per_10s));
        }
    }
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

/// 3. The build's drive type, written if the board has another and read back; skipped if the
/// plan keeps the board's own.
#[maybe_async::maybe_async]
async fn drive_type<L: Link>(run: &mut Run<'_, L>) -> Result<(), Failure> {
    let system_mode = run.report.snapshot.system_mode;
    let own = system_mode.drive_type();
    let Some(drive) = run.plan.drive else {
        log!(info, "[drive-type] kept: {}", own);
        run.link
            .note(Note::Skipped(Check::DriveType, Skip::DriveTypeKept));
        return Ok(());
    };
    run.link.note(Note::Start(Check::DriveType));
    if own == drive {
        log!(info, "[drive-type] already {}", drive);
    } else {
        let mode = system_mode.with_drive_type(drive);
        run.link
            .write(Write::SystemMode(mode))
            .await
            .map_err(Failure::driver(Check::DriveType))?;
        let raw = run
            .link
            .read_verified(Register::SystemMode)
            .await
            .map_err(Failure::driver(Check::DriveType))?;
        let read_back = chassis_protocol::SystemMode::from_bits(raw).drive_type();
        if read_back != drive {
            return Err(failure(Check::DriveType, Why::DriveTypeNotSet(read_back)));
        }
        log!(info, "[drive-type] {} -> {}", own, drive);
    }
    run.link.note(Note::Passed(Check::DriveType));
    Ok(())
}

/// The drive type the chassis has once [`drive_type`] passed: the plan's, or the board's own
/// (in `snapshot`) if the plan keeps it.
fn drive(plan: &Plan, snapshot: &Snapshot) -> DriveType {
    plan.drive
        .unwrap_or_else(|| snapshot.system_mode.drive_type())
}

/// Takes telemetry in until the pending angle (read every 200 ms from `start`) is within 1°
/// of 0, or the turn's time is up; the largest |gyro Z| seen.
#[maybe_async::maybe_async]
async fn until_turned<L: Link>(run: &mut Run<'_, L>, start: u64) -> Result<u16, Failure> {
    let mut next_read = start.saturating_add(200);
    let mut gyro_peak = 0u16;
    let mut pending = run.plan.turn_deci_degrees;
    loop {
        if run.link.core().failsafe_stops() != run.failsafe_before {
            return Err(failure(Check::Turn, Why::FailsafeStop));
        }
        let now = run.link.now_ms();
        if let Some(Event::Telemetry(Downlink::Imu(imu))) = run
            .link
            .poll()
            .await
            .map_err(Failure::driver(Check::Turn))?
        {
            gyro_peak = gyro_peak.max(imu.gyro[2].unsigned_abs());
        }
        if now >= next_read {
            next_read = now.saturating_add(200);
            // A reply lost on the line is read again at the next turn of the loop; the
            // timeout bounds the wait. The transport failing ends the check.
            match run.link.turn_remaining().await {
                Ok(left) => pending = left,
                Err(e @ chassis_protocol::driver::Error::Core(_)) => {
                    log!(warn, "[turn] pending angle unread: {}", e);
                }
                Err(e) => return Err(Failure::driver(Check::Turn)(e)),
            }
            if pending.unsigned_abs() <= 10 {
                return Ok(gyro_peak);
            }
            if now.saturating_sub(start) > run.plan.turn_timeout_ms {
                return Err(failure(Check::Turn, Why::TurnPending(pending)));
            }
        }
    }
}
