//! The covariance model: variances on the diagonal, large ones on the axes the chassis cannot
//! move, the pose's growing with the distance travelled.

/// The covariance parameters (variances, SI units squared): see `docs/odometry.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Noise {
    /// Variance of x and of y, m², per metre travelled (and at the start): the pose's grows
    /// as `pose_xy × (1 + distance travelled in m)`.
    pub pose_xy: f32,
    /// Variance of the heading, rad², per metre travelled and per radian turned (and at the
    /// start) while it is integrated; `pose_yaw` as it is while a quaternion gives it.
    pub pose_yaw: f32,
    /// Variance of vx and vy, (m/s)².
    pub twist_linear: f32,
    /// Variance of wz, (rad/s)².
    pub twist_angular: f32,
    /// Variance on the axes the chassis cannot move (z, roll, pitch; a differential chassis's
    /// sideways speed): large, neither 0 nor infinite. It also caps every other variance.
    pub immobile: f32,
}

impl Noise {
    /// Defaults for a small chassis on a hard floor: σ 3 cm in x and y per √m, 1.8° of heading
    /// per √m (or per √rad), 3 cm/s and 1.8°/s on the twist, 1 000 on what cannot move.
    pub const DEFAULT: Noise = Noise {
        pose_xy: 1e-3,
        pose_yaw: 1e-3,
        twist_linear: 1e-3,
        twist_angular: 1e-3,
        immobile: 1e3,
    };
}

impl Default for Noise {
    fn default() -> Self {
        Noise::DEFAULT
    }
}

/// The smallest variance given out: an estimated axis's is never 0.
pub(crate) const FLOOR: f64 = 1e-9;

/// The variance given for `immobile`: the parameter, or [`Noise::DEFAULT`]'s if it is not a
/// finite number above the floor.
fn immobile(noise: &Noise) -> f64 {
    let v = f64::from(noise.immobile);
    if v.is_finite() && v >= FLOOR {
        v
    } else {
        f64::from(Noise::DEFAULT.immobile)
    }
}

/// `variance` between the floor and the immobile variance (a NaN gives the floor).
fn bounded(variance: f64, noise: &Noise) -> f64 {
    variance.max(FLOOR).min(immobile(noise))
}

/// A row-major 6×6 diagonal over (x, y, z, roll, pitch, yaw) with z, roll and pitch immobile.
fn diagonal(x: f64, y: f64, yaw: f64, noise: &Noise) -> [f64; 36] {
    let still = immobile(noise);
    let mut m = [0.0; 36];
    for (i, v) in [
        bounded(x, noise),
        bounded(y, noise),
        still,
        still,
        still,
        bounded(yaw, noise),
    ]
    .into_iter()
    .enumerate()
    {
        if let Some(cell) = m.get_mut(i * 7) {
            *cell = v;
        }
    }
    m
}

/// The pose's covariance after travelling `travelled_m` and turning `turned_rad` (both
/// absolute, summed), the heading integrated or, if `heading_measured`, given by a quaternion.
pub(crate) fn pose(
    noise: &Noise,
    travelled_m: f32,
    turned_rad: f32,
    heading_measured: bool,
) -> [f64; 36] {
    let travelled = f64::from(travelled_m.max(0.0));
    let xy = f64::from(noise.pose_xy) * (1.0 + travelled);
    let yaw = if heading_measured {
        f64::from(noise.pose_yaw)
    } else {
        f64::from(noise.pose_yaw) * (1.0 + travelled + f64::from(turned_rad.max(0.0)))
    };
    diagonal(xy, xy, yaw, noise)
}

/// The twist's covariance; `sideways` false puts the immobile variance on vy.
pub(crate) fn twist(noise: &Noise, sideways: bool) -> [f64; 36] {
    let linear = f64::from(noise.twist_linear);
    let vy = if sideways { linear } else { immobile(noise) };
    diagonal(linear, vy, f64::from(noise.twist_angular), noise)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The diagonal's six values.
    fn diag(m: &[f64; 36]) -> [f64; 6] {
        [m[0], m[7], m[14], m[21], m[28], m[35]]
    }

    fn off_diagonal_zero(m: &[f64; 36]) -> bool {
        m.iter().enumerate().all(|(i, v)| i % 7 == 0 || *v == 0.0)
    }

    #[test]
    fn at_the_start_the_parameters_with_immobile_axes() {
        let m = pose(&Noise::DEFAULT, 0.0, 0.0, false);
        assert_eq!(
            diag(&m),
            [
                1e-3f32 as f64,
                1e-3f32 as f64,
                1e3,
                1e3,
                1e3,
                1e-3f32 as f64
            ]
        );
        assert!(off_diagonal_zero(&m));
    }

    #[test]
    fn pose_variance_grows_with_distance_and_turning() {
        // 3 m and 2 rad: x, y × 4; yaw × 6.
        let m = pose(&Noise::DEFAULT, 3.0, 2.0, false);
        let p = f64::from(1e-3f32);
        let d = diag(&m);
        assert!((d[0] - 4.0 * p).abs() < 1e-12 && (d[1] - 4.0 * p).abs() < 1e-12);
        assert!((d[5] - 6.0 * p).abs() < 1e-12);
        // A measured heading does not grow.
        let measured = pose(&Noise::DEFAULT, 3.0, 2.0, true);
        assert!((diag(&measured)[5] - p).abs() < 1e-12);
        // Growth stops at the immobile variance.
        let far = pose(&Noise::DEFAULT, 1e9, 0.0, false);
        assert_eq!(diag(&far)[0], 1e3);
    }

    #[test]
    fn twist_sideways_is_immobile_on_a_differential_chassis() {
        let p = f64::from(1e-3f32);
        assert_eq!(
            diag(&twist(&Noise::DEFAULT, true)),
            [p, p, 1e3, 1e3, 1e3, p]
        );
        assert_eq!(
            diag(&twist(&Noise::DEFAULT, false)),
            [p, 1e3, 1e3, 1e3, 1e3, p]
        );
    }

    #[test]
    fn never_zero_nor_infinite_whatever_the_parameters() {
        let bad = Noise {
            pose_xy: 0.0,
            pose_yaw: f32::NAN,
            twist_linear: -1.0,
            twist_angular: 0.0,
            immobile: f32::INFINITY,
        };
        for m in [
            pose(&bad, 1.0, 1.0, false),
            twist(&bad, true),
            twist(&bad, false),
        ] {
            for v in diag(&m) {
                assert!(v >= FLOOR && v.is_finite(), "{v}");
            }
            // The immobile axes get the default's 1 000.
            assert_eq!(diag(&m)[2], 1e3);
        }
    }
}
