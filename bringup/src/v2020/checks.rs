//! The 2020 checks, one function each, in the order [`super::bring_up`] runs them; each notes
//! its start and its end ([`Common::note`](crate::link::Common::note)).

use super::drive::drive_for;
use super::{Failure, Link, Plan, Report, Why};
use crate::link::listen;
use crate::{Check, LinkError, Note, Skip, divisor_ms, failure, per_10s};
use chassis_protocol::driver::Event;
use chassis_protocol::registers::Snapshot;
use chassis_protocol::{Downlink, DriveType, Kind, Register, Stream, Turn, Velocity, Write};

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

/// 1. Link up: each stream's frames counted over the listening time.
#[maybe_async::maybe_async]
pub(super) async fn link<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Link));
    let listen_ms = plan.timing.listen_ms;
    log!(info, "[link] listening to telemetry for {} ms", listen_ms);
    let mut counts = [0u32; 3];
    let count = |event| {
        if let Event::Telemetry(frame) = event {
            if let Kind::Telemetry(stream) = frame.kind() {
                if let Some(c) = counts.get_mut(stream.index()) {
                    *c = c.saturating_add(1);
                }
            }
        }
    };
    let elapsed = listen(link, listen_ms, count).await;
    let elapsed = divisor_ms(elapsed.map_err(Failure::driver(Check::Link))?);
    if let Err(why) = rates(counts, elapsed, &mut report.rates_per_10s) {
        log!(
            warn,
            "[link] frames {} in {} ms; parser {}",
            counts,
            elapsed,
            link.core().parser_stats()
        );
        return Err(failure(Check::Link, why));
    }
    log!(
        info,
        "[link] up: IMU {} Hz, encoders {} Hz, battery {} frame(s)",
        report.rates_per_10s[0] / 10,
        report.rates_per_10s[1] / 10,
        counts[2]
    );
    link.note(Note::Passed(Check::Link));
    Ok(())
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

/// 2. Every register, and the pending angle: logged, and the registers encoded with postcard.
#[maybe_async::maybe_async]
pub(super) async fn settings<L: Link>(
    link: &mut L,
    report: &mut Report,
) -> Result<Snapshot, Failure> {
    link.note(Note::Start(Check::Settings));
    let snapshot = link
        .read_settings()
        .await
        .map_err(Failure::driver(Check::Settings))?;
    report.pending_before = pending_angle(link)
        .await
        .map_err(Failure::driver(Check::Settings))?;
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
    Ok(snapshot)
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

/// Before anything moves: a turn left pending (by a program that was killed) is cancelled.
#[maybe_async::maybe_async]
pub(super) async fn cancel_pending_turn<L: Link>(
    link: &mut L,
    pending: i32,
) -> Result<(), Failure> {
    if pending.unsigned_abs() > 10 {
        log!(
            warn,
            "[settings] a turn of {} (0.1°) was pending: cancelled",
            pending
        );
        link.stop()
            .await
            .map_err(Failure::driver(Check::Settings))?;
    }
    Ok(())
}

/// 3. The build's drive type, written if the board has another and read back; the drive type
/// the chassis now has (the board's own if the plan keeps it).
#[maybe_async::maybe_async]
pub(super) async fn drive_type<L: Link>(
    link: &mut L,
    plan: &Plan,
    snapshot: &Snapshot,
) -> Result<DriveType, Failure> {
    let own = snapshot.system_mode.drive_type();
    let Some(drive) = plan.drive else {
        log!(info, "[drive-type] kept: {}", own);
        link.note(Note::Skipped(Check::DriveType, Skip::DriveTypeKept));
        return Ok(own);
    };
    link.note(Note::Start(Check::DriveType));
    if own == drive {
        log!(info, "[drive-type] already {}", drive);
    } else {
        let mode = snapshot.system_mode.with_drive_type(drive);
        link.write(Write::SystemMode(mode))
            .await
            .map_err(Failure::driver(Check::DriveType))?;
        let raw = link
            .read_verified(Register::SystemMode)
            .await
            .map_err(Failure::driver(Check::DriveType))?;
        let read_back = chassis_protocol::SystemMode::from_bits(raw).drive_type();
        if read_back != drive {
            return Err(failure(Check::DriveType, Why::DriveTypeNotSet(read_back)));
        }
        log!(info, "[drive-type] {} -> {}", own, drive);
    }
    link.note(Note::Passed(Check::DriveType));
    Ok(drive)
}

/// 4. Forward, then sideways: the encoders must count. A differential chassis has no
/// sideways (X unused); without encoders nothing counts.
#[maybe_async::maybe_async]
pub(super) async fn straight<L: Link>(
    link: &mut L,
    plan: &Plan,
    drive: DriveType,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    for (check, velocity, slot) in [
        (Check::Forward, Velocity::new(0, plan.speed, 0), 0usize),
        (Check::Strafe, Velocity::new(plan.speed, 0, 0), 1),
    ] {
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
        let seen = drive_for(link, plan, velocity, plan.timing.drive_ms, check).await?;
        if link.core().failsafe_stops() != failsafe_before {
            return Err(failure(check, Why::FailsafeStop));
        }
        if seen.ticks == 0 {
            return Err(failure(check, Why::EncodersStill));
        }
        if let Some(t) = report.ticks.get_mut(slot) {
            *t = seen.ticks;
        }
        log!(info, "[{}] encoders counted {} ticks", check, seen.ticks);
        link.note(Note::Passed(check));
    }
    Ok(())
}

/// 5. One turn, sent once: the pending angle must reach 0 in time, and the gyro see it.
#[maybe_async::maybe_async]
pub(super) async fn turn<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Turn));
    link.stop().await.map_err(Failure::driver(Check::Turn))?;
    link.turn(Turn::by_deci_degrees(plan.turn_deci_degrees))
        .await
        .map_err(Failure::driver(Check::Turn))?;
    log!(info, "[turn] {} (0.1°) sent once", plan.turn_deci_degrees);
    let start = link.now_ms();
    let gyro_peak = until_turned(link, plan, start, failsafe_before).await?;
    report.gyro_peak = gyro_peak;
    if gyro_peak < plan.gyro_threshold {
        return Err(failure(Check::Turn, Why::GyroStill));
    }
    log!(
        info,
        "[turn] done in {} ms, gyro Z peak {}",
        link.now_ms().saturating_sub(start),
        gyro_peak
    );
    link.note(Note::Passed(Check::Turn));
    Ok(())
}

/// Takes telemetry in until the pending angle (read every 200 ms from `start`) is within 1°
/// of 0, or the turn's time is up; the largest |gyro Z| seen.
#[maybe_async::maybe_async]
async fn until_turned<L: Link>(
    link: &mut L,
    plan: &Plan,
    start: u64,
    failsafe_before: u32,
) -> Result<u16, Failure> {
    let mut next_read = start.saturating_add(200);
    let mut gyro_peak = 0u16;
    let mut pending = plan.turn_deci_degrees;
    loop {
        if link.core().failsafe_stops() != failsafe_before {
            return Err(failure(Check::Turn, Why::FailsafeStop));
        }
        let now = link.now_ms();
        if let Some(Event::Telemetry(Downlink::Imu(imu))) =
            link.poll().await.map_err(Failure::driver(Check::Turn))?
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
                Err(e) => return Err(Failure::driver(Check::Turn)(e)),
            }
            if pending.unsigned_abs() <= 10 {
                return Ok(gyro_peak);
            }
            if now.saturating_sub(start) > plan.turn_timeout_ms {
                return Err(failure(Check::Turn, Why::TurnPending(pending)));
            }
        }
    }
}

/// 6. After a stop, the encoders stand still (after 100 ms to settle). Without encoders the
/// stop is sent and the check skipped.
#[maybe_async::maybe_async]
pub(super) async fn stop<L: Link>(
    link: &mut L,
    plan: &Plan,
    drive: DriveType,
) -> Result<(), Failure> {
    if drive == DriveType::DifferentialOpenLoop {
        link.stop().await.map_err(Failure::driver(Check::Stop))?;
        link.note(Note::Skipped(Check::Stop, Skip::NoEncoders));
        return Ok(());
    }
    link.note(Note::Start(Check::Stop));
    link.stop().await.map_err(Failure::driver(Check::Stop))?;
    let still = Velocity::new(0, 0, 0);
    let _ = drive_for(link, plan, still, 100, Check::Stop).await?;
    let seen = drive_for(link, plan, still, 200, Check::Stop).await?;
    // Still: the counters of most frames in a row agree. One frame can carry a changed byte
    // (no checksum), which changes the two pairs it is in; a chassis still moving changes
    // every pair.
    if seen.pairs == 0 {
        return Err(failure(Check::Stop, Why::NoEncoderFrames));
    }
    if seen.changed_pairs.saturating_mul(2) > seen.pairs {
        return Err(failure(Check::Stop, Why::EncodersMoving));
    }
    log!(info, "[stop] encoders still");
    link.note(Note::Passed(Check::Stop));
    Ok(())
}

/// 7. The battery is above its cut-off (the board's, or the plan's when the board uses its
/// built-in table). One frame can carry a changed byte (no checksum), so a reading at or below
/// the limit is judged again on the next frame before it fails.
#[maybe_async::maybe_async]
pub(super) async fn battery<L: Link>(
    link: &mut L,
    plan: &Plan,
    snapshot: &Snapshot,
    report: &mut Report,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::Battery));
    let limit = if snapshot.battery_cutoff_centivolts == 0x7FFF {
        plan.min_centivolts
    } else {
        snapshot.battery_cutoff_centivolts
    };
    let Some(first) = link.core().battery() else {
        return Err(failure(Check::Battery, Why::NoBattery));
    };
    let mut battery = first.value;
    if battery.centivolts <= limit {
        let start = link.now_ms();
        while link.now_ms().saturating_sub(start) < 1_500 {
            link.poll().await.map_err(Failure::driver(Check::Battery))?;
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
    link.note(Note::Passed(Check::Battery));
    Ok(())
}

/// 8. The steady control loop: slow forward, re-sent every command period, a verified register
/// read every [`Plan::loop_read_every_ms`] while moving, no failsafe stop; then stop.
#[maybe_async::maybe_async]
pub(super) async fn control_loop<L: Link>(
    link: &mut L,
    plan: &Plan,
    report: &mut Report,
    failsafe_before: u32,
) -> Result<(), Failure> {
    link.note(Note::Start(Check::ControlLoop));
    let check = Check::ControlLoop;
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
        if link.core().failsafe_stops() != failsafe_before {
            return Err(failure(check, Why::FailsafeStop));
        }
    }
    link.stop().await.map_err(Failure::driver(check))?;
    report.loop_reads = reads;
    log!(
        info,
        "[control-loop] {} ms, {} reads while moving, no failsafe stop",
        plan.timing.loop_ms,
        reads
    );
    link.note(Note::Passed(check));
    Ok(())
}
