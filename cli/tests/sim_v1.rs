//! `chassis sim --firmware v1.0.0`: the simulated v1.0.0 board through a real pseudo-terminal,
//! spoken to with bytes written by hand from `docs/protocol-v1.md`.

#![cfg(unix)]

use chassis_protocol::v1::{Downlink, DownlinkParser, Parser as _};
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The vendor's readback request for the system settings, as `docs/protocol-v1.md` quotes it.
const READ_SYSTEM: [u8; 14] = [0x7B, 0x33, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x48, 0x7D];

/// Its reply at power-up, the vendor example's 0, 10, 3600 (0E10), 2100 (0834), 165 (00A5):
/// BCC 7B^33^0A^0E^10^08^34^A5, step by step 48 42 4C 5C 54 60 C5.
const FACTORY_SYSTEM_REPLY: [u8; 14] = [
    0x7B, 0x33, 0, 0x0A, 0x0E, 0x10, 0x08, 0x34, 0, 0xA5, 0, 0, 0xC5, 0x7D,
];

/// The child, killed when dropped (also when an assertion fails).
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `chassis sim --pty --firmware v1.0.0` with `extra` arguments: the child (killed when
/// dropped) and the path it printed first.
fn sim_v1(extra: &[&std::ffi::OsStr]) -> (Killed, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_chassis"))
        .args(["sim", "--pty", "--firmware", "v1.0.0"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let child = Killed(child);
    let mut path = String::new();
    BufReader::new(stdout).read_line(&mut path).unwrap();
    (child, path.trim().to_string())
}

#[test]
fn sim_pty_firmware_v1_answers_a_readback_among_its_telemetry() {
    let (_child, path) = sim_v1(&[]);
    let path = path.as_str();
    assert!(
        path.starts_with("/dev/"),
        "the first line is the path: {path:?}"
    );

    let mut port = serialport::new(path, 115_200)
        .timeout(Duration::from_millis(50))
        .open()
        .unwrap();
    port.write_all(&READ_SYSTEM).unwrap();
    let mut wire = Vec::new();
    let mut buf = [0u8; 256];
    let deadline = Instant::now() + Duration::from_secs(3);
    // Until the reply is there and some telemetry after it.
    while Instant::now() < deadline {
        if let Ok(n) = port.read(&mut buf) {
            wire.extend_from_slice(&buf[..n]);
        }
        let reply_at = wire.windows(14).position(is_reply_0x33);
        if reply_at.is_some_and(|at| wire.len() > at + 14 + 64) {
            break;
        }
    }
    let at = wire
        .windows(14)
        .position(is_reply_0x33)
        .unwrap_or_else(|| panic!("no 0x33 reply in {} bytes", wire.len()));
    assert_eq!(wire[at..at + 14], FACTORY_SYSTEM_REPLY);

    let frames: Vec<Downlink> = DownlinkParser::new().frames(&wire).collect();
    let telemetry = frames
        .iter()
        .filter(|f| matches!(f, Downlink::Telemetry(_)))
        .count();
    let replies = frames.len() - telemetry;
    assert_eq!(replies, 1, "one reply");
    assert!(telemetry >= 2, "telemetry around it: {telemetry} frames");
}

/// 14 bytes: `7B 33`, ten bytes, the XOR of the twelve before, `7D`.
fn is_reply_0x33(w: &[u8]) -> bool {
    match w {
        [0x7B, 0x33, .., bcc, 0x7D] if w.len() == 14 => {
            w[..12].iter().fold(0u8, |acc, b| acc ^ b) == *bcc
        }
        _ => false,
    }
}

#[test]
fn an_unknown_firmware_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_chassis"))
        .args(["sim", "--pty", "--firmware", "v2"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let first = stderr.lines().next().unwrap_or("");
    assert!(
        first.contains("'v2'") && first.contains("2020 or v1.0.0"),
        "{stderr}"
    );
    assert!(out.stdout.is_empty());
}

/// 0.3 m/s forward, as `docs/protocol-v1.md`'s example writes it.
const FORWARD_300: [u8; 14] = [
    0x7B, 0x25, 0x02, 0x04, 0x00, 0x00, 0x01, 0x2C, 0x00, 0x00, 0x00, 0x00, 0x75, 0x7D,
];

#[test]
fn sim_pose_writes_the_true_pose_as_the_chassis_drives() {
    let dir = std::env::temp_dir().join(format!("chassis-sim-pose-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("pose.txt");
    let (_child, path) = sim_v1(&["--pose".as_ref(), file.as_os_str()]);
    let mut port = serialport::new(path, 115_200)
        .timeout(Duration::from_millis(50))
        .open()
        .unwrap();
    port.write_all(&FORWARD_300).unwrap();
    // 0.3 m/s for about a second: x near 0.3 m, y and yaw 0 (the board's own model).
    std::thread::sleep(Duration::from_millis(1_000));
    let text = std::fs::read_to_string(&file).unwrap();
    let lines: Vec<Vec<f64>> = text
        .lines()
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(
        lines.len() >= 50,
        "a line every 10 ms: {} lines",
        lines.len()
    );
    assert!(
        lines.windows(2).all(|w| w[1][0] - w[0][0] == 10.0),
        "10 ms apart"
    );
    let last = lines.last().unwrap();
    assert!(
        (0.15..0.4).contains(&last[1]) && last[2].abs() < 1e-6 && last[3].abs() < 1e-6,
        "forward, nothing else: {last:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
