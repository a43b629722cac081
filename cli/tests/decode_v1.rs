//! `chassis decode` on captures of the v1.0.0 firmware (`7B … BCC 7D`), run as the built
//! binary: the generation found from the capture itself, every frame decoded exactly, and the
//! 2020 captures decoded as before.
//!
//! The golden captures (`tests/golden/v1_*.hex`, `v1_both_logic2.csv`) and their JSON Lines were
//! written by hand from the tables of `docs/protocol-v1.md`, never by the crate's encoder. Values are
//! big-endian; each BCC is the XOR of every byte from the `7B` to the byte before it, worked
//! out step by step below (each step the running XOR after the next byte; `00` bytes change
//! nothing and are left out).
//!
//! Board → master (`v1_downlink.hex`, one frame a line):
//!
//! * T1, telemetry (32 bytes): vx 0, vy 300 (`01 2C`), wz -150 (`FF 6A`); accel 16, -32, 1000
//!   (`00 10 FF E0 03 E8`); gyro 0, 0, -150; quaternion 997, 0, 0, -75 (`03 E5 … FF B5`);
//!   battery 11 800 mV (`2E 18`). BCC: 7B, `01` 7A, `2C` 56, `FF` A9, `6A` C3, `10` D3, `FF` 2C,
//!   `E0` CC, `03` CF, `E8` 27, `FF` D8, `6A` B2, `03` B1, `E5` 54, `FF` AB, `B5` 1E, `2E` 30,
//!   `18` **28**.
//! * R33, the reply of `0x33` (the vendor example's system settings 0, 10, 3600, 2100, 165:
//!   `00 0A 0E 10 08 34 00 A5`): 7B, `33` 48, `0A` 42, `0E` 4C, `10` 5C, `08` 54, `34` 60,
//!   `A5` **C5**.
//! * T2, telemetry: vx -200 (`FF 38`), accel z 1000, quaternion w 1000 (`03 E8` each), battery
//!   11 790 mV (`2E 0E`), the rest 0. BCC: 7B, `FF` 84, `38` BC, `03` BF, `E8` 57, `03` 54,
//!   `E8` BC, `2E` 92, `0E` **9C**.
//! * R34, geometry 110, 110, 55, 60 (`00 6E 00 6E 00 37 00 3C`): 7B, `34` 4F, `6E` 21, `6E`
//!   4F, `37` 78, `3C` **44**.
//! * R35, body velocity: ctl 2, type 4, vx 0, vy 300, wz -150: 7B, `35` 4E, `02` 4C, `04` 48,
//!   `01` 49, `2C` 65, `FF` 9A, `6A` **F0**.
//! * R36, motor speeds: ctl 2, type 4, 150, -150, 150, -150 (`00 96 FF 6A` twice): 7B, `36`
//!   4D, `02` 4F, `04` 4B, `96` DD, `FF` 22, `6A` 48, `96` DE, `FF` 21, `6A` **4B**.
//! * R50, PID 3000, 1050, 0, 3000, 1050 (`0B B8 04 1A 00 00 0B B8 04 1A`: the pairs cancel):
//!   7B, `50` **2B** (as `docs/protocol-v1.md` gives for the request).
//! * T1 again.
//!
//! Master → board (`v1_uplink.hex`):
//!
//! * `0x25` ctl 2, type 4, vx -100 (`FF 9C`), vy 300 (`01 2C`), wz 500 (`01 F4`): 7B, `25` 5E,
//!   `02` 5C, `04` 58, `FF` A7, `9C` 3B, `01` 3A, `2C` 16, `01` 17, `F4` **E3**.
//! * `0x25` the forced stop, ten `00`: 7B, `25` **5E**.
//! * `0x26` ctl 2, type 4, 100, -100, 100, -100 (`00 64 FF 9C` twice, cancelling): 7B, `26` 5D,
//!   `02` 5F, `04` **5B**.
//! * `0x23` 0, 10, 3600, 2100, 165: 7B, `23` 58, `0A` 52, `0E` 5C, `10` 4C, `08` 44, `34` 70,
//!   `A5` **D5**.
//! * `0x24` 110, 110, 55, 60: 7B, `24` 5F, `6E` 31, `6E` 5F, `37` 68, `3C` **54**.
//! * `0x40` 3000, 1050, 0, 3000, 1050 (cancelling): 7B, `40` **3B**.
//! * The readback requests `0x33` (**48**), `0x50` (**2B**), as `docs/protocol-v1.md` gives them, and
//!   `0x36`: 7B, `36` **4D**.
//!
//! Both sides (`v1_both_logic2.csv`, one byte a row, 0.1 ms apart): the board sends T1 at
//! 10 ms; the master asks for the geometry at 20 ms (`7B 34`, ten `00`, 7B ^ 34 = **4F**, as
//! `docs/protocol-v1.md` gives); the board replies R34 at 23 ms; the master sends `0x25` ctl 2, type 4,
//! vy 300 at 40 ms (7B, `25` 5E, `02` 5C, `04` 58, `01` 59, `2C` **75**); the board sends T2 at
//! 55 ms.

mod harness;

use harness::chassis;
use harness::decoding::{
    self, CAPTURES_2020, assert_golden_decodes, chassis_with_input, golden, json_lines,
};
use std::process::Output;

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The one-line summary of `out`, a decode that succeeded: it holds every one of `said`.
fn summary_saying(out: &Output, said: &[&str]) -> String {
    let summary = stderr(out);
    assert!(!summary.contains("panicked"), "{summary}");
    assert_eq!(summary.lines().count(), 1, "one line: {summary}");
    for words in said {
        assert!(summary.contains(words), "{words:?} in {summary:?}");
    }
    summary
}

/// `chassis args` succeeds, writes the JSON lines of the golden file `expected`, and its one-line
/// summary holds every one of `said`. The summary.
fn assert_decodes_to(args: &[&str], expected: &str, said: &[&str]) -> String {
    summary_saying(&decoding::assert_decodes_to(args, expected), said)
}

/// `chassis args` succeeds with no frame on stdout, its summary saying `said`.
fn assert_no_frame(args: &[&str], said: &str) {
    let out = chassis(args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stdout.is_empty());
    assert!(stderr(&out).contains(said), "{}", stderr(&out));
}

/// The bytes of a hex golden file, read here (not by the binary).
fn hex_bytes(name: &str) -> Vec<u8> {
    std::fs::read_to_string(golden(name))
        .unwrap()
        .split_whitespace()
        .map(|pair| u8::from_str_radix(pair, 16).unwrap())
        .collect()
}

#[test]
fn a_v1_capture_is_detected_and_decoded_exactly() {
    summary_saying(
        &assert_golden_decodes("v1_downlink.hex", &["--input", "hex"], "v1_downlink.jsonl"),
        &[
            "firmware v1.0.0 (detected)",
            "166 bytes: 8 frames (telemetry 3, reply 5)",
            "0 bad BCC",
            "0 bytes discarded",
        ],
    );
    // The same bytes raw, through a pipe.
    let out = chassis_with_input(&["decode", "-"], &hex_bytes("v1_downlink.hex"));
    assert!(out.status.success(), "{}", stderr(&out));
    let want = json_lines(&std::fs::read_to_string(golden("v1_downlink.jsonl")).unwrap());
    assert_eq!(json_lines(&String::from_utf8_lossy(&out.stdout)), want);
    assert!(stderr(&out).contains("firmware v1.0.0 (detected)"));
}

#[test]
fn a_v1_uplink_capture_is_detected_and_decoded_exactly() {
    summary_saying(
        &assert_golden_decodes(
            "v1_uplink.hex",
            &["--input", "hex", "--uplink"],
            "v1_uplink.jsonl",
        ),
        &[
            "firmware v1.0.0 (detected)",
            "126 bytes: 9 frames",
            "0 bad BCC",
            "0 bytes discarded",
        ],
    );
}

#[test]
fn noise_and_a_bad_bcc_are_counted_and_never_output() {
    // `00 FF 7B 12 55` (5 bytes: 12 is no frame's code), T2 at 5, R34 with its BCC 45 for 44
    // at 37 (counted, its 14 bytes discarded), R33 at 51, `FF FF` at 65, T1 at 67, and the
    // first 4 bytes of a telemetry frame cut by the end: 5 + 14 + 2 + 4 = 25 bytes discarded.
    summary_saying(
        &assert_golden_decodes("v1_noisy.hex", &["--input", "hex"], "v1_noisy.jsonl"),
        &[
            "firmware v1.0.0 (detected)",
            "103 bytes: 3 frames (telemetry 2, reply 1)",
            "1 bad BCC, 0 bad end, 0 refused",
            "25 bytes discarded",
        ],
    );
}

#[test]
fn both_sides_of_a_v1_capture_in_time_order() {
    let path = golden("v1_both_logic2.csv");
    summary_saying(
        &assert_golden_decodes(
            "v1_both_logic2.csv",
            &["--input", "saleae-csv", "--master-analyzer", "master"],
            "v1_both.jsonl",
        ),
        &[
            "firmware v1.0.0 (detected)",
            "board: 78 bytes: 3 frames (telemetry 2, reply 1)",
            "master: 28 bytes: 2 frames",
        ],
    );
    // The board side alone, time-stamped: each frame with its first byte's time.
    let out = chassis_with_input(
        &["decode", "-", "--input", "saleae-csv"],
        std::fs::read_to_string(&path)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with("master,"))
            .collect::<Vec<_>>()
            .join("\n")
            .as_bytes(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let frames = json_lines(&String::from_utf8_lossy(&out.stdout));
    let times: Vec<f64> = frames.iter().map(|f| f["t"].as_f64().unwrap()).collect();
    assert_eq!(times, [0.01, 0.023, 0.055], "{frames:?}");
    assert!(frames.iter().all(|f| f.get("from").is_none()));
}

#[test]
fn v1_frames_as_text_one_line_each() {
    let out = chassis_with_input(
        &["decode", "-", "--format", "text"],
        &hex_bytes("v1_downlink.hex"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 8, "{text}");
    for (line, (offset, kind)) in lines.iter().zip([
        (0, "v1-telemetry"),
        (32, "v1-reply"),
        (46, "v1-telemetry"),
        (78, "v1-reply"),
        (92, "v1-reply"),
        (106, "v1-reply"),
        (120, "v1-reply"),
        (134, "v1-telemetry"),
    ]) {
        let mut words = line.split_whitespace();
        assert_eq!(words.next(), Some(offset.to_string().as_str()), "{line}");
        assert_eq!(words.next(), Some(kind), "{line}");
    }
    for words in [
        "vx 0 vy 300 mm/s wz -150 mrad/s",
        "battery 11800 mV",
        "system (0x33)",
        "pwm max 3600 min 2100",
        "geometry (0x34): wheel spacing 110 mm",
        "motor-speeds (0x36): ctl 0x02 type 4 speeds [150, -150, 150, -150] (raw)",
        "pid (0x50): position kp 3000 ki 1050 kd 0",
    ] {
        assert!(text.contains(words), "{words:?} in {text}");
    }

    let out = chassis_with_input(
        &["decode", "-", "--uplink", "--format", "text"],
        &hex_bytes("v1_uplink.hex"),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().count(), 9, "{text}");
    assert!(text.contains("v1-body-velocity  forced stop"), "{text}");
    assert!(text.contains("v1-readback       system (0x33)"), "{text}");

    let path = golden("v1_both_logic2.csv");
    let out = chassis(&[
        "decode",
        path.as_str(),
        "--input",
        "saleae-csv",
        "--master-analyzer",
        "master",
        "--format",
        "text",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    let from: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert_eq!(
        from,
        ["board", "master", "board", "master", "board"],
        "{text}"
    );
}

#[test]
fn reserved_bytes_of_a_reply_are_shown_when_not_00() {
    // R34 with `12 34` in its last two payload bytes: 44 (R34's BCC) ^ 12 = 56, ^ 34 = 62.
    let out = chassis_with_input(
        &["decode", "-", "--input", "hex"],
        b"7B 34 00 6E 00 6E 00 37 00 3C 12 34 62 7D",
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        json_lines(&String::from_utf8_lossy(&out.stdout)),
        json_lines(
            r#"{"offset":0,"frame":"v1-reply","request":"geometry","code":52,"wheel_spacing_mm":110,"axle_spacing_mm":110,"gear_ratio":55,"wheel_diameter_mm":60,"reserved_raw":[18,52]}"#
        )
    );
    // A reply decides alone (the board sent it: it carries a BCC).
    assert!(stderr(&out).contains("firmware v1.0.0 (detected)"));
}

#[test]
fn the_2020_golden_captures_are_still_2020() {
    let both: (&str, &[&str], &str) = (
        "both_logic2.csv",
        &["--input", "saleae-csv", "--master-analyzer", "master"],
        "both.jsonl",
    );
    for (input, args, expected) in CAPTURES_2020.into_iter().chain([both]) {
        summary_saying(
            &assert_golden_decodes(input, args, expected),
            &["firmware 2020 (detected)", "0 bytes discarded"],
        );
    }
}

#[test]
fn the_global_firmware_option_skips_detection() {
    let v1 = golden("v1_downlink.hex");
    for spelling in ["v1.0.0", "v1"] {
        assert_decodes_to(
            &[
                "decode",
                v1.as_str(),
                "--input",
                "hex",
                "--firmware",
                spelling,
            ],
            "v1_downlink.jsonl",
            &["firmware v1.0.0 (given)", "8 frames (telemetry 3, reply 5)"],
        );
    }
    let ff = golden("downlink.hex");
    assert_decodes_to(
        &[
            "--firmware",
            "2020",
            "decode",
            ff.as_str(),
            "--input",
            "hex",
        ],
        "downlink.jsonl",
        &["firmware 2020 (given)", "0 bytes discarded"],
    );
    // Told the other generation: no frame, every byte discarded, said.
    assert_no_frame(
        &[
            "decode",
            v1.as_str(),
            "--input",
            "hex",
            "--firmware",
            "2020",
        ],
        "firmware 2020 (given); 166 bytes: imu 0, encoders 0, battery 0, reply 0; 166 bytes discarded",
    );
    let up = golden("uplink.hex");
    assert_no_frame(
        &[
            "decode",
            up.as_str(),
            "--input",
            "hex",
            "--uplink",
            "--firmware",
            "v1",
        ],
        "firmware v1.0.0 (given); 94 bytes: 0 frames; 0 bad BCC",
    );
}

#[test]
fn a_capture_of_neither_generation_says_so_and_decodes_as_2020() {
    for (input, args, said) in [
        (&b""[..], &[][..], "no frames of either generation"),
        (
            &b""[..],
            &["--uplink"][..],
            "no frames of either generation",
        ),
        (
            &[0x01, 0x02, 0x03, 0x7B, 0x7D, 0xFF][..],
            &[][..],
            "no frames of either generation",
        ),
        (
            &[0x01, 0x02, 0x03, 0x7B, 0x7D, 0xFF][..],
            &["--uplink"][..],
            "no frames of either generation",
        ),
    ] {
        let mut all = vec!["decode", "-"];
        all.extend_from_slice(args);
        let out = chassis_with_input(&all, input);
        let summary = stderr(&out);
        assert!(out.status.success(), "as today: {summary}");
        assert!(out.stdout.is_empty(), "no frame");
        assert_eq!(summary.lines().count(), 1, "{summary}");
        assert!(summary.contains("firmware not recognised"), "{summary}");
        assert!(summary.contains(said), "{summary}");
        assert!(summary.contains("decoded as 2020"), "{summary}");
        assert!(!summary.contains("panicked"), "{summary}");
    }

    // One telemetry frame alone does not decide (the detector wants two, or a reply).
    let t1: Vec<u8> = hex_bytes("v1_downlink.hex").into_iter().take(32).collect();
    let out = chassis_with_input(&["decode", "-"], &t1);
    let summary = stderr(&out);
    assert!(out.status.success(), "{summary}");
    assert!(
        summary.contains("firmware not recognised (0 frames of 2020, 1 of v1.0.0"),
        "{summary}"
    );
}

#[test]
fn no_input_makes_decode_panic() {
    // Every prefix of the golden captures and of the noisy one, in both directions: a cut
    // frame anywhere.
    let mut all = hex_bytes("v1_noisy.hex");
    all.extend(hex_bytes("v1_uplink.hex"));
    all.extend(hex_bytes("uplink.hex"));
    for cut in (0..all.len()).step_by(7) {
        for args in [&["decode", "-"][..], &["decode", "-", "--uplink"][..]] {
            let out = chassis_with_input(args, &all[..cut]);
            assert!(out.status.success(), "{cut}: {}", stderr(&out));
            assert!(!stderr(&out).contains("panicked"));
        }
    }
}
