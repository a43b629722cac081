//! End to end: the bring-up firmware in QEMU (mps2-an386, Cortex-M4) against the simulated
//! chassis over TCP. Each test asserts on what the chassis received and on the firmware's exit
//! status. The firmware detects the board's generation first: most tests serve the 2020 board,
//! the `v1_` ones the v1.0.0 board (`7B … BCC 7D`), and the same ELF runs that generation's
//! bring-up.
//!
//! They need the firmware built and `qemu-system-arm`, so they are `#[ignore]`d in a plain
//! `cargo test`; `cargo xtask test` builds the firmware and runs them with `--ignored`, the
//! firmware's path in `CHASSIS_FIRMWARE`.

use chassis_host_tests::qemu::{
    self, Emulator, Run, Scenario, Sent, Served, is_motion, is_motion_v1,
};
use chassis_protocol::driver::Config;
use chassis_protocol::sim::{Faults, v1};
use chassis_protocol::v1::{BodyVelocity, Command as V1Command};
use chassis_protocol::{Command, Register, Setting, Snapshot, Velocity};
use std::path::PathBuf;
use std::sync::OnceLock;

/// The exit codes of the bring-up's checks (`chassis_bringup::Check::exit_code`).
const SETTINGS: i32 = 11;
const FORWARD: i32 = 13;
const STRAFE: i32 = 14;
const CONTROL_LOOP: i32 = 18;

/// The v1.0.0 forced stop, by hand from `docs/protocol-v1.md`: `7B`, code `25`, ten `00` (`ctl` 0,
/// type 0, vx vy wz 0, `00 00`), BCC `7B ^ 25 = 5E`, `7D`.
const FORCED_STOP: [u8; 14] = [
    0x7B, 0x25, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x5E, 0x7D,
];

/// The v1.0.0 driver's failsafe (`chassis_protocol::driver::v1::MIN_FAILSAFE_MS`: the QEMU
/// firmware's 100 ms is raised to it).
const V1_FAILSAFE_MS: u64 = 300;

fn firmware() -> PathBuf {
    let path = std::env::var_os("CHASSIS_FIRMWARE")
        .map(PathBuf::from)
        .expect("CHASSIS_FIRMWARE: the QEMU board's ELF (cargo xtask test sets it)");
    assert!(path.is_file(), "no firmware at {}", path.display());
    path
}

fn boot(scenario: Scenario) -> Run {
    boot_on(scenario)
}

/// Boots the firmware against a simulated board of generation `B`.
fn boot_on<B: Served>(scenario: Scenario) -> Run<B> {
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

/// The firmware's log, decoded; it must name every one of `steps`.
fn log_naming<B: Served>(run: &Run<B>, steps: &[&str]) -> String {
    let log = qemu::decode_log(&firmware(), &run.log).expect("defmt-print decodes the log");
    for step in steps {
        assert!(log.contains(step), "the log has {step:?}:\n{log}");
    }
    log
}

/// The RAM the log reports ("RAM: 24 B static + 1900 B stack at its peak": the stack is painted
/// at boot), static and stack, which must fit 8 KiB.
fn ram_fits(log: &str) -> (usize, usize) {
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
        static_ram + stack <= 8 * 1024,
        "the firmware fits 8 KiB of RAM: {static_ram} + {stack}"
    );
    (static_ram, stack)
}

/// Every check passed; else fails with `what` and the firmware's log.
fn assert_passed<B: Served>(run: &Run<B>, what: &str) {
    if run.exit_code() != Some(0) {
        let log = qemu::decode_log(&firmware(), &run.log).unwrap_or_default();
        panic!(
            "{what}: every check passes, not {:?}:\n{log}",
            run.exit_code()
        );
    }
}

/// After the board went silent, the failsafe sent `stop` (the frame `is_stop` picks) within
/// `failsafe_ms` of the silence, plus 60 ms of the emulator's and the host's latency (the
/// failsafe counts from the last frame heard, before the silence), and nothing moved the
/// chassis after it.
fn assert_failsafe_stop<B: Served>(
    run: &Run<B>,
    failsafe_ms: u64,
    stop: &str,
    is_stop: impl Fn(&B::Command) -> bool,
) {
    let silent = run.silenced_at_ms.expect("the board went silent");
    let sent = run
        .sent
        .iter()
        .find(|s| s.at_ms >= silent && is_stop(&s.command))
        .unwrap_or_else(|| panic!("{stop} was sent after the silence"));
    let after = sent.at_ms - silent;
    eprintln!("silent at {silent} ms, {stop} sent {after} ms later");
    assert!(
        after <= failsafe_ms + 60,
        "stopped {after} ms after the board went silent"
    );
    assert!(
        !run.sent
            .iter()
            .any(|s| s.at_ms > sent.at_ms && B::moves(&s.command)),
        "nothing moves the chassis after the failsafe's {stop}"
    );
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
    let log = log_naming(
        normal(),
        &[
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
        ],
    );
    let (_, stack) = ram_fits(&log);
    assert!(
        stack > 256,
        "the stack measurement measures something: {stack}"
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
    // The failsafe: 100 ms.
    let failsafe_ms = u64::from(Config::DEFAULT.failsafe_ms);
    assert_failsafe_stop(&run, failsafe_ms, "a stop", is_stop);
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
        assert_passed(&run, &format!("seed {seed}"));
        let turns = run
            .sent
            .iter()
            .filter(|s| matches!(s.command, Command::Turn(_)))
            .count();
        assert_eq!(turns, 1, "seed {seed}: one turn");
        assert_eq!(run.board.total_turn_commanded(), 900, "seed {seed}");
    }
}

/// The bring-up against the v1.0.0 board, run once for the tests that look at it.
fn normal_v1() -> &'static Run<v1::Board> {
    static RUN: OnceLock<Run<v1::Board>> = OnceLock::new();
    RUN.get_or_init(|| boot_on(Scenario::default()))
}

/// The frames that set the chassis moving or stop it (`0x25`, `0x26`).
fn motion_frames(sent: &[Sent<V1Command>]) -> impl Iterator<Item = &Sent<V1Command>> {
    sent.iter().filter(|s| {
        matches!(
            s.command,
            V1Command::BodyVelocity(_) | V1Command::MotorVelocity(_)
        )
    })
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn v1_board_bring_up_passes_and_ends_with_the_forced_stop() {
    let run = normal_v1();
    assert_passed(run, "v1.0.0");
    let stats = run.board.uplink_stats();
    assert_eq!(
        (
            stats.discarded,
            stats.bad_checksum,
            stats.bad_end,
            stats.refused
        ),
        (0, 0, 0, 0),
        "the board received only whole v1.0.0 frames: {stats:?}"
    );
    assert_eq!(
        run.board.total_commands() as usize,
        run.sent.len(),
        "every frame the firmware sent was taken"
    );
    for code in [0x23, 0x24, 0x40] {
        assert_eq!(
            run.board.received_count(code),
            0,
            "no settings frame {code:#04x}: nothing is written unasked"
        );
    }
    assert!(!run.sent.iter().any(|s| matches!(
        s.command,
        V1Command::System(_) | V1Command::Geometry(_) | V1Command::Pid(_)
    )));
    for code in [0x33, 0x34, 0x50] {
        assert!(
            run.board.received_count(code) >= 1,
            "the readback {code:#04x} was sent"
        );
    }
    let last = motion_frames(&run.sent)
        .last()
        .expect("motion frames were sent");
    assert_eq!(
        last.command.encode(),
        FORCED_STOP,
        "the last motion frame is the forced stop"
    );
    assert_eq!(
        run.board.velocity(),
        BodyVelocity::FORCED_STOP,
        "the board was left with the forced stop"
    );
    assert_eq!(run.board.measured_velocity(), [0, 0, 0], "and stands still");
    // While the chassis moves, its velocity is re-sent well inside the failsafe.
    let moving: Vec<&Sent<V1Command>> = motion_frames(&run.sent).collect();
    let longest = moving
        .windows(2)
        .filter(|w| is_motion_v1(&w[0].command))
        .map(|w| w[1].at_ms - w[0].at_ms)
        .max()
        .unwrap_or(0);
    assert!(
        longest < V1_FAILSAFE_MS / 2,
        "motion re-sent every period: longest gap {longest} ms"
    );
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn v1_log_names_the_firmware_and_every_check_and_the_ram_fits() {
    let log = log_naming(
        normal_v1(),
        &[
            "firmware v1.0.0",
            "[link] up",
            "[settings] SystemSettings",
            "[settings] Geometry",
            "[settings] Pid",
            "[Forward] commanded 300 mm/s",
            "[Strafe] commanded 300 mm/s",
            "[turn] rotated at 1000 mrad/s",
            "[stop] forced stop: still",
            "[battery]",
            "[control-loop]",
            "PASS: every check passed (v1.0.0)",
        ],
    );
    assert!(!log.contains("[drive-type]"), "no drive type on v1.0.0");
    ram_fits(&log);
}

#[test]
#[ignore = "needs the firmware and qemu-system-arm: cargo xtask test"]
fn v1_board_going_silent_in_the_control_loop_gets_the_failsafe_forced_stop() {
    // From the first motion: forward 0.4 s, sideways 0.4 s, the rotation 1.2 s, the stop
    // 0.5 s, then the control loop for 1.5 s: 3 s in is the middle of the loop.
    let run: Run<v1::Board> = boot_on(Scenario {
        silent_after_motion_ms: Some(3_000),
        ..Scenario::default()
    });
    let log = qemu::decode_log(&firmware(), &run.log).unwrap_or_default();
    assert_eq!(
        run.exit_code(),
        Some(CONTROL_LOOP),
        "the control loop fails:\n{log}"
    );
    assert!(
        log.contains("ControlLoop failed") && log.contains("FailsafeStop"),
        "the failsafe stopped it:\n{log}"
    );
    assert_failsafe_stop(&run, V1_FAILSAFE_MS, "the forced stop", |c| {
        c.encode() == FORCED_STOP
    });
    assert_eq!(run.board.velocity(), BodyVelocity::FORCED_STOP);
}
