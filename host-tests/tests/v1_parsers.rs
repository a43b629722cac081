//! Property tests of the v1.0.0 parsers' three ways in: `push` a byte at a time, `push_slice`
//! and `frames()`, over random chunkings of random noisy streams (the board's stream across a
//! noisy line, with bytes that look like frames sprinkled in, and quiet lines told at random
//! chunk ends). Each gives the frames and the counters of the deliberately simple reference
//! (`chassis_host_tests::v1::reference`), and holds the same bytes, at the end of every chunk.

use chassis_host_tests::channel::Noise;
use chassis_host_tests::pieces;
use chassis_host_tests::v1::reference::{BoardToMaster, Direction, MasterToBoard, Reference};
use chassis_host_tests::v1::{Board, Line, transmit};
use chassis_protocol::v1::{self, Parser, Stats};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(512)
}

/// A parser of the crate with its counters.
trait Counted: Parser + Default {
    fn stats(&self) -> Stats;
}

impl Counted for v1::DownlinkParser {
    fn stats(&self) -> Stats {
        v1::DownlinkParser::stats(self)
    }
}

impl Counted for v1::UplinkParser {
    fn stats(&self) -> Stats {
        v1::UplinkParser::stats(self)
    }
}

/// How a run feeds its parser.
#[derive(Clone, Copy, Debug)]
enum Way {
    Bytes,
    PushSlice,
    Frames,
}

/// What a run saw at the end of each chunk: the frames so far, the counters, the bytes held.
type Trace = Vec<(usize, Stats, usize)>;

/// The reference over `bytes` cut by `cuts`, the line told quiet after the chunks in `quiet`.
fn reference<D: Direction>(bytes: &[u8], cuts: &[usize], quiet: &[bool]) -> (Vec<D::Frame>, Trace) {
    let mut parser = Reference::<D>::default();
    let mut out = Vec::new();
    let mut trace = Vec::new();
    for (i, piece) in pieces(bytes, cuts).enumerate() {
        for byte in piece {
            out.extend(parser.push(*byte));
            out.extend(std::iter::from_fn(|| parser.poll()));
        }
        if quiet.get(i % quiet.len().max(1)).copied().unwrap_or(false) {
            out.extend(std::iter::from_fn(|| parser.quiet()));
        }
        trace.push((out.len(), parser.stats(), parser.buffered()));
    }
    (out, trace)
}

/// The crate's parser `P` over the same, fed `way`.
fn run<P: Counted>(
    bytes: &[u8],
    cuts: &[usize],
    quiet: &[bool],
    way: Way,
) -> (Vec<P::Frame>, Trace) {
    let mut parser = P::default();
    let mut out = Vec::new();
    let mut trace = Vec::new();
    for (i, piece) in pieces(bytes, cuts).enumerate() {
        match way {
            Way::Bytes => {
                for byte in piece {
                    out.extend(parser.push(*byte));
                    out.extend(std::iter::from_fn(|| parser.poll()));
                }
            }
            Way::PushSlice => {
                let mut rest = piece;
                while let (Some(frame), later) = parser.push_slice(rest) {
                    out.push(frame);
                    rest = later;
                }
            }
            Way::Frames => out.extend(parser.frames(piece)),
        }
        if quiet.get(i % quiet.len().max(1)).copied().unwrap_or(false) {
            out.extend(std::iter::from_fn(|| parser.quiet(5)));
        }
        trace.push((out.len(), parser.stats(), parser.buffered()));
    }
    (out, trace)
}

/// Bytes that start, end or name frames, more often than chance has them.
fn nasty_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        Just(v1::START),
        Just(v1::END),
        Just(v1::TELEMETRY_CODE),
        proptest::sample::select(vec![
            0x23u8, 0x24, 0x25, 0x26, 0x33, 0x34, 0x35, 0x36, 0x40, 0x50
        ]),
        any::<u8>(),
    ]
}

/// Runs of nasty bytes, each to go in at a random place.
fn sprinkles() -> impl Strategy<Value = Vec<(proptest::sample::Index, Vec<u8>)>> {
    proptest::collection::vec(
        (
            any::<proptest::sample::Index>(),
            proptest::collection::vec(nasty_byte(), 1..40),
        ),
        0..8,
    )
}

/// `bytes` with each run of `sprinkles` put in at its place.
fn sprinkled(mut bytes: Vec<u8>, sprinkles: &[(proptest::sample::Index, Vec<u8>)]) -> Vec<u8> {
    for (at, run) in sprinkles {
        let at = at.index(bytes.len() + 1);
        bytes.splice(at..at, run.iter().copied());
    }
    bytes
}

/// Every way in against the reference.
fn check_ways<P: Counted, D: Direction<Frame = P::Frame>>(
    bytes: &[u8],
    cuts: &[usize],
    quiet: &[bool],
) -> Result<(), TestCaseError>
where
    P::Frame: PartialEq + core::fmt::Debug,
{
    let (want, want_trace) = reference::<D>(bytes, cuts, quiet);
    for way in [Way::Bytes, Way::PushSlice, Way::Frames] {
        let (got, trace) = run::<P>(bytes, cuts, quiet, way);
        prop_assert_eq!(&got, &want, "{:?}", way);
        prop_assert_eq!(&trace, &want_trace, "{:?}", way);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// The board → master parser: the board's stream across a noisy line.
    #[test]
    fn downlink_push_push_slice_and_frames_agree_with_the_reference(
        seed in any::<u64>(),
        frames in 1usize..40,
        rate in proptest::sample::select(vec![0.0, 1e-3, 1e-2, 5e-2]),
        bit_error in proptest::sample::select(vec![0.0, 1e-3, 1e-2]),
        sprinkles in sprinkles(),
        cuts in proptest::collection::vec(1usize..80, 1..40),
        quiet in proptest::collection::vec(proptest::bool::weighted(0.1), 0..8),
    ) {
        let stream = Board::new(seed, 5.0).take(frames);
        let line = Line::bits(bit_error).with(Noise::mixed(rate));
        let arrived = transmit(&stream, &line, &mut Pcg64Mcg::seed_from_u64(seed));
        let bytes = sprinkled(arrived.rx.bytes, &sprinkles);
        check_ways::<v1::DownlinkParser, BoardToMaster>(&bytes, &cuts, &quiet)?;
    }

    /// The board → master parser on bytes made of nothing but frame starts, ends and codes.
    #[test]
    fn downlink_agrees_with_the_reference_on_nasty_bytes(
        bytes in proptest::collection::vec(nasty_byte(), 0..400),
        cuts in proptest::collection::vec(1usize..80, 1..40),
        quiet in proptest::collection::vec(proptest::bool::weighted(0.1), 0..8),
    ) {
        check_ways::<v1::DownlinkParser, BoardToMaster>(&bytes, &cuts, &quiet)?;
    }

    /// The master → board parser: commands, some refused for their payload, among nasty bytes.
    #[test]
    fn uplink_push_push_slice_and_frames_agree_with_the_reference(
        commands in proptest::collection::vec((any::<u8>(), prop_oneof![Just([0u8; 10]), any::<[u8; 10]>()]), 0..20),
        sprinkles in sprinkles(),
        cuts in proptest::collection::vec(1usize..40, 1..40),
        quiet in proptest::collection::vec(proptest::bool::weighted(0.1), 0..8),
    ) {
        let codes = [0x23u8, 0x24, 0x25, 0x26, 0x33, 0x34, 0x35, 0x36, 0x40, 0x50];
        let mut bytes = Vec::new();
        for (code, payload) in &commands {
            let code = codes[usize::from(*code) % codes.len()];
            let mut frame = vec![v1::START, code];
            frame.extend_from_slice(payload);
            frame.push(v1::bcc(&frame));
            frame.push(v1::END);
            bytes.extend(frame);
        }
        let bytes = sprinkled(bytes, &sprinkles);
        check_ways::<v1::UplinkParser, MasterToBoard>(&bytes, &cuts, &quiet)?;
    }
}
