//! The v1.0.0 board's telemetry in REP-103 axes: its measured velocity and its quaternion's yaw.

use chassis_protocol::v1::Telemetry;

use crate::Twist2;

/// The REP-103 body twist of a v1.0.0 telemetry frame's measured velocity. The board's vx is
/// sideways, to the right (`docs/odometry.md`: the choice the simulated board makes, as on the
/// 2020 board, decision A14), its vy forward, its wz counter-clockwise, in mm/s and mrad/s:
/// REP-103's vx is the board's vy, its vy the board's −vx, each ÷ 1 000.
#[must_use]
pub fn v1_twist(frame: &Telemetry) -> Twist2 {
    let [vx, vy, wz] = frame.velocity.map(|v| f32::from(v) / 1_000.0);
    Twist2 {
        vx: vy,
        vy: -vx,
        wz,
    }
}

/// The yaw (rad, counter-clockwise, in (-π, π]) of a v1.0.0 telemetry frame's quaternion
/// (w, x, y, z × 1000), or `None` if the frame has none (all four 0). The rotation about z of
/// any quaternion, unit or not: atan2(2(wz + xy), w² + x² − y² − z²).
#[must_use]
pub fn v1_yaw(frame: &Telemetry) -> Option<f32> {
    let [w, x, y, z] = frame.quaternion.map(f32::from);
    let (sin, cos) = (2.0 * (w * z + x * y), w * w + x * x - y * y - z * z);
    if sin == 0.0 && cos == 0.0 {
        return None;
    }
    Some(libm::atan2f(sin, cos))
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::{FRAC_PI_2, PI};

    fn frame(velocity: [i16; 3], quaternion: [i16; 4]) -> Telemetry {
        Telemetry {
            velocity,
            accel: [0; 3],
            gyro: [0; 3],
            quaternion,
            battery_mv: 12_000,
        }
    }

    #[test]
    fn the_boards_axes_turned_into_rep_103() {
        // 0.1 m/s to the right, 0.3 m/s forward, 0.05 rad/s clockwise.
        let t = v1_twist(&frame([100, 300, -50], [1_000, 0, 0, 0]));
        assert_eq!(
            t,
            Twist2 {
                vx: 0.3,
                vy: -0.1,
                wz: -0.05
            }
        );
    }

    #[test]
    fn yaw_of_the_quaternion() {
        assert_eq!(v1_yaw(&frame([0; 3], [1_000, 0, 0, 0])), Some(0.0));
        // cos 45°, sin 45° × 1000: a quarter turn counter-clockwise.
        let quarter = v1_yaw(&frame([0; 3], [707, 0, 0, 707])).unwrap();
        assert!((quarter - FRAC_PI_2).abs() < 1e-6, "{quarter}");
        // (0, 0, 0, 1000): half a turn, π.
        let half = v1_yaw(&frame([0; 3], [0, 0, 0, 1_000])).unwrap();
        assert!((half - PI).abs() < 1e-6, "{half}");
        // (cos 15°, 0, 0, −sin 15°) × 1000, rounded: −30° (to the rounding's 1e-3).
        let back = v1_yaw(&frame([0; 3], [966, 0, 0, -259])).unwrap();
        assert!((back + PI / 6.0).abs() < 1e-3, "{back}");
        assert_eq!(v1_yaw(&frame([0; 3], [0; 4])), None);
    }
}
