//! The odometry against the simulated boards' true pose: two computations that share no code
//! (the simulators integrate their own wheel motion or measured velocity every ms, in f64;
//! the odometry reads only the telemetry a master hears, in f32, along the arc).
//!
//! The commands are REP-103 twists made into the 2020 board's raw frame by
//! `RawScale::SIMULATOR` (decision A14's axes) or into the v1.0.0 board's mm/s and mrad/s:
//! where the board then truly goes is also checked against the twists' closed form.

use chassis_odometry::{Counts, Geometry, Noise, Odometry, Pose2, RawScale, Twist2};
use chassis_protocol::sim::{self, Board, SimConfig};
use chassis_protocol::v1::{self, BodyVelocity, Parser as _};
use chassis_protocol::{Downlink, DownlinkParser, Velocity};

/// What to do: a twist for so many ms (then the next; the last is followed by a stop).
const SCRIPT: [(Twist2, u64); 4] = [
    // 1 m forward.
    (
        Twist2 {
            vx: 0.25,
            vy: 0.0,
            wz: 0.0,
        },
        4_000,
    ),
    // A quarter turn counter-clockwise: 0.5 rad/s for π s (3 142 ms).
    (
        Twist2 {
            vx: 0.0,
            vy: 0.0,
            wz: 0.5,
        },
        3_142,
    ),
    // 0.5 m to the left (now heading along y: towards −x).
    (
        Twist2 {
            vx: 0.0,
            vy: 0.25,
            wz: 0.0,
        },
        2_000,
    ),
    // An arc: 0.2 m/s forward turning clockwise at 0.4 rad/s, for 2 s.
    (
        Twist2 {
            vx: 0.2,
            vy: 0.0,
            wz: -0.4,
        },
        2_000,
    ),
];

/// Where the script ends, worked out by hand along each leg's closed form: (1, 0) heading
/// π/2 + 0.0004 (3 142 ms at 0.5 rad/s: 1.571 rad); 0.5 m to the left: (1 − 0.5 cos(0.0004),
/// −0.5 sin(0.0004)) ≈ (0.5, −0.0002); then the arc at v = 0.2 m/s, ω = −0.4 rad/s for 2 s
/// from heading θ0 = 1.571: x += (v/ω)(sin(θ0 + ωt) − sin θ0), y −= (v/ω)(cos(θ0 + ωt) −
/// cos θ0), with v/ω = −0.5 m and ωt = −0.8 rad.
fn expected_end() -> (f64, f64, f64) {
    let theta0 = 3_142.0f64 / 1_000.0 * 0.5;
    let (mut x, mut y) = (1.0 - 0.5 * theta0.sin(), 0.5 * theta0.cos());
    let (r, turn) = (0.2 / 0.4, -0.8f64);
    x += -r * ((theta0 + turn).sin() - theta0.sin());
    y += r * ((theta0 + turn).cos() - theta0.cos());
    (x, y, theta0 + turn)
}

fn assert_near(
    what: &str,
    actual: (f64, f64, f64),
    expected: (f64, f64, f64),
    metres: f64,
    radians: f64,
) {
    let (dx, dy) = (actual.0 - expected.0, actual.1 - expected.1);
    let dyaw = (actual.2 - expected.2 + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
        - std::f64::consts::PI;
    // The figures docs/odometry.md quotes (`-- --nocapture` shows them).
    println!(
        "{what}: {:.3} mm, {:.3} mrad off",
        dx.hypot(dy) * 1e3,
        dyaw.abs() * 1e3
    );
    assert!(
        dx.hypot(dy) < metres && dyaw.abs() < radians,
        "{what}: {actual:?}, expected {expected:?} (within {metres} m, {radians} rad)"
    );
}

fn of(pose: Pose2) -> (f64, f64, f64) {
    (f64::from(pose.x), f64::from(pose.y), f64::from(pose.yaw))
}

#[test]
fn the_2020_encoders_follow_the_boards_true_pose() {
    let mut board = Board::new(SimConfig::default());
    let mut parser = DownlinkParser::new();
    let mut odometry = Odometry::new(Geometry::SIMULATOR, Counts::RunningTotal, Noise::DEFAULT);
    let mut buf = [0u8; 256];
    let mut frames = 0;
    let mut run = |board: &mut Board, for_ms: u64, odometry: &mut Odometry| {
        let until_ms = board.now_ms() + for_ms;
        while board.now_ms() < until_ms {
            let ms = board.now_ms() + 1;
            board.advance(ms);
            let n = board.transmit(&mut buf);
            let mut heard: Vec<Downlink> = parser.frames(&buf[..n]).collect();
            if n == 0 {
                heard.extend(std::iter::from_fn(|| parser.idle()));
            }
            for frame in heard {
                if let Downlink::Encoders(e) = frame {
                    odometry.encoder_frame(&e, ms);
                    frames += 1;
                }
            }
        }
    };
    // Still for 100 ms: the odometry's first frame (its origin) is the board's power-up pose.
    run(&mut board, 100, &mut odometry);
    for (twist, ms) in SCRIPT {
        let (x, y, z) = RawScale::SIMULATOR.to_raw(twist);
        board.receive(&Velocity::new(x.into(), y.into(), z.into()).encode());
        run(&mut board, ms, &mut odometry);
    }
    board.receive(&Velocity::STOP.encode());
    run(&mut board, 200, &mut odometry);
    println!("{frames} encoder frames heard");
    assert!(frames > 250, "{frames} encoder frames heard");

    // The board went where the twists say: its raw scale and axes are the odometry's. (The
    // raw values are whole ticks/s, exact here: 250, 110, 88.)
    assert_near("true pose", board.pose(), expected_end(), 1e-6, 1e-6);
    // The odometry, from whole ticks (1 mm) at 25 Hz: within 5 mm and 5 mrad.
    assert_near("odometry", of(odometry.pose()), board.pose(), 5e-3, 5e-3);
}

#[test]
fn the_v1_telemetry_follows_the_boards_true_pose() {
    let mut board = sim::v1::Board::new(sim::v1::SimConfig::default());
    let mut parser = v1::DownlinkParser::new();
    let mut odometry = Odometry::new(Geometry::SIMULATOR, Counts::RunningTotal, Noise::DEFAULT);
    let mut buf = [0u8; 256];
    let mut frames = 0;
    let mut run = |board: &mut sim::v1::Board, for_ms: u64, odometry: &mut Odometry| {
        let until_ms = board.now_ms() + for_ms;
        while board.now_ms() < until_ms {
            let ms = board.now_ms() + 1;
            board.advance(ms);
            let n = board.transmit(&mut buf);
            for frame in parser.frames(&buf[..n]) {
                if let v1::Downlink::Telemetry(t) = frame {
                    odometry.v1_telemetry(&t, ms);
                    frames += 1;
                }
            }
        }
    };
    run(&mut board, 100, &mut odometry);
    for (twist, ms) in SCRIPT {
        // The board's vx is to the right, vy forward, in mm/s; wz in mrad/s.
        let command = BodyVelocity::new(
            (-twist.vy * 1_000.0) as i16,
            (twist.vx * 1_000.0) as i16,
            (twist.wz * 1_000.0) as i16,
        );
        board.receive(&v1::Command::BodyVelocity(command).encode());
        run(&mut board, ms, &mut odometry);
    }
    board.receive(&v1::Command::BodyVelocity(BodyVelocity::FORCED_STOP).encode());
    run(&mut board, 200, &mut odometry);
    println!("{frames} telemetry frames heard");
    assert!(frames > 200, "{frames} telemetry frames heard");

    assert_near("true pose", board.pose(), expected_end(), 1e-6, 1e-6);
    // Frames every 45 ms (some dropped): each change of velocity between two frames is
    // averaged over their interval (up to 0.25 m/s × 45 ms / 2 ≈ 6 mm each, 9 changes);
    // the heading is the quaternion's, to its 1e-3 rounding.
    assert_near("odometry", of(odometry.pose()), board.pose(), 2e-2, 5e-3);
}
