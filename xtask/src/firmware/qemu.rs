//! QEMU: `cargo xtask demo` (the bring-up firmware against the simulated chassis) and
//! `cargo xtask qemu ELF` (the QEMU board's cargo runner), and what they need installed.

use super::{BOARDS, M4, build_board, elf};
use crate::cmd::{cargo, cargo_program, check, workspace_root};
use crate::tools::{ensure_apt, install_targets, installed};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// `qemu-system-arm` present, or installed through apt when running as root.
pub(super) fn ensure_qemu() -> Result<(), String> {
    ensure_apt(
        "qemu-system-arm",
        "--version",
        "qemu-system-arm",
        "Debian/Ubuntu: `sudo apt-get install -y qemu-system-arm`; macOS: `brew install qemu`",
    )
}

/// `defmt-print` present, or installed with cargo.
pub(super) fn ensure_defmt_print() -> Result<(), String> {
    if installed("defmt-print", "--version") {
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
