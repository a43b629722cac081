//! `cargo xtask test`: everything CI checks, in order. The host half is here (format, lints,
//! tests, each published crate alone, `no_std` builds, the host no-panic proof, docs, the
//! minimum Rust version); the tasks it includes each have their own module, the firmware half
//! [`crate::firmware::test`].

use crate::cmd::{cargo, cargo_program, run, run_with, workspace_root};
use crate::fuzz::{FuzzRun, fuzz};
use crate::tools::{install_cargo_tool, install_targets, rustup_list};
use crate::{firmware, package, public_api, python, ros2};

/// Thumb targets the protocol crate must build for: Cortex-M0+ and Cortex-M4F.
const THUMB_TARGETS: [&str; 2] = ["thumbv6m-none-eabi", "thumbv7em-none-eabihf"];

/// proptest's seed for the runs in `test`.
const PROPTEST_SEED: &str = "2026";

/// cargo-hack's version, pinned.
const CARGO_HACK: &str = "0.6.46";

/// `cargo xtask test`.
pub(crate) fn test() -> Result<(), String> {
    install_targets(&THUMB_TARGETS)?;
    format_and_lints()?;
    // Property tests with a fixed seed, as the fuzz runs below: CI goes through the same cases
    // every time. Exploring further: `PROPTEST_CASES=400000 cargo test --release -p
    // chassis-host-tests --test properties` (a new random seed each run).
    let seeded = [("PROPTEST_RNG_SEED", PROPTEST_SEED)];
    // The tests with cargo-nextest (`.config/nextest.toml`: the test binaries side by side, the
    // busiest tests one at a time), then the documentation's examples, which it does not run.
    install_cargo_tool("nextest", "cargo-nextest", None, &[])?;
    run_with(
        &cargo_program(),
        &["nextest", "run", "--workspace"],
        &seeded,
    )?;
    run_with(&cargo_program(), &["test", "--workspace", "--doc"], &seeded)?;
    crates_alone(&seeded)?;
    no_std_builds()?;
    // The link-time proof that the byte-facing functions cannot panic: this links only if the
    // compiler removed every panic path from them.
    cargo(&[
        "build",
        "--profile",
        "no-panic",
        "-p",
        "chassis-host-tests",
        "--features",
        "no-panic-proof",
        "--bin",
        "no_panic",
    ])?;
    // Every public item documented, every intra-doc link resolved.
    for features in ["--no-default-features", "--all-features"] {
        let doc = ["doc", "-p", "chassis-protocol", "--no-deps", features];
        run_with(&cargo_program(), &doc, &[("RUSTDOCFLAGS", "-D warnings")])?;
    }
    // The published crates package, and each builds from its package alone.
    package::package()?;
    // The protocol crate's public API is the one in its snapshot.
    public_api::public_api(&[])?;
    // (The benchmarks are checked by clippy over every target above; running them is `cargo
    // xtask bench`: timings do not belong in CI.)
    msrv()?;
    python::python()?;
    ros2::ros2()?;
    firmware::test()?;
    fuzz(FuzzRun::Repeatable)
}

/// The formatting of the workspace and of the fuzz targets, and clippy over the workspace and
/// over the protocol crate with every feature.
fn format_and_lints() -> Result<(), String> {
    cargo(&["fmt", "--all", "--check"])?;
    cargo(&[
        "fmt",
        "--check",
        "--manifest-path",
        "host-tests/fuzz/Cargo.toml",
    ])?;
    cargo(&[
        "clippy",
        "--workspace",
        "--all-targets",
        "--",
        "-D",
        "warnings",
    ])?;
    cargo(&[
        "clippy",
        "-p",
        "chassis-protocol",
        "--all-targets",
        "--all-features",
        "--",
        "-D",
        "warnings",
    ])
}

/// The protocol crate built for each Cortex-M target, with no feature, with the logging and
/// serialising ones, and with every feature a board may use.
fn no_std_builds() -> Result<(), String> {
    for target in THUMB_TARGETS {
        for features in ["", "defmt,serde", "driver,nb,async,sim,defmt,serde"] {
            let build = [
                "build",
                "-p",
                "chassis-protocol",
                "--release",
                "--target",
                target,
            ];
            cargo(&[&build[..], &["--features", features]].concat())?;
        }
    }
    Ok(())
}

/// Each published crate tests green on its own, as someone who downloaded it tests it: with
/// its default features, with none, with every feature alone and (where they go together) with
/// all, without the feature unification of the workspace (cargo-hack `--each-feature`). The
/// CLI's integration tests drive its binary and ran with the workspace; alone, it is built
/// and its unit tests run.
fn crates_alone(env: &[(&str, &str)]) -> Result<(), String> {
    install_cargo_tool("hack", "cargo-hack", Some(CARGO_HACK), &[])?;
    let hack = ["hack", "test", "--each-feature"];
    // The comparison of the 2020 parser's short ways with its general judgement on noisy
    // streams (most of the protocol crate's test time in a debug build) uses no feature: the
    // workspace's run above has it.
    let protocol = [
        "-p",
        "chassis-protocol",
        "--",
        "--skip",
        "the_short_ways_decide_as_the_general_judgement_on_noisy_streams",
    ];
    run_with(&cargo_program(), &[&hack[..], &protocol].concat(), env)?;
    run_with(
        &cargo_program(),
        &[&hack[..], &["-p", "chassis-capture"]].concat(),
        env,
    )?;
    // A board picks `blocking` or `async`: the two together do not build.
    let bringup = ["--exclude-all-features", "-p", "chassis-bringup"];
    run_with(&cargo_program(), &[&hack[..], &bringup].concat(), env)?;
    run_with(
        &cargo_program(),
        &[&hack[..], &["-p", "chassis-cli", "--bins"]].concat(),
        env,
    )
}

/// The protocol crate, with every feature, builds with the `rust-version` the workspace
/// declares (one place says it: the root `Cargo.toml`).
fn msrv() -> Result<(), String> {
    let manifest = workspace_root()?.join("Cargo.toml");
    let text = std::fs::read_to_string(&manifest)
        .map_err(|e| format!("cannot read {}: {e}", manifest.display()))?;
    let version = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("rust-version = "))
        .map(|v| v.trim_matches('"').to_string())
        .ok_or("no rust-version in the workspace manifest")?;
    if !rustup_list(&["toolchain", "list"])?
        .iter()
        .any(|l| l.starts_with(&format!("{version}-")) || l.starts_with(&format!("{version}.")))
    {
        run(
            "rustup",
            &["toolchain", "install", &version, "--profile", "minimal"],
        )?;
    }
    // Its own target directory: another compiler's artefacts would only evict the main ones.
    let toolchain = format!("+{version}");
    run(
        "cargo",
        &[
            &toolchain,
            "check",
            "-p",
            "chassis-protocol",
            "--all-features",
            "--target-dir",
            "target/msrv",
        ],
    )
}
