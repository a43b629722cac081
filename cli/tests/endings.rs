//! Every way a command ends stops the chassis, and its message says what happened: the
//! terminal closed under it, its standard input ended, a signal in its first moments, the
//! wrong firmware given, the board gone; and inputs past their stated size refused.

mod harness;

use harness::v1::v1_board;
use harness::{TestBoard, assert_stopped};
use std::time::{Duration, Instant};

/// Waits up to `secs` for the terminal's command to end; how long it took.
fn ends_within(term: &mut harness::Terminal, secs: u64) -> (std::process::ExitStatus, Duration) {
    let start = Instant::now();
    let status = term.wait(secs);
    (status, start.elapsed())
}

#[test]
fn a_closed_terminal_stops_a_driving_monitor_and_ends_it() {
    let board = TestBoard::start();
    let mut term = board.monitor_driving(b"w", harness::forward(300));
    term.close();
    let (status, took) = ends_within(&mut term, 5);
    assert!(!status.success(), "{status:?}");
    assert!(took < Duration::from_secs(2), "ended after {took:?}");
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
}

#[test]
fn a_closed_terminal_ends_a_watching_monitor() {
    let board = TestBoard::start();
    let mut term = harness::Terminal::spawn(&["--port", &board.path, "monitor"]);
    term.wait_for_text("LINK UP");
    term.close();
    let (status, took) = ends_within(&mut term, 5);
    assert!(!status.success(), "{status:?}");
    assert!(took < Duration::from_secs(2), "ended after {took:?}");
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "a watching monitor sent {heard:02X?}");
}

#[test]
fn a_terminal_that_takes_no_output_keeps_neither_the_failsafe_nor_a_signal_from_the_chassis() {
    let board = TestBoard::start();
    // A large terminal: its screen changes by some 12 KB a second, and a pseudo-terminal takes
    // about 17 KB that nobody reads.
    let args = ["--port", board.path.as_str(), "monitor", "--drive"];
    let mut term = harness::Terminal::spawn_sized(&args, 400, 150);
    term.wait_for_text("LINK UP");
    term.press(b"w");
    board.wait_for("the key's velocity", harness::forward(300));
    // Nobody reads the screen any more: the monitor's writes to it soon block.
    term.stop_reading();
    std::thread::sleep(Duration::from_millis(3_000));
    let sent = board.heard().len();
    std::thread::sleep(Duration::from_millis(300));
    assert!(
        board.heard().len() > sent,
        "the monitor kept driving (re-sent the velocity)"
    );
    // The board goes quiet: the failsafe stops the chassis all the same.
    board.go_silent(true);
    std::thread::sleep(Duration::from_millis(600));
    let heard = board.heard();
    let last_stop = heard
        .windows(harness::STOP.len())
        .rposition(|w| w == harness::STOP)
        .expect("the failsafe's stop");
    assert!(
        last_stop >= sent,
        "the stop came after the terminal stalled"
    );
    board.go_silent(false);
    harness::signal(&term.child, "INT");
    let (status, took) = ends_within(&mut term, 5);
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert!(took < Duration::from_secs(2), "ended after {took:?}");
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
}

/// `chassis args` on this board's port, started with SIGINT ignored, as a script's background
/// job starts it (`cmd &` in a script ignores SIGINT).
fn spawn_ignoring_sigint(path: &str, args: &[&str]) -> std::process::Child {
    std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"trap "" INT; exec "$0" "$@""#)
        .arg(harness::bin())
        .args(["--port", path])
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn a_sigint_in_the_first_moments_is_honoured_even_when_inherited_as_ignored() {
    // The board is quiet for its first 0.3 s, so the command is still finding its firmware
    // when the signal comes: it must end with nothing moved, never lose the signal and turn.
    for ms in [50, 100, 150, 200, 250] {
        let board = TestBoard::start();
        board.go_silent(true);
        let child = spawn_ignoring_sigint(&board.path, &["turn", "180"]);
        std::thread::sleep(Duration::from_millis(ms));
        harness::signal(&child, "INT");
        std::thread::sleep(Duration::from_millis(300 - ms));
        board.go_silent(false);
        let out = harness::wait(child, 10);
        let e = text(&out.stderr);
        assert_eq!(out.status.code(), Some(130), "at {ms} ms: {e}");
        assert!(e.contains("interrupted by SIGINT"), "at {ms} ms: {e}");
        assert!(e.contains("the chassis was not moved"), "at {ms} ms: {e}");
        let (_, heard) = board.finish();
        let sent = harness::commands(&heard);
        assert!(!sent.iter().any(harness::moves), "at {ms} ms: {sent:?}");
    }
}

#[test]
fn a_command_that_talks_to_no_board_still_dies_of_a_signal() {
    // `decode` reading a terminal-less standard input that never ends: SIGINT ends it.
    let mut child = std::process::Command::new(harness::bin())
        .args(["decode", "-"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(200));
    harness::signal(&child, "INT");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "decode ignored SIGINT"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    use std::os::unix::process::ExitStatusExt;
    assert_eq!(child.wait().unwrap().signal(), Some(2));
}

#[test]
fn a_forced_stop_sent_to_a_2020_board_is_not_said_to_have_stopped_it() {
    let board = TestBoard::start();
    // Left driving by a program that was killed.
    let driving = board.spawn(&["drive", "--y", "300", "--for", "3"]);
    board.wait_for("the drive", harness::forward(300));
    harness::signal(&driving, "KILL");
    let _ = harness::wait(driving, 10);
    let out = board.run(&["--firmware", "v1.0.0", "stop"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{}{e}", text(&out.stdout));
    assert!(
        !text(&out.stdout).contains("stopped"),
        "{}",
        text(&out.stdout)
    );
    assert!(
        e.contains("the forced stop was sent but not confirmed")
            && e.contains("no frame of the v1.0.0 firmware"),
        "{e}"
    );
    let (board, _) = board.finish();
    assert_eq!(
        board.motion(),
        chassis_protocol::sim::Motion::Velocity { x: 0, y: 300, z: 0 },
        "the 2020 board never got a stop it reads"
    );
}

#[test]
fn a_drive_with_the_wrong_firmware_says_what_came_instead() {
    let board = TestBoard::start();
    let out = board.run(&["--firmware", "v1.0.0", "drive", "--vy", "0.3", "--for", "2"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("no frame of the v1.0.0 firmware"), "{e}");
    assert!(
        !e.contains("is it powered"),
        "the board's telemetry streams: {e}"
    );
    assert!(!e.contains("nothing came"), "{e}");

    let board = v1_board();
    let out = board.run(&["--firmware", "2020", "drive", "--y", "300", "--for", "2"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("no frame of the 2020 firmware"), "{e}");
    assert!(!e.contains("is it powered"), "{e}");
}

#[test]
fn a_board_gone_mid_drive_is_never_said_to_have_got_the_stop() {
    for args in [
        &["drive", "--y", "300", "--for", "5"][..],
        &["drive", "--vy", "0.3", "--for", "5"][..],
    ] {
        let v1 = args.contains(&"--vy");
        let (path, child, vanish): (String, std::process::Child, Box<dyn FnOnce()>) = if v1 {
            let board = v1_board();
            let child = board.spawn(args);
            let start = Instant::now();
            while board.heard().len() < 28 {
                assert!(start.elapsed() < Duration::from_secs(5), "never drove");
                std::thread::sleep(Duration::from_millis(10));
            }
            (
                board.path.clone(),
                child,
                Box::new(move || drop(board.finish())),
            )
        } else {
            let board = TestBoard::start();
            let child = board.spawn(args);
            board.wait_for("the drive", harness::forward(300));
            (
                board.path.clone(),
                child,
                Box::new(move || drop(board.finish())),
            )
        };
        // The adapter pulled out: the line is gone.
        vanish();
        let out = harness::wait(child, 10);
        let e = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{path}: {e}");
        assert!(!e.contains("pending"), "no turn was sent: {e}");
        assert!(!e.contains("was sent"), "the stop's write failed: {e}");
        assert!(e.contains("could not be sent"), "{e}");
        assert!(e.contains("may still be moving"), "{e}");
    }
}

#[test]
fn inputs_past_their_stated_size_are_refused_at_once() {
    let board = TestBoard::start();
    for (args, needle) in [
        (
            &["settings", "--restore", "/dev/zero"][..],
            "more than 64 KiB",
        ),
        (
            &["--firmware", "v1.0.0", "settings", "--restore", "/dev/zero"],
            "more than 64 KiB",
        ),
    ] {
        let start = Instant::now();
        let out = board.run(args);
        let e = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.contains(needle) && e.contains("nothing was"),
            "{args:?}: {e}"
        );
        assert!(start.elapsed() < Duration::from_secs(5), "{args:?}");
    }
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "nothing written: {heard:02X?}");
    let out = harness::chassis(&["decode", "/dev/zero"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("/dev/zero holds more than 256 MiB"), "{e}");
}

#[test]
fn record_counts_the_frames_of_a_v1_board() {
    let board = v1_board();
    let dir = std::env::temp_dir().join(format!("chassis-record-v1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("v1.csv").to_string_lossy().into_owned();
    let out = board.run(&["record", "--out", &file, "--for", "1"]);
    let said = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let live: u64 = said
        .split(" frames)")
        .next()
        .and_then(|s| s.rsplit('(').next())
        .and_then(|n| n.parse().ok())
        .expect("the live frame count");
    let decoded = harness::chassis(&["decode", &file, "--input", "saleae-csv", "--quiet-ms", "40"]);
    let found = text(&decoded.stdout).lines().count() as u64;
    assert!(found >= 15, "about 22 frames a second: {found}");
    assert!(
        live == found || live + 1 == found,
        "{live} counted, {found} in the file: {said}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
