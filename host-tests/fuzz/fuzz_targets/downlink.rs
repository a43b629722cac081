//! Arbitrary bytes into the board → master parser, byte by byte and in arbitrary slices.
//!
//! Checked on every input: the two paths emit the same frames and end in the same state; every
//! byte is accounted for (emitted in a frame, discarded, or still buffered: progress on every
//! byte, nothing lost or counted twice); the window never holds more than `WINDOW` bytes; every frame
//! emitted is well formed (it re-encodes to bytes that decode to it, replies carry a code the
//! spec defines); after `idle` nothing is left buffered.
#![no_main]

use chassis_host_tests::pieces;
use chassis_protocol::{Downlink, DownlinkParser, Register};
use libfuzzer_sys::fuzz_target;

fn well_formed(frame: &Downlink) {
    assert_eq!(Downlink::decode(&frame.encode()), Ok(*frame));
    if let Downlink::Reply(reply) = frame {
        assert!(Register::from_reply_code(reply.code).is_some(), "{reply:?}");
    }
}

fn accounted(parser: &DownlinkParser, fed: usize, emitted: &[Downlink]) {
    let in_frames: usize = emitted.iter().map(|f| f.encode().len()).sum();
    let stats = parser.stats();
    assert_eq!(
        in_frames + stats.discarded as usize + parser.buffered(),
        fed
    );
    assert!(parser.buffered() <= chassis_protocol::parse::downlink::WINDOW);
}

fuzz_target!(|input: (Vec<u8>, Vec<u8>)| {
    let (bytes, cuts) = input;

    let mut one = DownlinkParser::new();
    let mut by_byte = Vec::new();
    for (i, b) in bytes.iter().enumerate() {
        if let Some(frame) = one.push(*b) {
            well_formed(&frame);
            by_byte.push(frame);
        }
        accounted(&one, i + 1, &by_byte);
    }

    let mut sliced = DownlinkParser::new();
    let mut by_slice = Vec::new();
    let cuts: Vec<usize> = cuts.iter().map(|c| usize::from(*c)).collect();
    for piece in pieces(&bytes, &cuts) {
        by_slice.extend(sliced.frames(piece));
    }
    // A frame may be ready in the window after the last byte: `poll` drains it on both.
    by_byte.extend(std::iter::from_fn(|| one.poll()));
    by_slice.extend(std::iter::from_fn(|| sliced.poll()));
    assert_eq!(by_slice, by_byte);
    assert_eq!(sliced.stats(), one.stats());
    assert_eq!(
        (sliced.lock(), sliced.buffered()),
        (one.lock(), one.buffered())
    );

    while let Some(frame) = one.idle() {
        well_formed(&frame);
        by_byte.push(frame);
    }
    assert_eq!(one.buffered(), 0);
    accounted(&one, bytes.len(), &by_byte);
});
