//! `cargo xtask icount --profile`: where the 2020 parser's instructions go on the Cortex-M4's
//! and the Cortex-M0's telemetry mix, by function and by byte, and the costliest bytes.
//!
//! The instruction-count binary runs in QEMU with every translated block's instructions and
//! every block executed logged (`-d in_asm,exec,nochain`). The run's SysTick reads
//! (`time::cycles`) cut it into its measurements; the first one through the byte path
//! (`icount::parse_all`) is the telemetry mix through `push`, the figure `cargo xtask icount`
//! prints, the second the random bytes. Each block's instructions are charged to the function
//! holding its first address (the ELF's symbols), and to the byte being fed: a byte starts
//! where `parse_all`'s loop comes back to its head.

use super::icount::{ICOUNT_MACHINES, IcountMachine};
use super::qemu::ensure_qemu;
use super::{BOARDS, Board, M0, M4, build_board, elf, firmware_target_dir};
use crate::tools::install_targets;
use object::{Object, ObjectSymbol, SymbolKind};
use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

/// The parser's loop over the mix, and the clock read that starts and ends a measurement.
const LOOP: &str = "parse_all";
const CLOCK: &str = "cycles";

/// `cargo xtask icount --profile`.
pub fn profile() -> Result<(), String> {
    install_targets(&[M4, M0])?;
    ensure_qemu()?;
    for machine in &ICOUNT_MACHINES {
        profile_on(machine)?;
    }
    Ok(())
}

/// The profile on one emulated core.
fn profile_on(machine: &IcountMachine) -> Result<(), String> {
    let board = Board {
        target: machine.target,
        ..BOARDS[0]
    };
    build_board(
        &board,
        &[
            "--no-default-features",
            "--bin",
            "icount",
            "--target",
            machine.target,
        ],
        &[("DEFMT_LOG", "off")],
    )?;
    let elf_path = elf(&board, "icount")?;
    let log = firmware_target_dir()?.join(format!("icount-profile-{}.log", machine.target));
    run_logged(machine, &elf_path, &log)?;
    let data = std::fs::read(&elf_path).map_err(|e| format!("{}: {e}", elf_path.display()))?;
    let functions = Functions::read(&data)?;
    let text = std::fs::read_to_string(&log).map_err(|e| format!("{}: {e}", log.display()))?;
    let (sizes, trace) = blocks(&text);
    let mut phases = byte_path_phases(&trace, &functions);
    let (Some(mix), Some(random)) = (phases.next(), phases.next()) else {
        return Err("no measurement through the byte path in the log".to_string());
    };
    let core = if machine.target == M4 {
        "Cortex-M4"
    } else {
        "Cortex-M0"
    };
    println!(
        "
## {core}
"
    );
    report(core, mix, &sizes, &functions);
    let cost = |pc: &u64| sizes.get(pc).copied().unwrap_or(0);
    let random = per_byte(random, &cost, &functions);
    let total: u64 = random.iter().sum();
    println!(
        "
random bytes through `push`: {} bytes, {:.1} instructions a byte; the costliest: {}",
        random.len(),
        total as f64 / random.len().max(1) as f64,
        costliest(&random)
    );
    Ok(())
}

/// Runs `elf` on `machine` in QEMU, every translated block and every block executed logged to
/// `log`.
fn run_logged(machine: &IcountMachine, elf: &Path, log: &Path) -> Result<(), String> {
    let status = Command::new("qemu-system-arm")
        .args(machine.qemu)
        .args(["-display", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-icount", "shift=0", "-d", "in_asm,exec,nochain", "-D"])
        .arg(log)
        .arg("-kernel")
        .arg(elf)
        .stdout(std::process::Stdio::null())
        .status()
        .map_err(|e| format!("could not start qemu-system-arm: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("the profiled run failed ({status})"))
    }
}

/// The firmware's functions: (start, end, name), sorted.
struct Functions(Vec<(u64, u64, String)>);

impl Functions {
    fn read(data: &[u8]) -> Result<Self, String> {
        let file = object::File::parse(data).map_err(|e| format!("the ELF: {e}"))?;
        let mut all: Vec<(u64, u64, String)> = file
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
            .filter_map(|s| {
                let name = demangle(s.name().ok()?);
                let start = s.address() & !1;
                Some((start, start.saturating_add(s.size()), name))
            })
            .collect();
        all.sort();
        Ok(Functions(all))
    }

    /// The function holding `pc`.
    fn of(&self, pc: u64) -> Option<&str> {
        let i = self.0.partition_point(|(start, _, _)| *start <= pc);
        let (start, end, name) = self.0.get(i.checked_sub(1)?)?;
        (*start <= pc && pc < *end).then_some(name.as_str())
    }

    /// Whether `pc` is in a function whose name contains `part`.
    fn is_in(&self, pc: u64, part: &str) -> bool {
        self.of(pc).is_some_and(|name| name.contains(part))
    }
}

/// A legacy-mangled Rust name's path without its hash (`a::b::c`), the name itself otherwise.
fn demangle(mangled: &str) -> String {
    let Some(mut rest) = mangled
        .strip_prefix("_ZN")
        .and_then(|r| r.strip_suffix('E'))
    else {
        return mangled.to_string();
    };
    let mut parts = Vec::new();
    while let Some(digits) = rest.find(|c: char| !c.is_ascii_digit()).filter(|n| *n > 0) {
        let Ok(len) = rest[..digits].parse::<usize>() else {
            break;
        };
        let Some(part) = rest.get(digits..digits + len) else {
            break;
        };
        if !(part.starts_with('h') && part.len() == 17) {
            parts.push(
                part.trim_start_matches('_')
                    .replace("$LT$", "<")
                    .replace("$GT$", ">")
                    .replace("$u20$", " ")
                    .replace("..", "::"),
            );
        }
        rest = &rest[digits + len..];
    }
    parts.join("::")
}

/// From QEMU's log: each translated block's instruction count by its address, and the
/// addresses of the blocks executed, in order.
fn blocks(log: &str) -> (HashMap<u64, u64>, Vec<u64>) {
    let (mut sizes, mut trace) = (HashMap::new(), Vec::new());
    let mut current: Option<u64> = None;
    for line in log.lines() {
        if line.starts_with("IN:") {
            current = None;
        } else if let Some(pc) = line
            .strip_prefix("0x")
            .and_then(|l| l.split(':').next())
            .and_then(|a| u64::from_str_radix(a, 16).ok())
        {
            let start = *current.get_or_insert(pc);
            *sizes.entry(start).or_insert(0) += 1;
        } else if line.starts_with("Trace") {
            // "Trace 0: 0x… [00000000/0000abcd/…] …": the block's address is the second field.
            if let Some(pc) = line
                .split('[')
                .nth(1)
                .and_then(|f| f.split('/').nth(1))
                .and_then(|a| u64::from_str_radix(a, 16).ok())
            {
                trace.push(pc);
            }
        }
    }
    (sizes, trace)
}

/// The blocks executed during each measurement through the byte path, in order: the telemetry
/// mix, then the random bytes.
fn byte_path_phases<'t>(
    trace: &'t [u64],
    functions: &'t Functions,
) -> impl Iterator<Item = &'t [u64]> + 't {
    trace
        .split(|pc| functions.is_in(*pc, CLOCK))
        .filter(|phase| phase.iter().any(|pc| functions.is_in(*pc, LOOP)))
}

/// Prints the mix's instructions by function, then by byte.
fn report(core: &str, mix: &[u64], sizes: &HashMap<u64, u64>, functions: &Functions) {
    let cost = |pc: &u64| sizes.get(pc).copied().unwrap_or(0);
    let total: u64 = mix.iter().map(cost).sum();
    let mut by_function: HashMap<&str, u64> = HashMap::new();
    for pc in mix {
        *by_function
            .entry(functions.of(*pc).unwrap_or("?"))
            .or_default() += cost(pc);
    }
    let mut rows: Vec<_> = by_function.into_iter().collect();
    rows.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    println!("the telemetry mix through `push` on the {core}: {total} instructions\n");
    println!("| function | instructions | share |\n|---|---|---|");
    for (name, n) in rows.iter().take(16) {
        println!(
            "| `{name}` | {n} | {:.1} % |",
            *n as f64 * 100.0 / total as f64
        );
    }
    let bytes = per_byte(mix, &cost, functions);
    report_bytes(&bytes);
    println!("\nthe costliest bytes of the mix: {}", costliest(&bytes));
}

/// The three costliest bytes: their instructions and where they are.
fn costliest(bytes: &[u64]) -> String {
    let mut order: Vec<usize> = (0..bytes.len()).collect();
    order.sort_by_key(|i| std::cmp::Reverse(bytes[*i]));
    order
        .iter()
        .take(3)
        .map(|i| format!("{} instructions (byte {i})", bytes[*i]))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Each byte's instructions: a byte starts where the loop comes back to its head (its most
/// executed block).
fn per_byte(mix: &[u64], cost: &dyn Fn(&u64) -> u64, functions: &Functions) -> Vec<u64> {
    let mut in_loop: HashMap<u64, u64> = HashMap::new();
    for pc in mix.iter().filter(|pc| functions.is_in(**pc, LOOP)) {
        *in_loop.entry(*pc).or_default() += 1;
    }
    let head = in_loop
        .into_iter()
        .max_by_key(|(pc, n)| (*n, *pc))
        .map(|(pc, _)| pc);
    // (What runs before the loop's head is first reached is the parser's setup: not a byte.)
    let mut bytes: Vec<u64> = Vec::new();
    for pc in mix {
        if Some(*pc) == head {
            bytes.push(0);
        }
        if let Some(last) = bytes.last_mut() {
            *last += cost(pc);
        }
    }
    bytes
}

/// Prints the bytes by what each cost, then by 512-byte stretch.
fn report_bytes(bytes: &[u64]) {
    println!(
        "\n{} bytes; each byte's instructions (the harness's loop included), by what they cost:\n",
        bytes.len()
    );
    println!("| instructions for the byte | bytes | instructions in all |\n|---|---|---|");
    for (low, high) in [(0, 29), (30, 119), (120, 299), (300, u64::MAX)] {
        let class: Vec<u64> = bytes
            .iter()
            .copied()
            .filter(|c| (low..=high).contains(c))
            .collect();
        let range = if high == u64::MAX {
            format!("{low} or more")
        } else {
            format!("{low}–{high}")
        };
        println!(
            "| {range} | {} | {} |",
            class.len(),
            class.iter().sum::<u64>()
        );
    }
    println!("\nby 512-byte stretch of the mix (the first holds the cold start):\n");
    println!("| bytes | instructions | a byte |\n|---|---|---|");
    for (i, chunk) in bytes.chunks(512).enumerate() {
        let sum: u64 = chunk.iter().sum();
        println!(
            "| {}–{} | {sum} | {:.1} |",
            i * 512,
            i * 512 + chunk.len() - 1,
            sum as f64 / chunk.len() as f64
        );
    }
}
