//! The simulated chassis's true pose, shared by both boards: where the body motion its wheels
//! make has taken it since power-up, in REP-103 axes (x forward, y left, yaw counter-clockwise,
//! metres and radians), integrated every simulated ms. What an odometry is measured against:
//! it is computed here from the board's own model, never from the telemetry a master reads.

/// π, in f64 (`core::f64::consts::PI`, named here once).
const PI: f64 = core::f64::consts::PI;

/// The true pose: x and y (m) in the frame the chassis powered up in, yaw (rad) in (-π, π].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Pose {
    x: f64,
    y: f64,
    yaw: f64,
}

impl Pose {
    /// At the origin, heading along x.
    pub(super) const fn new() -> Self {
        Pose {
            x: 0.0,
            y: 0.0,
            yaw: 0.0,
        }
    }

    /// (x m, y m, yaw rad in (-π, π]).
    pub(super) const fn get(&self) -> (f64, f64, f64) {
        (self.x, self.y, self.yaw)
    }

    /// Moves by a displacement made in one step, in the body's axes at the step's start:
    /// `forward` and `left` (m), `turn` (rad, counter-clockwise). The midpoint rule: the
    /// translation is taken along the heading halfway through the turn (for a 1 ms step its
    /// relative error is below φ²/24, φ the turn in the step: 4·10⁻⁸ at 1 rad/s).
    pub(super) fn advance(&mut self, forward: f64, left: f64, turn: f64) {
        if !(forward.is_finite() && left.is_finite() && turn.is_finite()) {
            return;
        }
        let (sin, cos) = sin_cos_any(wrap(self.yaw + turn / 2.0));
        self.x += forward * cos - left * sin;
        self.y += forward * sin + left * cos;
        self.yaw = wrap(self.yaw + turn);
    }
}

/// `angle` (rad) back into (-π, π], for an angle within a few turns of it.
fn wrap(mut angle: f64) -> f64 {
    for _ in 0..8 {
        if angle > PI {
            angle -= 2.0 * PI;
        } else if angle <= -PI {
            angle += 2.0 * PI;
        } else {
            break;
        }
    }
    angle
}

/// Sine and cosine of `x` in (-π, π]: of x/2 by the series, then the double angle.
fn sin_cos_any(x: f64) -> (f64, f64) {
    let (s, c) = sin_cos(x / 2.0);
    (2.0 * s * c, c * c - s * s)
}

/// Sine and cosine of `x` (|x| ≤ π/2) by their Taylor series to x¹⁵ and x¹⁴ (error < 1e-9;
/// `core` has no `sin`).
pub(super) fn sin_cos(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let (mut sin, mut cos) = (x, 1.0);
    let (mut sin_term, mut cos_term) = (x, 1.0);
    let mut k = 0.0;
    for _ in 0..7 {
        k += 2.0;
        cos_term *= -x2 / ((k - 1.0) * k);
        sin_term *= -x2 / (k * (k + 1.0));
        cos += cos_term;
        sin += sin_term;
    }
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_series_matches_std_over_a_whole_turn() {
        for i in -1_000..=1_000 {
            let x = PI * f64::from(i) / 1_000.0;
            let (s, c) = sin_cos_any(x);
            assert!((s - x.sin()).abs() < 1e-8, "sin {x}");
            assert!((c - x.cos()).abs() < 1e-8, "cos {x}");
        }
    }

    #[test]
    fn a_quarter_turn_then_forward_goes_left() {
        let mut pose = Pose::new();
        // A quarter turn in 1 000 steps, then 1 m straight on in 1 000.
        for _ in 0..1_000 {
            pose.advance(0.0, 0.0, PI / 2_000.0);
        }
        for _ in 0..1_000 {
            pose.advance(0.001, 0.0, 0.0);
        }
        let (x, y, yaw) = pose.get();
        assert!(x.abs() < 1e-9 && (y - 1.0).abs() < 1e-9, "({x}, {y})");
        assert!((yaw - PI / 2.0).abs() < 1e-9);
    }

    #[test]
    fn yaw_wraps_into_minus_pi_to_pi() {
        let mut pose = Pose::new();
        // 3/4 of a turn counter-clockwise is a quarter turn clockwise.
        for _ in 0..3 {
            pose.advance(0.0, 0.0, PI / 2.0);
        }
        assert!((pose.get().2 + PI / 2.0).abs() < 1e-12);
        // Half a turn each way from 0 ends at +π, never -π.
        let mut back = Pose::new();
        back.advance(0.0, 0.0, -PI);
        assert!((back.get().2 - PI).abs() < 1e-12);
    }

    #[test]
    fn a_displacement_that_is_not_finite_is_ignored() {
        let mut pose = Pose::new();
        pose.advance(f64::NAN, 0.0, 0.0);
        pose.advance(0.0, f64::INFINITY, 0.0);
        assert_eq!(pose.get(), (0.0, 0.0, 0.0));
    }
}
