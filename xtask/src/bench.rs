//! The parser's measurements on the host, not part of `test`: `cargo xtask bench` (beside its
//! peers, the ratios the parser issue sets as goals) and `cargo xtask sweep` (the noise sweeps).

use crate::cmd::{cargo_program, host_tests};
use std::process::Command;

/// The ratios the parser issue sets as goals: (goal, numerator, denominator, at least).
const BENCH_GOALS: [(&str, &str, &str, f64); 4] = [
    (
        "byte path ≥ 2 × sbus-rs",
        "byte path: chassis telemetry",
        "byte path: sbus-rs",
        2.0,
    ),
    (
        "slice path ≥ 2 × uf-crsf",
        "slice path: chassis telemetry",
        "slice path: uf-crsf",
        2.0,
    ),
    (
        "random bytes ≥ ½ telemetry (byte path)",
        "byte path: chassis random bytes",
        "byte path: chassis telemetry",
        0.5,
    ),
    (
        "random bytes ≥ ½ telemetry (slice path)",
        "slice path: chassis random bytes",
        "slice path: chassis telemetry",
        0.5,
    ),
];

/// Not goals: how far any byte path can get on this machine. A "parser" that only stores each
/// byte and calls out of line at a frame's end (see the bench) is the floor of the
/// byte-at-a-time interface; the byte-path goal is reachable only if the first is at least 2.
const BENCH_FLOOR: [(&str, &str, &str); 2] = [
    (
        "byte-path floor (store only) ÷ sbus-rs",
        "byte path: store-only floor",
        "byte path: sbus-rs",
    ),
    (
        "chassis byte path ÷ floor",
        "byte path: chassis telemetry",
        "byte path: store-only floor",
    ),
];

/// Not goals: the v1.0.0 board → master parser beside the 2020 one, each on its own board's
/// stream (and both on the same random bytes), in the same run.
const BENCH_GENERATIONS: [(&str, &str, &str); 4] = [
    (
        "v1 ÷ 2020, byte path, each board's stream",
        "byte path: chassis v1 telemetry",
        "byte path: chassis telemetry",
    ),
    (
        "v1 ÷ 2020, slice path, each board's stream",
        "slice path: chassis v1 telemetry",
        "slice path: chassis telemetry",
    ),
    (
        "v1 ÷ 2020, byte path, random bytes",
        "byte path: chassis v1 random bytes",
        "byte path: chassis random bytes",
    ),
    (
        "v1 ÷ 2020, slice path, random bytes",
        "slice path: chassis v1 random bytes",
        "slice path: chassis random bytes",
    ),
];

/// Runs the parser benchmark (`host-tests/benches/parsers.rs`: this parser and its peers in one
/// run) `runs` times and prints one table with the ratios the parser issue sets as goals: each
/// ratio is taken within a run (peers measured minutes apart on a shared machine are not
/// comparable), and the median over the runs is the one judged. Then the floor, and the v1.0.0
/// parser beside the 2020 one ([`BENCH_GENERATIONS`]).
pub(crate) fn bench(args: &[String]) -> Result<(), String> {
    let runs = match args {
        [] => 1,
        [flag, n] if flag == "--runs" => {
            n.parse::<usize>()
                .ok()
                .filter(|n| (1..=15).contains(n))
                .ok_or_else(|| format!("--runs takes 1 to 15, not {n:?}"))?
        }
        _ => return Err("usage: cargo xtask bench [--runs N]".to_string()),
    };
    let mut all: Vec<Rates> = Vec::new();
    for run in 1..=runs {
        eprintln!("run {run} of {runs}");
        all.push(bench_once()?);
    }
    print_rates(&all);
    print_goals(&all);
    println!();
    print_ratios(&all, &BENCH_FLOOR);
    println!();
    print_ratios(&all, &BENCH_GENERATIONS);
    Ok(())
}

/// One run's MB/s per benchmark, in the bench's order.
type Rates = Vec<(String, f64)>;

/// The MB/s of benchmark `name` in one run (NaN if it did not run).
fn rate(rates: &[(String, f64)], name: &str) -> f64 {
    rates
        .iter()
        .find(|(k, _)| k == name)
        .map_or(f64::NAN, |(_, v)| *v)
}

/// The ratio `a ÷ b` in each run.
fn per_run(all: &[Rates], a: &str, b: &str) -> Vec<f64> {
    all.iter().map(|r| rate(r, a) / rate(r, b)).collect()
}

/// The median of `v` (the upper one of an even count; NaN if empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Each run's ratio, to two places, comma-separated.
fn show(v: &[f64]) -> String {
    v.iter()
        .map(|r| format!("{r:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The table of every benchmark's MB/s, each run's in one cell.
fn print_rates(all: &[Rates]) {
    let names: Vec<String> = all
        .first()
        .map(|r| r.iter().map(|(n, _)| n.clone()).collect())
        .unwrap_or_default();
    println!(
        "| parser and stream | MB/s{} |",
        if all.len() > 1 { " (each run)" } else { "" }
    );
    println!("|---|---|");
    for n in &names {
        let each: Vec<String> = all.iter().map(|r| format!("{:.0}", rate(r, n))).collect();
        println!("| {n} | {} |", each.join(", "));
    }
}

/// The table of [`BENCH_GOALS`]: each ratio's median, each run's (with more than one) and
/// whether the goal is met.
fn print_goals(all: &[Rates]) {
    let runs = all.len();
    if runs > 1 {
        println!("\n| goal | ratio (median of {runs} runs) | each run | met |");
        println!("|---|---|---|---|");
    } else {
        println!("\n| goal | ratio | met |");
        println!("|---|---|---|");
    }
    for (goal, a, b, want) in BENCH_GOALS {
        let each = per_run(all, a, b);
        let r = median(each.clone());
        let met = if r >= want { "yes" } else { "no" };
        if runs > 1 {
            println!("| {goal} | {r:.2} | {} | {met} |", show(&each));
        } else {
            println!("| {goal} | {r:.2} | {met} |");
        }
    }
}

/// A line per ratio (not goals): its median and each run's.
fn print_ratios(all: &[Rates], ratios: &[(&str, &str, &str)]) {
    for (what, a, b) in ratios {
        let each = per_run(all, a, b);
        println!("{what}: {:.2} ({})", median(each.clone()), show(&each));
    }
}

/// One run of the benchmark: MB/s per benchmark, in the bench's order.
fn bench_once() -> Result<Rates, String> {
    let program = cargo_program();
    let args = [
        "bench",
        "-p",
        "chassis-host-tests",
        "--bench",
        "parsers",
        "--",
        "--noplot",
    ];
    eprintln!("$ cargo {}", args.join(" "));
    let output = Command::new(&program)
        .args(args)
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("could not start cargo bench: {e}"))?;
    if !output.status.success() {
        return Err(format!("cargo bench failed ({})", output.status));
    }
    let text = String::from_utf8_lossy(&output.stdout);
    // Criterion prints `parsers/<name>` and, a line or two later, `thrpt: [low mid high]`.
    let mut rates: Vec<(String, f64)> = Vec::new();
    let mut name = None;
    for line in text.lines() {
        if let Some(n) = line.trim().strip_prefix("parsers/") {
            name = Some(n.trim().to_string());
        } else if let (Some(n), Some(rest)) = (&name, line.trim().strip_prefix("thrpt:")) {
            let fields: Vec<&str> = rest
                .trim_matches(|c: char| c == '[' || c == ']' || c.is_whitespace())
                .split_whitespace()
                .collect();
            if let [_, _, mid, unit, ..] = fields.as_slice() {
                let value: f64 = mid.parse().map_err(|e| format!("{mid}: {e}"))?;
                let mib = match *unit {
                    "GiB/s" => value * 1024.0,
                    "KiB/s" => value / 1024.0,
                    _ => value,
                };
                rates.push((n.clone(), mib * 1.048_576));
            }
            name = None;
        }
    }
    Ok(rates)
}

/// The noise sweeps: the 2020 parser's (`noise-sweep`), then the v1.0.0 board → master
/// parser's (example `v1_sweep`); `--v1` runs only the second; `--seed N` for a seed other than
/// the one the figures quote.
pub(crate) fn sweep(args: &[String]) -> Result<(), String> {
    let v1_only = args.iter().any(|a| a == "--v1");
    let args: Vec<&str> = args
        .iter()
        .map(String::as_str)
        .filter(|a| *a != "--v1")
        .collect();
    match args.as_slice() {
        [] | ["--seed", _] => {}
        _ => return Err("usage: cargo xtask sweep [--seed N] [--v1]".to_string()),
    }
    if !v1_only {
        host_tests("--bin", "noise-sweep", &args)?;
        println!();
    }
    host_tests("--example", "v1_sweep", &args)
}
