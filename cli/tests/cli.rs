//! The `chassis` binary from outside: golden decodes and encodes (written by hand from the
//! spec's tables), every bad input of the CLI issue, and the device commands against the
//! simulated board through a real pseudo-terminal.

mod harness;

use harness::chassis;
use harness::decoding::{
    CAPTURES_2020, assert_decodes_to, assert_golden_decodes, chassis_with_input, golden, json_lines,
};
use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// One line on stderr, a non-zero exit, nothing on stdout.
fn assert_clear_error(out: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "fails: {stderr}");
    assert!(
        stderr.to_lowercase().contains(&needle.to_lowercase()),
        "{needle:?} in {stderr:?}"
    );
    assert!(!stderr.contains("panicked"), "no panic: {stderr}");
    assert!(out.stdout.is_empty(), "nothing on stdout");
}

#[test]
fn decode_golden_files() {
    for (input, args, expected) in CAPTURES_2020 {
        let out = assert_golden_decodes(input, args, expected);
        let summary = String::from_utf8_lossy(&out.stderr);
        assert!(summary.contains("0 bytes discarded"), "{summary}");
    }
}

#[test]
fn decode_both_sides_of_a_capture() {
    // The board sends IMU 1..5, the reply to the master's read of the pending angle (code 0x20,
    // 900: `23 20 00 00 03 84`), then IMU 6 with its count byte changed (0x44), and the capture
    // ends. Told nothing of the read, the parser cannot vouch for the reply (the frame after it
    // is damaged, row 11) and drops it; with the master's side, the reply is awaited and taken.
    let board = golden("both_board_logic2.csv");
    let master = golden("both_master_logic1.csv");
    let out = assert_decodes_to(
        &[
            "decode",
            board.as_str(),
            "--master",
            master.as_str(),
            "--input",
            "saleae-csv",
        ],
        "both.jsonl",
    );
    let summary = String::from_utf8_lossy(&out.stderr);
    assert!(summary.contains("reply 1"), "{summary}");
    assert!(summary.contains("1 reads told"), "{summary}");

    let alone = chassis(&["decode", board.as_str(), "--input", "saleae-csv"]);
    assert!(alone.status.success());
    let frames = json_lines(&String::from_utf8_lossy(&alone.stdout));
    assert!(frames.iter().all(|f| f["frame"] == "imu"), "{frames:?}");
    assert_eq!(frames.len(), 5, "{frames:?}");

    // Both sides need time stamps, and both must be files.
    let hex = golden("downlink.hex");
    assert_clear_error(
        &chassis(&[
            "decode",
            hex.as_str(),
            "--master",
            hex.as_str(),
            "--input",
            "hex",
        ]),
        "time",
    );
    assert_clear_error(
        &chassis(&["decode", "-", "--master", master.as_str()]),
        "files",
    );
    assert_clear_error(
        &chassis(&[
            "decode",
            board.as_str(),
            "--master",
            master.as_str(),
            "--uplink",
        ]),
        "cannot be used with",
    );
}

#[test]
fn decode_both_sides_from_one_logic2_export() {
    // The same capture as `decode_both_sides_of_a_capture`, as Logic 2 exports two analysers
    // ("board" and "master") in one data table.
    let both = golden("both_logic2.csv");
    assert_decodes_to(
        &[
            "decode",
            both.as_str(),
            "--master-analyzer",
            "master",
            "--input",
            "saleae-csv",
        ],
        "both.jsonl",
    );

    assert_clear_error(
        &chassis(&[
            "decode",
            both.as_str(),
            "--master-analyzer",
            "tx",
            "--input",
            "saleae-csv",
        ]),
        "no row",
    );
    let logic1 = golden("uplink_logic1.csv");
    assert_clear_error(
        &chassis(&[
            "decode",
            logic1.as_str(),
            "--master-analyzer",
            "master",
            "--input",
            "saleae-csv",
        ]),
        "name",
    );
    assert_clear_error(
        &chassis(&["decode", both.as_str(), "--master-analyzer", "master"]),
        "saleae-csv",
    );
}

#[test]
fn decode_raw_bytes_from_standard_input() {
    // The hex golden file's bytes, raw, through a pipe.
    let hex = std::fs::read_to_string(golden("downlink.hex")).unwrap();
    let bytes: Vec<u8> = hex
        .split_whitespace()
        .flat_map(|g| {
            let g = g.trim_start_matches("0x");
            (0..g.len())
                .step_by(2)
                .map(move |i| u8::from_str_radix(&g[i..i + 2], 16).unwrap())
        })
        .collect();
    let out = chassis_with_input(&["decode", "-", "--format", "text"], &bytes);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().count(), 11, "{text}");
    assert!(text.contains("reply     code 0x20 value -900"), "{text}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("imu 6, encoders 2, battery 1, reply 2"));
}

#[test]
fn encode_every_frame_to_the_spec_bytes() {
    for (args, want) in [
        // 1A: X reverse is dir bit 2.
        (
            &["velocity", "--x", "-100", "--y", "300"][..],
            "FF FE 01 00 64 01 2C 00 00 04",
        ),
        // Angle mode (bit 4), Z reverse (bit 0): -90.0°.
        (
            &["velocity", "--z", "-900", "--angle"][..],
            "FF FE 01 00 00 00 00 03 84 11",
        ),
        // 1D: MOTO1 reverse is bit 2, MOTO3 bit 0.
        (
            &[
                "motors", "--m1", "-1", "--m2", "2", "--m3", "-3", "--m4", "4",
            ][..],
            "FF FE 02 00 01 00 02 00 03 00 04 05",
        ),
        (
            &["motors", "--m1", "10000", "--open-loop"][..],
            "FF FE 03 27 10 00 00 00 00 00 00 00",
        ),
        // 2A: code 00, b5 80, b6 00, b7..b8 the action.
        (&["action", "save"][..], "FF FE 80 80 00 80 00 00 03 00"),
        (
            &["action", "gyro-recalibrate"][..],
            "FF FE 80 80 00 80 00 00 06 00",
        ),
        // 2B.
        (
            &["write", "max-speed", "1000"][..],
            "FF FE 80 80 01 00 00 03 E8 00",
        ),
        (
            &["write", "kp", "0x12345678"][..],
            "FF FE 80 80 06 12 34 56 78 00",
        ),
        (
            &["write", "battery-range", "1260", "1050"][..],
            "FF FE 80 80 0C 04 EC 04 1A 00",
        ),
        // 2C / 2D.
        (&["read", "max-speed"][..], "FF FE 80 80 11 00 00 00 00 00"),
        (
            &["read", "pending-angle"][..],
            "FF FE 80 80 20 00 00 00 00 00",
        ),
    ] {
        let mut all = vec!["encode"];
        all.extend_from_slice(args);
        let out = chassis(&all);
        assert!(out.status.success(), "{args:?}: {out:?}");
        assert_eq!(
            String::from_utf8_lossy(&out.stdout).trim(),
            want,
            "{args:?}"
        );
    }
}

#[test]
fn bad_input_is_one_clear_line_and_a_non_zero_exit() {
    let dir = std::env::temp_dir().join(format!("chassis-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let odd = dir.join("odd.hex");
    std::fs::write(&odd, "FF FA 0").unwrap();
    let csv = dir.join("not-serial.csv");
    std::fs::write(&csv, "Time [s],Channel 0\n0.1,1\n").unwrap();
    let odd = odd.to_string_lossy().into_owned();
    let csv = csv.to_string_lossy().into_owned();
    for (args, needle) in [
        (&["decode", "/nonexistent/capture.bin"][..], "cannot read"),
        (
            &["decode", odd.as_str(), "--input", "hex"][..],
            "odd number of digits",
        ),
        (
            &["decode", csv.as_str(), "--input", "saleae-csv"][..],
            "not an async-serial export",
        ),
        (&["encode", "read", "top-speed"][..], "invalid value"),
        (
            &["encode", "write", "max-speed", "70000"][..],
            "out of range",
        ),
        (&["encode", "velocity", "--x", "65536"][..], "out of range"),
        (
            &["encode", "motors", "--m1", "10001", "--open-loop"][..],
            "out of range",
        ),
        (&["encode", "write", "pending-angle", "1"][..], "read only"),
        (
            &["encode", "write", "battery-range", "1260"][..],
            "two values",
        ),
        (&["get", "max-speed"][..], "--port"),
        (
            &["--port", "/dev/does-not-exist", "get", "max-speed"][..],
            "cannot open /dev/does-not-exist",
        ),
        (&["sim"][..], "--pty or --tcp"),
        (
            &["sim", "--tcp", "127.0.0.1:0", "--faults", "2"][..],
            "out of range",
        ),
    ] {
        let out = chassis(args);
        assert_clear_error(&out, needle);
        if needle != "invalid value" {
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(stderr.lines().count(), 1, "one line: {stderr:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `chassis sim --pty` in the background; its path; killed when dropped.
#[cfg(unix)]
struct Sim {
    child: std::process::Child,
    path: String,
}

#[cfg(unix)]
impl Sim {
    fn start() -> Sim {
        let mut child = Command::new(env!("CARGO_BIN_EXE_chassis"))
            .args(["sim", "--pty"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        Sim {
            child,
            path: line.trim().to_string(),
        }
    }

    fn run(&self, args: &[&str]) -> Output {
        let mut all = vec!["--port", self.path.as_str()];
        all.extend_from_slice(args);
        chassis(&all)
    }
}

#[cfg(unix)]
impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[cfg(unix)]
fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[cfg(unix)]
#[test]
fn device_commands_through_a_real_pseudo_terminal() {
    let sim = Sim::start();
    assert!(sim.path.starts_with("/dev/"), "a path: {:?}", sim.path);
    assert_eq!(
        ok(&sim.run(&["get", "max-speed"])).trim(),
        "max-speed: 1000"
    );
    assert_eq!(
        ok(&sim.run(&["get", "battery-range"])).trim(),
        "battery-range: full built-in table, cut-off built-in table"
    );
    assert!(ok(&sim.run(&["set", "max-speed", "800"])).contains("max-speed: 800 (read back"));
    assert_eq!(ok(&sim.run(&["get", "max-speed"])).trim(), "max-speed: 800");

    let file = std::env::temp_dir().join(format!("chassis-settings-{}.json", std::process::id()));
    let file = file.to_string_lossy().into_owned();
    let _ = ok(&sim.run(&["settings", "--save", &file]));
    let saved: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert_eq!(saved["max_speed"], 800);
    let _ = ok(&sim.run(&["set", "max-speed", "1200"]));
    let _ = ok(&sim.run(&["settings", "--restore", &file]));
    assert_eq!(ok(&sim.run(&["get", "max-speed"])).trim(), "max-speed: 800");
    let all: Value = serde_json::from_str(&ok(&sim.run(&["settings"]))).unwrap();
    assert_eq!(all["motor_centivolts"], 1200);
    let _ = std::fs::remove_file(&file);

    assert!(ok(&sim.run(&["turn", "45"])).contains("turned 45.0°"));
    assert_eq!(
        ok(&sim.run(&["get", "pending-angle"])).trim(),
        "pending-angle: 0.0°"
    );
    assert!(ok(&sim.run(&["drive", "--y", "200", "--for", "0.3"])).contains("stopped"));
    assert!(ok(&sim.run(&["save"])).contains("stored"));

    // A port another program holds: a clear error.
    let held = serialport::new(&sim.path, 115_200).open_native().unwrap();
    assert_clear_error(&sim.run(&["get", "max-speed"]), "cannot open");
    drop(held);
    assert_eq!(ok(&sim.run(&["get", "max-speed"])).trim(), "max-speed: 800");
}

#[cfg(unix)]
#[test]
fn a_board_that_never_answers_is_a_clear_error_not_a_hang() {
    // A pseudo-terminal with nothing behind it.
    let (_board, silent) = serialport::TTYPort::pair().unwrap();
    let path = serialport::SerialPort::name(&silent).unwrap();
    let start = std::time::Instant::now();
    let out = chassis(&["--port", &path, "get", "max-speed"]);
    assert_clear_error(&out, "no answer to the read of max-speed");
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
}

#[cfg(unix)]
#[test]
fn calibrate_gyro_takes_its_30_seconds_and_reads_the_new_value() {
    let sim = Sim::start();
    let start = std::time::Instant::now();
    let out = sim.run(&["calibrate-gyro"]);
    let text = ok(&out);
    assert!(text.contains("gyro calibration value:"), "{text}");
    assert!(
        start.elapsed() >= Duration::from_secs(30),
        "{:?}",
        start.elapsed()
    );
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("do not move or touch it"),
        "the instructions are given"
    );
}

#[test]
fn sim_over_tcp_answers_a_read() {
    use chassis_protocol::{Downlink, DownlinkParser, Register, Setting};
    use std::io::{Read, Write};
    let mut child = Command::new(env!("CARGO_BIN_EXE_chassis"))
        .args(["sim", "--tcp", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut addr = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut addr)
        .unwrap();
    let mut stream = std::net::TcpStream::connect(addr.trim()).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let mut parser = DownlinkParser::new();
    parser.expect_reply(Some(Register::MaxSpeed));
    stream
        .write_all(&Setting::Read(Register::MaxSpeed).encode())
        .unwrap();
    let deadline = std::time::Instant::now() + Duration::from_secs(3);
    let mut reply = None;
    let mut telemetry = 0u32;
    let mut buf = [0u8; 256];
    while reply.is_none() && std::time::Instant::now() < deadline {
        if let Ok(n) = stream.read(&mut buf) {
            for frame in parser.frames(&buf[..n]) {
                match frame {
                    Downlink::Reply(r) => reply = Some(r),
                    _ => telemetry += 1,
                }
            }
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    let reply = reply.expect("the simulated board answered over TCP");
    assert_eq!((reply.code, reply.value), (0x01, 1_000));
    assert!(telemetry > 0, "telemetry flows too");
}
