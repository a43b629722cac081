//! The yaw of the v1.0.0 telemetry's quaternion, for the rotation check: single precision,
//! without `libm`.

/// π in mrad (rounded).
const PI_MRAD: i32 = 3_142;

/// A change of yaw back into (-π, π], mrad.
pub(super) const fn wrap_mrad(d: i32) -> i32 {
    if d > PI_MRAD {
        d.saturating_sub(2 * PI_MRAD)
    } else if d <= -PI_MRAD {
        d.saturating_add(2 * PI_MRAD)
    } else {
        d
    }
}

/// The yaw (rotation about z) of the quaternion w, x, y, z (× 1000), mrad in (-π, π]:
/// atan2(2 (w z + x y), w² + x² − y² − z²), which needs no normalised quaternion.
pub(super) fn yaw_mrad([w, x, y, z]: [i16; 4]) -> i32 {
    let (w, x, y, z) = (f32::from(w), f32::from(x), f32::from(y), f32::from(z));
    let sin = 2.0 * (w * z + x * y);
    let cos = w * w + x * x - y * y - z * z;
    // `as` saturates: |atan2| ≤ π, so it never needs to.
    (atan2(sin, cos) * 1_000.0) as i32
}

/// atan2 in single precision without `libm`: the polynomial of Abramowitz and Stegun 4.4.49
/// on [0, 1] (error ≤ 1e-5 rad), moved to the right octant.
fn atan2(y: f32, x: f32) -> f32 {
    use core::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    if ax == 0.0 && ay == 0.0 {
        return 0.0;
    }
    let steep = ay > ax;
    let a = if steep { ax / ay } else { ay / ax };
    let s = a * a;
    let mut r =
        a * (0.999_866 + s * (-0.330_299_5 + s * (0.180_141 + s * (-0.085_133 + s * 0.020_835_1))));
    if steep {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 { -r } else { r }
}

#[cfg(test)]
pub(super) mod tests {
    extern crate std;
    use super::*;

    /// The quaternion (× 1000) of a rotation by `yaw_rad` about z.
    pub(in crate::v1) fn about_z(yaw_rad: f64) -> [i16; 4] {
        let (s, c) = (yaw_rad / 2.0).sin_cos();
        [
            (c * 1000.0).round() as i16,
            0,
            0,
            (s * 1000.0).round() as i16,
        ]
    }

    /// `rad` back into (-π, π].
    pub(in crate::v1) fn wrap(rad: f64) -> f64 {
        let two_pi = std::f64::consts::TAU;
        let r = rad.rem_euclid(two_pi);
        if r > std::f64::consts::PI {
            r - two_pi
        } else {
            r
        }
    }

    #[test]
    fn the_yaw_of_a_rotation_about_z_is_its_angle() {
        for deg in (-179..=180).step_by(7) {
            let rad = f64::from(deg).to_radians();
            let yaw = yaw_mrad(about_z(rad));
            let want = (rad * 1000.0).round() as i32;
            // A quaternion in thousandths: about 2 mrad of resolution.
            assert!((yaw - want).abs() <= 3, "{deg}°: {yaw} mrad, not {want}");
        }
        assert_eq!(yaw_mrad([0, 0, 0, 0]), 0, "no quaternion: no yaw, no panic");
    }

    #[test]
    fn atan2_agrees_with_std() {
        for i in -50..=50 {
            for j in -50..=50 {
                let (y, x) = (i as f32 / 7.0, j as f32 / 3.0);
                if x == 0.0 && y == 0.0 {
                    continue;
                }
                assert!((atan2(y, x) - y.atan2(x)).abs() < 2e-5, "atan2({y}, {x})");
            }
        }
    }
}
