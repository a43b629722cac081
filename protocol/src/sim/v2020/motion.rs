//! Chassis motion: what the board was told, wheel speeds for each drive type, the encoders and
//! the gyro they move, angle turns at 90°/s, the true pose, a draining battery.

use super::Board;
use crate::command::DriveType;
use crate::sim::pose::Pose;

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
    /// The true pose (REP-103 axes): the body motion the wheels make, integrated every ms.
    pub(super) pose: Pose,
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
            pose: Pose::new(),
        }
    }
}

/// Turning speed in angle mode: 9 × 0.1° every 10 ms, 90°/s.
const TURN_DECI_DEGREES_PER_10_MS: i64 = 9;

/// Which way a counter-clockwise turn of the body moves each wheel: MOTO1 left front and MOTO4
/// left rear back, MOTO2 right front and MOTO3 right rear forward (every drive type).
const TURN_PATTERN: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];

impl Board {
    /// Wheel speeds in encoder ticks per second for the current motion: the firmware's mapping
    /// of the raw body velocity, in the axes of decision A14 (X to the right, Y forward, Z
    /// counter-clockwise). Mecanum and omni: MOTO1 left front Y + X − Z, MOTO2 right front
    /// Y − X + Z, MOTO3 right rear Y + X + Z, MOTO4 left rear Y − X − Z; differential: left
    /// (MOTO1, MOTO4) Y − Z, right (MOTO2, MOTO3) Y + Z.
    pub(super) fn wheel_speeds(&self) -> [i32; 4] {
        match self.chassis.motion {
            Motion::Motors(values) => values,
            Motion::Velocity { x, y, z } => match self.registers.live.system_mode.drive_type() {
                DriveType::Omni | DriveType::Mecanum => [
                    y.saturating_add(x).saturating_sub(z),
                    y.saturating_sub(x).saturating_add(z),
                    y.saturating_add(x).saturating_add(z),
                    y.saturating_sub(x).saturating_sub(z),
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

    /// The chassis's scales for its drive type: wheel ticks per metre the body travels, and
    /// per radian it turns; `None` without encoders (the model does not move such a chassis).
    ///
    /// Mecanum: ticks per metre of rim travel, and (half wheelbase + half track) × that per
    /// radian. Omni, its wheels at 45° on the corners (an X): each rim moves 1/√2 of what a
    /// mecanum wheel's would. Differential: half the track × ticks per metre per radian.
    fn scales(&self) -> Option<(f64, f64)> {
        let per_m = f64::from(self.config.ticks_per_m.max(1));
        let (lx, ly) = (
            f64::from(self.config.half_wheelbase_mm) / 1_000.0,
            f64::from(self.config.half_track_mm) / 1_000.0,
        );
        match self.registers.live.system_mode.drive_type() {
            DriveType::Mecanum => Some((per_m, (lx + ly) * per_m)),
            DriveType::Omni => Some((
                per_m * core::f64::consts::FRAC_1_SQRT_2,
                (lx + ly) * per_m * core::f64::consts::FRAC_1_SQRT_2,
            )),
            DriveType::Differential => Some((per_m, ly * per_m)),
            DriveType::DifferentialOpenLoop | DriveType::Reserved(_) => None,
        }
    }

    /// One ms of an angle turn: the rate (0.1° per 10 ms) goes to the gyro every ms; the angle
    /// moves on every 10th. The angle turned this ms, 0.1° (counter-clockwise positive).
    fn turn_one_ms(&mut self) -> i64 {
        if self.chassis.pending_deci_degrees == 0 {
            self.chassis.turn_carry = 0;
            return 0;
        }
        let rate = self
            .chassis
            .pending_deci_degrees
            .clamp(-TURN_DECI_DEGREES_PER_10_MS, TURN_DECI_DEGREES_PER_10_MS);
        self.chassis.turn_carry = rate;
        if self.port.now_ms.checked_rem(10) == Some(0) {
            self.chassis.pending_deci_degrees =
                self.chassis.pending_deci_degrees.saturating_sub(rate);
            rate
        } else {
            0
        }
    }

    /// One ms of motion: an angle turn goes on, the wheels turn (the turn's travel with
    /// theirs), the encoders count, the chassis moves (its true pose), the battery drains.
    pub(super) fn move_chassis(&mut self) {
        let turned_deci_degrees = self.turn_one_ms();
        let scales = self.scales();
        // The turn's travel of each wheel this ms, in ticks.
        let turn_radians = turned_deci_degrees as f64 * core::f64::consts::PI / 1_800.0;
        let turn_ticks = TURN_PATTERN.map(|sign| match scales {
            Some((_, per_radian)) => sign * per_radian * turn_radians,
            None => 0.0,
        });
        let speeds = self.wheel_speeds();
        let mut travel = [0.0f64; 4];
        for (((ticks, carry), (speed, turn)), moved) in self
            .chassis
            .wheel_ticks
            .iter_mut()
            .zip(&mut self.chassis.tick_carry)
            .zip(speeds.into_iter().zip(turn_ticks))
            .zip(&mut travel)
        {
            // Ticks per second → thousandths of a tick this ms, the turn's rounded in, the
            // remainder carried to the next ms.
            let milli_ticks = speed.saturating_add(round_i32(turn * 1_000.0));
            let total = carry.saturating_add(milli_ticks);
            let whole = total / 1_000;
            *carry = total % 1_000;
            *ticks = ticks.wrapping_add(whole as i16);
            // The true travel, unrounded.
            *moved = f64::from(speed) / 1_000.0 + turn;
        }
        if let Some((per_m, per_radian)) = scales {
            let differential =
                self.registers.live.system_mode.drive_type() == DriveType::Differential;
            let [x, y, z] = raw_body(travel, differential);
            // X is to the right: REP-103's left is -X.
            self.chassis
                .pose
                .advance(y / per_m, -x / per_m, z / per_radian);
        }
        let moving = speeds.iter().any(|s| *s != 0) || self.chassis.turn_carry != 0;
        let drain_every = if moving { 10_000 } else { 60_000 };
        if self.port.now_ms.checked_rem(drain_every) == Some(0) {
            self.chassis.centivolts = self.chassis.centivolts.saturating_sub(1);
        }
    }
}

/// The raw body motion (X to the right, Y forward, Z counter-clockwise; in wheel ticks) that
/// wheel travels give, MOTO1..MOTO4: the inverse of [`Board::wheel_speeds`]'s mapping (least
/// squares over the four wheels).
fn raw_body([m1, m2, m3, m4]: [f64; 4], differential: bool) -> [f64; 3] {
    if differential {
        let (left, right) = ((m1 + m4) / 2.0, (m2 + m3) / 2.0);
        [0.0, (left + right) / 2.0, (right - left) / 2.0]
    } else {
        [
            (m1 - m2 + m3 - m4) / 4.0,
            (m1 + m2 + m3 + m4) / 4.0,
            (-m1 + m2 + m3 - m4) / 4.0,
        ]
    }
}

/// `v` rounded half away from 0 (`core` has no `round` for f64), saturated to i32.
fn round_i32(v: f64) -> i32 {
    (if v < 0.0 { v - 0.5 } else { v + 0.5 }) as i32
}
