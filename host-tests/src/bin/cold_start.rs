//! Cold start, exact from the first byte: for every count model (those of the noise sweep and
//! a shared counter stepping by a constant drawn from the seed), a new parser starts at every
//! offset 0..200 of a clean stream of `--frames` frames (payloads at rest), fed one byte at a
//! time, in random slices of 1..64 bytes or in 62-byte USB packets, with the line's quiet
//! stretches after the start reported or not. Every frame that starts at or after the start
//! counts, the first whole one too. Then the same, one byte at a time, on payloads written to
//! fool a parser (the sweep's adversarial payloads, payloads of header bytes only, and payloads
//! whose every value reads -6..-4: a header at every other byte); and the last of these over
//! [`STREAMS`] short streams under shared counters, whose counts pass `FA`..`FC` (-6..-4's
//! second byte) at some starts.
//!
//! ```text
//! cargo run --release -p chassis-host-tests --bin cold-start -- [--frames N] [--seed S]
//! ```

use chassis_host_tests::cold::{Chunking, Model, cold_start};
use chassis_host_tests::models::count_models;
use chassis_host_tests::sweep::Args;
use chassis_host_tests::{CountModel, Payload};
use std::process::ExitCode;

/// Streams (seeds from the one given on) of [`lookalike_streams`].
const STREAMS: u64 = 400;

/// Start offsets tried in each stream.
const OFFSETS: std::ops::Range<usize> = 0..200;

fn main() -> ExitCode {
    let defaults = Args {
        seed: 2026,
        frames: 4_000,
    };
    let usage = "usage: cold-start [--frames N] [--seed S]";
    let Some(args) = Args::from_env_with("cold-start", usage, defaults) else {
        return ExitCode::from(2);
    };
    println!(
        "Cold start on a clean line: every offset {}..{} of a stream of {} frames (payloads at rest, 2 replies/s), seed {}; frames counted from the first that starts at or after the start\n",
        OFFSETS.start, OFFSETS.end, args.frames, args.seed
    );
    let mut summary = Vec::new();
    for (name, counts) in count_models(args.seed) {
        let model = Model {
            seed: args.seed,
            payload: Payload::Rest,
            counts,
            frames: args.frames,
        };
        let (missed, false_frames) = model_table(&name, model);
        summary.push((name, missed, false_frames));
    }
    println!(
        "| count model | frames missed at cold start (worst offset) | false frames (all starts) |"
    );
    println!("|---|---|---|");
    for (name, missed, false_frames) in summary {
        println!("| {name} | {missed} | {false_frames} |");
    }
    every_step(&args);
    hostile_payloads(&args);
    lookalike_streams(&args);
    ExitCode::SUCCESS
}

/// The table of one count model: every chunking, the quiet line reported or not. Returns the
/// worst start's frames missed and the false frames of all starts.
fn model_table(name: &str, model: Model) -> (usize, usize) {
    println!("{name}:\n");
    println!(
        "| quiet reported | chunks | starts | frames missed (all starts) | starts missing any | worst start: missed (offset; which) | false frames | starts with a false frame |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let (mut missed, mut false_frames) = (0, 0);
    for quiet in [false, true] {
        for (chunks, chunking) in Chunking::ALL {
            let c = cold_start(model, OFFSETS, quiet, chunking);
            println!(
                "| {} | {chunks} | {} | {} of {} | {} | {} ({}; {:?}) | {} | {} |",
                if quiet { "yes" } else { "no" },
                c.starts,
                c.missed,
                c.expected,
                c.starts_missing,
                c.worst.0,
                c.worst.1,
                c.worst_missed,
                c.false_frames,
                c.starts_false,
            );
            missed = missed.max(c.worst.0);
            false_frames += c.false_frames;
        }
    }
    println!();
    (missed, false_frames)
}

/// The shared counter at every step 1..=7 (the seed draws one), one byte at a time: the worst
/// start's misses and the false frames, the quiet line reported or not.
fn every_step(args: &Args) {
    println!(
        "\nOne shared counter at every step (1-byte chunks; worst start: frames missed; false frames):\n"
    );
    println!(
        "| step | no quiet: worst missed | no quiet: false | quiet reported: worst missed | quiet reported: false |"
    );
    println!("|---|---|---|---|---|");
    for step in 1..=7 {
        let model = Model {
            seed: args.seed,
            payload: Payload::Rest,
            counts: CountModel::SharedStep(step),
            frames: args.frames,
        };
        println!("| +{step} | {} |", quiet_or_not(model));
    }
}

/// The cells of `model` one byte at a time, without the quiet reported then with it: the worst
/// start's frames missed, and the false frames of all starts.
fn quiet_or_not(model: Model) -> String {
    let cells: Vec<String> = [false, true]
        .into_iter()
        .map(|quiet| {
            let c = cold_start(model, OFFSETS, quiet, Chunking::Bytes);
            format!("{} of {} | {}", c.worst.0, model.frames, c.false_frames)
        })
        .collect();
    cells.join(" | ")
}

/// Every count model on payloads written to fool a parser, one byte at a time: the worst
/// start's misses and the false frames, the quiet line reported or not.
fn hostile_payloads(args: &Args) {
    println!(
        "\nPayloads written to fool a parser (1-byte chunks; worst start: frames missed; false frames):\n"
    );
    println!(
        "| payload | count model | no quiet: worst missed | no quiet: false | quiet reported: worst missed | quiet reported: false |"
    );
    println!("|---|---|---|---|---|---|");
    for (payload_name, payload) in [
        ("adversarial", Payload::Adversarial),
        ("header bytes only", Payload::Headers),
        ("every value -6..-4", Payload::Lookalikes),
    ] {
        for (name, counts) in count_models(args.seed) {
            let model = Model {
                seed: args.seed,
                payload,
                counts,
                frames: args.frames,
            };
            println!("| {payload_name} | {name} | {} |", quiet_or_not(model));
        }
    }
}

/// Payloads whose every value reads -6..-4 under shared counters (+1, +2, +3 a frame), over
/// [`STREAMS`] streams of 60 frames, every start 0..200, one byte at a time: a shared counter
/// starts anywhere, so in some streams its counts pass `FA`..`FC`, the second bytes of the
/// headers every payload is made of, and the count byte tells a frame from a lookalike no more.
fn lookalike_streams(args: &Args) {
    println!(
        "\nEvery value -6..-4, {STREAMS} streams of 60 frames (seeds {} on), every start 0..200, 1-byte chunks:\n",
        args.seed
    );
    println!(
        "| count model | quiet reported | streams with a false frame | starts with a false frame | false frames |"
    );
    println!("|---|---|---|---|---|");
    for (name, counts) in [
        ("one shared counter", CountModel::Shared),
        ("one shared counter +2", CountModel::SharedStep(2)),
        ("one shared counter +3", CountModel::SharedStep(3)),
    ] {
        for quiet in [false, true] {
            let (mut streams, mut starts, mut false_frames) = (0, 0, 0);
            for k in 0..STREAMS {
                let model = Model {
                    seed: args.seed.wrapping_add(k),
                    payload: Payload::Lookalikes,
                    counts,
                    frames: 60,
                };
                let c = cold_start(model, OFFSETS, quiet, Chunking::Bytes);
                streams += usize::from(c.false_frames > 0);
                starts += c.starts_false;
                false_frames += c.false_frames;
            }
            println!(
                "| {name} | {} | {streams} of {STREAMS} | {starts} of {} | {false_frames} |",
                if quiet { "yes" } else { "no" },
                STREAMS as usize * OFFSETS.len()
            );
        }
    }
}
