//! A realistic board stream with arbitrary bytes spliced in (and the bytes they replace cut
//! out): after the corruption ends, the parser must be back within a bound.
//!
//! The bound: every frame that starts at least `RECOVERY_BYTES` after the end of the corruption
//! comes out, nothing false comes out from the first of them on, and the parser ends Locked.
//! `RECOVERY_BYTES` is `FORGET_AFTER` (the longest a false count learnt from the corruption can
//! hold out) plus three of the longest frames; on most inputs recovery takes one or two frames.
#![no_main]

use chassis_host_tests::BoardStream;
use chassis_protocol::parse::downlink::FORGET_AFTER;
use chassis_protocol::{DownlinkParser, Lock, Telemetry};
use libfuzzer_sys::fuzz_target;

const RECOVERY_BYTES: usize = FORGET_AFTER as usize + 3 * 15;

fuzz_target!(|input: (u64, u16, u8, Vec<u8>)| {
    let (seed, at, cut, garbage) = input;
    let garbage = &garbage[..garbage.len().min(64)];
    let (clean, sent) = BoardStream::new(seed, 2.0).take(120);

    // Replace `cut` bytes at `at` (past the first few frames) with the garbage.
    let at = 60 + usize::from(at) % (clean.len() / 2);
    let cut = usize::from(cut) % 32;
    let mut wire = clean[..at].to_vec();
    wire.extend_from_slice(garbage);
    let resume = at + cut;
    wire.extend_from_slice(&clean[resume..]);
    let shift = |sent_offset: usize| sent_offset + garbage.len() - cut;

    let mut parser = DownlinkParser::new();
    let mut out: Vec<(usize, Telemetry)> = Vec::new();
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
        return;
    };
    for f in &after {
        assert!(out.iter().any(|(_, o)| *o == f.frame), "lost {:?}", f.frame);
    }
    // Nothing false from the first frame after the bound on (found by where it ended, since
    // two replies can be equal).
    let first_end = shift(first_after.start) + first_after.frame.encode().len() - 1;
    let from = out
        .iter()
        .position(|(i, _)| *i >= first_end)
        .unwrap_or(out.len());
    for (_, frame) in &out[from..] {
        assert!(
            after.iter().any(|f| f.frame == *frame),
            "false frame {frame:?}"
        );
    }
    assert_eq!(parser.lock(), Lock::Locked);
});
