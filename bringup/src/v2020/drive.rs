//! A timed drive, as the 2020 checks judge it: the velocity re-sent every command period, the
//! encoder frames taken in.

use super::checks::Run;
use super::{Failure, Link, Why};
use crate::{Check, failure};
use chassis_protocol::Downlink;
use chassis_protocol::Velocity;
use chassis_protocol::driver::Event;

/// What the encoder frames of a timed drive showed.
pub(super) struct Seen {
    /// Sum over the wheels of |ticks at the end − ticks at the start|.
    pub(super) ticks: u32,
    /// Encoder frames in a row (pairs) seen, and how many of them differ.
    pub(super) pairs: u32,
    pub(super) changed_pairs: u32,
}

/// Drives at `velocity` for `ms`, re-sending it every command period (a velocity of 0 is not
/// sent: the stop check watches after its stop), taking telemetry in. The driver's failsafe
/// stopping the chassis ends it at once: never command motion past that.
#[maybe_async::maybe_async]
pub(super) async fn drive_for<L: Link>(
    run: &mut Run<'_, L>,
    velocity: Velocity,
    ms: u64,
    check: Check,
) -> Result<Seen, Failure> {
    let (plan, link) = (run.plan, &mut *run.link);
    let still = Velocity::new(0, 0, 0);
    let start = link.now_ms();
    let mut next_send = start;
    let mut first: Option<[i16; 4]> = None;
    let mut last: Option<[i16; 4]> = None;
    let (mut pairs, mut changed_pairs) = (0u32, 0u32);
    let failsafe_before = link.core().failsafe_stops();
    while link.now_ms().saturating_sub(start) < ms {
        if link.core().failsafe_stops() != failsafe_before {
            return Err(failure(check, Why::FailsafeStop));
        }
        let now = link.now_ms();
        if now >= next_send && velocity != still {
            next_send = now.saturating_add(plan.timing.command_period_ms);
            link.set_velocity(velocity)
                .await
                .map_err(Failure::driver(check))?;
        }
        if let Some(Event::Telemetry(Downlink::Encoders(e))) =
            link.poll().await.map_err(Failure::driver(check))?
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
    if velocity != still && first.is_none() {
        return Err(failure(check, Why::NoEncoderFrames));
    }
    Ok(Seen {
        ticks: ticks(first, last),
        pairs,
        changed_pairs,
    })
}

/// Sum over the wheels of |`last` − `first`| (0 without both).
fn ticks(first: Option<[i16; 4]>, last: Option<[i16; 4]>) -> u32 {
    match (first, last) {
        (Some(a), Some(b)) => a
            .iter()
            .zip(b.iter())
            .map(|(a, b)| u32::from(b.wrapping_sub(*a).unsigned_abs()))
            .fold(0u32, u32::saturating_add),
        _ => 0,
    }
}
