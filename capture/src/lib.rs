//! The decoder of `chassis decode` and of the Python package's `decode_capture`: a capture
//! in, one JSON object per frame out (JSON Lines), in stream order, and a one-line summary.
//!
//! The JSON is a public contract (documented in `docs/cli.md`): every object has `"offset"` (the
//! byte offset of the frame's first byte in the input) and `"frame"`, the fields of its kind,
//! and `"t"` (seconds) when the capture has time stamps.
//!
//! A capture of either firmware generation is decoded: the 2020 one (`FF FE` frames) or v1.0.0
//! (`7B … BCC 7D` frames, kinds named `v1-…`). Unless the caller gives the generation, it is
//! found from the capture itself ([`Detection`]); when nothing decides, the capture is decoded
//! as 2020 and the summary says the generation was not recognised.
//!
//! The crate's parts: [`read_capture`] and its kin read the capture formats; [`Detection`]
//! says which generation it holds; each generation's decoder (2020, v1.0.0) is written once,
//! its JSON and text beside it, and picked in one place; [`decode`] and [`decode_both`] put
//! the frames in order and write the summary.

mod detect;
mod found;
mod generation;
mod read;
mod v1;
mod v2020;

pub use detect::{Detection, detect_downlink, detect_uplink};
pub use found::{Format, Found};
pub use read::{
    Capture, Input, QUIET_GAP_S, parse_hex, parse_saleae, parse_saleae_sides, read_capture,
};
pub use v1::describe_v1_uplink;

use chassis_protocol::detect::Firmware;
use serde_json::{Value, json};

/// What a decode found, with its counters.
#[derive(Debug, Default)]
pub struct Decoded {
    /// The frames, in stream order.
    pub frames: Vec<Found>,
    /// The summary line.
    pub summary: String,
}

/// Decodes `capture` (board → master, or master → board with `uplink`) as `firmware`, or as
/// the generation its frames show (`None`).
pub fn decode(capture: &Capture, uplink: bool, firmware: Option<Firmware>) -> Decoded {
    let detection = match firmware {
        Some(f) => Detection::Given(f),
        None if uplink => detect_uplink(capture),
        None => detect_downlink(capture),
    };
    let decoder = generation::of(detection.firmware());
    let side = if uplink {
        decoder.uplink(capture)
    } else {
        decoder.downlink(capture)
    };
    Decoded {
        frames: side.frames,
        summary: format!("{}; {}", detection.words(), side.summary),
    }
}

/// Decodes both sides of one capture, `board` (board → master) and `master` (master → board),
/// both time-stamped, as `firmware` or as the generation their frames show (`None`). The frames
/// of both sides come out in time order, each with `"from"`: `"board"` or `"master"` (offsets
/// are into its own side's input).
///
/// In a 2020 capture, each read the master sent tells the board side's parser which reply is
/// awaited from the read's last byte on (until the driver's reply timeout), as the driver does.
/// A v1.0.0 reply carries its request's code and a BCC: each side is decoded on its own.
pub fn decode_both(
    board: &Capture,
    master: &Capture,
    firmware: Option<Firmware>,
) -> Result<Decoded, String> {
    if board.times.is_none() || master.times.is_none() {
        return Err(
            "--master needs the time of every byte on both sides, to line them up: \
                    export each side as an async-serial CSV and give --input saleae-csv"
                .into(),
        );
    }
    let detection = match firmware {
        Some(f) => Detection::Given(f),
        None => detect::detect_both(board, master),
    };
    let (board, master, told) = generation::of(detection.firmware()).both(board, master);
    Ok(Decoded {
        frames: merge(board.frames, master.frames),
        summary: format!(
            "{}; board: {}; master: {}{told}",
            detection.words(),
            board.summary,
            master.summary
        ),
    })
}

/// The frames of both sides in time order, each with `"from"` (and its name before its text).
fn merge(board: Vec<Found>, master: Vec<Found>) -> Vec<Found> {
    let mut frames: Vec<(f64, u8, Found)> = Vec::new();
    for (side, list, name) in [(0u8, board, "board"), (1, master, "master")] {
        for mut found in list {
            let t = found.json.get("t").and_then(Value::as_f64).unwrap_or(0.0);
            if let Some(map) = found.json.as_object_mut() {
                map.insert("from".into(), json!(name));
            }
            found.text = format!("{name:<6} {}", found.text);
            frames.push((t, side, found));
        }
    }
    // Stable: frames of one side keep their order; at the same instant the board's first.
    frames.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    frames.into_iter().map(|(_, _, f)| f).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes of a hex golden file (`tests/golden/`), pairs only.
    fn golden(text: &str) -> Capture {
        Capture {
            bytes: parse_hex(text.as_bytes()).unwrap_or_default(),
            ..Capture::default()
        }
    }

    const V1_DOWNLINK: &str = include_str!("../../cli/tests/golden/v1_downlink.hex");
    const V1_UPLINK: &str = include_str!("../../cli/tests/golden/v1_uplink.hex");
    const DOWNLINK_2020: &str = include_str!("../../cli/tests/golden/downlink.hex");
    const UPLINK_2020: &str = include_str!("../../cli/tests/golden/uplink.hex");

    #[test]
    fn a_given_generation_skips_detection() {
        let v1 = golden(V1_DOWNLINK);
        let as_2020 = decode(&v1, false, Some(Firmware::V2020));
        assert!(as_2020.summary.starts_with("firmware 2020 (given); "));
        assert!(
            as_2020
                .frames
                .iter()
                .all(|f| f.json["frame"] != "v1-telemetry")
        );
        let as_v1 = decode(&v1, false, Some(Firmware::V1_0_0));
        assert!(as_v1.summary.starts_with("firmware v1.0.0 (given); "));
        assert_eq!(as_v1.frames.len(), 8);

        let ff = golden(DOWNLINK_2020);
        let as_v1 = decode(&ff, false, Some(Firmware::V1_0_0));
        assert!(as_v1.summary.starts_with("firmware v1.0.0 (given); "));
        assert!(as_v1.frames.is_empty());
        let up = decode(&golden(V1_UPLINK), true, Some(Firmware::V1_0_0));
        assert!(
            up.summary
                .starts_with("firmware v1.0.0 (given); 126 bytes: 9 frames")
        );
    }

    #[test]
    fn each_side_detected_by_its_own_rule() {
        assert_eq!(
            detect_downlink(&golden(V1_DOWNLINK)),
            Detection::Detected(Firmware::V1_0_0)
        );
        assert_eq!(
            detect_downlink(&golden(DOWNLINK_2020)),
            Detection::Detected(Firmware::V2020)
        );
        assert_eq!(
            detect_uplink(&golden(V1_UPLINK)),
            Detection::Detected(Firmware::V1_0_0)
        );
        assert_eq!(
            detect_uplink(&golden(UPLINK_2020)),
            Detection::Detected(Firmware::V2020)
        );
        // Nine of each generation: neither has clearly more.
        let mut mixed = golden(V1_UPLINK);
        mixed.bytes.extend(golden(UPLINK_2020).bytes);
        assert_eq!(
            detect_uplink(&mixed),
            Detection::NotRecognised {
                frames_2020: 9,
                frames_v1: 9
            }
        );
        let words = detect_uplink(&mixed).words();
        assert!(
            words.contains("not recognised (9 frames of 2020, 9 of v1.0.0"),
            "{words}"
        );
    }

    #[test]
    fn sides_that_disagree_are_not_recognised() {
        let stamped = |mut c: Capture| {
            c.times = Some((0..c.bytes.len()).map(|i| i as f64 * 1e-4).collect());
            c
        };
        let board = stamped(golden(DOWNLINK_2020));
        let master = stamped(golden(V1_UPLINK));
        let decoded = decode_both(&board, &master, None).unwrap_or_default();
        assert!(
            decoded.summary.starts_with(
                "firmware not recognised (the board side's frames are 2020, the master side's \
                 v1.0.0), decoded as 2020; "
            ),
            "{}",
            decoded.summary
        );
        // A side that decides nothing follows the other.
        let silent = stamped(Capture::default());
        let decoded = decode_both(&silent, &master, None).unwrap_or_default();
        assert!(decoded.summary.starts_with("firmware v1.0.0 (detected); "));
        assert_eq!(decoded.frames.len(), 9);
    }

    #[test]
    fn no_bytes_make_it_panic() {
        // A deterministic stream of bytes biased to frame starts and ends, in every path.
        let mut x: u32 = 0x1234_5678;
        let mut bytes = Vec::new();
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let b = x.to_le_bytes()[0];
            bytes.push(match b % 8 {
                0 => 0x7B,
                1 => 0x7D,
                2 => 0xFF,
                _ => b,
            });
        }
        let times: Vec<f64> = (0..bytes.len()).map(|i| i as f64 * 3e-4).collect();
        let capture = Capture {
            bytes,
            times: Some(times),
            quiet_s: None,
        };
        for firmware in [None, Some(Firmware::V2020), Some(Firmware::V1_0_0)] {
            let _ = decode(&capture, false, firmware);
            let _ = decode(&capture, true, firmware);
            let _ = decode_both(&capture, &capture, firmware);
        }
    }
}
