//! Installing what the tasks need when it is missing: rustup targets and toolchains, and cargo's
//! own tools (cargo-fuzz, and cargo-hack and cargo-public-api at pinned versions).

use crate::cmd::{cargo, run, run_with};
use std::process::Command;

/// Adds the rustup targets that are not installed yet.
pub(crate) fn install_targets(targets: &[&str]) -> Result<(), String> {
    let installed = rustup_list(&["target", "list", "--installed"])?;
    let missing: Vec<&str> = targets
        .iter()
        .copied()
        .filter(|t| !installed.iter().any(|line| line.trim() == *t))
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    run("rustup", &[&["target", "add"][..], &missing].concat())
}

/// The lines `rustup <args>` prints.
pub(crate) fn rustup_list(args: &[&str]) -> Result<Vec<String>, String> {
    let output = Command::new("rustup")
        .args(args)
        .output()
        .map_err(|e| format!("rustup is needed (rustup {}): {e}", args.join(" ")))?;
    Ok(String::from_utf8_lossy(&output.stdout)
        .lines()
        .map(str::to_string)
        .collect())
}

/// Installs the nightly toolchain (minimal profile) if it is missing: cargo-fuzz needs it.
pub(crate) fn install_nightly() -> Result<(), String> {
    if rustup_list(&["toolchain", "list"])?
        .iter()
        .any(|l| l.starts_with("nightly"))
    {
        return Ok(());
    }
    run(
        "rustup",
        &["toolchain", "install", "nightly", "--profile", "minimal"],
    )
}

/// Installs the cargo subcommand `cargo <command>` from the crate `krate` (`cargo install
/// --locked`, then `extra`) unless it runs: at `version` when one is given, unless
/// `cargo <command> --version` names that version.
pub(crate) fn install_cargo_tool(
    command: &str,
    krate: &str,
    version: Option<&str>,
    extra: &[&str],
) -> Result<(), String> {
    let present = Command::new("cargo")
        .args([command, "--version"])
        .output()
        .is_ok_and(|o| {
            o.status.success()
                && version.is_none_or(|version| {
                    String::from_utf8_lossy(&o.stdout)
                        .split_whitespace()
                        .any(|word| word == version)
                })
        });
    if present {
        return Ok(());
    }
    let mut args = vec!["install", "--locked"];
    args.extend_from_slice(extra);
    args.push(krate);
    if let Some(version) = version {
        args.extend(["--version", version]);
    }
    cargo(&args)
}

/// Whether `program <version_flag>` runs.
pub(crate) fn installed(program: &str, version_flag: &str) -> bool {
    Command::new(program)
        .arg(version_flag)
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `program` present (`program <version_flag>` runs), or the Debian package `package` installed
/// through apt when running as root; else an error that says how (`how`).
pub(crate) fn ensure_apt(
    program: &str,
    version_flag: &str,
    package: &str,
    how: &str,
) -> Result<(), String> {
    if installed(program, version_flag) {
        return Ok(());
    }
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !root {
        return Err(format!(
            "{program} is missing: install it ({how}) and run this again"
        ));
    }
    run_with("apt-get", &["update", "-qq"], &[])?;
    run_with(
        "apt-get",
        &["install", "-y", "-qq", package],
        &[("DEBIAN_FRONTEND", "noninteractive")],
    )
}
