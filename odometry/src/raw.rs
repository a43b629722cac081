//! The 2020 board's raw velocity frame values (`chassis_protocol::Velocity`'s x, y, z) for a
//! body twist, and back.

use crate::Twist2;

/// The 2020 board's raw velocity frame values for a body twist, and back, through a scale
/// (raw units per m/s, raw units per rad/s): the board states no unit (A8).
///
/// The frame's axes are decision A14 (`docs/protocol-2020.md`): X to the right, Y forward, Z
/// counter-clockwise. So X = −vy × `per_m_s`, Y = vx × `per_m_s`, Z = wz × `per_rad_s`. How to
/// measure both on a board: `docs/odometry.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawScale {
    /// Raw units per m/s (X and Y).
    pub per_m_s: f32,
    /// Raw units per rad/s (Z).
    pub per_rad_s: f32,
}

/// `v` rounded (half away from 0) and clamped to i16; NaN gives 0.
fn to_i16(v: f32) -> i16 {
    let r = libm::roundf(v);
    if r.is_nan() {
        0
    } else {
        r.clamp(f32::from(i16::MIN), f32::from(i16::MAX)) as i16
    }
}

impl RawScale {
    /// The simulated 2020 board's: its raw units are wheel ticks per second, 1 000 ticks per
    /// metre, and a turn's lever is 0.10 + 0.12 m (mecanum): 1 000 per m/s, 220 per rad/s.
    pub const SIMULATOR: RawScale = RawScale {
        per_m_s: 1_000.0,
        per_rad_s: 220.0,
    };

    /// (x, y, z) of `chassis_protocol::Velocity::new(x, y, z)` for `body`, rounded and clamped to i16.
    ///
    /// A differential chassis has no X (reserved, 0): give it a twist with vy 0
    /// ([`Geometry::moves_sideways`](crate::Geometry::moves_sideways)).
    #[must_use]
    pub fn to_raw(&self, body: Twist2) -> (i16, i16, i16) {
        (
            to_i16(-body.vy * self.per_m_s),
            to_i16(body.vx * self.per_m_s),
            to_i16(body.wz * self.per_rad_s),
        )
    }

    /// The body twist of a velocity frame's raw (x, y, z); 0 on an axis whose scale is 0 or
    /// not finite. (A negative scale is allowed both ways: a board that turns the other way.)
    #[must_use]
    pub fn to_body(&self, x: i32, y: i32, z: i32) -> Twist2 {
        let per = |raw: i32, scale: f32| {
            if scale.is_finite() && scale != 0.0 {
                raw as f32 / scale
            } else {
                0.0
            }
        };
        Twist2 {
            vx: per(y, self.per_m_s),
            vy: -per(x, self.per_m_s),
            wz: per(z, self.per_rad_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn twist(vx: f32, vy: f32, wz: f32) -> Twist2 {
        Twist2 { vx, vy, wz }
    }

    #[test]
    fn golden_values_of_the_simulators_scale() {
        let s = RawScale::SIMULATOR;
        assert_eq!(s.to_raw(twist(1.0, 0.0, 0.0)), (0, 1_000, 0));
        // Left is negative X (X is to the right).
        assert_eq!(s.to_raw(twist(0.0, 0.5, 0.0)), (-500, 0, 0));
        // Counter-clockwise is positive Z.
        assert_eq!(s.to_raw(twist(0.0, 0.0, 1.0)), (0, 0, 220));
    }

    #[test]
    fn rounded_half_away_from_0() {
        // 2 per unit: 0.75 → 1.5 → 2, −1.25 → X 2.5 → 3, −0.25 → −0.5 → −1 (exact in binary).
        let s = RawScale {
            per_m_s: 2.0,
            per_rad_s: 2.0,
        };
        assert_eq!(s.to_raw(twist(0.75, -1.25, -0.25)), (3, 2, -1));
    }

    #[test]
    fn clamped_and_nan_safe() {
        let s = RawScale::SIMULATOR;
        assert_eq!(
            s.to_raw(twist(100.0, -100.0, -1e9)),
            (32_767, 32_767, -32_768)
        );
        assert_eq!(
            s.to_raw(twist(f32::NAN, f32::INFINITY, 0.0)),
            (-32_768, 0, 0)
        );
    }

    #[test]
    fn back_to_the_body() {
        let s = RawScale::SIMULATOR;
        assert_eq!(s.to_body(-500, 1_000, 220), twist(1.0, 0.5, 1.0));
        let broken = RawScale {
            per_m_s: 0.0,
            per_rad_s: f32::NAN,
        };
        assert_eq!(broken.to_body(1, 2, 3), twist(0.0, 0.0, 0.0));
        // A board that turns the other way: the same scale negated, both ways.
        let mirrored = RawScale {
            per_m_s: 1_000.0,
            per_rad_s: -220.0,
        };
        assert_eq!(mirrored.to_raw(twist(0.0, 0.0, 1.0)), (0, 0, -220));
        assert_eq!(mirrored.to_body(0, 0, -220), twist(0.0, 0.0, 1.0));
    }
}
