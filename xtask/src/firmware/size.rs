//! `cargo xtask size`: flash and RAM of every board's firmware against its budget, and the
//! protocol crate's share (size probes on the QEMU board).

use super::{BOARDS, FIRMWARE_TARGETS, M4, build_board, elf};
use crate::tools::install_targets;
use std::path::Path;

/// Flash and static RAM of a firmware ELF, from its allocated sections.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sizes {
    /// Code, read-only data and the initial values of `.data`.
    pub flash: u64,
    /// `.data`, `.bss` and `.uninit` (not the stack).
    pub ram: u64,
}

/// Reads the section sizes of `elf`.
pub fn sizes(elf: &Path) -> Result<Sizes, String> {
    use object::{Object, ObjectSection, SectionFlags, SectionKind};
    let data = std::fs::read(elf).map_err(|e| format!("cannot read {}: {e}", elf.display()))?;
    let file =
        object::File::parse(&*data).map_err(|e| format!("{} is no ELF: {e}", elf.display()))?;
    let mut sizes = Sizes::default();
    for section in file.sections() {
        let SectionFlags::Elf { sh_flags } = section.flags() else {
            continue;
        };
        const ALLOC: u64 = object::elf::SHF_ALLOC as u64;
        const WRITE: u64 = object::elf::SHF_WRITE as u64;
        // esp-hal's `.stack` (all the RAM left: not static) and `.rotext_dummy` (a hole that
        // aligns the flash cache's mapping: no memory at all) are address space, not contents.
        if sh_flags & ALLOC == 0 || matches!(section.name(), Ok(".stack" | ".rotext_dummy")) {
            continue;
        }
        match section.kind() {
            SectionKind::UninitializedData | SectionKind::UninitializedTls => {
                sizes.ram += section.size()
            }
            _ if sh_flags & WRITE != 0 => {
                sizes.ram += section.size();
                sizes.flash += section.size();
            }
            _ => sizes.flash += section.size(),
        }
    }
    Ok(sizes)
}

/// The size probes of the QEMU board (`src/bin/size_*.rs`), each the board plus one part.
const PROBES: [&str; 8] = [
    "size_baseline",
    "size_parsers",
    "size_builders",
    "size_protocol",
    "size_driver",
    "size_downlink",
    "size_v1_downlink",
    "size_v1_parsers",
];

/// The firmware's size budgets, in bytes.
pub mod budget {
    /// The whole QEMU bring-up firmware's flash: both generations' bring-up, generation
    /// detection, both drivers and parsers (47 236 B).
    pub const FIRMWARE_FLASH: u64 = 47 * 1024;
    /// The whole QEMU bring-up firmware's RAM (static here; the stack peak is checked by the
    /// end-to-end test, which reads it from the firmware's log).
    pub const FIRMWARE_RAM: u64 = 8 * 1024;
    /// The goal for parsers + builders at opt-level "s" on thumbv7em (stretch: 4 KiB): **not
    /// met** today.
    pub const PROTOCOL_GOAL: u64 = 6 * 1024;
    /// What parsers + builders may not grow past: a regression guard until the goal above is
    /// met, a little above what they measure (12 988 B). Most of it is the 2020 board → master
    /// parser's general judgement, which the noise sweep's and the cold start's figures rest
    /// on; the short ways that take a frame without it cost flash for instructions
    /// (`docs/performance.md`).
    pub const PROTOCOL_CEILING: u64 = 12 * 1024 + 768;
    /// Hardware boards' budgets, by directory: (flash, static RAM), a little above what each
    /// measured when it was added (a regression guard; the ESP32-C3's RAM counts the 3 KiB of
    /// code esp-hal runs from its SRAM).
    pub const BOARDS: [(&str, u64, u64); 3] = [
        ("esp32c3", 70 * 1024, 5 * 1024),
        ("nrf52840", 48 * 1024, 4 * 1024),
        ("stm32-dma", 51 * 1024, 4 * 1024),
    ];
    /// What the v1.0.0 board → master parser may not grow past (`size_v1_downlink` − board): a
    /// regression guard a little above what it measured when it was set (2 424 B).
    pub const V1_DOWNLINK_CEILING: u64 = 2_600;
}

/// Builds the probes and the bring-up firmware, prints the table, returns whether every
/// asserted budget holds.
pub fn size_table() -> Result<bool, String> {
    let probes = probe_sizes()?;
    board_table(&probes)
}

/// Builds every board's bring-up firmware, prints its table and the protocol's share from
/// `probes` ([`probe_sizes`]), returns whether every asserted budget holds.
pub fn board_table(probes: &[Sizes]) -> Result<bool, String> {
    install_targets(&FIRMWARE_TARGETS)?;
    let mut firmware = Vec::new();
    for b in &BOARDS {
        build_board(b, &[], &[])?;
        firmware.push(sizes(&elf(b, b.bin)?)?);
    }
    let fw_ok = print_firmware(&firmware);
    let protocol_ok = print_protocol_share(probes);
    Ok(fw_ok && protocol_ok)
}

/// Builds the size probes on the QEMU board and reads their sizes, in [`PROBES`]' order.
pub fn probe_sizes() -> Result<Vec<Sizes>, String> {
    install_targets(&FIRMWARE_TARGETS)?;
    let board = &BOARDS[0];
    // Probes: no logger, no log, so they measure the protocol and nothing else.
    let mut bins = Vec::new();
    for probe in PROBES {
        bins.push("--bin");
        bins.push(probe);
    }
    let mut args = vec!["--no-default-features"];
    args.extend(bins);
    build_board(board, &args, &[("DEFMT_LOG", "off")])?;
    let mut probe = Vec::new();
    for name in PROBES {
        probe.push(sizes(&elf(board, name)?)?);
    }
    Ok(probe)
}

/// The table of every board's bring-up firmware (`firmware`, in [`BOARDS`]' order) and each
/// against its budget; whether every budget is met.
fn print_firmware(firmware: &[Sizes]) -> bool {
    println!(
        "\nmcu-example's release profile: opt-level \"s\", fat LTO, codegen-units 1; defmt at info"
    );
    println!("\n| bring-up firmware | target | flash | static RAM |");
    println!("|---|---|---|---|");
    for (b, s) in BOARDS.iter().zip(firmware) {
        println!(
            "| {} | {} | {} B | {} B |",
            b.name, b.target, s.flash, s.ram
        );
    }
    let qemu = firmware[0];
    let fw_ok = qemu.flash <= budget::FIRMWARE_FLASH && qemu.ram <= budget::FIRMWARE_RAM;
    println!(
        "\nQEMU firmware against its budget ({} KiB flash, {} KiB RAM; its stack peak is measured \
         in the end-to-end test): {}",
        budget::FIRMWARE_FLASH / 1024,
        budget::FIRMWARE_RAM / 1024,
        met(fw_ok)
    );
    let mut boards_ok = true;
    for (b, s) in BOARDS.iter().zip(firmware) {
        if let Some(&(_, flash, ram)) = budget::BOARDS.iter().find(|(dir, ..)| *dir == b.dir) {
            let ok = s.flash <= flash && s.ram <= ram;
            boards_ok &= ok;
            println!(
                "{} against its budget ({flash} B flash, {ram} B RAM): {}",
                b.name,
                met(ok)
            );
        }
    }
    fw_ok && boards_ok
}

/// The table of the protocol crate's share, from the probes' sizes (`probe`, in [`PROBES`]'
/// order), and the parsers against their goal and ceilings; whether every ceiling holds.
fn print_protocol_share(probe: &[Sizes]) -> bool {
    let base = probe[0].flash;
    let part = |i: usize| probe[i].flash.saturating_sub(base);
    println!(
        "\nThe protocol crate's share, on {M4}: each size probe is the QEMU board plus one part.\n"
    );
    println!("| part of the protocol crate | flash | measured as |");
    println!("|---|---|---|");
    println!("| the board alone (UART, SysTick, vectors) | {base} B | `size_baseline` |");
    println!(
        "| parsers (board → master and master → board) | {} B | `size_parsers` − board |",
        part(1)
    );
    println!(
        "| builders (every master → board frame) | {} B | `size_builders` − board |",
        part(2)
    );
    let protocol = part(3);
    println!("| parsers + builders | {protocol} B | `size_protocol` − board |");
    println!(
        "| blocking driver, with the parser and builders it uses | {} B | `size_driver` − board |",
        part(4)
    );
    println!(
        "| driver alone | {} B | `size_driver` − `size_protocol` |",
        probe[4].flash.saturating_sub(probe[3].flash)
    );
    println!(
        "| board → master parser alone (`DownlinkParser`) | {} B | `size_downlink` − board |",
        part(5)
    );
    let v1_downlink = part(6);
    println!(
        "| v1.0.0 board → master parser (`v1::DownlinkParser`) | {v1_downlink} B | `size_v1_downlink` − board |"
    );
    println!(
        "| v1.0.0 parsers (board → master and master → board) | {} B | `size_v1_parsers` − board |",
        part(7)
    );
    print_ceilings(protocol, v1_downlink)
}

/// Parsers + builders (`protocol` bytes) against their goal and ceiling, and the v1.0.0 board →
/// master parser (`v1_downlink` bytes) against its ceiling; whether both ceilings hold.
fn print_ceilings(protocol: u64, v1_downlink: u64) -> bool {
    let goal = protocol <= budget::PROTOCOL_GOAL;
    let protocol_ok = protocol <= budget::PROTOCOL_CEILING;
    println!(
        "\nparsers + builders: {protocol} B against the 6 KiB goal (stretch 4 KiB): {}; ceiling {} B (regression guard): {}",
        met(goal),
        budget::PROTOCOL_CEILING,
        held(protocol_ok)
    );
    let v1_ok = v1_downlink <= budget::V1_DOWNLINK_CEILING;
    println!(
        "v1.0.0 board → master parser: {v1_downlink} B, ceiling {} B (regression guard): {}",
        budget::V1_DOWNLINK_CEILING,
        held(v1_ok)
    );
    protocol_ok && v1_ok
}

/// A goal or budget in the tables: `met` or `NOT MET`.
pub(super) fn met(ok: bool) -> &'static str {
    if ok { "met" } else { "NOT MET" }
}

/// A ceiling in the tables: `held` or `EXCEEDED`.
pub(super) fn held(ok: bool) -> &'static str {
    if ok { "held" } else { "EXCEEDED" }
}

/// `cargo xtask size`.
pub fn size() -> Result<(), String> {
    if size_table()? {
        Ok(())
    } else {
        Err("a size budget is exceeded (see the table)".into())
    }
}
