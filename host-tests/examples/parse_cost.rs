//! Parses a realistic board stream (100 000 frames; `noisy`: with 1e-3 errors per byte; `slices`:
//! through `frames()` in 64-byte reads instead of `push`) and prints bytes and frames. Run it
//! under `valgrind --tool=callgrind --toggle-collect='*DownlinkParser*'` for a deterministic
//! instruction count per byte (host instructions; Cortex-M counts belong to the MCU issue).

use chassis_host_tests::BoardStream;
use chassis_host_tests::channel::{Noise, transmit};
use chassis_protocol::DownlinkParser;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

fn main() {
    let noisy = std::env::args().any(|a| a == "noisy");
    let sliced = std::env::args().any(|a| a == "slices");
    let (bytes, _) = BoardStream::new(2026, 2.0).take(100_000);
    let bytes = if noisy {
        transmit(&bytes, &Noise::mixed(1e-3), &mut Pcg64Mcg::seed_from_u64(1)).bytes
    } else {
        bytes
    };
    let mut parser = DownlinkParser::new();
    let mut frames = 0usize;
    if sliced {
        // Reads of 64 bytes, as a DMA buffer would give them.
        for chunk in black_box(&bytes).chunks(64) {
            frames += parser.frames(chunk).count();
        }
    } else {
        for b in black_box(&bytes) {
            frames += usize::from(parser.push(*b).is_some());
        }
    }
    println!("{} bytes, {frames} frames", bytes.len());
}
