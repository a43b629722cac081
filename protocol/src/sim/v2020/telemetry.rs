//! The telemetry clock: IMU at 100 Hz, encoders at 25 Hz, battery at 1 Hz, each with its
//! rolling count.

use super::{Board, Motion, clamp_i32};
use crate::telemetry::{Battery, Downlink, Encoders, Imu};

/// Downlink periods in ms: IMU, encoders, battery.
const PERIODS_MS: [u64; 3] = [10, 40, 1_000];

/// The telemetry clock: each stream's count and next frame, and a pause while settings are
/// made.
#[derive(Clone, Debug)]
pub(super) struct Streams {
    /// Each stream's rolling count: IMU, encoders, battery.
    pub(super) seq: [u8; 3],
    /// When each stream's next frame is due, ms.
    pub(super) next_due_ms: [u64; 3],
    /// Telemetry is paused until then, ms.
    pub(super) quiet_until_ms: u64,
}

impl Streams {
    /// The clock at power-up.
    pub(super) const fn new() -> Self {
        Streams {
            seq: [0; 3],
            next_due_ms: [0, 5, 500],
            quiet_until_ms: 0,
        }
    }
}

impl Board {
    /// Sends every telemetry frame due at `now` (unless telemetry is stopped or paused; the
    /// clock goes on either way, so the rates hold when it resumes).
    pub(super) fn send_due_telemetry(&mut self, now: u64) {
        let sending = !self.port.line.faults.telemetry_stopped && !self.telemetry_paused();
        for stream in 0..3 {
            let (Some(due), Some(period)) = (
                self.streams.next_due_ms.get(stream).copied(),
                PERIODS_MS.get(stream),
            ) else {
                continue;
            };
            if now < due {
                continue;
            }
            if let Some(slot) = self.streams.next_due_ms.get_mut(stream) {
                *slot = due.saturating_add(*period);
            }
            if sending {
                let frame = self.telemetry(stream);
                self.send(&frame.encode());
            }
        }
    }

    pub(super) fn telemetry(&mut self, stream: usize) -> Downlink {
        let seq = match self.streams.seq.get_mut(stream) {
            Some(s) => {
                *s = s.wrapping_add(1);
                *s
            }
            None => 0,
        };
        match stream {
            0 => {
                let noise = |b: &mut Board| ((b.next_random() % 9) as i16).wrapping_sub(4);
                let rotation = match self.chassis.motion {
                    Motion::Velocity { z, .. } => z,
                    Motion::Motors(_) => 0,
                };
                let turning = clamp_i32(self.chassis.turn_carry.saturating_mul(10));
                let gyro_z = rotation.saturating_add(turning).clamp(-32_768, 32_767) as i16;
                Downlink::Imu(Imu {
                    accel: [
                        noise(self),
                        noise(self),
                        16_384i16.wrapping_add(noise(self)),
                    ],
                    gyro: [noise(self), noise(self), gyro_z.saturating_add(noise(self))],
                    seq,
                })
            }
            1 => Downlink::Encoders(Encoders {
                ticks: self.chassis.wheel_ticks,
                seq,
            }),
            _ => {
                let (full, cutoff) = match (
                    self.registers.live.battery_full_centivolts,
                    self.registers.live.battery_cutoff_centivolts,
                ) {
                    (0x7FFF, _) | (_, 0x7FFF) => (1_260, 1_050),
                    (full, cutoff) => (full, cutoff),
                };
                let span = u32::from(full.saturating_sub(cutoff)).max(1);
                let above = u32::from(self.chassis.centivolts.saturating_sub(cutoff));
                let percent = above
                    .saturating_mul(100)
                    .checked_div(span)
                    .unwrap_or(0)
                    .min(100) as u16;
                Downlink::Battery(Battery {
                    centivolts: self.chassis.centivolts,
                    percent,
                    seq,
                })
            }
        }
    }
}
