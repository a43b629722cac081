//! What the v1.0.0 board's chassis does: what its wheels were last told, the body velocity it
//! moves at, the yaw it turns by, the battery; the mecanum kinematics both ways.

use super::Board;
use crate::sim::pose::{Pose, sin_cos};
use crate::v1::{BodyVelocity, MotorVelocity};

/// Battery voltage at power-up, mV.
pub const START_MV: i16 = 12_000;

/// π and 2π in µrad.
const PI_URAD: i64 = 3_141_593;
const TWO_PI_URAD: i64 = 6_283_185;

/// What the wheels were last told: the body (`0x25`) or each motor (`0x26`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Drive {
    Body(BodyVelocity),
    Motors(MotorVelocity),
}

/// What the chassis does: what the wheels were last told, the heading, the battery, where it
/// truly is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Chassis {
    /// What the wheels were last told.
    pub(super) drive: Drive,
    /// The heading, µrad in (-π, π].
    pub(super) yaw_urad: i64,
    /// The battery, mV.
    pub(super) battery_mv: i16,
    /// The true pose (REP-103 axes), the measured velocity integrated every ms.
    pub(super) pose: Pose,
}

impl Chassis {
    /// Standing still (the forced stop), heading 0, a full battery.
    pub(super) const fn new() -> Self {
        Chassis {
            drive: Drive::Body(BodyVelocity::FORCED_STOP),
            yaw_urad: 0,
            battery_mv: START_MV,
            pose: Pose::new(),
        }
    }
}

impl Board {
    /// One ms of motion: the heading turns by wz, the chassis moves (its true pose), the
    /// battery drains (faster while moving).
    pub(super) fn move_chassis(&mut self, now: u64) {
        let [vx, vy, wz] = self.measured_velocity();
        // mrad/s for 1 ms: µrad.
        self.chassis.yaw_urad = wrap_yaw(self.chassis.yaw_urad.saturating_add(i64::from(wz)));
        // mm/s and mrad/s for 1 ms: µm and µrad. The board's vx is to the right, vy forward
        // (see the module's kinematics): REP-103's forward is vy, its left is -vx.
        self.chassis.pose.advance(
            f64::from(vy) * 1e-6,
            -f64::from(vx) * 1e-6,
            f64::from(wz) * 1e-6,
        );
        let moving = self.measured_velocity() != [0; 3];
        let drain_every = if moving { 2_000 } else { 20_000 };
        if now.checked_rem(drain_every) == Some(0) {
            self.chassis.battery_mv = self.chassis.battery_mv.saturating_sub(1).max(0);
        }
    }

    /// The body-velocity state, as `0x35` answers it: the last `0x25` frame as received, or
    /// after a `0x26` its `ctl` and type with the body velocity its wheel speeds give.
    #[must_use]
    pub fn velocity(&self) -> BodyVelocity {
        match self.chassis.drive {
            Drive::Body(v) => v,
            Drive::Motors(m) => {
                let [vx_mm_s, vy_mm_s, wz_mrad_s] = self.measured_velocity();
                BodyVelocity {
                    ctl: m.ctl,
                    kind: m.kind,
                    vx_mm_s,
                    vy_mm_s,
                    wz_mrad_s,
                }
            }
        }
    }

    /// The wheel speeds, as `0x36` answers them: the last `0x26` command's (0 unless its `ctl`
    /// drives), or those the body velocity gives, with the `0x25` frame's `ctl` and type.
    #[must_use]
    pub fn motor_speeds(&self) -> MotorVelocity {
        match self.chassis.drive {
            Drive::Motors(m) if m.ctl == BodyVelocity::DRIVE => m,
            Drive::Motors(m) => MotorVelocity {
                speeds: [0; 4],
                ..m
            },
            Drive::Body(v) => MotorVelocity {
                ctl: v.ctl,
                kind: v.kind,
                speeds: wheels(self.measured_velocity(), self.lever_mm()),
            },
        }
    }

    /// The body velocity the chassis moves at (what telemetry reports): vx, vy (mm/s), wz
    /// (mrad/s); 0 unless the last command's `ctl` drives.
    #[must_use]
    pub fn measured_velocity(&self) -> [i16; 3] {
        match self.chassis.drive {
            Drive::Body(v) if v.ctl == BodyVelocity::DRIVE => [v.vx_mm_s, v.vy_mm_s, v.wz_mrad_s],
            Drive::Motors(m) if m.ctl == BodyVelocity::DRIVE => body(m.speeds, self.lever_mm()),
            Drive::Body(_) | Drive::Motors(_) => [0; 3],
        }
    }

    /// The heading, in µrad in (-π, π]: wz integrated since power-up.
    #[must_use]
    pub const fn yaw_urad(&self) -> i64 {
        self.chassis.yaw_urad
    }

    /// Where the chassis truly is: x, y (m) and yaw (rad, in (-π, π]) since power-up, REP-103
    /// axes (x forward, y left, yaw counter-clockwise), the measured body velocity integrated
    /// every ms. What an odometry built on the telemetry is measured against.
    #[must_use]
    pub const fn pose(&self) -> (f64, f64, f64) {
        self.chassis.pose.get()
    }

    /// The battery voltage, mV.
    #[must_use]
    pub const fn battery_mv(&self) -> i16 {
        self.chassis.battery_mv
    }

    /// The lever of the rotation on each wheel: (wheel spacing + axle spacing) / 2, mm.
    pub(super) fn lever_mm(&self) -> i32 {
        (i32::from(self.registers.geometry.wheel_spacing_mm)
            .saturating_add(i32::from(self.registers.geometry.axle_spacing_mm)))
            / 2
    }
}

fn saturate(v: i32) -> i16 {
    i16::try_from(v.clamp(i32::from(i16::MIN), i32::from(i16::MAX))).unwrap_or(0)
}

/// Mecanum wheel rim speeds (mm/s) of a body velocity (vx, vy mm/s, wz mrad/s): M1 front-left,
/// M2 front-right, M3 rear-left, M4 rear-right.
fn wheels([vx, vy, wz]: [i16; 3], lever_mm: i32) -> [i16; 4] {
    let (vx, vy) = (i32::from(vx), i32::from(vy));
    let turn = i32::from(wz).saturating_mul(lever_mm) / 1_000;
    [
        vy.saturating_add(vx).saturating_sub(turn),
        vy.saturating_sub(vx).saturating_add(turn),
        vy.saturating_sub(vx).saturating_sub(turn),
        vy.saturating_add(vx).saturating_add(turn),
    ]
    .map(saturate)
}

/// The body velocity of mecanum wheel speeds: the inverse of [`wheels`].
fn body(speeds: [i16; 4], lever_mm: i32) -> [i16; 3] {
    let [m1, m2, m3, m4] = speeds.map(i32::from);
    let vy = m1.saturating_add(m2).saturating_add(m3).saturating_add(m4) / 4;
    let vx = m1.saturating_add(m4).saturating_sub(m2).saturating_sub(m3) / 4;
    let turn = m2.saturating_add(m4).saturating_sub(m1).saturating_sub(m3);
    let wz = turn
        .saturating_mul(1_000)
        .checked_div(lever_mm.saturating_mul(4))
        .unwrap_or(0);
    [saturate(vx), saturate(vy), saturate(wz)]
}

/// `yaw` back into (-π, π] (it moves less than 2π a step).
pub(super) fn wrap_yaw(yaw: i64) -> i64 {
    if yaw > PI_URAD {
        yaw.saturating_sub(TWO_PI_URAD)
    } else if yaw <= -PI_URAD {
        yaw.saturating_add(TWO_PI_URAD)
    } else {
        yaw
    }
}

/// The quaternion w, x, y, z (× 1000) of a rotation by `yaw_urad` (in (-π, π]) about z.
pub(super) fn quaternion(yaw_urad: i64) -> [i16; 4] {
    let (sin, cos) = sin_cos(yaw_urad as f64 / 2_000_000.0);
    [milli(cos), 0, 0, milli(sin)]
}

/// `v` × 1000, rounded (half away from 0).
fn milli(v: f64) -> i16 {
    let r = v * 1_000.0;
    (if r < 0.0 { r - 0.5 } else { r + 0.5 }) as i16
}
