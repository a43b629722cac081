//! The 2020 firmware's captures (`FF FE` commands, `FF FA/FB/FC` telemetry, `#` replies, no
//! checksum): each side's parser over the bytes, told of the quiet gaps in their time stamps;
//! on both sides of one capture, the master's reads tell the board side's parser which reply is
//! awaited.

mod describe;

use crate::found::{Placed, Side};
use crate::generation::Generation;
use crate::read::Capture;
use chassis_protocol::driver::Config;
use chassis_protocol::{Command, Downlink, DownlinkParser, Register, Setting, UplinkParser};
use describe::{describe_downlink, describe_uplink};

/// The 2020 firmware's decoder.
pub(crate) struct V2020;

impl Generation for V2020 {
    fn downlink(&self, capture: &Capture) -> Side {
        downlink(capture, &[])
    }

    fn uplink(&self, capture: &Capture) -> Side {
        uplink(capture).0
    }

    /// Each read the master sent tells the board side's parser which reply is awaited from the
    /// read's last byte on (until the driver's reply timeout), as the driver does.
    fn both(&self, board: &Capture, master: &Capture) -> (Side, Side, String) {
        let (master_side, reads) = uplink(master);
        let reads: Vec<(f64, Register)> = reads
            .iter()
            .filter_map(|(last, register)| Some((master.time_of(*last)?, *register)))
            .collect();
        let board_side = downlink(board, &reads);
        let told = format!(
            "; {} reads told the board side's parser which reply to await",
            reads.len()
        );
        (board_side, master_side, told)
    }

    fn uplink_frames(&self, capture: &Capture) -> u32 {
        let mut parser = UplinkParser::new();
        for (i, &byte) in capture.bytes.iter().enumerate() {
            if capture.gap_before(i).is_some() {
                parser.idle();
            }
            let _ = parser.push(byte);
        }
        parser.stats().frames
    }
}

/// The master → board side: its frames and summary, and each read (the index of its last byte
/// and the register read).
fn uplink(capture: &Capture) -> (Side, Vec<(usize, Register)>) {
    let mut placed = Placed::new(capture);
    let mut reads = Vec::new();
    let mut parser = UplinkParser::new();
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if capture.gap_before(i).is_some() {
            parser.idle();
        }
        if let Some(command) = parser.push(byte) {
            if let Command::Setting(Setting::Read(register)) = command {
                reads.push((i, register));
            }
            let described = describe_uplink(&command);
            // Encoding consumes the command (a turn is sent once, even in a decoder).
            let wire = command.encode();
            placed.add(wire.as_slice(), i + 1, described);
        }
    }
    let s = parser.stats();
    let summary = format!(
        "{} bytes: {} frames; {} bytes discarded, {} resyncs",
        capture.bytes.len(),
        s.frames,
        s.discarded,
        s.resyncs
    );
    (placed.side(summary), reads)
}

/// The board → master side, the parser told of each read in `reads` (the time of its last
/// byte, in the capture's clock, and the register) from the first byte received after it.
fn downlink(capture: &Capture, reads: &[(f64, Register)]) -> Side {
    let mut placed = Placed::new(capture);
    let timeout_s = f64::from(Config::DEFAULT.reply_timeout_ms()) / 1000.0;
    let mut reads = reads.iter().peekable();
    // The read awaited, and when the master gives up on it.
    let mut awaited: Option<f64> = None;
    let mut parser = DownlinkParser::new();
    let mut emit = |frame: Downlink, upto: usize| {
        placed.add(frame.encode().as_slice(), upto, describe_downlink(&frame));
    };
    for (i, &byte) in capture.bytes.iter().enumerate() {
        if let Some(ms) = capture.gap_before(i) {
            while let Some(frame) = parser.quiet(ms) {
                emit(frame, i);
            }
        }
        if let Some(now) = capture.time_of(i) {
            while let Some((sent, register)) = reads.next_if(|(t, _)| *t <= now) {
                parser.expect_reply(Some(*register));
                awaited = Some(sent + timeout_s);
            }
            if awaited.is_some_and(|deadline| now > deadline) {
                parser.expect_reply(None);
                awaited = None;
            }
        }
        if let Some(frame) = parser.push(byte) {
            emit(frame, i + 1);
        }
        while let Some(frame) = parser.poll() {
            emit(frame, i + 1);
        }
    }
    // The end of a capture is a quiet line.
    while let Some(frame) = parser.quiet(1_000) {
        emit(frame, capture.bytes.len());
    }
    let summary = downlink_summary(capture, &parser);
    placed.side(summary)
}

/// What the board → master parser counted over `capture`.
fn downlink_summary(capture: &Capture, parser: &DownlinkParser) -> String {
    let s = parser.stats();
    let gaps: u32 = s.gaps.iter().sum();
    let missed: u32 = s.missed.iter().sum();
    format!(
        "{} bytes: imu {}, encoders {}, battery {}, reply {}; {} bytes discarded; {} count gaps ({} frames missed)",
        capture.bytes.len(),
        s.frames[0],
        s.frames[1],
        s.frames[2],
        s.frames[3],
        s.discarded,
        gaps,
        missed
    )
}
