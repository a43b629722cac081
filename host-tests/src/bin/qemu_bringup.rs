//! Boots a bring-up firmware in QEMU against the simulated chassis and shows what happens: the
//! firmware's defmt log (decoded by `defmt-print`), a live line of what the chassis sees, and a
//! verdict. Exits with the firmware's exit code. What `cargo xtask demo` and the QEMU board's
//! `cargo run` runner call.
//!
//! ```text
//! qemu-bringup FIRMWARE.elf [--scenario normal|noisy|silent|no-replies] [--seed N]
//! ```

use chassis_host_tests::qemu::{self, Emulator, Progress, Scenario};
use chassis_protocol::sim::Faults;
use chassis_protocol::{Command, Setting};
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command as Process, ExitCode, Stdio};

fn main() -> ExitCode {
    match run() {
        Ok(code) => code,
        Err(message) => {
            eprintln!("qemu-bringup: {message}");
            ExitCode::from(2)
        }
    }
}

fn scenario(name: &str, seed: u64) -> Result<Scenario, String> {
    let mut scenario = Scenario {
        seed,
        ..Scenario::default()
    };
    match name {
        "normal" => {}
        "noisy" => {
            scenario.faults = Faults {
                drop_per_million: 333,
                corrupt_per_million: 334,
                insert_per_million: 333,
                ..Faults::default()
            }
        }
        "silent" => scenario.silent_after_motion_ms = Some(200),
        "no-replies" => {
            scenario.faults = Faults {
                replies_stopped: true,
                ..Faults::default()
            }
        }
        other => {
            return Err(format!(
                "unknown scenario {other:?} (normal, noisy, silent, no-replies)"
            ));
        }
    }
    Ok(scenario)
}

fn run() -> Result<ExitCode, String> {
    let mut args = std::env::args().skip(1);
    let mut elf = None;
    let mut name = String::from("normal");
    let mut seed = 1u64;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--scenario" => name = args.next().ok_or("--scenario needs a name")?,
            "--seed" => {
                seed = args
                    .next()
                    .and_then(|s| s.parse().ok())
                    .ok_or("--seed needs a number")?
            }
            _ if elf.is_none() => elf = Some(PathBuf::from(arg)),
            other => return Err(format!("unexpected argument {other:?}")),
        }
    }
    let elf = elf.ok_or("usage: qemu-bringup FIRMWARE.elf [--scenario NAME] [--seed N]")?;
    if !elf.is_file() {
        return Err(format!("no firmware at {}", elf.display()));
    }
    let scenario = scenario(&name, seed)?;

    // The log goes through defmt-print, which needs the ELF for its strings.
    let mut decoder = Process::new("defmt-print")
        .arg("-e")
        .arg(&elf)
        .args(["--log-format", "{t:>6} {L:<5} {s}"])
        .stdin(Stdio::piped())
        .spawn()
        .map_err(|e| {
            format!("cannot start defmt-print ({e}); `cargo install --locked defmt-print`")
        })?;
    let mut to_decoder = decoder.stdin.take();

    eprintln!(
        "chassis: simulated board on a loopback TCP port; QEMU mps2-an386 boots the firmware"
    );
    let emulator = Emulator::mps2_an386();
    let mut last_line = 0u64;
    let result = qemu::run(
        &emulator,
        &elf,
        &scenario,
        |bytes| {
            if let Some(pipe) = to_decoder.as_mut() {
                let _ = pipe.write_all(bytes);
                let _ = pipe.flush();
            }
        },
        |p: Progress<'_>| {
            if p.now_ms >= last_line + 1_000 {
                last_line = p.now_ms;
                eprintln!("{}", live_line(&p));
            }
        },
    );
    drop(to_decoder);
    let _ = decoder.wait();
    let run = result.map_err(|e| e.to_string())?;

    if let Ok(path) = std::env::var("CHASSIS_DUMP_DOWNLINK") {
        let mut text = String::new();
        for (t, bytes) in &run.downlink {
            text.push_str(&format!("{t}"));
            for b in bytes {
                text.push_str(&format!(" {b:02X}"));
            }
            text.push('\n');
        }
        std::fs::write(&path, text).map_err(|e| format!("{path}: {e}"))?;
    }
    let reads = run
        .sent
        .iter()
        .filter(|s| matches!(s.command, Command::Setting(Setting::Read(_))))
        .count();
    let turns = run
        .sent
        .iter()
        .filter(|s| matches!(s.command, Command::Turn(_)))
        .count();
    let stops = run
        .sent
        .iter()
        .filter(|s| matches!(s.command, Command::Velocity(v) if v.x == 0 && v.y == 0 && v.z == 0))
        .count();
    let code = run.exit_code();
    println!();
    println!("──────────────────────────────── verdict ────────────────────────────────");
    println!(
        " firmware   {} on QEMU mps2-an386 (Cortex-M4)",
        elf.file_name().map_or_else(
            || elf.display().to_string(),
            |n| n.to_string_lossy().into_owned()
        )
    );
    println!(" scenario   {name}");
    println!(
        " run        {:.1} s wall; the chassis received {} frames: {} register reads, {} turn(s), {} stop(s)",
        run.elapsed.as_secs_f64(),
        run.sent.len(),
        reads,
        turns,
        stops
    );
    println!(
        " chassis    turned {:.1}° in all, pending {:.1}°, {} frames dropped on its line",
        run.board.total_turn_commanded() as f64 / 10.0,
        f64::from(run.board.pending_deci_degrees()) / 10.0,
        run.board.dropped_frames()
    );
    println!(" checks     {}", checklist(code));
    let verdict = match code {
        Some(0) => "PASS: every bring-up check passed".to_string(),
        Some(c) => format!("FAIL: exit code {c} ({})", check_name(c)),
        None => format!(
            "FAIL: no exit within {} s (killed)",
            emulator.limit.as_secs()
        ),
    };
    println!(" verdict    {verdict}");
    println!("─────────────────────────────────────────────────────────────────────────");
    Ok(match code {
        Some(c) => ExitCode::from(u8::try_from(c).unwrap_or(1)),
        None => ExitCode::from(124),
    })
}

fn live_line(p: &Progress<'_>) -> String {
    let motion = p.board.motion();
    format!(
        "  [chassis t={:>5.1}s] {} frames in, last {:<24} motion {:?}, pending {:.1}°",
        p.now_ms as f64 / 1000.0,
        p.sent,
        p.last.map_or("-".to_string(), |s| describe(&s.command)),
        motion,
        f64::from(p.board.pending_deci_degrees()) / 10.0,
    )
}

fn describe(command: &Command) -> String {
    match command {
        Command::Velocity(v) => format!("velocity({}, {}, {})", v.x, v.y, v.z),
        Command::Turn(t) => format!("turn({:?})", t),
        Command::Motors(_) => "motors".to_string(),
        Command::Setting(Setting::Read(r)) => format!("read {r:?}"),
        Command::Setting(Setting::Write(w)) => format!("write {:?}", w.register()),
        Command::Setting(s) => format!("{s:?}"),
    }
}

/// The bring-up's checks in order, with the exit code each fails with
/// (`chassis_bringup::Check::exit_code`).
const CHECKS: [(&str, i32); 9] = [
    ("link", 10),
    ("settings", 11),
    ("drive type", 12),
    ("forward", 13),
    ("strafe", 14),
    ("turn", 15),
    ("stop", 16),
    ("battery", 17),
    ("control loop", 18),
];

/// Each check marked passed (✓), failed (✗) or not run (·).
fn checklist(code: Option<i32>) -> String {
    CHECKS
        .iter()
        .map(|(name, fails_with)| {
            let mark = match code {
                Some(0) => "✓",
                Some(c) if c == *fails_with => "✗",
                Some(c) if (10..=18).contains(&c) && *fails_with < c => "✓",
                _ => "·",
            };
            format!("{mark} {name}")
        })
        .collect::<Vec<_>>()
        .join("  ")
}

/// The check a firmware exit code names (the same table as the checklist).
fn check_name(code: i32) -> &'static str {
    match CHECKS.iter().find(|(_, fails_with)| *fails_with == code) {
        Some((name, _)) => name,
        None if code == 101 => "the firmware panicked",
        None => "unknown",
    }
}
