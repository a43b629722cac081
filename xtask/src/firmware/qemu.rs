//! QEMU: `cargo xtask demo` (the bring-up firmware against the simulated chassis) and
//! `cargo xtask qemu ELF` (the QEMU board's cargo runner), and what they need installed.

use super::{BOARDS, M4, build_board, elf};
use crate::cmd::{cargo, cargo_program, check, run_with, workspace_root};
use crate::tools::install_targets;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// Whether `program --version` runs.
fn installed(program: &str) -> bool {
    Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `qemu-system-arm` present, or installed through apt when running as root.
pub(super) fn ensure_qemu() -> Result<(), String> {
    if installed("qemu-system-arm") {
        return Ok(());
    }
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !root {
        return Err(
            "qemu-system-arm is missing: install it (Debian/Ubuntu: `sudo apt-get install -y \
             qemu-system-arm`; macOS: `brew install qemu`) and run this again"
                .to_string(),
        );
    }
    run_with("apt-get", &["update", "-qq"], &[])?;
    run_with(
        "apt-get",
        &["install", "-y", "-qq", "qemu-system-arm"],
        &[("DEBIAN_FRONTEND", "noninteractive")],
    )
}

/// `defmt-print` present, or installed with cargo.
pub(super) fn ensure_defmt_print() -> Result<(), String> {
    if installed("defmt-print") {
        return Ok(());
    }
    cargo(&["install", "--locked", "defmt-print"])
}

/// Cargo's arguments that name the QEMU harness binary, after `build` or `run`.
const HARNESS: [&str; 6] = [
    "--release",
    "--quiet",
    "-p",
    "chassis-host-tests",
    "--bin",
    "qemu-bringup",
];

/// Boots `elf` in QEMU against the simulated chassis, through the `qemu-bringup` harness.
fn boot(elf: &Path, args: &[&str]) -> Result<(), String> {
    ensure_qemu()?;
    ensure_defmt_print()?;
    let elf = elf.to_string_lossy().into_owned();
    check(
        Command::new(cargo_program())
            .arg("run")
            .args(HARNESS)
            .args(["--", &elf])
            .args(args)
            .current_dir(workspace_root()?),
        "cargo",
        |status| format!("the bring-up did not pass ({status})"),
    )
}

/// `cargo xtask demo`: the bring-up firmware in QEMU against the simulated chassis.
pub fn demo() -> Result<(), String> {
    let start = Instant::now();
    install_targets(&[M4])?;
    ensure_qemu()?;
    ensure_defmt_print()?;
    let board = &BOARDS[0];
    build_board(board, &[], &[])?;
    // The harness, built before the clock of the run starts.
    cargo(&[&["build"][..], &HARNESS[..]].concat())?;
    eprintln!(
        "built in {:.0} s; booting the firmware\n",
        start.elapsed().as_secs_f64()
    );
    let result = boot(&elf(board, board.bin)?, &[]);
    eprintln!(
        "cargo xtask demo: {:.0} s in all",
        start.elapsed().as_secs_f64()
    );
    result
}

/// `cargo xtask qemu ELF [--scenario NAME]`: the QEMU board's cargo runner.
pub fn qemu(args: &[String]) -> Result<(), String> {
    let Some((elf, rest)) = args.split_first() else {
        return Err("usage: cargo xtask qemu FIRMWARE.elf [--scenario NAME] [--seed N]".into());
    };
    let rest: Vec<&str> = rest.iter().map(String::as_str).collect();
    boot(Path::new(elf), &rest)
}
