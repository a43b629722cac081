//! The fuzz targets (`host-tests/fuzz`): `cargo xtask fuzz [SECONDS]` explores, `test` runs each
//! a fixed number of times from a fixed seed.

use crate::cmd::{check, host_tests, workspace_root};
use crate::tools::{install_cargo_tool, install_nightly};
use std::path::Path;
use std::process::Command;

/// The fuzz targets, in `host-tests/fuzz`, each with the number of runs `test` gives it (about
/// 30 s each on a 2-core machine: 5 000 runs a second on `downlink`, 1 200 on `spliced`, 7 000
/// to 16 000 on the others).
const FUZZ_TARGETS: [(&str, u32); 5] = [
    ("downlink", 150_000),
    ("uplink", 250_000),
    ("roundtrip", 400_000),
    ("spliced", 40_000),
    ("v1", 500_000),
];

/// libFuzzer's seed for the runs in `test`.
const CI_FUZZ_SEED: &str = "2026";

/// How a fuzz run is driven.
pub(crate) enum FuzzRun {
    /// `test`: a fixed seed, a fixed number of runs per target (capped at two minutes) and
    /// corpora generated afresh, so that every CI run goes through the same inputs: CI fails on
    /// a change to the code, never on the luck of the draw. Exploring is `fuzz`'s job.
    Repeatable,
    /// `fuzz SECONDS`: a random seed, each target for SECONDS, corpora kept between runs in
    /// `host-tests/fuzz/corpus`, so that every run explores further.
    Explore(u32),
}

/// Copies the inputs that once crashed a target (`host-tests/fuzz/regressions/<target>/`, kept
/// in the repository) into its corpus, so that every run, the repeatable one included, goes
/// through them first.
fn add_regressions(regressions: &Path, corpus: &Path) -> Result<(), String> {
    for (target, _) in FUZZ_TARGETS {
        let Ok(inputs) = std::fs::read_dir(regressions.join(target)) else {
            continue;
        };
        let into = corpus.join(target);
        std::fs::create_dir_all(&into)
            .map_err(|e| format!("cannot create {}: {e}", into.display()))?;
        for input in inputs {
            let input = input.map_err(|e| format!("cannot list {}: {e}", regressions.display()))?;
            let to = into.join(format!(
                "regression-{}",
                input.file_name().to_string_lossy()
            ));
            std::fs::copy(input.path(), &to)
                .map_err(|e| format!("cannot copy {}: {e}", input.path().display()))?;
        }
    }
    Ok(())
}

/// Runs every fuzz target, from generated seed corpora; fails on any crash.
pub(crate) fn fuzz(run: FuzzRun) -> Result<(), String> {
    install_nightly()?;
    install_cargo_tool("fuzz", "cargo-fuzz", None, &[])?;
    let root = workspace_root()?;
    let fuzz_dir = root.join("host-tests").join("fuzz");
    let corpus = match run {
        FuzzRun::Repeatable => {
            let fresh = root.join("target").join("fuzz-ci-corpus");
            if fresh.exists() {
                std::fs::remove_dir_all(&fresh)
                    .map_err(|e| format!("cannot clear {}: {e}", fresh.display()))?;
            }
            fresh
        }
        FuzzRun::Explore(_) => fuzz_dir.join("corpus"),
    };
    let corpus_arg = corpus.to_string_lossy().into_owned();
    host_tests("--bin", "fuzz-seeds", &[&corpus_arg])?;
    add_regressions(&fuzz_dir.join("regressions"), &corpus)?;
    for (target, runs) in FUZZ_TARGETS {
        let target_corpus = corpus.join(target).to_string_lossy().into_owned();
        let limits = match run {
            FuzzRun::Repeatable => vec![
                format!("-seed={CI_FUZZ_SEED}"),
                format!("-runs={runs}"),
                "-max_total_time=120".to_string(),
            ],
            FuzzRun::Explore(seconds) => vec![format!("-max_total_time={seconds}")],
        };
        let mut args = vec!["+nightly", "fuzz", "run", target, &target_corpus, "--"];
        args.extend(limits.iter().map(String::as_str));
        eprintln!("$ cargo {}", args.join(" "));
        check(
            Command::new("cargo").args(&args).current_dir(&fuzz_dir),
            "cargo fuzz",
            |status| {
                format!(
                    "fuzz target {target} failed ({status}): see host-tests/fuzz/artifacts/{target}"
                )
            },
        )?;
    }
    Ok(())
}
