//! A timed drive, as the v1.0.0 checks judge it: the velocity re-sent every command period,
//! the telemetry frames taken in.

use super::checks::Run;
use super::yaw::{wrap_mrad, yaw_mrad};
use super::{Failure, Link, Why};
use crate::{Check, failure};
use chassis_protocol::driver::v1::Event;
use chassis_protocol::v1::{BodyVelocity, Telemetry};

/// What the telemetry of a timed drive showed, from its judged part on.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Seen {
    pub(super) frames: u32,
    /// Sum of each measured velocity component.
    sum: [i32; 3],
    /// The largest |component|.
    pub(super) peak: [u16; 3],
    /// When the first and the last frame judged came.
    pub(super) first_at: Option<u64>,
    pub(super) last_at: u64,
    /// The yaw of the last frame, and the changes from frame to frame added up, mrad.
    yaw_mrad: Option<i32>,
    pub(super) turned_mrad: i32,
    pub(super) gyro_z_peak: u16,
}

impl Seen {
    fn take(&mut self, t: &Telemetry, at_ms: u64) {
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
    pub(super) fn mean(&self, axis: usize) -> Option<i16> {
        let sum = *self.sum.get(axis)?;
        let n = i32::try_from(self.frames).ok().filter(|n| *n > 0)?;
        i16::try_from(sum.checked_div(n)?).ok()
    }
}

/// Drives at `velocity` (if any: `None` watches after the forced stop) for `ms`, re-sending it
/// every command period, taking telemetry in; frames that come `judge_after_ms` or more after
/// the start are judged. The driver's failsafe stopping the chassis (since the settings were
/// read) ends it at once: never command motion past that.
#[maybe_async::maybe_async]
pub(super) async fn drive_for<L: Link>(
    run: &mut Run<'_, L>,
    velocity: Option<BodyVelocity>,
    ms: u64,
    judge_after_ms: u64,
    check: Check,
) -> Result<Seen, Failure> {
    let (plan, link, failsafe_before) = (run.plan, &mut *run.link, run.failsafe_before);
    let start = link.now_ms();
    let mut next_send = start;
    let mut seen = Seen::default();
    loop {
        let now = link.now_ms();
        if now.saturating_sub(start) >= ms {
            return Ok(seen);
        }
        if link.core().failsafe_stops() != failsafe_before {
            return Err(failure(check, Why::FailsafeStop));
        }
        if let Some(velocity) = velocity {
            if now >= next_send {
                next_send = now.saturating_add(plan.timing.command_period_ms);
                link.set_velocity(velocity)
                    .await
                    .map_err(Failure::driver(check))?;
            }
        }
        if let Some(Event::Telemetry(t)) = link.poll().await.map_err(Failure::driver(check))? {
            if now.saturating_sub(start) >= judge_after_ms {
                seen.take(&t, now);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::Seen;
    use crate::v1::yaw::tests::{about_z, wrap};

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
}
