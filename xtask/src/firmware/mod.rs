//! The firmware tasks: `demo` (the bring-up in QEMU), `qemu ELF` (the QEMU board's cargo
//! runner), `size`, `icount` (and `icount --profile`), and the firmware half of `test` (every
//! board built, the firmware's no-panic proof, the size budgets, the end-to-end tests in QEMU).
//! Here: the boards and how one is built; [`mod@qemu`] boots a firmware in QEMU, [`mod@size`],
//! [`mod@icount`] and [`mod@profile`] measure it.

mod icount;
mod profile;
mod qemu;
mod size;

pub use icount::icount;
pub use profile::profile;
pub use qemu::{demo, qemu};
pub use size::size;

use crate::cmd::{cargo, cargo_program, check, run_with, workspace_root};
use crate::tools::install_targets;
use qemu::{ensure_defmt_print, ensure_qemu};
use std::path::PathBuf;
use std::process::Command;

/// Cortex-M4F: the QEMU board and the STM32F411.
pub(crate) const M4: &str = "thumbv7em-none-eabihf";
/// Cortex-M0+: the RP2040.
pub(crate) const M0: &str = "thumbv6m-none-eabi";
/// RISC-V RV32IMC: the ESP32-C3.
const RV32: &str = "riscv32imc-unknown-none-elf";
/// Every target a board is built for.
pub(crate) const FIRMWARE_TARGETS: [&str; 3] = [M4, M0, RV32];

/// A board: its directory under `mcu-example/boards`, its target, its binaries.
#[derive(Clone, Copy)]
pub struct Board {
    /// Directory under `mcu-example/boards`.
    pub dir: &'static str,
    /// What it is, for the tables.
    pub name: &'static str,
    /// Its rustup target.
    pub target: &'static str,
    /// The bring-up binary.
    pub bin: &'static str,
}

/// Every board the firmware is built for; the first runs in QEMU.
pub const BOARDS: [Board; 7] = [
    Board {
        dir: "qemu-an386",
        name: "QEMU mps2-an386 (Cortex-M4), blocking driver",
        target: M4,
        bin: "bringup-qemu-an386",
    },
    Board {
        dir: "stm32f411",
        name: "STM32F411 (Cortex-M4F), embassy, async driver",
        target: M4,
        bin: "bringup-stm32f411",
    },
    Board {
        dir: "rp2040",
        name: "RP2040 (Cortex-M0+), embassy, async driver",
        target: M0,
        bin: "bringup-rp2040",
    },
    Board {
        dir: "rp2040-blocking",
        name: "RP2040 (Cortex-M0+), rp2040-hal, nb + blocking driver",
        target: M0,
        bin: "bringup-rp2040-blocking",
    },
    Board {
        dir: "esp32c3",
        name: "ESP32-C3 (RISC-V), esp-hal, blocking driver",
        target: RV32,
        bin: "bringup-esp32c3",
    },
    Board {
        dir: "nrf52840",
        name: "nRF52840 (Cortex-M4F), embassy, async driver",
        target: M4,
        bin: "bringup-nrf52840",
    },
    Board {
        dir: "stm32-dma",
        name: "STM32F411 (Cortex-M4F), embassy, DMA ring into the driver core",
        target: M4,
        bin: "bringup-stm32-dma",
    },
];

/// A board's directory.
fn board_dir(board: &Board) -> Result<PathBuf, String> {
    Ok(workspace_root()?
        .join("mcu-example")
        .join("boards")
        .join(board.dir))
}

/// The firmware workspace's target directory.
fn firmware_target_dir() -> Result<PathBuf, String> {
    Ok(workspace_root()?.join("mcu-example").join("target"))
}

/// Builds `board` (release) from its own directory, so that its `.cargo/config.toml` applies;
/// `extra` adds cargo arguments (features, binaries).
pub(crate) fn build_board(
    board: &Board,
    extra: &[&str],
    env: &[(&str, &str)],
) -> Result<(), String> {
    let dir = board_dir(board)?;
    let mut args = vec!["build", "--release"];
    args.extend_from_slice(extra);
    eprintln!(
        "$ (cd mcu-example/boards/{}) cargo {}",
        board.dir,
        args.join(" ")
    );
    check(
        Command::new(cargo_program())
            .args(&args)
            .envs(env.iter().copied())
            .current_dir(&dir),
        "cargo",
        |status| format!("building the {} firmware failed ({status})", board.name),
    )
}

/// Where a board's release binary lands.
pub(crate) fn elf(board: &Board, bin: &str) -> Result<PathBuf, String> {
    Ok(firmware_target_dir()?
        .join(board.target)
        .join("release")
        .join(bin))
}

/// The firmware half of `cargo xtask test`. Whatever builds with logging compiled out (the size
/// probes, the no-panic proof, the instruction counts) builds first, then the boards with their
/// log: `DEFMT_LOG` is read by a proc macro every target shares, so each change of it rebuilds
/// every crate that logs, on every target.
pub fn test() -> Result<(), String> {
    install_targets(&FIRMWARE_TARGETS)?;
    ensure_qemu()?;
    ensure_defmt_print()?;
    let root = workspace_root()?;
    let manifest = root.join("mcu-example").join("Cargo.toml");
    let manifest = manifest.to_string_lossy().into_owned();
    cargo(&["fmt", "--all", "--check", "--manifest-path", &manifest])?;
    let probes = size::probe_sizes()?;
    no_panic_proof()?;
    // The instructions per byte on the emulated cores.
    icount()?;
    // Every board built, and the size budgets.
    if !size::board_table(&probes)? {
        return Err("a size budget is exceeded (see the table)".into());
    }
    clippy()?;
    end_to_end()
}

/// The no-panic proof, on the QEMU firmware: with logging compiled out (defmt-semihosting
/// exports a logger with a reentrancy panic of its own), it links only if no panicking path is
/// left in the bring-up, the driver, the parsers, the UART and the clock. (The hardware boards
/// keep panic-probe for their HAL's start-up.) Built as the size probes are (no default
/// feature, no log), beside them: only the board's own crate is built again. Its firmware
/// takes the bring-up's place until the boards are built after it.
fn no_panic_proof() -> Result<(), String> {
    let board = &BOARDS[0];
    build_board(
        board,
        &["--no-default-features", "--features", "no-panic-proof"],
        &[("DEFMT_LOG", "off")],
    )?;
    eprintln!("no-panic proof: the {} firmware links", board.name);
    Ok(())
}

/// Clippy on the firmware, for its target.
fn clippy() -> Result<(), String> {
    for board in &BOARDS {
        let dir = board_dir(board)?;
        check(
            Command::new(cargo_program())
                .args(["clippy", "--release", "--", "-D", "warnings"])
                .current_dir(&dir),
            "cargo clippy",
            |_| format!("clippy on the {} firmware failed", board.name),
        )?;
    }
    Ok(())
}

/// The end-to-end tests: the QEMU firmware against the simulated chassis, one at a time (an
/// emulator spins a core; two of them and their simulators on a 2-core machine starve each
/// other into silences the failsafe rightly takes for a dead board).
fn end_to_end() -> Result<(), String> {
    let firmware = elf(&BOARDS[0], BOARDS[0].bin)?;
    let firmware = firmware.to_string_lossy().into_owned();
    run_with(
        &cargo_program(),
        &[
            "test",
            "-p",
            "chassis-host-tests",
            "--test",
            "qemu",
            "--",
            "--ignored",
            "--test-threads=1",
        ],
        &[("CHASSIS_FIRMWARE", &firmware)],
    )
}
