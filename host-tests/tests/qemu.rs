//! End to end: the bring-up firmware in QEMU (mps2-an386, Cortex-M4) against the simulated
//! chassis over TCP. Each test asserts on what the chassis received and on the firmware's exit
//! status.
//!
//! They need the firmware built and `qemu-system-arm`, so they are `#[ignore]`d in a plain
//! `cargo test`; `cargo xtask test` builds the firmware and runs them with `--ignored`, the
//! firmware's path in `CHASSIS_FIRMWARE`.

use chassis_host_tests::qemu::{self, Emulator, Run, Scenario, Sent, is_motion};
use chassis_protocol::driver::Config;
use chassis_protocol::sim::Faults;
use chassis_protocol::{Command, Register, Setting, Snapshot, Velocity};
use std::path::PathBuf;
use std::sync::OnceLock;

/// The exit codes of the bring-up's checks (`chassis_bringup::Check::exit_code`).
const SETTINGS: i32 = 11;
const FORWARD: i32 = 13;
const STRAFE: i32 = 14;

fn firmware() -> PathBuf {
    let path = std::env::var_os("CHASSIS_FIRMWARE")
        .map(PathBuf::from)
        .expect("CHASSIS_FIRMWARE: the QEMU board's ELF (cargo xtask test sets it)");
    assert!(path.is_file(), "no firmware at {}", path.display());
    path
}

fn boot(scenario: Scenario) -> Run {
    let run = qemu::run(
        &Emulator::mps2_an386(),
        &firmware(),
        &scenario,
        |_| {},
        |_| {},
    )
    .expect("QEMU runs");
    eprintln!(
        "exit {:?} after {:.1} s, {} frames received",
        run.exit_code(),
        run.elapsed.as_secs_f64(),
        run.sent.len()
    );
    run
}

/// The normal bring-up, run once for the tests that look at it.
fn normal() -> &'static Run {
    static RUN: OnceLock<Run> = OnceLock::new();
    RUN.get_or_init(|| boot(Scenario::default()))
}

fn is_stop(command: &Command) -> bool {
    matches!(command, Command::Velocity(v) if *v == Velocity::new(0, 0, 0))
}

fn reads(sent: &[Sent]) -> Vec<Register> {
    sent.iter()
        .filter_map(|s| match s.command {
            Command::Setting(Setting::Read(r)) => Some(r),
            _ => None,
        })
        .collect()
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn normal_bring_up_reads_every_register_turns_once_and_ends_stopped() {
    let run = normal();
    assert_eq!(run.exit_code(), Some(0), "every check passes");
    let read = reads(&run.sent);
    for register in Snapshot::REGISTERS.iter().chain([&Register::PendingAngle]) {
        assert!(read.contains(register), "{register:?} was read");
    }
    let turns: Vec<&Sent> = run
        .sent
        .iter()
        .filter(|s| matches!(s.command, Command::Turn(_)))
        .collect();
    assert_eq!(turns.len(), 1, "the turn is sent exactly once");
    assert_eq!(run.board.total_turn_commanded(), 900, "90.0° in all");
    assert_eq!(run.board.pending_deci_degrees(), 0, "and all of it turned");
    let last_motion = run
        .sent
        .iter()
        .rev()
        .find(|s| matches!(s.command, Command::Velocity(_) | Command::Motors(_)))
        .expect("motion commands were sent");
    assert!(
        is_stop(&last_motion.command),
        "the last motion command is a stop"
    );
    assert_eq!(
        run.board.stored_registers(),
        &chassis_protocol::sim::FACTORY,
        "nothing was saved to the board's flash"
    );
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn the_log_names_every_check_and_the_ram_used_fits_the_budget() {
    let run = normal();
    let log = qemu::decode_log(&firmware(), &run.log).expect("defmt-print decodes the log");
    for step in [
        "[link] up",
        "[settings] Snapshot",
        "[settings] postcard",
        "[Forward] encoders counted",
        "[Strafe] encoders counted",
        "[turn] done",
        "[stop] encoders still",
        "[battery]",
        "[control-loop]",
        "PASS",
    ] {
        assert!(log.contains(step), "the log has {step:?}:\n{log}");
    }
    // "RAM: 24 B static + 1900 B stack at its peak": the stack is painted at boot.
    let line = log
        .lines()
        .find(|l| l.contains("RAM: "))
        .expect("the firmware reports its RAM");
    let numbers: Vec<usize> = line
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    let [static_ram, stack] = numbers[..] else {
        panic!("unexpected RAM line {line:?}");
    };
    eprintln!("RAM: {static_ram} B static + {stack} B stack");
    assert!(
        stack > 256,
        "the stack measurement measures something: {stack}"
    );
    assert!(
        static_ram + stack <= 8 * 1024,
        "the firmware fits 8 KiB of RAM: {static_ram} + {stack}"
    );
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn register_reads_while_moving_cause_no_false_stop() {
    let run = normal();
    assert_eq!(run.exit_code(), Some(0));
    // The control loop cruises at half speed: from its first velocity frame to its last, reads
    // go out and not one stop does.
    let cruise =
        |s: &&Sent| matches!(s.command, Command::Velocity(v) if v == Velocity::new(0, 150, 0));
    let first = run
        .sent
        .iter()
        .position(|s| cruise(&s))
        .expect("cruise sent");
    let last = run
        .sent
        .iter()
        .rposition(|s| cruise(&s))
        .expect("cruise sent");
    let span = &run.sent[first..=last];
    let reads_while_moving = reads(span).len();
    assert!(
        reads_while_moving >= 4,
        "{reads_while_moving} reads while cruising"
    );
    assert!(
        !span.iter().any(|s| is_stop(&s.command)),
        "no stop while cruising: {:?}",
        span.iter()
            .filter(|s| is_stop(&s.command))
            .collect::<Vec<_>>()
    );
    let period = span
        .windows(2)
        .filter(|w| cruise(&&w[0]) || cruise(&&w[1]))
        .map(|w| w[1].at_ms - w[0].at_ms)
        .max()
        .unwrap_or(0);
    assert!(
        period < u64::from(Config::DEFAULT.failsafe_ms),
        "the velocity is re-sent well inside the failsafe: longest gap {period} ms"
    );
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn a_board_going_silent_mid_motion_is_stopped_within_the_failsafe_limit() {
    let run = boot(Scenario {
        silent_after_motion_ms: Some(200),
        ..Scenario::default()
    });
    let code = run.exit_code();
    assert!(
        matches!(code, Some(FORWARD | STRAFE)),
        "the motion check fails: {code:?}"
    );
    let silent = run.silenced_at_ms.expect("the board went silent");
    let stop = run
        .sent
        .iter()
        .find(|s| s.at_ms >= silent && is_stop(&s.command))
        .expect("a stop was sent after the silence");
    let after = stop.at_ms - silent;
    eprintln!("silent at {silent} ms, stop sent {after} ms later");
    // The failsafe (100 ms) plus the emulator's and the host's latency.
    assert!(
        after <= u64::from(Config::DEFAULT.failsafe_ms) + 60,
        "stopped {after} ms after the board went silent"
    );
    assert!(
        !run.sent
            .iter()
            .any(|s| s.at_ms > stop.at_ms && is_motion(&s.command)),
        "nothing moves the chassis after the failsafe stop"
    );
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn replies_that_never_come_fail_the_settings_check_without_a_hang() {
    let run = boot(Scenario {
        faults: Faults {
            replies_stopped: true,
            ..Faults::default()
        },
        ..Scenario::default()
    });
    assert_eq!(run.exit_code(), Some(SETTINGS), "the settings check fails");
    let log = qemu::decode_log(&firmware(), &run.log).expect("defmt-print decodes the log");
    assert!(
        log.contains("Settings failed") && log.contains("Unconfirmed(MaxSpeed)"),
        "the log names the check and the reason:\n{log}"
    );
    assert!(
        run.elapsed.as_secs() < 10,
        "it gives up in bounded time: {:?}",
        run.elapsed
    );
    assert!(
        !run.sent.iter().any(|s| is_motion(&s.command)),
        "nothing moves after a failed bring-up"
    );
    assert!(
        reads(&run.sent).len() <= usize::from(Config::DEFAULT.read_tries),
        "the first register is tried at most read_tries times: {:?}",
        reads(&run.sent)
    );
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn a_line_with_one_error_in_a_thousand_bytes_still_brings_up() {
    for seed in [11, 12, 13] {
        let run = boot(Scenario {
            seed,
            faults: Faults {
                drop_per_million: 333,
                corrupt_per_million: 334,
                insert_per_million: 333,
                ..Faults::default()
            },
            ..Scenario::default()
        });
        if run.exit_code() != Some(0) {
            let log = qemu::decode_log(&firmware(), &run.log).unwrap_or_default();
            panic!(
                "seed {seed}: every check passes, not {:?}:\n{log}",
                run.exit_code()
            );
        }
        let turns = run
            .sent
            .iter()
            .filter(|s| matches!(s.command, Command::Turn(_)))
            .count();
        assert_eq!(turns, 1, "seed {seed}: one turn");
        assert_eq!(run.board.total_turn_commanded(), 900, "seed {seed}");
    }
}
