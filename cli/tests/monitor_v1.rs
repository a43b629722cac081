//! `chassis monitor [--drive]` on a board running the v1.0.0 firmware, in a terminal of its own
//! (a pseudo-terminal), keys typed into it, against the simulated v1.0.0 board served on a real
//! pseudo-terminal. The frames the board must receive are written by hand from `docs/protocol-v1.md`:
//! `7B`, code, ten payload bytes, BCC = XOR of every byte before it, `7D`.

#![cfg(unix)]

mod harness;

use chassis_protocol::sim::v1::Board;
use harness::monitor::assert_failsafe_holds;
use harness::v1::{FORCED_STOP, FORWARD, frames, v1_board};
use harness::{Terminal, TestBoard, signal};
use std::time::{Duration, Instant};

/// `0x25`, ctl 2, type 4, vy 350 mm/s (01 5E); BCC 7B^25^02^04^01^5E = 07.
const FORWARD_350: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0x01, 0x5E, 0, 0, 0, 0, 0x07, 0x7D,
];
/// `0x25`, ctl 2, type 4, vx 300 mm/s (01 2C): to the right; BCC 7B^25^02^04^01^2C = 75.
const RIGHT: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0x01, 0x2C, 0, 0, 0, 0, 0, 0, 0x75, 0x7D,
];
/// `0x25`, ctl 2, type 4, wz 500 mrad/s (01 F4): counter-clockwise; BCC 7B^25^02^04^01^F4 = AD.
const ROTATE_LEFT: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0, 0, 0x01, 0xF4, 0, 0, 0xAD, 0x7D,
];
/// `0x25`, ctl 2, type 4, wz -500 mrad/s (FE 0C): clockwise; BCC 7B^25^02^04^FE^0C = AA.
const ROTATE_RIGHT: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0, 0, 0, 0, 0xFE, 0x0C, 0, 0, 0xAA, 0x7D,
];

/// A frame that sets the chassis moving: `0x25` with ctl 2 and a velocity not zero.
fn moves(frame: &[u8; 14]) -> bool {
    frame[1] == 0x25 && frame[2] == 0x02 && frame[4..10].iter().any(|b| *b != 0)
}

/// Waits (up to 5 s) until the board heard `frame`, byte for byte, `n` times.
fn wait_for_frame(board: &TestBoard<Board>, what: &str, frame: [u8; 14], n: usize) {
    let start = Instant::now();
    while frames(&board.heard())
        .iter()
        .filter(|f| **f == frame)
        .count()
        < n
    {
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "the board was never sent {what}: {:02X?}",
            frames(&board.heard())
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Waits (up to 5 s) until the board heard `frame` after the last `after`.
fn wait_for_frame_after(board: &TestBoard<Board>, what: &str, frame: [u8; 14], after: [u8; 14]) {
    let start = Instant::now();
    loop {
        let all = frames(&board.heard());
        let from = all.iter().rposition(|f| *f == after).map_or(0, |i| i + 1);
        if all[from..].contains(&frame) {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "the board was never sent {what}: {all:02X?}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The last frame the board heard is the forced stop.
fn ends_with_the_forced_stop(heard: &[u8]) {
    let all = frames(heard);
    assert_eq!(
        all.last(),
        Some(&FORCED_STOP),
        "the last frame is the forced stop: {all:02X?}"
    );
}

/// What the board was sent after the last forced stop that moves it.
fn driven_after_last_stop(heard: &[u8]) -> Vec<[u8; 14]> {
    let all = frames(heard);
    let at = all
        .iter()
        .rposition(|f| *f == FORCED_STOP)
        .expect("a forced stop");
    all[at + 1..].iter().copied().filter(moves).collect()
}

/// `chassis monitor ARGS` on `board` in a terminal, once the link is up.
fn monitor(board: &TestBoard<Board>, args: &[&str]) -> Terminal {
    let mut all = vec!["--port", board.path.as_str(), "monitor"];
    all.extend_from_slice(args);
    let term = Terminal::spawn(&all);
    term.wait_for_text("LINK UP");
    term
}

#[test]
fn the_view_shows_the_link_the_battery_and_the_yaw_and_sends_nothing() {
    let board = v1_board();
    // No --firmware: the monitor finds the generation by listening.
    let mut term = monitor(&board, &[]);
    term.wait_for_text("firmware v1.0.0");
    // The simulated board's 12 000 mV.
    term.wait_for_text("12.00 V");
    // Standing still: yaw 0 from the quaternion (1000, 0, 0, 0).
    term.wait_for_text("yaw     0.0°");
    term.wait_for_text("accel raw");
    term.wait_for_text("gyro raw");
    term.wait_for_text(" Hz");
    term.wait_for_text("frames good");
    term.wait_for_text("bad BCC         0");
    term.wait_for_text("read only");
    term.press(b"q");
    let status = term.wait(5);
    assert!(status.success(), "{status:?}: {}", term.text());
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "a read-only monitor sent {heard:02X?}");
}

#[test]
fn keys_drive_in_mm_per_s_and_q_ends_with_the_forced_stop() {
    let board = v1_board();
    let mut term = monitor(&board, &["--drive"]);
    term.wait_for_text("z/x rotate 0.5 rad/s");
    term.press(b"w");
    wait_for_frame(&board, "vy = 300 mm/s after w", FORWARD, 1);
    // Re-sent while the key's velocity stands.
    wait_for_frame(&board, "vy = 300 mm/s again", FORWARD, 3);
    term.wait_for_text("driving at 0.300 m/s: vx 0.000 vy 0.300 m/s, wz 0.000 rad/s");
    // The board measures what it was told.
    term.wait_for_text("vy   0.300 m/s");
    term.press(b"+");
    wait_for_frame(&board, "vy = 350 mm/s after +", FORWARD_350, 1);
    term.press(b"-");
    wait_for_frame_after(&board, "vy = 300 mm/s after -", FORWARD, FORWARD_350);
    term.press(b"z");
    wait_for_frame(&board, "wz = 0.5 rad/s after z", ROTATE_LEFT, 1);
    term.wait_for_text("wz   0.500 rad/s");
    // Turning counter-clockwise at 28.6°/s: the yaw from the quaternion grows.
    let start = Instant::now();
    while !(10..=120).any(|deg| term.text().contains(&format!("yaw {deg:>5}."))) {
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "the yaw turns: {}",
            term.text()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    term.press(b"x");
    wait_for_frame(&board, "wz = -0.5 rad/s after x", ROTATE_RIGHT, 1);
    // Space: the forced stop, and nothing re-sent after it.
    term.press(b" ");
    wait_for_frame(&board, "the forced stop after space", FORCED_STOP, 1);
    term.wait_for_text("stopped");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        driven_after_last_stop(&board.heard()),
        Vec::<[u8; 14]>::new()
    );

    term.press(b"d");
    wait_for_frame(&board, "vx = 300 mm/s after d", RIGHT, 1);
    term.press(b"q");
    let status = term.wait(5);
    assert!(status.success(), "{status:?}: {}", term.text());
    let (sim, heard) = board.finish();
    ends_with_the_forced_stop(&heard);
    assert_eq!(
        sim.velocity(),
        chassis_protocol::v1::BodyVelocity::FORCED_STOP
    );
}

#[test]
fn ctrl_c_ends_with_the_forced_stop() {
    let board = v1_board();
    let mut term = monitor(&board, &["--drive"]);
    term.press(b"w");
    wait_for_frame(&board, "vy = 300 mm/s after w", FORWARD, 2);
    // Ctrl-C, a key in the monitor's raw mode, quits, stopping first.
    term.press(&[0x03]);
    let status = term.wait(5);
    assert!(status.success(), "{status:?}: {}", term.text());
    let (_, heard) = board.finish();
    ends_with_the_forced_stop(&heard);
}

#[test]
fn every_signal_stops_a_driving_monitor() {
    for (name, number) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let board = v1_board();
        let mut term = monitor(&board, &["--drive"]);
        term.press(b"d");
        wait_for_frame(&board, "vx = 300 mm/s after d", RIGHT, 2);
        signal(&term.child, name);
        let status = term.wait(5);
        assert_eq!(status.code(), Some(128 + number), "SIG{name}");
        let (_, heard) = board.finish();
        ends_with_the_forced_stop(&heard);
    }
}

#[test]
fn t_sends_nothing_and_says_there_is_no_turn_by_an_angle() {
    let board = v1_board();
    let mut term = monitor(&board, &["--drive"]);
    term.press(b"t");
    term.wait_for_text("no turn by an angle on v1.0.0");
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(board.heard(), Vec::<u8>::new(), "t sent something");
    term.press(b"q");
    let status = term.wait(5);
    assert!(status.success(), "{status:?}: {}", term.text());
    let (_, heard) = board.finish();
    assert_eq!(frames(&heard), vec![FORCED_STOP], "only the quit's stop");
}

#[test]
fn after_its_failsafe_stop_the_monitor_drives_only_on_a_new_key() {
    let board = v1_board();
    let mut term = monitor(&board, &["--drive"]);
    term.press(b"w");
    wait_for_frame(&board, "vy = 300 mm/s after w", FORWARD, 2);

    // The board goes quiet with the key's velocity being re-sent, then comes back: the
    // failsafe's forced stop holds.
    assert_failsafe_holds(&board, &term, driven_after_last_stop, &["measured (stale)"]);

    // A key, pressed again, drives.
    term.press(b"w");
    let start = Instant::now();
    while driven_after_last_stop(&board.heard()).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "the key drives again"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(driven_after_last_stop(&board.heard())[0], FORWARD);

    term.press(b"q");
    let status = term.wait(5);
    assert!(status.success(), "{status:?}: {}", term.text());
    let (_, heard) = board.finish();
    ends_with_the_forced_stop(&heard);
}

#[test]
fn a_speed_out_of_range_is_refused_in_mm_per_s() {
    let board = v1_board();
    let out = board.run(&["monitor", "--drive", "--speed", "5000"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("5000 is out of range"), "{err}");
    assert!(err.contains("mm/s"), "{err}");
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "{heard:02X?}");
}

#[test]
fn without_a_terminal_it_says_so_in_one_line_and_sends_nothing() {
    let board = v1_board();
    let out = board.run(&["monitor", "--drive"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("monitor draws on a terminal"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "{heard:02X?}");
}
