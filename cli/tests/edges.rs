//! `chassis` at its edges, through a real pseudo-terminal to a simulated board that records
//! every byte it is sent: every signal stops a moving command and the board ends still; a
//! turn is never sent on top of one pending; every message says what did and did not happen.

#![cfg(unix)]

mod harness;

use chassis_protocol::sim::Motion;
use chassis_protocol::{Command, Setting, Write as RegWrite};
use harness::{TestBoard, assert_stopped, chassis, moves, signal, wait};
use std::process::Output;
use std::time::{Duration, Instant};

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// One line on stderr, non-zero exit, no panic; `needles` all in it.
fn assert_error(out: &Output, needles: &[&str]) {
    let e = stderr(out);
    assert!(!out.status.success(), "fails: {e}");
    assert!(!e.contains("panicked"), "{e}");
    for n in needles {
        assert!(e.contains(n), "{n:?} in {e:?}");
    }
}

const SIGNALS: [(&str, i32); 3] = [("INT", 2), ("TERM", 15), ("HUP", 1)];

#[test]
fn every_signal_during_drive_stops_the_chassis() {
    for (name, number) in SIGNALS {
        let board = TestBoard::start();
        let out = board.signal_mid(
            &["drive", "--y", "300", "--for", "20"],
            "y = 300",
            harness::forward(300),
            300,
            name,
        );
        assert_eq!(out.status.code(), Some(128 + number), "SIG{name}: {out:?}");
        assert!(
            stderr(&out).contains(&format!(
                "interrupted by SIG{name}: the chassis was stopped"
            )),
            "{}",
            stderr(&out)
        );
        let (board, heard) = board.finish();
        assert_stopped(&board, &heard);
        println!(
            "drive, SIG{name}: exit {:?}, the board's motion {:?}",
            out.status.code(),
            board.motion()
        );
    }
}

#[test]
fn every_signal_during_turn_cancels_the_turn_and_stops() {
    for (name, number) in SIGNALS {
        let board = TestBoard::start();
        let out = board.signal_mid(
            &["turn", "360"],
            "the turn",
            |c| matches!(c, Command::Turn(t) if t.deci_degrees == 3_600),
            400,
            name,
        );
        assert_eq!(out.status.code(), Some(128 + number), "SIG{name}: {out:?}");
        let e = stderr(&out);
        assert!(e.contains(&format!("interrupted by SIG{name}")), "{e}");
        assert!(e.contains("turn was sent, "), "{e}");
        assert!(e.contains("the chassis was stopped"), "{e}");
        let (board, heard) = board.finish();
        assert_stopped(&board, &heard);
        let turns = harness::turns(&harness::commands(&heard));
        assert_eq!(turns.len(), 2, "the turn and its cancel: {turns:?}");
        assert!(turns[1] < 0 && turns[1] > -3_600, "{turns:?}");
        println!(
            "turn 360, SIG{name} after 0.4 s: turns sent {turns:?}, left pending {} (0.1°)",
            board.pending_deci_degrees()
        );
    }
}

#[test]
fn a_turn_is_never_sent_on_top_of_one_pending() {
    let board = TestBoard::start();
    let child = board.spawn(&["turn", "360"]);
    board.wait_for("the turn", |c| matches!(c, Command::Turn(_)));
    std::thread::sleep(Duration::from_millis(400));
    // SIGKILL cannot be caught: the board is left turning.
    signal(&child, "KILL");
    let _ = wait(child, 5);
    let out = board.run(&["turn", "90"]);
    assert_error(&out, &["still has", "pending", "not sent", "chassis stop"]);
    // `chassis stop` cancels what the killed one left.
    let out = board.run(&["stop"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let said = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(said.contains("was cancelled"), "{said}");
    let (board, heard) = board.finish();
    let turns = harness::turns(&harness::commands(&heard));
    assert_eq!(turns.first(), Some(&3_600), "{turns:?}");
    assert_eq!(
        turns.len(),
        2,
        "the turn and the stop's cancel, never a second +900"
    );
    assert_stopped(&board, &heard);
}

#[test]
fn a_turn_outlives_lost_replies_and_a_zero_turn_is_refused() {
    let board = TestBoard::start();
    // The first read (is a turn pending?) is answered; then two answers are lost.
    let child = board.spawn(&["turn", "90"]);
    board.wait_for("the turn", |c| matches!(c, Command::Turn(_)));
    board.lose_pending_angle_replies(2);
    let out = wait(child, 15);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("turned 90.0°"));

    for tiny in ["0.04", "-0.04"] {
        let before = board.heard().len();
        let out = board.run(&["turn", tiny]);
        assert_error(&out, &["rounds to 0.0°", "nothing sent"]);
        assert_eq!(board.heard().len(), before, "nothing went to the board");
    }
    let (board, _) = board.finish();
    assert_eq!(board.total_turn_commanded(), 900);
}

#[test]
fn a_set_on_a_silent_board_says_the_write_went_out() {
    let board = TestBoard::start();
    board.go_silent(true);
    let out = board.run(&["set", "max-speed", "800"]);
    assert_error(
        &out,
        &[
            "max-speed: 800 was written",
            "not confirmed",
            "nothing came from the board",
        ],
    );
    let (board, _) = board.finish();
    assert_eq!(board.registers().max_speed, 800, "the write was applied");
}

#[test]
fn errors_name_registers_as_the_cli_does_and_hint_only_at_silence() {
    let board = TestBoard::with(|b| b.set_faults(harness::no_replies()));
    let out = board.run(&["get", "max-speed"]);
    assert_error(&out, &["max-speed"]);
    let e = stderr(&out);
    assert!(!e.contains("MaxSpeed"), "{e}");
    assert!(
        !e.contains("powered"),
        "telemetry arrives: no wiring hint: {e}"
    );
    assert!(e.contains("telemetry arrives"), "{e}");

    let silent = TestBoard::start();
    silent.go_silent(true);
    let out = silent.run(&["get", "pending-angle"]);
    assert_error(&out, &["pending-angle", "is it powered"]);
    assert!(!stderr(&out).contains("PendingAngle"));
}

#[test]
fn writes_that_start_a_calibration_need_yes() {
    let board = TestBoard::start();
    for args in [
        &["set", "system-mode", "0x8"][..],
        &["set", "gyro-calibration", "0xFFFF"][..],
    ] {
        let out = board.run(args);
        assert_error(
            &out,
            &["starts a gyro calibration", "--yes", "nothing written"],
        );
    }
    let out = board.run(&["set", "system-mode", "0x8", "--yes"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("gyro calibration started"));
    // Already on: writing it again starts nothing, and needs no --yes.
    let out = board.run(&["set", "system-mode", "0x18"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (board, heard) = board.finish();
    assert!(board.calibrating(), "the --yes write started it");
    let writes: Vec<_> = harness::commands(&heard)
        .into_iter()
        .filter_map(|c| match c {
            Command::Setting(Setting::Write(w)) => Some(w),
            _ => None,
        })
        .collect();
    assert_eq!(
        writes.len(),
        2,
        "only the --yes write and the 0x18 one: {writes:?}"
    );
    assert!(matches!(writes[0], RegWrite::SystemMode(m) if m.bits() == 0x8));
}

#[test]
fn a_restore_says_what_it_did_not_restore() {
    let board = TestBoard::start();
    let file = std::env::temp_dir().join(format!("chassis-restore-{}.json", std::process::id()));
    let file = file.to_string_lossy().into_owned();
    let out = board.run(&["settings", "--save", &file]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    saved["max_speed"] = 700.into();
    saved["system_mode"] = 0x18.into();
    saved["gyro_calibration"] = 0x1234.into();
    std::fs::write(&file, saved.to_string()).unwrap();
    let out = board.run(&["settings", "--restore", &file]);
    assert!(out.status.success(), "{}", stderr(&out));
    let e = stderr(&out);
    for needle in [
        "max-speed 700",
        "bit 3 (gyro compensation), kept off",
        "the file says on",
        "not restored: gyro-calibration (the file says 4660",
        "chassis save",
    ] {
        assert!(e.contains(needle), "{needle:?} in {e}");
    }
    let _ = std::fs::remove_file(&file);
    let (board, _) = board.finish();
    assert_eq!(board.registers().max_speed, 700);
    assert!(!board.calibrating(), "a restore never starts a calibration");
}

#[test]
fn a_restore_is_checked_as_set_is_before_anything_is_written() {
    let board = TestBoard::start();
    let file = std::env::temp_dir().join(format!("chassis-inverted-{}.json", std::process::id()));
    let file = file.to_string_lossy().into_owned();
    let out = board.run(&["settings", "--save", &file]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    // Full 10.00 V below the cut-off 12.00 V: `set battery-range 1000 1200` refuses it.
    saved["battery_full_centivolts"] = 1000.into();
    saved["battery_cutoff_centivolts"] = 1200.into();
    saved["max_speed"] = 700.into();
    std::fs::write(&file, saved.to_string()).unwrap();
    let sent_before = board.commands().len();
    let out = board.run(&["settings", "--restore", &file]);
    assert_error(&out, &["not above cut-off", "nothing was written"]);
    let _ = std::fs::remove_file(&file);
    assert_eq!(board.commands().len(), sent_before, "nothing sent");
    let (board, _) = board.finish();
    assert_eq!(board.registers().max_speed, 1000);
}

#[test]
fn bad_arguments_fail_before_the_board_is_asked() {
    let board = TestBoard::start();
    let out = board.run(&["set", "max-speed", "-1"]);
    assert_error(&out, &["out of range"]);
    let out = board.run(&["settings", "--save", "/nonexistent-folder/settings.json"]);
    assert_error(&out, &["cannot write /nonexistent-folder/settings.json"]);
    assert!(board.heard().is_empty(), "no register was read");

    let file = std::env::temp_dir().join(format!("chassis-not-a-port-{}", std::process::id()));
    std::fs::write(&file, "").unwrap();
    let path = file.to_string_lossy().into_owned();
    let out = chassis(&["--port", &path, "get", "max-speed"]);
    assert_error(&out, &["is a file, not a serial port"]);
    assert!(!stderr(&out).contains("typewriter"));
    let _ = std::fs::remove_file(&file);

    let out = board.run(&["set", "battery-range", "1050", "1260"]);
    assert_error(&out, &["not above cut-off"]);
    let bogus = std::env::temp_dir().join(format!("chassis-bogus-{}.json", std::process::id()));
    std::fs::write(
        &bogus,
        r#"{"max_speed":700,"speed_kp":300,"speed_ki":20,"gyro_gain":50000,"system_mode":1,"gyro_calibration":512,"motor_centivolts":1200,"battery_full_centivolts":32767,"battery_cutoff_centivolts":32767,"max_sped":1}"#,
    )
    .unwrap();
    let out = board.run(&["settings", "--restore", &bogus.to_string_lossy()]);
    assert_error(&out, &["not a settings file", "max_sped"]);
    let _ = std::fs::remove_file(&bogus);
    assert!(board.heard().is_empty(), "nothing was written or read");
    let out = chassis(&["--port", "/dev/null", "get", "max-speed"]);
    assert_error(&out, &["not a serial port"]);

    let out = board.run(&["monitor"]);
    assert_error(&out, &["terminal"]);
    assert!(!stderr(&out).contains("os error"), "{}", stderr(&out));
}

#[test]
fn input_buffered_before_the_port_opens_is_not_read_as_new() {
    let board = TestBoard::start();
    // 2 s of telemetry wait in the pseudo-terminal with nobody reading.
    std::thread::sleep(Duration::from_secs(2));
    let dir = std::env::temp_dir().join(format!("chassis-stale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("capture.csv").to_string_lossy().into_owned();
    let out = board.run(&["record", "--out", &file, "--for", "0.5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = std::fs::read_to_string(&file).unwrap().lines().count() - 1;
    // The board sends about 1.9 kB/s (IMU 100 Hz, encoders 25 Hz, battery 1 Hz): half a
    // second is under 1 kB; the 2 s buffered would be 3.8 kB more.
    println!("recorded {rows} bytes in 0.5 s after 2 s unread");
    assert!(rows < 1_500, "{rows} bytes: stale input was read");
    assert!(rows > 300, "{rows} bytes: the board was recorded");
    let _ = std::fs::remove_dir_all(&dir);
    drop(board);
}

#[test]
fn the_simulated_board_serves_on_with_nobody_reading() {
    // `chassis sim --pty`, nobody opens it for 14 s (its pseudo-terminal fills up in about
    // 11 s), then a read is answered.
    let (mut child, line) = harness::sim_pty(&[]);
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(14) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "chassis sim --pty ended by itself after {:?}",
            start.elapsed()
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    let out = chassis(&["--port", line.trim(), "get", "max-speed"]);
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "max-speed: 1000"
    );
}

#[test]
fn a_board_gone_quiet_mid_drive_is_stopped_and_said() {
    let board = TestBoard::start();
    let child = board.spawn(&["drive", "--y", "300", "--for", "10"]);
    board.wait_for(
        "y = 300",
        |c| matches!(c, Command::Velocity(v) if v.y == 300),
    );
    // Heard for a while first (a board silent from the start is "nothing came").
    std::thread::sleep(Duration::from_millis(300));
    board.go_silent(true);
    let out = wait(child, 5);
    assert_error(&out, &["went quiet", "failsafe stopped it"]);
    let (board, heard) = board.finish();
    assert_eq!(board.motion(), Motion::Velocity { x: 0, y: 0, z: 0 });
    assert!(harness::commands(&heard).last().is_some_and(|c| !moves(c)));
}

fn json_lines(bytes: &[u8]) -> Vec<serde_json::Value> {
    String::from_utf8_lossy(bytes)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON object per line"))
        .collect()
}

#[test]
fn record_ends_cleanly_on_ctrl_c_and_decodes_back_exactly() {
    let board = TestBoard::start();
    let dir = std::env::temp_dir().join(format!("chassis-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("capture.csv").to_string_lossy().into_owned();
    let child = board.spawn(&["record", "--out", &file]);
    std::thread::sleep(Duration::from_millis(1_500));
    signal(&child, "INT");
    let out = wait(child, 5);
    assert!(
        out.status.success(),
        "Ctrl-C is how a recording ends: {}",
        stderr(&out)
    );
    let said = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        said.contains("recorded") && said.contains("chassis decode"),
        "{said}"
    );
    assert!(board.heard().is_empty(), "record sends nothing");

    let decoded = chassis(&["decode", &file, "--input", "saleae-csv", "--quiet-ms", "40"]);
    assert!(decoded.status.success(), "{}", stderr(&decoded));
    let summary = stderr(&decoded);
    // Exact: the decode finds every frame the live count found. Only a
    // frame cut by the start or the end of the recording is thrown away.
    let live: usize = said
        .split(" frames)")
        .next()
        .and_then(|s| s.rsplit('(').next())
        .and_then(|n| n.parse().ok())
        .expect("the live frame count");
    // The decode may find one more: the frame the live parser still held (awaiting the next
    // frame's start) when the recording ended, which the file's end lets out.
    let found = json_lines(&decoded.stdout).len();
    assert!(
        found == live || found == live + 1,
        "{found} decoded, {live} live: {summary}"
    );
    let discarded: usize = summary
        .split(" bytes discarded")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .expect("the bytes discarded");
    assert!(discarded < 30, "at most a frame cut at each end: {summary}");
    let imu: Vec<u64> = json_lines(&decoded.stdout)
        .iter()
        .filter(|f| f["frame"] == "imu")
        .map(|f| f["count"].as_u64().unwrap())
        .collect();
    assert!(imu.len() > 100, "1.5 s of IMU at 100 Hz: {}", imu.len());
    for pair in imu.windows(2) {
        assert_eq!((pair[0] + 1) % 256, pair[1], "no IMU frame lost: {imu:?}");
    }
    println!("recorded 1.5 s: {} IMU frames; {summary}", imu.len());

    // A file that cannot be written fails before the port is touched.
    let out = board.run(&["record", "--out", "/nonexistent-folder/c.csv"]);
    assert_error(&out, &["cannot write /nonexistent-folder/c.csv"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_flag_captures_both_sides_of_a_command() {
    let board = TestBoard::start();
    let dir = std::env::temp_dir().join(format!("chassis-record-both-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("get.csv").to_string_lossy().into_owned();
    let out = board.run(&["--record", &file, "get", "max-speed"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let decoded = chassis(&[
        "decode",
        &file,
        "--input",
        "saleae-csv",
        "--quiet-ms",
        "40",
        "--master-analyzer",
        "master",
    ]);
    assert!(decoded.status.success(), "{}", stderr(&decoded));
    let frames = json_lines(&decoded.stdout);
    let reads: Vec<_> = frames.iter().filter(|f| f["from"] == "master").collect();
    assert!(!reads.is_empty(), "the reads the command sent");
    assert!(
        reads
            .iter()
            .all(|f| f["frame"] == "read" && f["code"] == 0x11),
        "{reads:?}"
    );
    let replies: Vec<_> = frames.iter().filter(|f| f["frame"] == "reply").collect();
    assert!(
        replies.len() >= 2
            && replies
                .iter()
                .all(|f| f["value"] == 1_000 && f["from"] == "board"),
        "a verified read is two replies of 1000: {replies:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_failed_save_or_record_leaves_the_file_that_was_there() {
    let dir = std::env::temp_dir().join(format!("chassis-keep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let keep = |name: &str| {
        let path = dir.join(name).to_string_lossy().into_owned();
        std::fs::write(&path, "what was there\n").unwrap();
        path
    };
    let (settings, capture, both) = (keep("s.json"), keep("c.csv"), keep("b.csv"));
    let missing = "/dev/does-not-exist";
    assert_error(
        &chassis(&["--port", missing, "settings", "--save", &settings]),
        &["cannot open"],
    );
    assert_error(
        &chassis(&["--port", missing, "record", "--out", &capture]),
        &["cannot open"],
    );
    assert_error(
        &chassis(&["--port", missing, "--record", &both, "get", "max-speed"]),
        &["cannot open"],
    );
    // A board that never answers: nothing to save.
    let silent = TestBoard::start();
    silent.go_silent(true);
    assert_error(
        &silent.run(&["settings", "--save", &settings]),
        &["max-speed"],
    );
    for path in [&settings, &capture, &both] {
        assert_eq!(
            std::fs::read_to_string(path).unwrap(),
            "what was there\n",
            "{path}"
        );
    }
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(left.len(), 3, "no partial file left behind: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn global_options_are_refused_where_they_mean_nothing() {
    let dir = std::env::temp_dir().join(format!("chassis-global-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("in.hex").to_string_lossy().into_owned();
    std::fs::write(&input, "FF FA").unwrap();
    let out = chassis(&["--record", &input, "decode", &input, "--input", "hex"]);
    assert_error(&out, &["decode talks to no board", "--record"]);
    assert_eq!(
        std::fs::read_to_string(&input).unwrap(),
        "FF FA",
        "the input is untouched"
    );
    assert_error(
        &chassis(&["--port", "/dev/ttyUSB0", "encode", "read", "kp"]),
        &["encode talks to no board", "--port"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_recording_that_cannot_be_written_fails_its_command() {
    let board = TestBoard::start();
    let out = board.run(&["--record", "/dev/full", "get", "max-speed"]);
    assert_error(&out, &["cannot write /dev/full"]);
}

#[test]
fn a_closed_output_pipe_neither_panics_nor_leaves_the_chassis_moving() {
    let board = TestBoard::start();
    let mut child = board.spawn(&["check", "--yes"]);
    // Read the first line, then close the pipe (as `| head -1` does).
    let mut line = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(child.stdout.take().unwrap()),
        &mut line,
    )
    .unwrap();
    assert!(line.contains("chassis check on"), "{line}");
    let out = wait(child, 30);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
    let (board, heard) = board.finish();
    assert_stopped(&board, &heard);
}
