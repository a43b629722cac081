//! Chassis motion: what the board was told, wheel speeds for each drive type, the encoders and
//! the gyro they move, angle turns at 90°/s, a draining battery.

use super::Board;
use crate::command::DriveType;

/// What the chassis was last told to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Motion {
    /// Body velocity (mode `01`, angle mode off).
    Velocity {
        /// X.
        x: i32,
        /// Y.
        y: i32,
        /// Z.
        z: i32,
    },
    /// Each motor (modes `02` / `03`).
    Motors([i32; 4]),
}

/// What the chassis does: what it was told, the turn pending, the wheels' encoders, the
/// battery.
#[derive(Clone, Debug)]
pub(super) struct Chassis {
    /// What it was last told to do.
    pub(super) motion: Motion,
    /// The turn still pending, 0.1°.
    pub(super) pending_deci_degrees: i64,
    /// Every angle ever commanded, added up, 0.1°.
    pub(super) total_turn_deci_degrees: i64,
    /// The turn rate this ms, 0.1° per 10 ms (the gyro reads it).
    pub(super) turn_carry: i64,
    /// The encoders' counters.
    pub(super) wheel_ticks: [i16; 4],
    /// What each encoder counted of a tick so far, thousandths.
    pub(super) tick_carry: [i32; 4],
    /// The battery, 0.01 V.
    pub(super) centivolts: u16,
}

impl Chassis {
    /// Standing still, a full battery.
    pub(super) const fn new() -> Self {
        Chassis {
            motion: Motion::Velocity { x: 0, y: 0, z: 0 },
            pending_deci_degrees: 0,
            total_turn_deci_degrees: 0,
            turn_carry: 0,
            wheel_ticks: [0; 4],
            tick_carry: [0; 4],
            centivolts: 1_240,
        }
    }
}

/// Turning speed in angle mode: 9 × 0.1° every 10 ms, 90°/s.
const TURN_DECI_DEGREES_PER_10_MS: i64 = 9;
impl Board {
    /// Wheel speeds in encoder ticks per second for the current motion.
    pub(super) fn wheel_speeds(&self) -> [i32; 4] {
        match self.chassis.motion {
            Motion::Motors(values) => values,
            Motion::Velocity { x, y, z } => match self.registers.live.system_mode.drive_type() {
                DriveType::Omni | DriveType::Mecanum => [
                    y.saturating_add(x).saturating_add(z),
                    y.saturating_sub(x).saturating_sub(z),
                    y.saturating_add(x).saturating_sub(z),
                    y.saturating_sub(x).saturating_add(z),
                ],
                DriveType::Differential => {
                    let (left, right) = (y.saturating_sub(z), y.saturating_add(z));
                    [left, right, right, left]
                }
                // No encoders to move.
                DriveType::DifferentialOpenLoop | DriveType::Reserved(_) => [0; 4],
            },
        }
    }

    pub(super) fn move_chassis(&mut self) {
        let speeds = self.wheel_speeds();
        for ((ticks, carry), speed) in self
            .chassis
            .wheel_ticks
            .iter_mut()
            .zip(&mut self.chassis.tick_carry)
            .zip(speeds)
        {
            // Ticks per second → per ms, carrying the remainder.
            let total = carry.saturating_add(speed);
            let whole = total / 1_000;
            *carry = total % 1_000;
            *ticks = ticks.wrapping_add(whole as i16);
        }
        if self.chassis.pending_deci_degrees != 0 {
            // The rate (0.1° per 10 ms) goes to the gyro every ms; the angle moves on every 10.
            let rate = self
                .chassis
                .pending_deci_degrees
                .clamp(-TURN_DECI_DEGREES_PER_10_MS, TURN_DECI_DEGREES_PER_10_MS);
            if self.port.now_ms.checked_rem(10) == Some(0) {
                self.chassis.pending_deci_degrees =
                    self.chassis.pending_deci_degrees.saturating_sub(rate);
            }
            self.chassis.turn_carry = rate;
        } else {
            self.chassis.turn_carry = 0;
        }
        let moving = speeds.iter().any(|s| *s != 0) || self.chassis.turn_carry != 0;
        let drain_every = if moving { 10_000 } else { 60_000 };
        if self.port.now_ms.checked_rem(drain_every) == Some(0) {
            self.chassis.centivolts = self.chassis.centivolts.saturating_sub(1);
        }
    }
}
