//! The 2020 board's chassis: its true pose and its encoders, against values worked out by hand
//! from its geometry (the defaults of `SimConfig`: 1 000 ticks/m, half wheelbase 0.10 m, half
//! track 0.12 m) and the axes of decision A14 (X to the right, Y forward, Z counter-clockwise).
//! The velocity frames are written by hand from `docs/protocol-2020.md`.

use super::*;
use crate::command::{DriveType, Setting, SystemMode, Write};
use core::f64::consts::{FRAC_PI_2, SQRT_2};

/// Y = 250 (0x00FA) forward, direction 0.
const FORWARD_250: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0xFA, 0x00, 0x00, 0x00];
/// X = 250 (0x00FA), direction 0: positive X.
const RIGHT_250: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0xFA, 0x00, 0x00, 0x00, 0x00, 0x00];
/// Z = 220 (0x00DC), direction 0: positive Z.
const TURN_220: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0xDC, 0x00];
/// Z = 120 (0x0078), direction 0: positive Z.
const TURN_120: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x78, 0x00];
/// Angle mode, +90.0° (0x0384), direction 0x10.
const ANGLE_PLUS_90: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0x84, 0x10];
/// Y = 30 000 (0x7530) forward.
const FORWARD_30000: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x75, 0x30, 0x00, 0x00, 0x00];
const STOP: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00];

fn board_with(drive: DriveType) -> Board {
    let mut board = Board::new(SimConfig::default());
    board.receive(&Setting::Write(Write::SystemMode(SystemMode::new(drive))).encode());
    board
}

/// Sends `frame` at the board's current time, runs `ms`, then stops.
fn drive_for(board: &mut Board, frame: &[u8], ms: u64) {
    board.receive(frame);
    board.advance(board.now_ms() + ms);
    board.receive(&STOP);
}

fn near(actual: (f64, f64, f64), expected: (f64, f64, f64), tolerance: f64) {
    let (x, y, yaw) = actual;
    assert!(
        (x - expected.0).abs() < tolerance
            && (y - expected.1).abs() < tolerance
            && (yaw - expected.2).abs() < tolerance,
        "pose {actual:?}, expected {expected:?} within {tolerance}"
    );
}

#[test]
fn forward_for_4_s_at_250_ticks_a_second_is_1_m() {
    let mut board = Board::new(SimConfig::default());
    drive_for(&mut board, &FORWARD_250, 4_000);
    // 250 ticks/s ÷ 1 000 ticks/m × 4 s.
    near(board.pose(), (1.0, 0.0, 0.0), 1e-9);
    // Every wheel counted the metre: 1 000 ticks.
    assert_eq!(board.wheel_ticks(), [1_000; 4]);
    // Stopped: it stays there.
    board.advance(board.now_ms() + 1_000);
    near(board.pose(), (1.0, 0.0, 0.0), 1e-9);
}

#[test]
fn positive_x_is_to_the_right() {
    let mut board = Board::new(SimConfig::default());
    drive_for(&mut board, &RIGHT_250, 4_000);
    near(board.pose(), (0.0, -1.0, 0.0), 1e-9);
    // MOTO1 left front and MOTO3 right rear forward, the others back (Y + X, Y − X).
    assert_eq!(board.wheel_ticks(), [1_000, -1_000, 1_000, -1_000]);
}

#[test]
fn positive_z_turns_counter_clockwise_on_mecanum() {
    let mut board = Board::new(SimConfig::default());
    // 220 ticks/s on the lever 0.10 + 0.12 m at 1 000 ticks/m: 1 rad/s, for 1 s.
    drive_for(&mut board, &TURN_220, 1_000);
    near(board.pose(), (0.0, 0.0, 1.0), 1e-9);
    // Left wheels back, right wheels forward: 220 ticks each.
    assert_eq!(board.wheel_ticks(), [-220, 220, 220, -220]);
}

#[test]
fn positive_z_turns_counter_clockwise_on_a_differential_chassis_too() {
    let mut board = board_with(DriveType::Differential);
    // 120 ticks/s on half the track, 0.12 m: 1 rad/s, for 1 s.
    drive_for(&mut board, &TURN_120, 1_000);
    near(board.pose(), (0.0, 0.0, 1.0), 1e-9);
    assert_eq!(board.wheel_ticks(), [-120, 120, 120, -120]);
}

#[test]
fn an_omni_chassis_goes_root_2_further_than_its_rims() {
    let mut board = board_with(DriveType::Omni);
    drive_for(&mut board, &FORWARD_250, 4_000);
    // Rims at 0.25 m/s on wheels at 45°: the body at 0.25·√2 m/s.
    near(board.pose(), (SQRT_2, 0.0, 0.0), 1e-9);
}

#[test]
fn a_quarter_turn_then_forward_goes_left() {
    let mut board = Board::new(SimConfig::default());
    // π/2 rad at 1 rad/s: 1 570.8 ms; 1 571 ms overshoots by 0.2 mrad.
    drive_for(&mut board, &TURN_220, 1_571);
    drive_for(&mut board, &FORWARD_250, 4_000);
    let (x, y, yaw) = board.pose();
    assert!((yaw - FRAC_PI_2).abs() < 3e-4, "yaw {yaw}");
    assert!(x.abs() < 1e-3 && (y - 1.0).abs() < 1e-6, "({x}, {y})");
}

#[test]
fn a_positive_angle_turn_is_counter_clockwise_and_moves_the_wheels() {
    let mut board = Board::new(SimConfig::default());
    board.advance(10);
    board.receive(&ANGLE_PLUS_90);
    board.advance(2_000);
    assert_eq!(board.pending_deci_degrees(), 0);
    near(board.pose(), (0.0, 0.0, FRAC_PI_2), 1e-9);
    // Each wheel: 0.22 m × π/2 = 0.3456 m, 345.6 ticks, counted in 100 steps of 3.456 (3.455
    // kept: whole thousandths): 345 whole ticks.
    assert_eq!(board.wheel_ticks(), [-345, 345, 345, -345]);
}

#[test]
fn the_encoders_are_running_totals_that_wrap_at_16_bits() {
    let mut board = Board::new(SimConfig::default());
    drive_for(&mut board, &FORWARD_30000, 2_000);
    // 60 000 ticks: past 32 767, so -65 536 + 60 000.
    assert_eq!(board.wheel_ticks(), [-5_536; 4]);
    near(board.pose(), (60.0, 0.0, 0.0), 1e-9);
}

#[test]
fn a_chassis_without_encoders_does_not_move_in_the_model() {
    let mut board = board_with(DriveType::DifferentialOpenLoop);
    drive_for(&mut board, &FORWARD_250, 1_000);
    assert_eq!(board.pose(), (0.0, 0.0, 0.0));
    assert_eq!(board.wheel_ticks(), [0; 4]);
}
