//! A chassis's geometry and its kinematics both ways: the wheel speeds of a body twist, and the
//! body twist of wheel speeds.

use crate::Twist2;
use core::f32::consts::{FRAC_1_SQRT_2, SQRT_2};

/// How the chassis's wheels move it (the board's system-mode drive types; the one without
/// encoders has nothing to measure and is not here).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Drive {
    /// Four mecanum wheels, rollers at 45°: moves in every direction.
    Mecanum,
    /// Four omni wheels on the corners, each driving at 45° to the chassis's axes (an X):
    /// moves in every direction. Each rim moves 1/√2 of what a mecanum wheel's would.
    Omni,
    /// Wheels driven per side (left MOTO1 + MOTO4, right MOTO2 + MOTO3): forward and turning
    /// only.
    Differential,
}

/// A chassis: its drive and its sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Geometry {
    /// How the wheels move it.
    pub drive: Drive,
    /// centre to the front/rear axle, m (lx)
    pub half_wheelbase_m: f32,
    /// centre to a wheel sideways, m (ly; a differential chassis: half its track)
    pub half_track_m: f32,
    /// encoder ticks per metre of wheel travel
    pub ticks_per_m: f32,
}

/// Why a [`Geometry`] cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum GeometryError {
    /// `ticks_per_m` is not a positive finite number.
    TicksPerMetre,
    /// `half_track_m` is not a positive finite number.
    HalfTrack,
    /// `half_wheelbase_m` is negative or not finite.
    HalfWheelbase,
}

impl core::fmt::Display for GeometryError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            GeometryError::TicksPerMetre => "ticks per metre must be a positive finite number",
            GeometryError::HalfTrack => "the half track must be a positive finite number of metres",
            GeometryError::HalfWheelbase => {
                "the half wheelbase must be a finite number of metres, 0 or more"
            }
        })
    }
}

impl core::error::Error for GeometryError {}

impl Geometry {
    /// The simulated 2020 board's chassis (`chassis_protocol::sim::SimConfig`'s defaults):
    /// mecanum, half wheelbase 0.10 m, half track 0.12 m, 1 000 ticks per metre.
    pub const SIMULATOR: Geometry = Geometry {
        drive: Drive::Mecanum,
        half_wheelbase_m: 0.10,
        half_track_m: 0.12,
        ticks_per_m: 1_000.0,
    };

    /// Whether every size can be used: ticks per metre and the half track positive, the half
    /// wheelbase 0 or more (a differential chassis does not use it), all finite. With a
    /// geometry that fails this, [`Geometry::body_twist`] may give values that are not finite,
    /// which [`Odometry`](crate::Odometry) ignores.
    ///
    /// # Errors
    ///
    /// The first size that cannot be used.
    pub fn validate(&self) -> Result<(), GeometryError> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !positive(self.ticks_per_m) {
            return Err(GeometryError::TicksPerMetre);
        }
        if !positive(self.half_track_m) {
            return Err(GeometryError::HalfTrack);
        }
        if !(self.half_wheelbase_m.is_finite() && self.half_wheelbase_m >= 0.0) {
            return Err(GeometryError::HalfWheelbase);
        }
        Ok(())
    }

    /// The lever of a turn on each wheel, m: lx + ly (mecanum, omni), ly (differential).
    fn lever(&self) -> f32 {
        match self.drive {
            Drive::Mecanum | Drive::Omni => self.half_wheelbase_m + self.half_track_m,
            Drive::Differential => self.half_track_m,
        }
    }

    /// Wheel surface speeds, m/s, in the board's motor order: MOTO1 left front, MOTO2 right front,
    /// MOTO3 right rear, MOTO4 left rear (a differential chassis: left = MOTO1 + MOTO4,
    /// right = MOTO2 + MOTO3).
    ///
    /// Mecanum, with k = lx + ly: MOTO1 vx − vy − k·wz, MOTO2 vx + vy + k·wz, MOTO3
    /// vx − vy + k·wz, MOTO4 vx + vy − k·wz. Omni: the same over √2. Differential: left
    /// vx − ly·wz, right vx + ly·wz (vy cannot be made and is left out).
    #[must_use]
    pub fn wheel_speeds(&self, body: Twist2) -> [f32; 4] {
        let Twist2 { vx, vy, wz } = body;
        let turn = self.lever() * wz;
        match self.drive {
            Drive::Mecanum => [
                vx - vy - turn,
                vx + vy + turn,
                vx - vy + turn,
                vx + vy - turn,
            ],
            Drive::Omni => [
                vx - vy - turn,
                vx + vy + turn,
                vx - vy + turn,
                vx + vy - turn,
            ]
            .map(|s| s * FRAC_1_SQRT_2),
            Drive::Differential => {
                let (left, right) = (vx - turn, vx + turn);
                [left, right, right, left]
            }
        }
    }

    /// The body twist those wheel speeds give (least squares over the four wheels; vy = 0 on a
    /// differential chassis).
    ///
    /// Mecanum: vx = (m1 + m2 + m3 + m4) / 4, vy = (−m1 + m2 − m3 + m4) / 4,
    /// wz = (−m1 + m2 + m3 − m4) / 4k; omni: the same × √2. Differential: left and right are
    /// each side's mean, vx = (left + right) / 2, wz = (right − left) / 2ly. Also right for
    /// distances: wheel travels in m give the body's displacement and turn.
    #[must_use]
    pub fn body_twist(&self, wheels: [f32; 4]) -> Twist2 {
        let [m1, m2, m3, m4] = wheels;
        let lever = self.lever();
        match self.drive {
            Drive::Mecanum | Drive::Omni => {
                let scale = if self.drive == Drive::Omni {
                    SQRT_2
                } else {
                    1.0
                };
                Twist2 {
                    vx: (m1 + m2 + m3 + m4) / 4.0 * scale,
                    vy: (-m1 + m2 - m3 + m4) / 4.0 * scale,
                    wz: (-m1 + m2 + m3 - m4) / (4.0 * lever) * scale,
                }
            }
            Drive::Differential => {
                let (left, right) = ((m1 + m4) / 2.0, (m2 + m3) / 2.0);
                Twist2 {
                    vx: (left + right) / 2.0,
                    vy: 0.0,
                    wz: (right - left) / (2.0 * lever),
                }
            }
        }
    }

    /// Whether the chassis can move sideways (mecanum and omni: yes).
    #[must_use]
    pub fn moves_sideways(&self) -> bool {
        !matches!(self.drive, Drive::Differential)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MECANUM: Geometry = Geometry::SIMULATOR;
    const OMNI: Geometry = Geometry {
        drive: Drive::Omni,
        ..Geometry::SIMULATOR
    };
    const DIFFERENTIAL: Geometry = Geometry {
        drive: Drive::Differential,
        ..Geometry::SIMULATOR
    };

    fn twist(vx: f32, vy: f32, wz: f32) -> Twist2 {
        Twist2 { vx, vy, wz }
    }

    fn close(a: [f32; 4], b: [f32; 4]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6)
    }

    #[test]
    fn mecanum_golden_values() {
        // lx 0.10, ly 0.12: k = 0.22.
        assert_eq!(MECANUM.wheel_speeds(twist(1.0, 0.0, 0.0)), [1.0; 4]);
        assert!(close(
            MECANUM.wheel_speeds(twist(0.0, 0.0, 1.0)),
            [-0.22, 0.22, 0.22, -0.22]
        ));
        // Left: the front-left and rear-right wheels back, the others forward.
        assert_eq!(
            MECANUM.wheel_speeds(twist(0.0, 1.0, 0.0)),
            [-1.0, 1.0, -1.0, 1.0]
        );
    }

    #[test]
    fn omni_golden_values() {
        let r = core::f32::consts::FRAC_1_SQRT_2;
        assert!(close(OMNI.wheel_speeds(twist(1.0, 0.0, 0.0)), [r; 4]));
        assert!(close(
            OMNI.wheel_speeds(twist(0.0, 0.0, 1.0)),
            [-0.22 * r, 0.22 * r, 0.22 * r, -0.22 * r]
        ));
    }

    #[test]
    fn differential_golden_values() {
        // Half the track 0.12 m: 1 rad/s is 0.12 m/s on each side, left back.
        assert!(close(
            DIFFERENTIAL.wheel_speeds(twist(0.5, 0.0, 1.0)),
            [0.38, 0.62, 0.62, 0.38]
        ));
        // Sideways cannot be made: left out.
        assert_eq!(DIFFERENTIAL.wheel_speeds(twist(0.0, 1.0, 0.0)), [0.0; 4]);
    }

    #[test]
    fn round_trips() {
        for t in [
            twist(1.0, 0.0, 0.0),
            twist(0.3, -0.2, 0.7),
            twist(-1.5, 2.0, -3.0),
            twist(0.0, 0.0, 0.0),
        ] {
            for g in [MECANUM, OMNI] {
                let back = g.body_twist(g.wheel_speeds(t));
                assert!(
                    (back.vx - t.vx).abs() < 1e-5
                        && (back.vy - t.vy).abs() < 1e-5
                        && (back.wz - t.wz).abs() < 1e-5,
                    "{g:?}: {t:?} → {back:?}"
                );
            }
            let back = DIFFERENTIAL.body_twist(DIFFERENTIAL.wheel_speeds(t));
            assert!(
                (back.vx - t.vx).abs() < 1e-5 && back.vy == 0.0 && (back.wz - t.wz).abs() < 1e-5,
                "differential: {t:?} → {back:?}"
            );
        }
    }

    #[test]
    fn body_twist_golden_values() {
        // Wheels that disagree: least squares. Mecanum [1, 0, 0, 0]: vx 1/4, vy −1/4,
        // wz −1/(4 × 0.22).
        let t = MECANUM.body_twist([1.0, 0.0, 0.0, 0.0]);
        assert!((t.vx - 0.25).abs() < 1e-6 && (t.vy + 0.25).abs() < 1e-6);
        assert!((t.wz + 1.0 / 0.88).abs() < 1e-5);
        // Differential left side at 1 (one wheel of it): left 0.5, right 0.
        let t = DIFFERENTIAL.body_twist([1.0, 0.0, 0.0, 0.0]);
        assert!((t.vx - 0.25).abs() < 1e-6 && t.vy == 0.0);
        assert!((t.wz + 0.5 / 0.24).abs() < 1e-5);
    }

    #[test]
    fn sideways() {
        assert!(MECANUM.moves_sideways());
        assert!(OMNI.moves_sideways());
        assert!(!DIFFERENTIAL.moves_sideways());
    }

    #[test]
    fn validation() {
        assert_eq!(MECANUM.validate(), Ok(()));
        let zero_ticks = Geometry {
            ticks_per_m: 0.0,
            ..MECANUM
        };
        assert_eq!(zero_ticks.validate(), Err(GeometryError::TicksPerMetre));
        let nan_track = Geometry {
            half_track_m: f32::NAN,
            ..MECANUM
        };
        assert_eq!(nan_track.validate(), Err(GeometryError::HalfTrack));
        let negative = Geometry {
            half_wheelbase_m: -0.1,
            ..MECANUM
        };
        assert_eq!(negative.validate(), Err(GeometryError::HalfWheelbase));
        let differential_no_wheelbase = Geometry {
            half_wheelbase_m: 0.0,
            ..DIFFERENTIAL
        };
        assert_eq!(differential_no_wheelbase.validate(), Ok(()));
    }
}
