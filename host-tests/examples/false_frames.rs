//! The false frames of one stream model, by class: where each starts and ends in what the board
//! sent (a frame's header, payload or count byte, or a byte the channel added), counted per
//! class, the first few shown byte by byte. `cargo xtask sweep` gives the counts; this gives
//! what they are.
//!
//! ```text
//! cargo run --release -p chassis-host-tests --example false_frames -- \
//!     [--counts p1|p235|shared|tick] [--payload rest|adversarial] \
//!     [--channel mixed|drops|insertions|dropouts] [--quiet] [--reads] \
//!     [--seed N] [--frames N] [--show N] [--context N]
//! ```
//!
//! Defaults: one shared counter, adversarial payloads, drops at 1e-3, nothing reported to the
//! parser, seed 2026, 1 000 000 frames, 3 shown (16 bytes before each, 8 after): the sweep's worst
//! row.

use chassis_host_tests::board::SentFrame;
use chassis_host_tests::channel::{Noise, Received, transmit};
use chassis_host_tests::{
    BoardStream, CountModel, FalseFrame, Payload, reads_behind, score_downlink_traced,
};
use chassis_protocol::{Downlink, Kind};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::collections::BTreeMap;
use std::process::ExitCode;

struct Args {
    counts: CountModel,
    payload: Payload,
    channel: Noise,
    quiet: bool,
    reads: bool,
    seed: u64,
    frames: usize,
    show: usize,
    /// Bytes shown before and after each false frame shown.
    context: Option<usize>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        counts: CountModel::Shared,
        payload: Payload::Adversarial,
        channel: Noise {
            drop: 1e-3,
            ..Noise::default()
        },
        quiet: false,
        reads: false,
        seed: 2026,
        frames: 1_000_000,
        show: 3,
        context: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        let number = |v: String| {
            v.replace('_', "")
                .parse::<u64>()
                .map_err(|e| format!("{v:?}: {e}"))
        };
        match flag.as_str() {
            "--counts" => {
                args.counts = match value()?.as_str() {
                    "p1" => CountModel::PerStream([1, 1, 1]),
                    "p235" => CountModel::PerStream([2, 3, 5]),
                    "shared" => CountModel::Shared,
                    "tick" => CountModel::Tick,
                    other => return Err(format!("--counts {other:?}: p1, p235, shared or tick")),
                }
            }
            "--payload" => {
                args.payload = match value()?.as_str() {
                    "rest" => Payload::Rest,
                    "adversarial" => Payload::Adversarial,
                    other => return Err(format!("--payload {other:?}: rest or adversarial")),
                }
            }
            "--channel" => {
                args.channel = match value()?.as_str() {
                    "mixed" => Noise::mixed(1e-3),
                    "drops" => Noise {
                        drop: 1e-3,
                        ..Noise::default()
                    },
                    "insertions" => Noise {
                        insert: 1e-3,
                        ..Noise::default()
                    },
                    "dropouts" => Noise::dropouts(1e-4, 32),
                    other => {
                        return Err(format!(
                            "--channel {other:?}: mixed, drops, insertions or dropouts"
                        ));
                    }
                }
            }
            "--quiet" => args.quiet = true,
            "--reads" => args.reads = true,
            "--seed" => args.seed = number(value()?)?,
            "--frames" => {
                args.frames = usize::try_from(number(value()?)?).map_err(|e| e.to_string())?
            }
            "--show" => {
                args.show = usize::try_from(number(value()?)?).map_err(|e| e.to_string())?
            }
            "--context" => {
                args.context = Some(usize::try_from(number(value()?)?).map_err(|e| e.to_string())?)
            }
            other => {
                return Err(format!(
                    "unknown argument {other:?} (see the example's docs)"
                ));
            }
        }
    }
    Ok(args)
}

/// What the received byte at `j` was when the board sent it: the frame it belongs to and its
/// place in it, or a byte the channel added.
fn origin<'a>(rx: &Received, sent: &'a [SentFrame], j: usize) -> Option<(&'a SentFrame, usize)> {
    let o = rx.origin.get(j).copied().flatten()?;
    let i = sent.partition_point(|f| f.start <= o).checked_sub(1)?;
    let f = sent.get(i)?;
    Some((f, o - f.start))
}

fn letter(frame: &Downlink) -> &'static str {
    match frame {
        Downlink::Imu(_) => "IMU",
        Downlink::Encoders(_) => "encoders",
        Downlink::Battery(_) => "battery",
        Downlink::Reply(_) => "reply",
    }
}

/// The class of the received byte at `j`: "IMU count", "reply payload", "added", …
fn class(rx: &Received, sent: &[SentFrame], j: usize) -> String {
    match origin(rx, sent, j) {
        None => "a byte the channel added".to_string(),
        Some((f, off)) => {
            let len = f.frame.kind().len();
            let part = if off < 2 {
                "header"
            } else if off + 1 == len && matches!(f.frame.kind(), Kind::Telemetry(_)) {
                "count"
            } else {
                "payload"
            };
            format!("{} {part}", letter(&f.frame))
        }
    }
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(args) => args,
        Err(message) => {
            eprintln!("false_frames: {message}");
            return ExitCode::from(2);
        }
    };
    let (bytes, sent, gaps) = BoardStream::new(args.seed, 2.0)
        .with_models(args.payload, args.counts)
        .take_with_gaps(args.frames);
    let rx = transmit(
        &bytes,
        &args.channel,
        &mut Pcg64Mcg::seed_from_u64(args.seed ^ 0x5EED),
    );
    let gaps = if args.quiet { &gaps[..] } else { &[] };
    let reads = if args.reads {
        reads_behind(&sent)
    } else {
        Vec::new()
    };
    let mut found: Vec<FalseFrame> = Vec::new();
    let score = score_downlink_traced(&sent, &rx, gaps, &reads, &mut |f| found.push(f));

    let mut classes: BTreeMap<String, usize> = BTreeMap::new();
    for f in &found {
        let key = format!(
            "{} from {} to {}",
            letter(&f.frame),
            class(&rx, &sent, f.start),
            class(&rx, &sent, f.end)
        );
        *classes.entry(key).or_default() += 1;
    }
    println!(
        "{} frames, recall {:.3} %, {} false ({:.1} per million)\n",
        score.sent,
        score.recall() * 100.0,
        score.false_frames,
        score.false_per_million()
    );
    println!("| false frame | starts in | ends in | count |\n|---|---|---|---|");
    for (key, n) in &classes {
        let (kind, rest) = key.split_once(" from ").unwrap_or((key, ""));
        let (from, to) = rest.split_once(" to ").unwrap_or((rest, ""));
        println!("| {kind} | {from} | {to} | {n} |");
    }
    for f in found.iter().take(args.show) {
        println!("\n{:?}, received bytes {}..={}:", f.frame, f.start, f.end);
        let lo = f.start.saturating_sub(args.context.unwrap_or(16));
        let hi = (f.end + args.context.unwrap_or(8)).min(rx.bytes.len().saturating_sub(1));
        for j in lo..=hi {
            let mark = if (f.start..=f.end).contains(&j) {
                '*'
            } else {
                ' '
            };
            let what = match origin(&rx, &sent, j) {
                None => "added by the channel".to_string(),
                Some((s, off)) => format!(
                    "{} {}byte {off}",
                    letter(&s.frame),
                    s.frame.seq().map(|c| format!("#{c} ")).unwrap_or_default()
                ),
            };
            println!("  {mark} {j:>9}  {:02X}  {what}", rx.bytes[j]);
        }
    }
    ExitCode::SUCCESS
}
