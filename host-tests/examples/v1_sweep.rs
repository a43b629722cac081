//! The noise sweep of the v1.0.0 board → master parser (`chassis_protocol::v1::DownlinkParser`):
//! a driven chassis' telemetry at 22 Hz with a reply a second, the line idle between frames,
//! through every line of `chassis_host_tests::v1::rows` (bit errors, bursts, drops, insertions,
//! dropouts), with fixed seeds so the figures repeat.
//!
//! ```text
//! cargo run --release -p chassis-host-tests --example v1_sweep -- [--seed N] [--frames N]
//! ```
//!
//! Defaults: seed 2026, 1 000 000 frames per row. Prints a Markdown table per row: frames made by
//! the framing (goal 0), frames damaged in place that passed the BCC beside what the arithmetic
//! expects and what the plausibility check catches, the share of untouched frames recovered
//! (goal ≥ 99.9 % at 1e-3); then the parser's own counters, and the worst row of each figure.

use chassis_host_tests::sweep::Args;
use chassis_host_tests::v1::expect::{undetected_reply, undetected_telemetry};
use chassis_host_tests::v1::{Score, rows, run, run_reporting_quiet, startup};
use std::process::ExitCode;
use std::time::Instant;

/// `n` with a space every three digits.
fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

fn main() -> ExitCode {
    let Some(args) = Args::from_env("v1_sweep", "usage: v1_sweep [--seed N] [--frames N]") else {
        return ExitCode::from(2);
    };
    println!(
        "v1.0.0 board → master: {} frames per row (telemetry 22 Hz, a reply a second, the line idle between frames), seed {}\n",
        grouped(args.frames),
        args.seed
    );
    println!(
        "Probability that bit errors at p per bit change a frame in place and its BCC still checks:\n"
    );
    println!(
        "| p per bit | telemetry (32 B) | reply 33 or 50 (14 B) | reply 35 or 36 | reply 34 |"
    );
    println!("|---|---|---|---|---|");
    for p in [1e-4, 1e-3, 1e-2] {
        println!(
            "| {p:.0e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} |",
            undetected_telemetry(p),
            undetected_reply(p, 0x33),
            undetected_reply(p, 0x35),
            undetected_reply(p, 0x34)
        );
    }
    println!();
    println!(
        "| line | error events | untouched | recovered | framing false (quiet told: the driver) | framing false (not told: a capture without timing) | reassembled as sent | undetected by the BCC | expected | caught by plausibility |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut results: Vec<(&str, Score)> = Vec::new();
    for row in rows() {
        let start = Instant::now();
        let s = run_reporting_quiet(&row.line, args.frames, args.seed);
        let blind = run(&row.line, args.frames, args.seed);
        eprintln!("{}: {:.1} s", row.name, start.elapsed().as_secs_f64());
        let telemetry = s.undetected - s.undetected_replies;
        let replies = if s.undetected_replies > 0 {
            format!(" (+ {} replies, unchecked)", s.undetected_replies)
        } else {
            String::new()
        };
        let caught = |s: &Score| {
            if s.framing_false > 0 {
                format!(
                    " ({} joined across lost bytes, {} implausible)",
                    s.framing_false_joined, s.framing_false_implausible
                )
            } else {
                String::new()
            }
        };
        let false_caught = caught(&s);
        let blind_caught = caught(&blind);
        println!(
            "| {} | {} | {} | {:.3} % | {}{false_caught} | {}{blind_caught} | {} | {} | {:.1} | {} of {telemetry}{replies} |",
            row.name,
            grouped(s.errors),
            grouped(s.untouched),
            s.recovery() * 100.0,
            s.framing_false,
            blind.framing_false,
            s.reassembled,
            grouped(s.undetected),
            s.expected_undetected,
            grouped(s.undetected_implausible),
        );
        results.push((row.name, s));
    }

    println!("\nThe parser's own counters (`v1::Stats`):\n");
    println!("| line | frames | bad BCC | bad end | bytes discarded |");
    println!("|---|---|---|---|---|");
    for (name, s) in &results {
        println!(
            "| {name} | {} | {} | {} | {} |",
            grouped(s.stats.frames as usize),
            grouped(s.stats.bad_checksum as usize),
            grouped(s.stats.bad_end as usize),
            grouped(s.stats.discarded as usize),
        );
    }

    let seeds = 500;
    println!(
        "\nStarting to listen mid-stream (clean line, every offset in the first three frames, {seeds} streams with five replies a second):\n"
    );
    println!(
        "| starts | every frame from the offset on | worst frames lost | starts with a false frame | false frames |"
    );
    println!("|---|---|---|---|---|");
    let s = startup(0..seeds, 40);
    println!(
        "| {} | {:.2} % | {} | {:.2} % | {} |",
        grouped(s.starts),
        s.all_after_first as f64 * 100.0 / s.starts.max(1) as f64,
        s.worst_lost,
        s.with_false as f64 * 100.0 / s.starts.max(1) as f64,
        s.false_frames
    );

    let worst = |key: &dyn Fn(&Score) -> f64| {
        results
            .iter()
            .max_by(|a, b| key(&a.1).total_cmp(&key(&b.1)))
            .map(|(name, s)| (*name, s))
    };
    println!();
    if let Some((name, s)) = worst(&|s| s.per_million(s.framing_false)) {
        if s.framing_false == 0 {
            println!("Framing false frames: none in any row.");
        } else {
            println!(
                "Framing false frames, worst row: {name}: {} ({:.2} per million frames sent).",
                s.framing_false,
                s.per_million(s.framing_false)
            );
        }
    }
    if let Some((name, s)) = worst(&|s| s.per_million(s.undetected)) {
        println!(
            "Undetected by the BCC, worst row: {name}: {} ({:.0} per million frames sent; {:.1} expected), {} left past the plausibility check.",
            s.undetected,
            s.per_million(s.undetected),
            s.expected_undetected,
            s.undetected - s.undetected_implausible
        );
    }
    if let Some((name, s)) = worst(&|s| -s.recovery()) {
        if s.recovered == s.untouched {
            println!("Recovery of untouched frames: 100 % in every row.");
        } else {
            println!(
                "Recovery of untouched frames, worst row: {name}: {:.4} % ({} of {}).",
                s.recovery() * 100.0,
                s.recovered,
                s.untouched
            );
        }
    }
    let alarms: usize = results.iter().map(|(_, s)| s.sent_implausible).sum();
    println!("Frames delivered as sent that the plausibility check refuses, all rows: {alarms}.");

    for (name, s) in &results {
        for f in s.false_samples.iter().take(3) {
            println!("\nframing false frame ({name}): {:?}", f.frame);
            for (byte, origin) in &f.bytes {
                let from = origin.map_or("added by the line".to_string(), |o| {
                    format!("sent byte {o}")
                });
                println!("  {byte:02X}  {from}");
            }
        }
    }
    ExitCode::SUCCESS
}
