//! A body twist, a pose, and the pose after a motion at a constant twist: along the exact arc.

use core::f32::consts::PI;

/// A body twist (REP-103): velocities in the chassis's own axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Twist2 {
    /// Forward, m/s.
    pub vx: f32,
    /// To the left, m/s.
    pub vy: f32,
    /// Turning counter-clockwise (seen from above), rad/s.
    pub wz: f32,
}

/// A pose in the plane (REP-105's odometry frame): where the chassis is and where it heads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pose2 {
    /// m.
    pub x: f32,
    /// m.
    pub y: f32,
    /// Heading, rad, counter-clockwise from x, in (-π, π].
    pub yaw: f32,
}

/// Below this |φ| (the turn over one step, rad), the arc's two coefficients come from their
/// Taylor series instead of a division by φ. There the series' first omitted terms (φ⁴/120 and
/// φ⁵/720) are under 10⁻¹⁰, far below an `f32`'s resolution, so the two forms agree across
/// the threshold to rounding (tested).
pub(crate) const SERIES_BELOW: f32 = 1e-2;

/// The arc's coefficients for a turn φ: (sin φ / φ, (1 − cos φ) / φ). The second is computed as
/// 2 sin²(φ/2) / φ, without the cancellation of 1 − cos φ in `f32`.
pub(crate) fn arc_coefficients(phi: f32) -> (f32, f32) {
    if phi.abs() < SERIES_BELOW {
        let phi2 = phi * phi;
        (1.0 - phi2 / 6.0, phi / 2.0 * (1.0 - phi2 / 12.0))
    } else {
        let half = libm::sinf(phi / 2.0);
        (libm::sinf(phi) / phi, 2.0 * half * half / phi)
    }
}

/// `angle` (rad) into (-π, π]; a value that is not finite is left as it is.
pub(crate) fn wrap(angle: f32) -> f32 {
    if !angle.is_finite() {
        return angle;
    }
    if angle > -PI && angle <= PI {
        return angle;
    }
    let turns = libm::roundf(angle / (2.0 * PI));
    let wrapped = angle - turns * 2.0 * PI;
    if wrapped <= -PI {
        wrapped + 2.0 * PI
    } else if wrapped > PI {
        wrapped - 2.0 * PI
    } else {
        wrapped
    }
}

impl Pose2 {
    /// The pose after a motion at a constant body twist that, straight on, would have moved
    /// `forward` and `left` (m: the twist's vx·dt and vy·dt) and that turned by `turn` (rad:
    /// wz·dt): along the exact arc. In the body's axes at the start the chassis ends at
    /// (a·forward − b·left, b·forward + a·left) with a = sin φ / φ and b = (1 − cos φ) / φ,
    /// φ = `turn`; that is turned by the heading and added, and the heading turns by φ.
    #[must_use]
    pub fn along_arc(self, forward: f32, left: f32, turn: f32) -> Pose2 {
        let (a, b) = arc_coefficients(turn);
        let (ahead, aside) = (a * forward - b * left, b * forward + a * left);
        let (sin, cos) = (libm::sinf(self.yaw), libm::cosf(self.yaw));
        Pose2 {
            x: self.x + cos * ahead - sin * aside,
            y: self.y + sin * ahead + cos * aside,
            yaw: wrap(self.yaw + turn),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_minus_pi_to_pi() {
        assert_eq!(wrap(0.5), 0.5);
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(-PI), PI);
        assert!((wrap(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-6);
        assert!((wrap(-3.0 * PI / 2.0) - PI / 2.0).abs() < 1e-6);
        assert!((wrap(20.0 * PI + 0.25) - 0.25).abs() < 1e-4);
        assert!(wrap(f32::NAN).is_nan());
    }

    #[test]
    fn straight_on_heading_along_x() {
        let pose = Pose2::default().along_arc(1.0, 0.0, 0.0);
        assert_eq!(
            pose,
            Pose2 {
                x: 1.0,
                y: 0.0,
                yaw: 0.0
            }
        );
    }

    #[test]
    fn a_half_circle_of_radius_1() {
        // π m forward while turning by π: a half circle to the left, ending 2 m to the left,
        // heading back.
        let pose = Pose2::default().along_arc(PI, 0.0, PI);
        assert!(
            pose.x.abs() < 1e-6 && (pose.y - 2.0).abs() < 1e-6,
            "{pose:?}"
        );
        assert!((pose.yaw - PI).abs() < 1e-6);
    }

    #[test]
    fn a_quarter_circle_sideways() {
        // π/2 m to the left while turning by π/2 (radius 1, centre behind): ends at (−1, 1).
        let pose = Pose2::default().along_arc(0.0, PI / 2.0, PI / 2.0);
        assert!(
            (pose.x + 1.0).abs() < 1e-6 && (pose.y - 1.0).abs() < 1e-6,
            "{pose:?}"
        );
    }

    #[test]
    fn the_series_and_the_division_agree_across_the_threshold() {
        for phi in [SERIES_BELOW, -SERIES_BELOW] {
            let below = arc_coefficients(phi * (1.0 - 1e-6));
            let at = arc_coefficients(phi);
            let above = arc_coefficients(phi * (1.0 + 1e-6));
            for (x, y) in [(below, at), (at, above)] {
                assert!((x.0 - y.0).abs() < 1e-6, "{x:?} {y:?}");
                // b ≈ φ/2 = 5e-3, moving by 5e-9 over the step of 1e-6·φ: agreement to 4e-6
                // of it.
                assert!((x.1 - y.1).abs() < 2e-8, "{x:?} {y:?}");
            }
        }
        // The textbook values on either side: sin φ / φ and (1 − cos φ) / φ in f64 (the
        // latter as 2 sin²(φ/2) / φ, exact in f64 where 1 − cos φ would cancel).
        for phi in [1e-7f64, 1e-4, 9.9e-3, 1.01e-2, 0.5, 3.0] {
            let (a, b) = arc_coefficients(phi as f32);
            let (ea, eb) = (
                sin64(phi) / phi,
                2.0 * sin64(phi / 2.0) * sin64(phi / 2.0) / phi,
            );
            assert!((f64::from(a) - ea).abs() < 1e-6, "a at {phi}");
            assert!(
                (f64::from(b) - eb).abs() < 1e-6 * eb.abs().max(1e-3),
                "b at {phi}"
            );
        }
        // φ = 0: no division.
        assert_eq!(arc_coefficients(0.0), (1.0, 0.0));
    }

    /// f64 sine by libm's double version: another implementation than the f32 one under test.
    fn sin64(x: f64) -> f64 {
        libm::sin(x)
    }
}
