//! Property: a constant twist held for 1 s, heard at 25 Hz, ends where the closed form says.
//! The closed form is worked out here in f64 (the motion at a constant twist from the origin:
//! x = (vx sin ωT − vy (1 − cos ωT)) / ω, y = (vx (1 − cos ωT) + vy sin ωT) / ω, yaw = ωT), the
//! wheels' travel by hand from the mecanum equations.

use chassis_odometry::{Counts, Geometry, Noise, Odometry, Twist2};
use proptest::prelude::*;

/// Where a constant twist (vx, vy, wz) takes the chassis from the origin in `t` s.
fn closed_form(vx: f64, vy: f64, wz: f64, t: f64) -> (f64, f64, f64) {
    let phi = wz * t;
    if phi.abs() < 1e-12 {
        return (vx * t, vy * t, 0.0);
    }
    (
        (vx * phi.sin() - vy * (1.0 - phi.cos())) / wz,
        (vx * (1.0 - phi.cos()) + vy * phi.sin()) / wz,
        phi,
    )
}

fn check(odometry: &Odometry, expected: (f64, f64, f64), metres: f64, radians: f64) {
    let pose = odometry.pose();
    let (dx, dy) = (
        f64::from(pose.x) - expected.0,
        f64::from(pose.y) - expected.1,
    );
    let dyaw = f64::from(pose.yaw) - expected.2;
    assert!(
        dx.hypot(dy) < metres && dyaw.abs() < radians,
        "{pose:?}, expected {expected:?}"
    );
}

proptest! {
    /// Measured velocity (the v1.0.0 path) at 25 Hz: each interval is an exact arc, so only
    /// f32 rounding is left (26 frames): within 10 µm and 10 µrad.
    #[test]
    fn measured_velocity(vx in -1.0f32..1.0, vy in -1.0f32..1.0, wz in -3.0f32..3.0) {
        let mut odometry = Odometry::new(Geometry::SIMULATOR, Counts::RunningTotal, Noise::DEFAULT);
        for i in 0..=25u64 {
            odometry.body(Twist2 { vx, vy, wz }, None, 40 * i);
        }
        let expected = closed_form(f64::from(vx), f64::from(vy), f64::from(wz), 1.0);
        check(&odometry, expected, 1e-5, 1e-5);
    }

    /// Encoder frames at 25 Hz, running totals wrapping at 16 bits from a random start, at
    /// 1e5 ticks/m (0.01 mm a tick, so that the ticks' rounding stays small: the heading off
    /// by at most 4 × 0.5 tick / (4 × 0.22 × 1e5) = 2.3e-5 rad, the position by less than
    /// 0.1 mm): within 0.1 mm and 0.05 mrad.
    #[test]
    fn encoders(
        vx in -1.0f64..1.0,
        vy in -1.0f64..1.0,
        wz in -3.0f64..3.0,
        start in proptest::array::uniform4(any::<i16>()),
    ) {
        let geometry = Geometry { ticks_per_m: 1e5, ..Geometry::SIMULATOR };
        let mut odometry = Odometry::new(geometry, Counts::RunningTotal, Noise::DEFAULT);
        // MOTO1..4 of a mecanum chassis, k = 0.10 + 0.12 m.
        let k = 0.22;
        let wheels = [vx - vy - k * wz, vx + vy + k * wz, vx - vy + k * wz, vx + vy - k * wz];
        for i in 0..=25u64 {
            let t = 0.04 * i as f64;
            let mut ticks = [0i16; 4];
            for ((tick, w), s) in ticks.iter_mut().zip(wheels).zip(start) {
                let travelled = (w * t * 1e5).round() as i64;
                *tick = (i64::from(s) + travelled) as i16;
            }
            let twist = odometry.encoders(ticks, 40 * i);
            prop_assert_eq!(twist.is_some(), i > 0);
        }
        check(&odometry, closed_form(vx, vy, wz, 1.0), 1e-4, 5e-5);
    }
}
