//! Arbitrary bytes into the master → board parser, byte by byte and in arbitrary slices: the
//! same frames, every byte accounted for, every command well formed.
#![no_main]

use chassis_host_tests::pieces;
use chassis_protocol::{Command, UplinkParser};
use libfuzzer_sys::fuzz_target;

fn accounted(parser: &UplinkParser, fed: usize, emitted: &[Command]) {
    let in_frames: usize = emitted.iter().map(Command::len).sum();
    assert_eq!(
        in_frames + parser.stats().discarded as usize + parser.buffered(),
        fed
    );
    assert!(parser.buffered() <= 12);
}

fuzz_target!(|input: (Vec<u8>, Vec<u8>)| {
    let (bytes, cuts) = input;

    let mut one = UplinkParser::new();
    let mut by_byte = Vec::new();
    for (i, b) in bytes.iter().enumerate() {
        if let Some(command) = one.push(*b) {
            assert_eq!(
                Command::decode(&command.clone().encode()),
                Ok(command.clone())
            );
            by_byte.push(command);
        }
        accounted(&one, i + 1, &by_byte);
    }

    let mut sliced = UplinkParser::new();
    let mut by_slice = Vec::new();
    let cuts: Vec<usize> = cuts.iter().map(|c| usize::from(*c)).collect();
    for piece in pieces(&bytes, &cuts) {
        by_slice.extend(sliced.frames(piece));
    }
    assert_eq!(by_slice, by_byte);
    assert_eq!(sliced.stats(), one.stats());
    assert_eq!(sliced.buffered(), one.buffered());

    one.idle();
    assert_eq!(one.buffered(), 0);
});
