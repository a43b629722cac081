//! The CLI on a board running the v1.0.0 firmware, served on a real pseudo-terminal: `detect`
//! on both generations, a silent line and bytes of neither; `drive` stopped at its end and on
//! every signal; `turn` refused with nothing sent; `get` / `set` / `settings` over the
//! readbacks and the settings frames. The frames the board must receive are written by hand
//! from `docs/protocol-v1.md` (BCC = XOR of the bytes before it).

mod harness;

use harness::v1::{FORCED_STOP, FORWARD, frames, v1_board};
use harness::{TestBoard, signal, wait};
use serialport::{SerialPort as _, TTYPort};
use std::time::{Duration, Instant};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn detect_names_each_generation_and_sends_nothing_to_a_streaming_board() {
    let v1 = v1_board();
    let out = v1.run(&["detect"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let line = text(&out.stdout);
    assert!(line.contains("v1.0.0"), "{line}");
    assert!(line.contains("nothing was sent"), "{line}");
    let (_, heard) = v1.finish();
    assert!(heard.is_empty(), "detect sent {heard:02X?}");

    let old = TestBoard::start();
    let out = old.run(&["detect"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let line = text(&out.stdout);
    assert!(line.contains("firmware 2020"), "{line}");
    let (_, heard) = old.finish();
    assert!(heard.is_empty(), "detect sent {heard:02X?}");
}

#[test]
fn detect_on_a_silent_line_sends_only_the_probes_and_says_so_within_seconds() {
    let (mut board_end, path_end) = TTYPort::pair().unwrap();
    board_end.set_timeout(Duration::from_millis(50)).unwrap();
    let path = path_end.name().unwrap();
    let start = Instant::now();
    let out = harness::chassis(&["--port", &path, "detect"]);
    assert!(start.elapsed() < Duration::from_secs(5));
    assert_eq!(out.status.code(), Some(3), "{}", text(&out.stderr));
    let line = text(&out.stderr);
    assert!(line.contains("nothing came from the board"), "{line}");
    assert_eq!(line.lines().count(), 1, "{line}");
    let mut heard = Vec::new();
    let mut buf = [0u8; 64];
    while let Ok(n) = std::io::Read::read(&mut board_end, &mut buf) {
        if n == 0 {
            break;
        }
        heard.extend_from_slice(&buf[..n]);
    }
    // The 2020 read of the motor voltage (2C) and the vendor's v1.0.0 readback 0x33.
    let mut probes = vec![0xFF, 0xFE, 0x80, 0x80, 0x1B, 0, 0, 0, 0, 0];
    probes.extend([0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D]);
    assert_eq!(heard, probes);
}

#[test]
fn detect_on_bytes_of_neither_generation_says_so() {
    let device = harness::OtherDevice::start();
    let out = harness::chassis(&["--port", &device.path, "detect"]);
    let sent = device.finish();
    assert_eq!(out.status.code(), Some(4), "{}", text(&out.stderr));
    let line = text(&out.stderr);
    assert!(line.contains("no frame of either firmware"), "{line}");
    // The line was not quiet: no probe to a device that is not the board.
    assert!(sent.is_empty(), "sent {sent:02X?}");
    // A command then refuses to guess.
}

#[test]
fn drive_on_v1_sends_the_velocity_then_the_forced_stop() {
    let board = v1_board();
    let out = board.run(&["drive", "--vy", "0.3", "--for", "1"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (board, heard) = board.finish();
    let frames = frames(&heard);
    assert!(frames.len() >= 15, "{} frames in 1 s", frames.len());
    assert!(frames[..frames.len() - 1].iter().all(|f| *f == FORWARD));
    assert_eq!(frames.last(), Some(&FORCED_STOP));
    assert_eq!(
        board.velocity(),
        chassis_protocol::v1::BodyVelocity::FORCED_STOP
    );
}

#[test]
fn drive_on_v1_is_stopped_by_every_signal() {
    for (name, number) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let board = v1_board();
        let child = board.spawn(&["drive", "--vy", "0.3", "--for", "30"]);
        let start = Instant::now();
        while !board.heard().windows(14).any(|w| w == FORWARD) {
            assert!(start.elapsed() < Duration::from_secs(5), "never drove");
            std::thread::sleep(Duration::from_millis(10));
        }
        std::thread::sleep(Duration::from_millis(200));
        signal(&child, name);
        let out = wait(child, 10);
        assert_eq!(out.status.code(), Some(128 + number), "SIG{name}");
        assert!(
            text(&out.stderr).contains("the chassis was stopped"),
            "{}",
            text(&out.stderr)
        );
        let (board, heard) = board.finish();
        assert_eq!(frames(&heard).last(), Some(&FORCED_STOP), "SIG{name}");
        assert_eq!(
            board.velocity(),
            chassis_protocol::v1::BodyVelocity::FORCED_STOP
        );
    }
}

#[test]
fn the_2020_axes_and_turn_are_refused_on_v1_with_nothing_sent() {
    let board = v1_board();
    for args in [
        &["turn", "90"][..],
        &["drive", "--y", "300", "--for", "1"],
        &["save"],
        &["calibrate-gyro"],
        &["get", "max-speed"],
    ] {
        let out = board.run(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let line = text(&out.stderr);
        assert_eq!(line.lines().count(), 1, "{args:?}: {line}");
    }
    let out = board.run(&["turn", "90"]);
    assert!(text(&out.stderr).contains("no turn by an angle"));
    let (_, heard) = board.finish();
    assert!(heard.is_empty(), "sent {heard:02X?}");
    // And the v1.0.0 axes on a 2020 board.
    let old = TestBoard::start();
    let out = old.run(&["drive", "--vy", "0.3", "--for", "1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("--x --y --z"));
    let (_, heard) = old.finish();
    assert!(heard.is_empty());
}

#[test]
fn get_set_and_settings_round_trip_on_v1() {
    let board = v1_board();
    let out = board.run(&["get", "wheel-diameter"]);
    assert_eq!(text(&out.stdout).trim(), "wheel-diameter: 60");
    let out = board.run(&["set", "wheel-diameter", "65"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = board.run(&["get", "geometry"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["wheel_diameter_mm"], 65);
    assert_eq!(json["wheel_spacing_mm"], 110, "the rest of the frame kept");

    let dir = std::env::temp_dir().join(format!("chassis-v1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("settings.json");
    let file = file.to_str().unwrap();
    let out = board.run(&["settings", "--save", file]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let saved = std::fs::read_to_string(file).unwrap();
    assert!(saved.contains("\"firmware\": \"v1.0.0\""), "{saved}");
    let out = board.run(&["set", "pwm-max", "3000"]);
    assert!(out.status.success());
    let out = board.run(&["settings", "--restore", file]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (board, heard) = board.finish();
    assert_eq!(board.system().pwm_max, 3600, "restored");
    assert_eq!(board.geometry().wheel_diameter_mm, 65);
    // Writes: the two sets, then the restore's three frames, nothing else.
    let written: Vec<u8> = frames(&heard)
        .iter()
        .map(|f| f[1])
        .filter(|c| [0x23, 0x24, 0x40].contains(c))
        .collect();
    assert_eq!(written, vec![0x24, 0x23, 0x23, 0x24, 0x40]);
    let _ = std::fs::remove_dir_all(&dir);

    // A 2020 settings file is refused on v1.0.0, nothing written.
    let other = dir.join("old.json");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&other, "{\"max_speed\": 1000}").unwrap();
    let board = v1_board();
    let out = board.run(&["settings", "--restore", other.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("not a v1.0.0 settings file"));
    let (_, heard) = board.finish();
    assert!(heard.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn firmware_given_skips_detection() {
    // A v1.0.0 board told it is 2020: the 2020 read goes out (nothing decides for the user).
    let board = v1_board();
    let out = board.run(&["--firmware", "v1.0.0", "stop"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (_, heard) = board.finish();
    assert_eq!(frames(&heard), vec![FORCED_STOP]);
}

#[test]
fn a_silent_line_is_taken_as_the_generation_the_arguments_belong_to() {
    for args in [
        &["drive", "--vy", "0.1", "--for", "1"][..],
        &["get", "geometry"],
    ] {
        let (_board_end, path_end) = TTYPort::pair().unwrap();
        let path = path_end.name().unwrap();
        let mut all = vec!["--port", path.as_str()];
        all.extend_from_slice(args);
        let out = harness::chassis(&all);
        let e = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {e}");
        assert!(e.contains("nothing came from the board"), "{args:?}: {e}");
        assert!(!e.contains("runs the 2020"), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{args:?}: {e}");
    }
}

#[test]
fn the_wrong_firmware_given_is_said_as_frames_of_another_firmware() {
    let old = TestBoard::start();
    let out = old.run(&["--firmware", "v1.0.0", "get", "geometry"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("bytes came from the board") && e.contains("chassis detect"),
        "{e}"
    );
    assert!(!e.contains("is it powered"), "{e}");
    let v1 = v1_board();
    let out = v1.run(&["--firmware", "2020", "get", "max-speed"]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("bytes came from the board") && e.contains("chassis detect"),
        "{e}"
    );
}

#[test]
fn a_board_gone_quiet_during_a_turn_is_said_so_with_what_to_do() {
    let board = TestBoard::start();
    let child = board.spawn(&["turn", "360"]);
    board.wait_for(
        "the turn",
        |c| matches!(c, chassis_protocol::Command::Turn(t) if t.deci_degrees == 3600),
    );
    std::thread::sleep(Duration::from_millis(300));
    board.go_silent(true);
    let out = wait(child, 15);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("went quiet"), "{e}");
    assert!(!e.contains("telemetry arrives"), "{e}");
    assert!(e.contains("chassis stop"), "{e}");
}

#[test]
fn get_names_the_fields_as_decode_does() {
    // The keys of each reply in chassis decode's golden output (hand-written from the spec),
    // less those that place the frame.
    let golden = include_str!("golden/v1_downlink.jsonl");
    let decode_keys = |request: &str| -> Vec<String> {
        let line = golden
            .lines()
            .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
            .find(|v| v["frame"] == "v1-reply" && v["request"] == request)
            .unwrap_or_else(|| panic!("{request} in the golden file"));
        let mut keys: Vec<String> = line
            .as_object()
            .unwrap()
            .keys()
            .filter(|k| !["offset", "frame", "request", "code"].contains(&k.as_str()))
            .cloned()
            .collect();
        keys.sort();
        keys
    };
    let board = v1_board();
    for request in ["system", "geometry", "body-velocity", "motor-speeds", "pid"] {
        let out = board.run(&["get", request]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let mut keys: Vec<String> = json.as_object().unwrap().keys().cloned().collect();
        keys.sort();
        assert_eq!(keys, decode_keys(request), "get {request}");
    }
}

#[test]
fn a_v1_settings_file_on_a_2020_board_is_named_as_such_with_nothing_written() {
    let v1 = v1_board();
    let file = std::env::temp_dir().join(format!("chassis-v1-on-2020-{}.json", std::process::id()));
    let file = file.to_str().unwrap().to_string();
    let out = v1.run(&["settings", "--save", &file]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    drop(v1);
    let old = TestBoard::start();
    let out = old.run(&["settings", "--restore", &file]);
    let e = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("a v1.0.0 settings file"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    let (_, heard) = old.finish();
    assert!(heard.is_empty(), "sent {heard:02X?}");
    let _ = std::fs::remove_file(&file);
}
