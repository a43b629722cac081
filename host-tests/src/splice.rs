//! The recovery check behind the `spliced` fuzz target: a realistic board stream with arbitrary
//! bytes spliced in (and the bytes they replace cut out); after the corruption ends, the parser
//! must be back within a bound.
//!
//! The bound: every frame that starts at least [`RECOVERY_BYTES`] after the end of the
//! corruption comes out, nothing false comes out from the first of them on, and the parser ends
//! Locked. Inputs the fuzzer found are kept as regression tests (`tests/regressions.rs`).

use crate::BoardStream;
use chassis_protocol::parse::downlink::FORGET_AFTER;
use chassis_protocol::{Downlink, DownlinkParser, Lock};

/// `FORGET_AFTER` (the longest a false count learnt from the corruption can hold out) plus three
/// of the longest frames; on most inputs recovery takes one or two frames.
pub const RECOVERY_BYTES: usize = FORGET_AFTER as usize + 3 * 15;

/// At most this many garbage bytes are spliced in.
pub const MAX_GARBAGE: usize = 64;

/// One splice: the stream's seed, where the splice goes (`at`, reduced into the stream), how
/// many real bytes it cuts (`cut`, reduced below 32) and the bytes it puts in their place
/// (the first [`MAX_GARBAGE`]). Any values are valid: the fuzzer picks them.
#[derive(Clone, Debug)]
pub struct Splice<'a> {
    /// Seed of the board stream (120 frames, 2 replies a second).
    pub seed: u64,
    /// Where the splice starts, reduced to a point past the first few frames.
    pub at: u16,
    /// How many real bytes are cut out, reduced modulo 32.
    pub cut: u8,
    /// The bytes spliced in.
    pub garbage: &'a [u8],
}

/// Runs the splice through a new parser, one byte at a time, and checks the bound. `Err` says
/// what broke it: a frame lost, a false frame, or the parser not Locked at the end.
pub fn check_recovery(splice: &Splice<'_>) -> Result<(), String> {
    let garbage = splice.garbage.get(..MAX_GARBAGE).unwrap_or(splice.garbage);
    let (clean, sent) = BoardStream::new(splice.seed, 2.0).take(120);

    // Replace `cut` bytes at `at` (past the first few frames) with the garbage.
    let at = 60 + usize::from(splice.at) % (clean.len() / 2);
    let cut = usize::from(splice.cut) % 32;
    let resume = at + cut;
    let mut wire = clean[..at].to_vec();
    wire.extend_from_slice(garbage);
    wire.extend_from_slice(&clean[resume..]);
    let shift = |sent_offset: usize| sent_offset + garbage.len() - cut;

    let mut parser = DownlinkParser::new();
    let mut out: Vec<(usize, Downlink)> = Vec::new();
    for (i, b) in wire.iter().enumerate() {
        if let Some(frame) = parser.push(*b) {
            out.push((i, frame));
        }
    }
    while let Some(frame) = parser.idle() {
        out.push((wire.len(), frame));
    }

    let bound = shift(resume) + RECOVERY_BYTES;
    let after: Vec<_> = sent
        .iter()
        .filter(|f| f.start >= resume && shift(f.start) >= bound)
        .collect();
    let Some(first_after) = after.first() else {
        return Ok(());
    };
    for f in &after {
        if !out.iter().any(|(_, o)| *o == f.frame) {
            return Err(format!(
                "lost {:?} (at {} of the wire; splice at {at}, {cut} cut, {} in)",
                f.frame,
                shift(f.start),
                garbage.len()
            ));
        }
    }
    // Nothing false from the first frame after the bound on (found by where it ended, since
    // two replies can be equal).
    let first_end = shift(first_after.start) + first_after.frame.encode().len() - 1;
    let from = out
        .iter()
        .position(|(i, _)| *i >= first_end)
        .unwrap_or(out.len());
    // (A real frame sent after the splice may come out late, after the first one past the
    // bound: a reply nobody awaits waits for the next frame's count.)
    let real_after_splice = |frame: &Downlink| {
        sent.iter()
            .filter(|f| f.start >= resume)
            .any(|f| f.frame == *frame)
    };
    if let Some((i, frame)) = out[from..]
        .iter()
        .find(|(_, frame)| !real_after_splice(frame))
    {
        return Err(format!("false frame {frame:?} ending at {i}"));
    }
    match parser.lock() {
        Lock::Locked => Ok(()),
        lock => Err(format!("{lock:?} at the end of the stream")),
    }
}
