//! Parses a realistic board stream (100 000 frames; `noisy`: with 1e-3 errors per byte; `random`:
//! as many random bytes instead; `adversarial`: another board (seed 7) whose payloads are full
//! of headers and whose counts are one counter shared by all streams, a stream the shortcuts
//! were not tuned on; `slices`: through `frames()` in 64-byte reads instead of `push`)
//! and prints bytes and frames. Run it
//! under `valgrind --tool=callgrind --toggle-collect='*parse_cost::parse*'` for a deterministic
//! instruction count of the parsing alone (the stream is made outside the measured functions).
//! Host instructions; Cortex-M counts belong to the MCU issue.

use chassis_host_tests::channel::{Noise, transmit};
use chassis_host_tests::{BoardStream, CountModel, Payload};
use chassis_protocol::DownlinkParser;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

/// Every byte through `push`: frames found.
#[inline(never)]
fn parse_bytewise(bytes: &[u8]) -> usize {
    let mut parser = DownlinkParser::new();
    let mut frames = 0usize;
    for b in bytes {
        frames += usize::from(parser.push(*b).is_some());
    }
    frames
}

/// Reads of 64 bytes, as a DMA buffer would give them, through `frames()`.
#[inline(never)]
fn parse_slices(bytes: &[u8]) -> usize {
    let mut parser = DownlinkParser::new();
    let mut frames = 0usize;
    for chunk in bytes.chunks(64) {
        frames += parser.frames(chunk).count();
    }
    frames
}

fn main() {
    let noisy = std::env::args().any(|a| a == "noisy");
    let random = std::env::args().any(|a| a == "random");
    let sliced = std::env::args().any(|a| a == "slices");
    let adversarial = std::env::args().any(|a| a == "adversarial");
    let (bytes, _) = if adversarial {
        BoardStream::new(7, 2.0)
            .with_models(Payload::Adversarial, CountModel::Shared)
            .take(100_000)
    } else {
        BoardStream::new(2026, 2.0).take(100_000)
    };
    let bytes = if random {
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        (0..bytes.len()).map(|_| rng.random()).collect()
    } else if noisy {
        transmit(&bytes, &Noise::mixed(1e-3), &mut Pcg64Mcg::seed_from_u64(1)).bytes
    } else {
        bytes
    };
    let frames = if sliced {
        parse_slices(black_box(&bytes))
    } else {
        parse_bytewise(black_box(&bytes))
    };
    println!("{} bytes, {frames} frames", bytes.len());
}
