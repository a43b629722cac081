//! The fuzz targets (`host-tests/fuzz`): `cargo xtask fuzz [SECONDS]` explores, `test` runs each
//! a fixed number of times from a fixed seed. Built once, then run as many side by side as the
//! machine has cores, each one's output in `target/fuzz-logs/<target>.log`.

use crate::cmd::{check, host_tests, workspace_root};
use crate::tools::{install_cargo_tool, install_nightly};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The fuzz targets, in `host-tests/fuzz`, each with the number of runs `test` gives it (about
/// 30 s each on one core of a 2-core machine: 5 000 runs a second on `downlink`, 1 200 on
/// `spliced`, 7 000 to 16 000 on the others).
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
    // Every target built once, then run side by side (libFuzzer keeps one core busy): the
    // binaries themselves, as `cargo fuzz run` would start them.
    let target_dir = fuzz_dir.join("target");
    let target_dir_arg = target_dir.to_string_lossy().into_owned();
    let build = ["+nightly", "fuzz", "build", "--target-dir", &target_dir_arg];
    eprintln!("$ cargo {}", build.join(" "));
    check(
        Command::new("cargo").args(build).current_dir(&fuzz_dir),
        "cargo fuzz",
        |status| format!("cargo fuzz build failed ({status})"),
    )?;
    let bins = target_dir.join(host_triple()?).join("release");
    let logs = root.join("target").join("fuzz-logs");
    std::fs::create_dir_all(&logs).map_err(|e| format!("cannot create {}: {e}", logs.display()))?;
    let jobs: Vec<FuzzJob> = FUZZ_TARGETS
        .iter()
        .map(|&(target, runs)| FuzzJob::new(target, runs, &run, &fuzz_dir, &bins, &corpus, &logs))
        .collect();
    let side_by_side = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    run_jobs(&jobs, side_by_side)
}

/// One fuzz target's run.
struct FuzzJob {
    target: &'static str,
    program: PathBuf,
    args: Vec<String>,
    artifacts: PathBuf,
    log: PathBuf,
}

impl FuzzJob {
    /// `target`'s run: its binary in `bins`, its corpus in `corpus`, its log in `logs`, `runs`
    /// runs if the run is repeatable.
    fn new(
        target: &'static str,
        runs: u32,
        run: &FuzzRun,
        fuzz_dir: &Path,
        bins: &Path,
        corpus: &Path,
        logs: &Path,
    ) -> Self {
        let artifacts = fuzz_dir.join("artifacts").join(target);
        let mut args = vec![
            format!("-artifact_prefix={}/", artifacts.display()),
            corpus.join(target).to_string_lossy().into_owned(),
        ];
        match run {
            FuzzRun::Repeatable => args.extend([
                format!("-seed={CI_FUZZ_SEED}"),
                format!("-runs={runs}"),
                "-max_total_time=120".to_string(),
            ]),
            FuzzRun::Explore(seconds) => args.push(format!("-max_total_time={seconds}")),
        }
        FuzzJob {
            target,
            program: bins.join(target),
            args,
            artifacts,
            log: logs.join(format!("{target}.log")),
        }
    }

    /// Runs it to the end, its output into its log; what went wrong, if anything.
    fn run(&self) -> Result<(), String> {
        if let Err(e) = std::fs::create_dir_all(&self.artifacts) {
            return Err(format!("cannot create {}: {e}", self.artifacts.display()));
        }
        let log = std::fs::File::create(&self.log)
            .map_err(|e| format!("cannot create {}: {e}", self.log.display()))?;
        let err = log
            .try_clone()
            .map_err(|e| format!("cannot write {}: {e}", self.log.display()))?;
        eprintln!("$ {} {}", self.program.display(), self.args.join(" "));
        let status = Command::new(&self.program)
            .args(&self.args)
            .stdout(log)
            .stderr(err)
            .status()
            .map_err(|e| format!("could not start {}: {e}", self.program.display()))?;
        let text = std::fs::read_to_string(&self.log).unwrap_or_default();
        if status.success() {
            let done = text
                .lines()
                .rev()
                .find(|l| l.starts_with("Done "))
                .unwrap_or("done");
            eprintln!("fuzz target {}: {done}", self.target);
            Ok(())
        } else {
            let lines: Vec<&str> = text.lines().collect();
            let tail = lines.get(lines.len().saturating_sub(40)..).unwrap_or(&[]);
            eprintln!("{}", tail.join("\n"));
            Err(format!(
                "fuzz target {} failed ({status}): see {} and {}",
                self.target,
                self.artifacts.display(),
                self.log.display()
            ))
        }
    }
}

/// Runs `jobs`, `side_by_side` at a time, each to its end; every failure, if any, in one error.
fn run_jobs(jobs: &[FuzzJob], side_by_side: usize) -> Result<(), String> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..side_by_side.clamp(1, jobs.len().max(1)) {
            scope.spawn(|| {
                while let Some(job) =
                    jobs.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
                {
                    if let Err(e) = job.run() {
                        if let Ok(mut failures) = failures.lock() {
                            failures.push(e);
                        }
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap_or_default();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(failures.join("; "))
    }
}

/// The host's target triple, where `cargo fuzz build` puts the binaries.
fn host_triple() -> Result<String, String> {
    let output = Command::new("rustc")
        .args(["+nightly", "-vV"])
        .output()
        .map_err(|e| format!("could not start rustc: {e}"))?;
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .map(str::to_string)
        .ok_or_else(|| "rustc -vV names no host".to_string())
}
