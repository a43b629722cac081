//! `chassis check` on a board running the v1.0.0 firmware, served on a real pseudo-terminal:
//! the bring-up passes and ends with the forced stop, `--no-motion` sends only readbacks, every
//! signal and a board gone quiet leave the forced stop as the last frame the board received, and
//! nothing is ever written. The frames are written by hand from `docs/protocol-v1.md` (BCC = XOR of
//! the bytes before it).

#![cfg(unix)]

mod harness;

use chassis_protocol::sim::v1::Board;
use chassis_protocol::v1::BodyVelocity;
use harness::v1::{FORCED_STOP, FORWARD, frames, v1_board};
use harness::{TestBoard, signal, wait};
use std::process::Output;
use std::time::{Duration, Instant};

/// The readback requests' codes (system, geometry, body velocity, motor speeds, PID).
const READBACKS: [u8; 5] = [0x33, 0x34, 0x35, 0x36, 0x50];
/// The settings frames' codes (system, geometry, PID): the check never sends one.
const SETTINGS: [u8; 3] = [0x23, 0x24, 0x40];

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Waits until the board was sent the check's forward drive.
fn wait_for_motion(board: &TestBoard<Board>) {
    let start = Instant::now();
    while !board.heard().windows(14).any(|w| w == FORWARD) {
        assert!(start.elapsed() < Duration::from_secs(10), "never drove");
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_v1_board_passes_every_check_and_ends_with_the_forced_stop() {
    let board = v1_board();
    let out = board.run(&["check", "--yes"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    for needle in [
        "(firmware v1.0.0)",
        "[1/8] link         ok",
        "[2/8] settings     ok",
        "[3/8] forward      ok",
        "[4/8] strafe       ok",
        "[5/8] rotation     ok",
        "[6/8] stop         ok",
        "[7/8] battery      ok",
        "[8/8] control-loop ok",
        "PASS: 8 checks passed in",
        "wheel diameter 60 mm",
        "the chassis is stopped (forced stop)",
    ] {
        assert!(stdout.contains(needle), "{needle:?} in\n{stdout}");
    }
    println!("{stdout}");
    let (board, heard) = board.finish();
    let frames = frames(&heard);
    assert_eq!(frames.last(), Some(&FORCED_STOP));
    assert_eq!(board.velocity(), BodyVelocity::FORCED_STOP);
    assert!(frames.contains(&FORWARD));
    assert!(
        frames.iter().all(|f| !SETTINGS.contains(&f[1])),
        "nothing written"
    );
    // Only velocities, the forced stop and readbacks.
    assert!(
        frames
            .iter()
            .all(|f| f[1] == 0x25 || READBACKS.contains(&f[1])),
        "{frames:02X?}"
    );
}

#[test]
fn no_motion_on_v1_sends_only_readbacks() {
    let board = v1_board();
    let out = board.run(&["check", "--no-motion"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("PASS: 3 checks passed, 5 skipped"),
        "{stdout}"
    );
    assert!(
        stdout.contains("nothing moved, nothing was written"),
        "{stdout}"
    );
    let (_, heard) = board.finish();
    let frames = frames(&heard);
    // The system, geometry and PID readbacks, each a whole request: 7B code, ten 00, BCC, 7D.
    let request = |code: u8| {
        let mut f = [0u8; 14];
        f[0] = 0x7B;
        f[1] = code;
        f[12] = 0x7B ^ code;
        f[13] = 0x7D;
        f
    };
    assert_eq!(frames, vec![request(0x33), request(0x34), request(0x50)]);
}

#[test]
fn every_signal_during_the_v1_check_sends_the_forced_stop() {
    for (name, number) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let board = v1_board();
        let child = board.spawn(&["check", "--yes"]);
        wait_for_motion(&board);
        std::thread::sleep(Duration::from_millis(100));
        signal(&child, name);
        let out = wait(child, 10);
        let (stdout, stderr) = text(&out);
        assert_eq!(
            out.status.code(),
            Some(128 + number),
            "SIG{name}: {stdout}\n{stderr}"
        );
        assert!(
            stderr.contains(&format!("interrupted by SIG{name}"))
                && stderr.contains("the chassis was stopped (forced stop)"),
            "{stderr}"
        );
        let (board, heard) = board.finish();
        assert_eq!(frames(&heard).last(), Some(&FORCED_STOP), "SIG{name}");
        assert_eq!(board.velocity(), BodyVelocity::FORCED_STOP, "SIG{name}");
    }
}

#[test]
fn a_v1_board_gone_quiet_during_the_check_fails_it_and_gets_the_forced_stop() {
    let board = v1_board();
    let child = board.spawn(&["check", "--yes"]);
    wait_for_motion(&board);
    board.go_silent(true);
    let out = wait(child, 20);
    let (stdout, stderr) = text(&out);
    let code = out.status.code().unwrap_or(0);
    assert!((13..=18).contains(&code), "{code}: {stdout}\n{stderr}");
    assert!(stderr.contains("FAIL: "), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("went quiet") || stderr.contains("no telemetry"),
        "{stderr}"
    );
    assert!(
        stderr.contains("the forced stop was sent but not confirmed"),
        "{stderr}"
    );
    assert!(!stderr.contains("the chassis was stopped"), "{stderr}");
    let (board, heard) = board.finish();
    assert_eq!(frames(&heard).last(), Some(&FORCED_STOP));
    assert_eq!(board.velocity(), BodyVelocity::FORCED_STOP);
}

#[test]
fn the_v1_check_refuses_a_drive_type_and_asks_before_moving_with_nothing_sent() {
    let board = v1_board();
    let out = board.run(&["check", "--yes", "--drive-type", "mecanum"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("no drive-type register"), "{stderr}");
    // Without --yes and no terminal to ask at: nothing moves.
    let out = board.run(&["check"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("a rotation at 1 rad/s") && stderr.contains("add --yes"),
        "{stderr}"
    );
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "sent {heard:02X?}");
}

#[test]
fn bytes_of_neither_firmware_fail_the_link_check_with_nothing_sent() {
    let device = harness::OtherDevice::start();
    let out = harness::chassis(&["--port", &device.path, "check", "--yes"]);
    let heard = device.finish();
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(10), "{stderr}");
    assert!(
        stderr.contains("FAIL: link") && stderr.contains("no frame of either firmware"),
        "{stderr}"
    );
    assert!(heard.is_empty(), "sent {heard:02X?}");
}
