//! Boots a bring-up firmware in QEMU against the simulated chassis and shows what happens: the
//! firmware's defmt log (decoded by `defmt-print`), a live line of what the chassis sees, and a
//! verdict. Exits with the firmware's exit code. What `cargo xtask demo` and the QEMU board's
//! `cargo run` runner call.
//!
//! ```text
//! qemu-bringup FIRMWARE.elf [--firmware 2020|v1.0.0] [--scenario normal|noisy|silent|no-replies] [--seed N]
//! ```
//!
//! `--firmware` is the simulated board's generation (2020 by default); the firmware detects it
//! by itself and runs that generation's bring-up.

use chassis_host_tests::qemu::{self, Emulator, Progress, Run, Scenario, Served};
use chassis_protocol::sim::{Board, Faults, v1};
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

/// What the verdict says of each simulated board.
trait Shown: Served {
    /// The generation's name.
    const NAME: &'static str;
    /// Whether its bring-up has a drive-type check.
    const DRIVE_TYPE: bool;
    /// A line of what the chassis sees now.
    fn live(p: &Progress<'_, Self>) -> String;
    /// What the chassis received and did, in the verdict's lines.
    fn summary(run: &Run<Self>) -> Vec<String>;
}

impl Shown for Board {
    const NAME: &'static str = "2020";
    const DRIVE_TYPE: bool = true;
    fn live(p: &Progress<'_, Self>) -> String {
        live_line(p)
    }
    fn summary(run: &Run<Self>) -> Vec<String> {
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
            .filter(
                |s| matches!(s.command, Command::Velocity(v) if v.x == 0 && v.y == 0 && v.z == 0),
            )
            .count();
        vec![
            format!(
                " run        {:.1} s wall; the chassis received {} frames: {} register reads, {} turn(s), {} stop(s)",
                run.elapsed.as_secs_f64(),
                run.sent.len(),
                reads,
                turns,
                stops
            ),
            format!(
                " chassis    turned {:.1}° in all, pending {:.1}°, {} frames dropped on its line",
                run.board.total_turn_commanded() as f64 / 10.0,
                f64::from(run.board.pending_deci_degrees()) / 10.0,
                run.board.dropped_frames()
            ),
        ]
    }
}

impl Shown for v1::Board {
    const NAME: &'static str = "v1.0.0";
    const DRIVE_TYPE: bool = false;
    fn live(p: &Progress<'_, Self>) -> String {
        let [vx, vy, wz] = p.board.measured_velocity();
        format!(
            "  [chassis t={:>5.1}s] {} frames in, last {:<24} velocity ({vx}, {vy}) mm/s, {wz} mrad/s, yaw {:.1}°",
            p.now_ms as f64 / 1000.0,
            p.sent,
            p.last.map_or("-".to_string(), |s| describe_v1(&s.command)),
            (p.board.yaw_urad() as f64 / 1e6).to_degrees(),
        )
    }
    fn summary(run: &Run<Self>) -> Vec<String> {
        let b = &run.board;
        let readbacks: u32 = [0x33, 0x34, 0x35, 0x36, 0x50]
            .iter()
            .map(|c| b.received_count(*c))
            .sum();
        let settings: u32 = [0x23, 0x24, 0x40]
            .iter()
            .map(|c| b.received_count(*c))
            .sum();
        vec![
            format!(
                " run        {:.1} s wall; the chassis received {} frames: {} readbacks, {} settings frames, {} forced stop(s)",
                run.elapsed.as_secs_f64(),
                run.sent.len(),
                readbacks,
                settings,
                b.forced_stops()
            ),
            format!(
                " chassis    left at {}, yaw {:.1}°, {} telemetry frames sent, {} dropped while commanded",
                describe_v1(&chassis_protocol::v1::Command::BodyVelocity(b.velocity())),
                (b.yaw_urad() as f64 / 1e6).to_degrees(),
                b.telemetry_sent(),
                b.telemetry_dropped()
            ),
        ]
    }
}

fn describe_v1(command: &chassis_protocol::v1::Command) -> String {
    use chassis_protocol::v1::Command as V1;
    match command {
        V1::BodyVelocity(v) if v.is_forced_stop() => "forced stop".to_string(),
        V1::BodyVelocity(v) => format!("velocity({}, {}, {})", v.vx_mm_s, v.vy_mm_s, v.wz_mrad_s),
        V1::MotorVelocity(_) => "motors".to_string(),
        V1::Readback(r) => format!("readback {r:?}"),
        other => format!("settings {:#04x}", other.code()),
    }
}

fn run() -> Result<ExitCode, String> {
    let mut args = std::env::args().skip(1);
    let mut elf = None;
    let mut name = String::from("normal");
    let mut seed = 1u64;
    let mut generation = String::from("2020");
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--scenario" => name = args.next().ok_or("--scenario needs a name")?,
            "--firmware" => generation = args.next().ok_or("--firmware needs 2020 or v1.0.0")?,
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
    let elf = elf.ok_or(
        "usage: qemu-bringup FIRMWARE.elf [--firmware 2020|v1.0.0] [--scenario NAME] [--seed N]",
    )?;
    if !elf.is_file() {
        return Err(format!("no firmware at {}", elf.display()));
    }
    let scenario = scenario(&name, seed)?;
    match generation.as_str() {
        "2020" => show::<Board>(&elf, &name, &scenario),
        "v1.0.0" | "v1" => show::<v1::Board>(&elf, &name, &scenario),
        other => Err(format!("unknown --firmware {other:?} (2020 or v1.0.0)")),
    }
}

/// Runs the firmware against the simulated board `B`, with the log, the live line and the
/// verdict.
fn show<B: Shown>(
    elf: &std::path::Path,
    name: &str,
    scenario: &Scenario,
) -> Result<ExitCode, String> {
    // The log goes through defmt-print, which needs the ELF for its strings.
    let mut decoder = Process::new("defmt-print")
        .arg("-e")
        .arg(elf)
        .args(["--log-format", "{t:>6} {L:<5} {s}"])
        .stdin(Stdio::piped())
        .spawn()
        .map_err(|e| {
            format!("cannot start defmt-print ({e}); `cargo install --locked defmt-print`")
        })?;
    let mut to_decoder = decoder.stdin.take();

    eprintln!(
        "chassis: simulated {} board on a loopback TCP port; QEMU mps2-an386 boots the firmware",
        B::NAME
    );
    let emulator = Emulator::mps2_an386();
    let mut last_line = 0u64;
    let result = qemu::run(
        &emulator,
        elf,
        scenario,
        |bytes| {
            if let Some(pipe) = to_decoder.as_mut() {
                let _ = pipe.write_all(bytes);
                let _ = pipe.flush();
            }
        },
        |p: Progress<'_, B>| {
            if p.now_ms >= last_line + 1_000 {
                last_line = p.now_ms;
                eprintln!("{}", B::live(&p));
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
    println!(" board      simulated, firmware {}", B::NAME);
    println!(" scenario   {name}");
    for line in B::summary(&run) {
        println!("{line}");
    }
    println!(" checks     {}", checklist(code, B::DRIVE_TYPE));
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

/// Each check marked passed (✓), failed (✗) or not run (·); without a drive-type check (on
/// v1.0.0), that one is left out.
fn checklist(code: Option<i32>, drive_type: bool) -> String {
    CHECKS
        .iter()
        .filter(|(_, fails_with)| drive_type || *fails_with != 12)
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
