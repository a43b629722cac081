//! Arbitrary bytes into both v1.0.0 parsers (`7B … BCC 7D`), byte by byte and in arbitrary
//! slices: the same frames either way, every byte accounted for (in a frame, discarded or
//! held), never more than one frame held, and every frame found is, byte for byte, a run of
//! the input whose BCC checks.
#![no_main]

use chassis_host_tests::pieces;
use chassis_protocol::v1::{self, Command, Downlink, DownlinkParser, Parser, UplinkParser};
use libfuzzer_sys::fuzz_target;

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    haystack.windows(needle.len()).any(|w| w == needle)
}

fuzz_target!(|input: (Vec<u8>, Vec<u8>)| {
    let (bytes, cuts) = input;
    let cuts: Vec<usize> = cuts.iter().map(|c| usize::from(*c)).collect();

    let mut down = DownlinkParser::new();
    let mut found: Vec<Downlink> = Vec::new();
    let mut in_frames = 0usize;
    for (i, b) in bytes.iter().enumerate() {
        let mut next = down.push(*b);
        while let Some(frame) = next {
            let wire = frame.encode();
            assert!(contains(&bytes, wire.as_slice()), "a frame the input holds");
            assert_eq!(Downlink::decode(wire.as_slice()), Ok(frame));
            in_frames += wire.as_slice().len();
            found.push(frame);
            next = down.poll();
        }
        assert_eq!(
            in_frames + down.stats().discarded as usize + down.buffered(),
            i + 1
        );
        assert!(down.buffered() <= v1::TELEMETRY_LEN);
    }
    let mut sliced = DownlinkParser::new();
    let mut by_slice = Vec::new();
    for piece in pieces(&bytes, &cuts) {
        by_slice.extend(sliced.frames(piece));
    }
    assert_eq!(by_slice, found);
    assert_eq!(sliced.stats(), down.stats());

    let mut up = UplinkParser::new();
    let mut commands: Vec<Command> = Vec::new();
    for b in &bytes {
        let mut next = up.push(*b);
        while let Some(command) = next {
            assert!(contains(&bytes, &command.encode()));
            commands.push(command);
            next = up.poll();
        }
        assert!(up.buffered() <= v1::COMMAND_LEN);
    }
    assert_eq!(
        commands.len() * v1::COMMAND_LEN + up.stats().discarded as usize + up.buffered(),
        bytes.len()
    );
    let mut sliced = UplinkParser::new();
    let by_slice: Vec<Command> = pieces(&bytes, &cuts)
        .flat_map(|piece| sliced.frames(piece).collect::<Vec<_>>())
        .collect();
    assert_eq!(by_slice, commands);
});
