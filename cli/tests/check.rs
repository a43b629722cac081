//! `chassis check`: the firmware's bring-up from a PC, against a simulated board on a real
//! pseudo-terminal (one that records what it is sent, can go silent), and against
//! `chassis sim --pty` with line faults.

#![cfg(unix)]

mod harness;

use chassis_protocol::{Command, DriveType, Setting};
use harness::{TestBoard, assert_stopped, signal, wait};
use std::process::Output;
use std::time::Duration;

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_working_board_passes_every_check_and_ends_stopped() {
    let board = TestBoard::start();
    let out = board.run(&["check", "--yes"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    for needle in [
        "[1/9] link",
        "[2/9] settings",
        "[3/9] drive-type   skipped (the board's own kept",
        "[4/9] forward      ok",
        "[5/9] strafe       ok",
        "[6/9] turn         ok",
        "[7/9] stop         ok",
        "[8/9] battery      ok",
        "[9/9] control-loop ok",
        "PASS: 8 checks passed, 1 skipped",
        "the chassis is stopped",
    ] {
        assert!(stdout.contains(needle), "{needle:?} in\n{stdout}");
    }
    println!("{stdout}");
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
    assert_eq!(
        harness::turns(&harness::commands(&heard)),
        vec![900],
        "one turn, sent once"
    );
    assert!(
        !harness::commands(&heard)
            .iter()
            .any(|c| matches!(c, Command::Setting(Setting::Write(_)))),
        "nothing written without --drive-type"
    );
}

#[test]
fn no_motion_only_reads() {
    let board = TestBoard::start();
    let out = board.run(&["check", "--no-motion"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("PASS: 3 checks passed, 6 skipped"),
        "{stdout}"
    );
    assert!(
        stdout.contains("nothing moved, nothing was written"),
        "{stdout}"
    );
    let (board, heard) = board.finish();
    let commands = harness::commands(&heard);
    assert!(!commands.is_empty());
    assert!(
        commands
            .iter()
            .all(|c| matches!(c, Command::Setting(Setting::Read(_)))),
        "reads only: {commands:?}"
    );
    assert_eq!(board.total_turn_commanded(), 0);
}

#[test]
fn nothing_moves_without_a_yes() {
    let board = TestBoard::start();
    let out = board.run(&["check"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(stderr.contains("the chassis will move"), "{stderr}");
    assert!(stderr.contains("--yes"), "{stderr}");
    assert!(board.heard().is_empty(), "nothing sent");
}

#[test]
fn a_drive_type_given_is_set_and_read_back() {
    let board = TestBoard::start();
    let out = board.run(&["check", "--yes", "--drive-type", "omni"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("[3/9] drive-type   ok"), "{stdout}");
    let (board, _) = board.finish();
    assert_eq!(board.registers().system_mode.drive_type(), DriveType::Omni);
}

#[test]
fn a_board_gone_silent_mid_check_fails_its_check_and_is_stopped() {
    let board = TestBoard::start();
    let child = board.spawn(&["check", "--yes"]);
    board.wait_for(
        "the forward drive",
        |c| matches!(c, Command::Velocity(v) if v.y == 300),
    );
    board.go_silent(true);
    let out = wait(child, 20);
    let (stdout, stderr) = text(&out);
    assert!(
        matches!(out.status.code(), Some(13 | 14)),
        "forward (13) or strafe (14) fails: {:?}\n{stdout}\n{stderr}",
        out.status
    );
    assert!(stderr.contains("went quiet"), "{stderr}");
    // The board no longer answers: that the stop arrived is not known, and not claimed.
    assert!(
        stderr.contains("the stop was sent but not confirmed"),
        "{stderr}"
    );
    assert!(!stderr.contains("the chassis was stopped"), "{stderr}");
    assert!(
        stderr.contains("turn, stop, battery, control-loop"),
        "{stderr}"
    );
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
    assert_eq!(board.total_turn_commanded(), 0, "no turn after the silence");
}

#[test]
fn ctrl_c_mid_turn_cancels_it_and_stops() {
    let board = TestBoard::start();
    let child = board.spawn(&["check", "--yes"]);
    board.wait_for("the turn", |c| matches!(c, Command::Turn(_)));
    std::thread::sleep(Duration::from_millis(300));
    signal(&child, "INT");
    let out = wait(child, 10);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(130), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("interrupted by SIGINT during the turn check; the chassis was stopped"),
        "{stderr}"
    );
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
    let turns = harness::turns(&harness::commands(&heard));
    assert_eq!(turns.first(), Some(&900));
    assert_eq!(turns.len(), 2, "the turn, then its cancel: {turns:?}");
}

#[test]
fn a_silent_board_fails_the_link_check_with_the_wiring_hint() {
    let board = TestBoard::start();
    board.go_silent(true);
    let out = board.run(&["check", "--no-motion"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(10), "{stdout}\n{stderr}");
    assert!(stderr.contains("FAIL: link: no telemetry"), "{stderr}");
    assert!(stderr.contains("at 115200 bps"), "{stderr}");
}

#[test]
fn check_passes_through_chassis_sim_with_line_faults() {
    // `chassis sim --pty` with 1e-3 line errors per byte (dropped, changed, added).
    let (mut sim, path) = harness::sim_pty(&["--faults", "1e-3", "--seed", "7"]);
    let out = harness::chassis(&["--port", &path, "check", "--yes"]);
    let _ = sim.kill();
    let _ = sim.wait();
    let (stdout, stderr) = text(&out);
    println!("{stdout}{stderr}");
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("PASS: 8 checks passed, 1 skipped"),
        "{stdout}"
    );
}

#[test]
fn lost_replies_during_the_turn_do_not_fail_it() {
    let board = TestBoard::start();
    let child = board.spawn(&["check", "--yes"]);
    board.wait_for("the turn", |c| matches!(c, Command::Turn(_)));
    board.lose_pending_angle_replies(2);
    let out = harness::wait(child, 20);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
}

#[test]
fn a_turn_left_pending_is_cancelled_before_anything_moves() {
    // A turn of 360° the board still has (a program killed while it turned).
    let leftover = chassis_protocol::Turn::by_deci_degrees(3_600).encode();
    let board = TestBoard::with(|b| b.receive(&leftover));
    let out = board.run(&["check", "--yes"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let (board, heard) = board.finish();
    let commands = harness::commands(&heard);
    let cancel = commands
        .iter()
        .position(|c| matches!(c, Command::Turn(t) if t.deci_degrees < 0))
        .expect("the leftover turn cancelled");
    let first_drive = commands
        .iter()
        .position(harness::moves)
        .expect("the checks drove it");
    assert!(
        cancel <= first_drive,
        "cancelled before anything moved: {commands:?}"
    );
    assert_stopped(&board, &heard);
}

#[test]
fn a_differential_chassis_skips_the_sideways_check() {
    let board = TestBoard::start();
    let out = board.run(&["check", "--yes", "--drive-type", "differential"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("strafe       skipped (a differential chassis does not move sideways)"),
        "{stdout}"
    );
    let (_, heard) = board.finish();
    assert!(
        !harness::commands(&heard)
            .iter()
            .any(|c| matches!(c, Command::Velocity(v) if v.x != 0)),
        "never told to move sideways"
    );
}
