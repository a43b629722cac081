//! `chassis monitor --drive` in a terminal of its own (a pseudo-terminal), keys typed into
//! it, against a simulated board that records every byte it is sent and can go silent.

#![cfg(unix)]

mod harness;

use chassis_protocol::Command;
use harness::monitor::assert_failsafe_holds;
use harness::{Terminal, TestBoard, assert_stopped, commands, moves, signal};
use std::time::Duration;

fn ys(board: &TestBoard, y: i32) -> usize {
    board
        .commands()
        .iter()
        .filter(|c| matches!(c, Command::Velocity(v) if v.y == y))
        .count()
}

fn turns(board: &TestBoard) -> Vec<i32> {
    harness::turns(&board.commands())
}

/// What the board was sent after the last stop frame moved it: nothing.
fn driven_after_last_stop(heard: &[u8]) -> Vec<Command> {
    let at = heard
        .windows(harness::STOP.len())
        .rposition(|w| w == harness::STOP)
        .expect("a stop frame");
    commands(&heard[at + harness::STOP.len()..])
        .into_iter()
        .filter(moves)
        .collect()
}

#[test]
fn after_its_failsafe_stop_the_monitor_drives_only_on_a_new_key() {
    let board = TestBoard::start();
    let mut term = board.monitor_driving(b"w", harness::forward(300));

    // The board goes quiet with the key's velocity being re-sent, then comes back: the
    // failsafe's stop holds.
    assert_failsafe_holds(&board, &term, driven_after_last_stop, &[]);

    // A key, pressed again, drives.
    let before = ys(&board, 300);
    term.press(b"w");
    let start = std::time::Instant::now();
    while ys(&board, 300) == before {
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "the key drives again"
        );
        std::thread::sleep(Duration::from_millis(10));
    }

    // Ctrl-C, a key in the monitor's raw mode, quits, stopping first.
    term.press(&[0x03]);
    let status = term.wait(5);
    assert!(status.success(), "{status:?}");
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
}

#[test]
fn the_monitor_turn_ends_and_speed_keys_apply_at_once() {
    let board = TestBoard::start();
    let mut term = board.monitor_driving(b"w", harness::forward(300));
    term.press(b"+");
    board.wait_for(
        "y = 350 after +",
        |c| matches!(c, Command::Velocity(v) if v.y == 350),
    );
    term.press(b"-");
    term.press(b"-");
    board.wait_for(
        "y = 250 after - -",
        |c| matches!(c, Command::Velocity(v) if v.y == 250),
    );
    term.press(b" ");
    std::thread::sleep(Duration::from_millis(200));

    term.press(b"t");
    board.wait_for("the turn", |c| matches!(c, Command::Turn(_)));
    // 90° at the simulated board's 90°/s: done in about a second, and said.
    term.wait_for_text("turn done");
    assert!(!term.text().contains("(turning)"), "{}", term.text());
    term.press(b"t");
    let start = std::time::Instant::now();
    while turns(&board).len() < 2 {
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "a second t turns again: {}",
            term.text()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(turns(&board), vec![900, 900]);
    term.press(b"q");
    let status = term.wait(5);
    assert!(status.success(), "{status:?}");
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
}

#[test]
fn every_signal_stops_a_driving_monitor() {
    for (name, number) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let board = TestBoard::start();
        let mut term =
            board.monitor_driving(b"d", |c| matches!(c, Command::Velocity(v) if v.x == 300));
        signal(&term.child, name);
        let status = term.wait(5);
        assert_eq!(status.code(), Some(128 + number), "SIG{name}");
        let (board, heard) = board.finish();
        assert_stopped(&board, &heard);
    }
}

#[test]
fn turn_and_drive_show_their_progress_on_a_terminal() {
    let board = TestBoard::start();
    let mut term = Terminal::spawn(&["--port", &board.path, "turn", "90"]);
    term.wait_for_text("turning");
    term.wait_for_text("of 90.0°");
    assert!(term.wait(10).success(), "{}", term.text());
    let mut term = Terminal::spawn(&["--port", &board.path, "drive", "--y", "100", "--for", "1"]);
    term.wait_for_text("driving");
    term.wait_for_text("/1 s");
    assert!(term.wait(10).success(), "{}", term.text());
}
