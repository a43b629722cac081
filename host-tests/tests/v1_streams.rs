//! The v1.0.0 board → master parser on the stream model of `chassis_host_tests::v1`: every line
//! of the sweep at test size (fixed seed), and a clean stream from every start offset in random
//! chunkings. (The codec's own tests in `protocol/src/v1/tests.rs` cover a hand-made stream in
//! fixed chunk sizes from offsets 0..40; this is the model's stream, in random chunks.)

use chassis_host_tests::v1::{Board, Line, plausible, rows, run, run_reporting_quiet};
use chassis_protocol::v1::{Downlink, DownlinkParser, Parser};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Frames per row here (the sweep runs 1 000 000).
const FRAMES: usize = 30_000;

/// The seed the sweep quotes.
const SEED: u64 = 2026;

/// Whether `line` loses runs of bytes as long as a frame (or two replies): then the start of one
/// frame and the rest of the next can make a frame whose BCC checks (the XOR of the first bytes
/// of both agrees), which no framing can tell from a frame sent.
fn joins_frames(line: &Line) -> bool {
    line.noise.dropout > 0.0 && [14, 28, 32].contains(&line.noise.burst_len)
}

#[test]
fn with_the_quiet_line_told_no_row_has_a_frame_made_by_the_framing() {
    // The driver tells its parser of every quiet line: no frame spans one, so no lost run of
    // bytes joins two frames, and every other property holds as without.
    for row in rows() {
        let s = run_reporting_quiet(&row.line, FRAMES, SEED);
        assert_eq!(s.framing_false, 0, "{}: {:?}", row.name, s.false_samples);
        if !row.name.contains("1e-2") {
            assert!(s.recovery() >= 0.999, "{}: {:?}", row.name, s.recovery());
        }
    }
}

#[test]
fn every_line_of_the_sweep_at_test_size() {
    for row in rows() {
        let s = run(&row.line, FRAMES, SEED);
        assert_eq!(s.sent, FRAMES, "{}", row.name);
        // (a) No frame made by the framing, but where a lost run of bytes joins two frames.
        if joins_frames(&row.line) {
            assert_eq!(
                s.framing_false, s.framing_false_joined,
                "{}: {:?}",
                row.name, s.false_samples
            );
        } else {
            assert_eq!(s.framing_false, 0, "{}: {:?}", row.name, s.false_samples);
        }
        // (b) What the BCC lets through is what the arithmetic expects.
        let e = s.expected_undetected;
        assert!(
            (s.undetected as f64 - e).abs() <= 5.0 * e.sqrt() + 3.0,
            "{}: {} undetected, {e:.1} expected",
            row.name,
            s.undetected
        );
        // (c) Untouched frames come out: at least 99.9 % at 1e-3 and below.
        if row.name.contains("1e-3") {
            assert!(s.untouched > FRAMES / 2, "{}", row.name);
        }
        if !row.name.contains("1e-2") {
            assert!(
                s.recovery() >= 0.999,
                "{}: {} of {}",
                row.name,
                s.recovered,
                s.untouched
            );
        }
        // The plausibility check refuses nothing the board sent.
        assert_eq!(s.sent_implausible, 0, "{}", row.name);
    }
}

/// 300 frames, five replies a second; the offset of a telemetry frame followed by a reply.
fn clean_stream() -> (Vec<u8>, Vec<(usize, Downlink)>, usize) {
    let stream = Board::new(SEED, 5.0).take(300);
    let frames: Vec<(usize, Downlink)> = stream.frames.iter().map(|f| (f.start, f.frame)).collect();
    let at = stream
        .frames
        .windows(2)
        .skip(1)
        .find(|w| {
            matches!(w[0].frame, Downlink::Telemetry(_)) && matches!(w[1].frame, Downlink::Reply(_))
        })
        .map(|w| w[0].start)
        .expect("a telemetry frame followed by a reply");
    (stream.bytes, frames, at)
}

#[test]
fn a_clean_stream_from_every_offset_in_random_chunkings() {
    let (bytes, frames, at) = clean_stream();
    // Every byte of a telemetry frame (32) and of the reply after it (14).
    for offset in 0..46 {
        let start = at + offset;
        let want: Vec<Downlink> = frames
            .iter()
            .filter(|(s, _)| *s >= start)
            .map(|(_, f)| *f)
            .collect();
        for chunking in 0..4u64 {
            let mut rng = Pcg64Mcg::seed_from_u64(offset as u64 * 8 + chunking);
            let mut parser = DownlinkParser::new();
            let mut got = Vec::new();
            let mut rest = &bytes[start..];
            while !rest.is_empty() {
                let n = rng.random_range(1..=70).min(rest.len());
                let (piece, later) = rest.split_at(n);
                got.extend(parser.frames(piece));
                rest = later;
            }
            assert_eq!(got, want, "offset {offset}, chunking {chunking}");
        }
        // Byte by byte, through `push` and `poll`.
        let mut parser = DownlinkParser::new();
        let mut got = Vec::new();
        for b in &bytes[start..] {
            let mut out = parser.push(*b);
            while let Some(f) = out {
                got.push(f);
                out = parser.poll();
            }
        }
        assert_eq!(got, want, "offset {offset}, byte by byte");
    }
}

#[test]
fn the_plausibility_check_passes_everything_the_board_sends() {
    // An hour of driving.
    let stream = Board::new(SEED, 1.0).take(22 * 3_600);
    for f in &stream.frames {
        if let Downlink::Telemetry(t) = &f.frame {
            assert!(plausible(t), "{t:?}");
        }
    }
}
