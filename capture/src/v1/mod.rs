//! Firmware v1.0.0's captures (`7B … BCC 7D` frames): each side's parser over the bytes, every
//! frame checked by its BCC. A reply carries its request's code: each side of a capture is
//! decoded on its own.

mod describe;

pub use describe::describe_v1_uplink;

use crate::found::{Placed, Side};
use crate::generation::Generation;
use crate::read::Capture;
use chassis_protocol::v1;
use describe::describe_v1_downlink;

/// Firmware v1.0.0's decoder.
pub(crate) struct V1;

impl Generation for V1 {
    /// Telemetry and replies, each checked by its BCC (gaps in the time stamps change nothing:
    /// a frame is whole and checked, or not a frame).
    fn downlink(&self, capture: &Capture) -> Side {
        let mut placed = Placed::new(capture);
        let (mut telemetry, mut replies) = (0u32, 0u32);
        let mut parser = v1::DownlinkParser::new();
        let mut found = |frame: v1::Downlink, end: usize| {
            match frame {
                v1::Downlink::Telemetry(_) => telemetry = telemetry.saturating_add(1),
                v1::Downlink::Reply(_) => replies = replies.saturating_add(1),
            }
            placed.add(frame.encode().as_slice(), end, describe_v1_downlink(&frame));
        };
        for (i, &byte) in capture.bytes.iter().enumerate() {
            // A frame's bytes come back to back: none spans a quiet line in the time stamps
            // (a frame whole before it ends there).
            if capture.gap_before(i).is_some() {
                while let Some(frame) = parser.quiet() {
                    found(frame, i);
                }
            }
            let mut next = parser.push(byte);
            while let Some(frame) = next {
                found(frame, i + 1);
                next = parser.poll();
            }
        }
        let s = parser.stats();
        let summary = format!(
            "{} bytes: {} frames (telemetry {telemetry}, reply {replies}); {}",
            capture.bytes.len(),
            s.frames,
            counters(&s, parser.buffered())
        );
        placed.side(summary)
    }

    fn uplink(&self, capture: &Capture) -> Side {
        let mut placed = Placed::new(capture);
        let mut parser = v1::UplinkParser::new();
        for (i, &byte) in capture.bytes.iter().enumerate() {
            if capture.gap_before(i).is_some() {
                while let Some(command) = parser.quiet() {
                    placed.add(&command.encode(), i, describe_v1_uplink(&command));
                }
            }
            let mut next = parser.push(byte);
            while let Some(command) = next {
                placed.add(&command.encode(), i + 1, describe_v1_uplink(&command));
                next = parser.poll();
            }
        }
        let s = parser.stats();
        let summary = format!(
            "{} bytes: {} frames; {}",
            capture.bytes.len(),
            s.frames,
            counters(&s, parser.buffered())
        );
        placed.side(summary)
    }

    /// The parser is not told of the quiet gaps here: a frame is whole and checked, or not a
    /// frame.
    fn uplink_frames(&self, capture: &Capture) -> u32 {
        let mut parser = v1::UplinkParser::new();
        for &byte in &capture.bytes {
            let mut next = parser.push(byte);
            while next.is_some() {
                next = parser.poll();
            }
        }
        parser.stats().frames
    }
}

/// The counters of a v1.0.0 parser, a frame cut by the end of the capture (`held` bytes)
/// counted with the bytes discarded.
fn counters(s: &v1::Stats, held: usize) -> String {
    let discarded = u64::from(s.discarded).saturating_add(held as u64);
    format!(
        "{} bad BCC, {} bad end, {} refused; {discarded} bytes discarded",
        s.bad_checksum, s.bad_end, s.refused
    )
}
