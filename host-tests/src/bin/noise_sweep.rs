//! The noise sweep: a realistic board stream through a noisy channel into the downlink parser,
//! at rates from 1e-5 to 1e-2 per byte, with a fixed seed so the figures repeat.
//!
//! ```text
//! cargo run --release -p chassis-host-tests --bin noise-sweep -- [--frames N] [--seed S]
//! ```
//!
//! Prints Markdown tables: recall of untouched frames, false frames per million sent, untouched
//! frames lost per channel error, latency, and the parser's own counters; then every stream model
//! (payloads, count models, quiet reported or not) with the parser told nothing of the master's
//! reads, and again with them known (as the driver, or `chassis decode --master`, tells it);
//! the simulator's stream; starting to listen mid-stream; and last, stream models the parser
//! was never developed against (payloads of header bytes only, a shared counter stepping by a
//! constant drawn per seed, the line delivered in USB packets; `chassis_host_tests::models`).

use chassis_host_tests::board::simulator_stream;
use chassis_host_tests::channel::{Noise, transmit};
use chassis_host_tests::models::{DELIVERIES, Delivery, PAYLOADS, RATES, count_models, run_model};
use chassis_host_tests::sweep::Args;
use chassis_host_tests::usb::Host;
use chassis_host_tests::{
    BoardStream, CountModel, Payload, Score, reads_behind, score_downlink,
    score_downlink_listening, startup, startup_with_idle,
};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::process::ExitCode;

/// Runs `frames` frames through `noise`, as one stream into one parser.
fn run(noise: &Noise, frames: usize, seed: u64) -> Score {
    let (bytes, sent) = BoardStream::new(seed, 2.0).take(frames);
    let rx = transmit(&bytes, noise, &mut Pcg64Mcg::seed_from_u64(seed ^ 0x5EED));
    score_downlink(&sent, &rx)
}

/// One row of the table.
fn print_row(name: &str, rate: f64, s: &Score) {
    println!(
        "| {name} | {rate:.0e} | {} | {} | {:.3} % | {:.1} | {:.3} | {:.2} % | {:.2} / {} |",
        s.errors,
        s.untouched,
        s.recall() * 100.0,
        s.false_per_million(),
        s.lost_per_error(),
        s.on_time_locked as f64 * 100.0 / s.recalled_locked.max(1) as f64,
        s.mean_latency(),
        s.latency_max,
    );
}

fn main() -> ExitCode {
    let Some(args) = Args::from_env("noise-sweep", "usage: noise-sweep [--frames N] [--seed S]")
    else {
        return ExitCode::from(2);
    };
    println!(
        "{} frames per row (IMU 100 Hz, encoders 25 Hz, battery 1 Hz, 2 replies/s), seed {}\n",
        args.frames, args.seed
    );
    println!(
        "| channel | rate/byte | errors | untouched | recall | false/M | lost/error | on time while locked | mean / max latency (bytes) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut rows: Vec<(String, f64, Noise)> = Vec::new();
    for rate in [1e-5, 1e-4, 1e-3, 3e-3, 1e-2] {
        rows.push(("mixed".to_string(), rate, Noise::mixed(rate)));
    }
    for (name, make) in [
        (
            "substitute",
            (|r| Noise {
                substitute: r,
                ..Noise::default()
            }) as fn(f64) -> Noise,
        ),
        ("drop", |r| Noise {
            drop: r,
            ..Noise::default()
        }),
        ("insert", |r| Noise {
            insert: r,
            ..Noise::default()
        }),
    ] {
        rows.push((name.to_string(), 1e-3, make(1e-3)));
    }
    for rate in [1e-4, 1e-3] {
        rows.push(("bursts of 8".to_string(), rate, Noise::bursts(rate, 8)));
    }
    for rate in [1e-4, 1e-3] {
        rows.push((
            "dropouts of 32".to_string(),
            rate,
            Noise::dropouts(rate, 32),
        ));
    }
    for (name, rate, noise) in rows {
        let s = run(&noise, args.frames, args.seed);
        print_row(&name, rate, &s);
    }
    // Stream models the parser was not written against: payloads dense with `FF FA`..`FF FC`
    // and `23`+code in every field, every count model of A10, with and without the line's quiet
    // stretches reported, at 1e-3 mixed errors per byte and a few other channels.
    println!(
        "\nEvery stream model ({} frames per row, 2 replies/s interleaved between telemetry frames, seed {}):\n",
        args.frames, args.seed
    );
    println!(
        "| payload | count model | quiet reported | channel | recall | false/M | lost/error | on time while locked |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let channels = [
        ("mixed 1e-3", Noise::mixed(1e-3)),
        (
            "drops 1e-3",
            Noise {
                drop: 1e-3,
                ..Noise::default()
            },
        ),
        (
            "insertions 1e-3",
            Noise {
                insert: 1e-3,
                ..Noise::default()
            },
        ),
        ("dropouts of 32, 1e-4", Noise::dropouts(1e-4, 32)),
    ];
    model_rows(&args, &channels, false, "Worst row");

    // The same stream models with the master's side known: the parser told of each read the
    // master sent (the driver does this; so does `chassis decode --master`).
    println!(
        "\nEvery stream model with the master's reads known (each reply awaited from the start of the frame before it, for 55 ms at most), seed {}:\n",
        args.seed
    );
    println!(
        "| payload | count model | quiet reported | channel | recall | false/M | lost/error | on time while locked |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    model_rows(&args, &channels, true, "Worst row with the reads known");

    // The same channel over the board simulator's own output (telemetry at real rates, a read
    // every half second answered while telemetry pauses).
    for rate in [1e-4, 1e-3, 1e-2] {
        let (bytes, sent) = simulator_stream(args.seed, args.frames);
        let rx = transmit(
            &bytes,
            &Noise::mixed(rate),
            &mut Pcg64Mcg::seed_from_u64(args.seed ^ 0x5EED),
        );
        let s = score_downlink(&sent, &rx);
        print_row("simulator, mixed", rate, &s);
    }

    let seeds = 500;
    println!(
        "\nStarting to listen mid-stream (clean line, every offset in the first three frames, {seeds} streams):\n"
    );
    println!(
        "| stream | starts | every frame after the first complete one | worst frames lost after it | starts with a false frame | false frames |"
    );
    println!("|---|---|---|---|---|---|");
    let rows = [
        ("frames back to back", startup(0..seeds, 40)),
        (
            "simulator, idle() between bursts",
            startup_with_idle(0..seeds, 40),
        ),
    ];
    for (name, s) in rows {
        println!(
            "| {name} | {} | {:.2} % | {} | {:.2} % | {} |",
            s.starts,
            s.all_after_first as f64 * 100.0 / s.starts as f64,
            s.worst_lost,
            s.with_false as f64 * 100.0 / s.starts as f64,
            s.false_frames
        );
    }
    never_tuned_on(&args);
    ExitCode::SUCCESS
}

/// The groups of rows whose worst row per error rate the section names after its table.
const GROUPS: [&str; 4] = [
    "header bytes only (good hosts)",
    "shared counter +k (good hosts)",
    "USB, host watching the gaps",
    "BAD HOST: idle() after every packet",
];

/// Which of [`GROUPS`] a row is in.
fn groups(payload: Payload, counts: CountModel, delivery: Delivery) -> [bool; 4] {
    let bad = matches!(delivery, Delivery::Usb(_, Host::IdleEveryPacket));
    [
        payload == Payload::Headers && !bad,
        matches!(counts, CountModel::SharedStep(_)) && !bad,
        matches!(delivery, Delivery::Usb(_, Host::QuietAfter(_))),
        bad,
    ]
}

/// The worst rows of each of [`GROUPS`] at each rate of [`RATES`]: the one with the most false
/// frames (then the lowest recall), and the one with the lowest recall (then the most false).
struct Worst {
    /// `rows[group][rate]`: (false per million, recall, row) of each.
    most_false: Vec<Vec<(f64, f64, String)>>,
    lowest_recall: Vec<Vec<(f64, f64, String)>>,
}

impl Worst {
    fn new() -> Self {
        let none = vec![vec![(f64::MIN, f64::MAX, String::new()); RATES.len()]; GROUPS.len()];
        Worst {
            most_false: none.clone(),
            lowest_recall: none,
        }
    }

    /// Counts the row `name`, scored `row[rate]`, in `group`.
    fn note(&mut self, group: usize, name: &str, row: &[Score]) {
        for (rate, s) in row.iter().enumerate() {
            let (false_per_million, recall) = (s.false_per_million(), s.recall());
            let w = &mut self.most_false[group][rate];
            if (false_per_million, -recall) > (w.0, -w.1) {
                *w = (false_per_million, recall, name.to_string());
            }
            let w = &mut self.lowest_recall[group][rate];
            if (-recall, false_per_million) > (-w.1, w.0) {
                *w = (false_per_million, recall, name.to_string());
            }
        }
    }

    fn print(&self) {
        for (kind, table) in [
            ("most false frames", &self.most_false),
            ("lowest recall", &self.lowest_recall),
        ] {
            println!();
            for (group, rows) in GROUPS.iter().zip(table) {
                for (rate, (false_per_million, recall, row)) in RATES.iter().zip(rows) {
                    let rate = if *rate > 0.0 {
                        format!("{rate:.0e}")
                    } else {
                        "clean".to_string()
                    };
                    println!(
                        "Worst row ({kind}), {group}, {rate}: {row}: {false_per_million:.1} false frames per million, recall {:.3} %",
                        recall * 100.0
                    );
                }
            }
        }
    }
}

/// The section of stream models never tuned on: every payload of [`PAYLOADS`], count model
/// and delivery, at the error rates of [`RATES`]; then the worst rows of each group per rate.
fn never_tuned_on(args: &Args) {
    println!(
        "\nStream models never tuned on ({} frames per row, seed {}, 2 replies/s; mixed channel; each cell: recall / false frames per million):\n",
        args.frames, args.seed
    );
    println!("| payload | count model | delivery | clean | 1e-4 | 1e-3 | 1e-2 |");
    println!("|---|---|---|---|---|---|---|");
    let mut worst = Worst::new();
    let deliveries: Vec<Delivery> = DELIVERIES.iter().map(|(_, d)| *d).collect();
    for (payload_name, payload) in PAYLOADS {
        for (count_name, counts) in count_models(args.seed) {
            let models = (payload, counts);
            let scores = run_model(args.seed, args.frames, models, &deliveries, &RATES);
            for ((delivery_name, delivery), row) in DELIVERIES.iter().zip(&scores) {
                let cells: Vec<String> = row
                    .iter()
                    .map(|s| format!("{:.3} % / {:.1}", s.recall() * 100.0, s.false_per_million()))
                    .collect();
                let name = format!("{payload_name} | {count_name} | {delivery_name}");
                println!("| {name} | {} |", cells.join(" | "));
                let member = groups(payload, counts, *delivery);
                for (group, _) in member.iter().enumerate().filter(|(_, m)| **m) {
                    worst.note(group, &name, row);
                }
            }
        }
    }
    worst.print();
}

/// One row per stream model and channel: payloads, every count model, quiet reported or not;
/// with `reads`, the parser is told of the master's reads. Then the worst row, after `label`.
fn model_rows(args: &Args, channels: &[(&str, Noise)], reads: bool, label: &str) {
    let mut worst: Option<(f64, f64, String)> = None;
    for (payload_name, payload) in [
        ("at rest", Payload::Rest),
        ("adversarial", Payload::Adversarial),
    ] {
        for (count_name, counts) in CountModel::ALL {
            for quiet in [false, true] {
                for (channel_name, noise) in channels {
                    if *channel_name != "mixed 1e-3" && payload != Payload::Adversarial {
                        continue;
                    }
                    let (bytes, sent, gaps) = BoardStream::new(args.seed, 2.0)
                        .with_models(payload, counts)
                        .take_with_gaps(args.frames);
                    let rx = transmit(
                        &bytes,
                        noise,
                        &mut Pcg64Mcg::seed_from_u64(args.seed ^ 0x5EED),
                    );
                    let gaps = if quiet { &gaps[..] } else { &[] };
                    let reads = if reads {
                        reads_behind(&sent)
                    } else {
                        Vec::new()
                    };
                    let s = score_downlink_listening(&sent, &rx, gaps, &reads);
                    let row =
                        format!("{payload_name} / {count_name} / quiet {quiet} / {channel_name}");
                    println!(
                        "| {payload_name} | {count_name} | {} | {channel_name} | {:.3} % | {:.1} | {:.3} | {:.2} % |",
                        if quiet { "yes" } else { "no" },
                        s.recall() * 100.0,
                        s.false_per_million(),
                        s.lost_per_error(),
                        s.on_time_locked as f64 * 100.0 / s.recalled_locked.max(1) as f64,
                    );
                    let key = (s.false_per_million(), -s.recall());
                    if worst.as_ref().is_none_or(|w| key > (w.0, w.1)) {
                        worst = Some((key.0, key.1, row));
                    }
                }
            }
        }
    }
    if let Some((false_per_million, recall, row)) = worst {
        println!(
            "\n{label}: {row}: {false_per_million:.1} false frames per million, recall {:.3} %",
            -recall * 100.0
        );
    }
}
