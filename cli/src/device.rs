//! The commands that talk to a board over a serial port (115 200 8N1), through the driver's
//! host transport: get, set, settings, save, calibrate-gyro, stop, drive, turn.
//!
//! Every command that moves the chassis stops it on its way out, whatever ends it: done, an
//! error, a board gone quiet, or SIGINT / SIGTERM / SIGHUP ([`crate::signals`]); a turn in
//! progress is cancelled (the angle still pending is read and the opposite turn sent).

use crate::encode::write_of;
use crate::names::{RegisterName, register_name};
use crate::newfile::NewFile;
use crate::port::{self, Board};
use crate::signals;
use chassis_protocol::driver::host::Heard;
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::driver::{CoreError, Error, Outcome, Request, TurnState};
use chassis_protocol::{Action, Register, Snapshot, SystemMode, Velocity, Write};
use std::time::{Duration, Instant};

/// Opens the board's serial port with the host defaults.
pub fn open(port: &str) -> Result<Board, String> {
    port::open(port, None)
}

/// A driver error as one line, in the CLI's words. "Is it powered?" only when nothing at all
/// came from the board.
pub fn explain(driver: &Board, e: Error<SerialError>) -> String {
    let port = driver.uart().name();
    match e {
        Error::Core(e) => core_words(e, driver.core().heard(driver.uart().now_ms()), port),
        Error::Transport(e) => format!("serial port {port}: {}", e.0),
        other => other.to_string(),
    }
}

/// The driver's logic error `e` in the CLI's words, told by what came from the board on
/// `port`. Shared by every command and `chassis check` (and the Python package).
pub fn core_words(e: CoreError, heard: Heard, port: &str) -> String {
    chassis_protocol::driver::host::words_heard(e, heard, port)
}

/// Reads `register` until two replies agree; its raw value.
pub fn read(driver: &mut Board, register: Register) -> Result<u32, String> {
    match driver.run(Request::ReadVerified(register)) {
        Ok(Outcome::Value(v)) => Ok(v),
        Ok(_) => Err(format!("no value for {}", register_name(register))),
        Err(e) => Err(explain(driver, e)),
    }
}

/// A register's value, for a person.
pub fn show(register: Register, raw: u32) -> String {
    match register {
        Register::PendingAngle => format!("{:.1}°", f64::from(raw as i32) / 10.0),
        Register::MotorVoltage => format!("{:.2} V", f64::from(raw) / 100.0),
        Register::GyroGain => format!("{} ({:.5})", raw, f64::from(raw) / 100_000.0),
        Register::SystemMode => {
            let mode = SystemMode::from_bits(raw);
            format!("0x{raw:08X} (drive type {:?})", mode.drive_type())
        }
        Register::BatteryRange => {
            let (full, cut) = (raw >> 16, raw & 0xFFFF);
            let volts = |v: u32| {
                if v == 0x7FFF {
                    "built-in table".to_string()
                } else {
                    format!("{:.2} V", f64::from(v) / 100.0)
                }
            };
            format!("full {}, cut-off {}", volts(full), volts(cut))
        }
        _ => raw.to_string(),
    }
}

/// `chassis get REGISTER`.
pub fn get(port: &str, register: RegisterName) -> Result<(), String> {
    let mut driver = open(port)?;
    let raw = read(&mut driver, register.register())?;
    say!("{}: {}", register.name(), show(register.register(), raw));
    Ok(())
}

/// The instructions of a gyro calibration.
const CALIBRATION: &str = "a gyro calibration takes 30 s: put the chassis down within 10 s, then do not move or touch it for 20 s";

/// `chassis set REGISTER VALUE [CUTOFF]`: writes, then reads back. A write that starts a gyro
/// calibration (gyro-calibration 0xFFFF; system-mode switching bit 3 on) needs `yes`.
pub fn set(
    port: &str,
    register: RegisterName,
    value: &str,
    cutoff: Option<&str>,
    yes: bool,
) -> Result<(), String> {
    let write = write_of(register, value, cutoff)?;
    let mut driver = open(port)?;
    let calibrates = match write {
        Write::GyroCalibration(0xFFFF) => true,
        Write::SystemMode(mode) if mode.gyro_compensation() => {
            // Switching bit 3 on starts a calibration; already on, it does not.
            match read(&mut driver, Register::SystemMode) {
                Ok(now) => !SystemMode::from_bits(now).gyro_compensation(),
                Err(e) => {
                    return Err(format!(
                        "{e}; nothing written (the mode could not be read to tell whether this write starts a gyro calibration)"
                    ));
                }
            }
        }
        _ => false,
    };
    if calibrates && !yes {
        return Err(format!(
            "this write starts a gyro calibration ({CALIBRATION}); nothing written: add --yes to go ahead, or use `chassis calibrate-gyro`, which waits it out"
        ));
    }
    driver.write(write).map_err(|e| explain(&driver, e))?;
    if calibrates {
        tell!("gyro calibration started: {CALIBRATION}");
    }
    let back = read(&mut driver, register.register()).map_err(|e| {
        format!(
            "{}: {} was written (the frame went out) but not confirmed: {e}",
            register.name(),
            show(register.register(), write.value())
        )
    })?;
    if back != write.value() {
        return Err(format!(
            "{}: wrote {}, but it reads back {}",
            register.name(),
            show(register.register(), write.value()),
            show(register.register(), back)
        ));
    }
    say!(
        "{}: {} (read back; `chassis save` keeps it over a power cycle{})",
        register.name(),
        show(register.register(), back),
        if register.register() == Register::SystemMode {
            ", all but bit 3, gyro compensation, which the board never stores"
        } else {
            ""
        }
    );
    Ok(())
}

/// What a restore of `file` wrote, in words: every register, the gyro-compensation bit as
/// the board kept it, what was left out.
fn restored(file: &str, wanted: &Snapshot, board: &Snapshot) -> String {
    let mut lines = vec![format!(
        "restored from {file}: max-speed {}, kp {}, ki {}, gyro-gain {}, motor-voltage {}, battery-range {}",
        wanted.max_speed,
        wanted.speed_kp,
        wanted.speed_ki,
        wanted.gyro_gain,
        show(Register::MotorVoltage, u32::from(wanted.motor_centivolts)),
        show(
            Register::BatteryRange,
            (u32::from(wanted.battery_full_centivolts) << 16)
                | u32::from(wanted.battery_cutoff_centivolts)
        ),
    )];
    let onoff = |on: bool| if on { "on" } else { "off" };
    let (want, kept) = (
        wanted.system_mode.gyro_compensation(),
        board.system_mode.gyro_compensation(),
    );
    lines.push(format!(
        "system-mode 0x{:08X}: all bits from the file{}",
        board.system_mode.bits(),
        if want == kept {
            String::new()
        } else {
            format!(
                " but bit 3 (gyro compensation), kept {} as the board had it (the file says {}; switching it on starts a 30 s calibration: `chassis set system-mode 0x{:X} --yes`)",
                onoff(kept),
                onoff(want),
                wanted.system_mode.bits()
            )
        }
    ));
    lines.push(format!(
        "not restored: gyro-calibration (the file says {}, the board keeps {}: a calibration value belongs to one board and one place; `chassis calibrate-gyro` makes a new one)",
        wanted.gyro_calibration, board.gyro_calibration
    ));
    lines
        .push("not stored in the board's flash: `chassis save` keeps it over a power cycle".into());
    lines.join("\n")
}

/// `chassis settings [--save FILE | --restore FILE]`.
pub fn settings(port: &str, save: Option<&str>, restore: Option<&str>) -> Result<(), String> {
    if let Some(file) = restore {
        let text = std::fs::read_to_string(file).map_err(|e| format!("cannot read {file}: {e}"))?;
        let snapshot: Snapshot = serde_json::from_str(&text).map_err(|e| {
            let v1 = serde_json::from_str::<serde_json::Value>(&text)
                .is_ok_and(|v| v.get("firmware").and_then(|f| f.as_str()) == Some("v1.0.0"));
            if v1 {
                format!(
                    "{file}: a v1.0.0 settings file, and this board runs the 2020 firmware: nothing was written"
                )
            } else {
                format!("{file}: not a settings file: {e}")
            }
        })?;
        chassis_protocol::driver::host::check_settings(&snapshot)
            .map_err(|e| format!("{file}: {e}; nothing was written"))?;
        let mut driver = open(port)?;
        driver
            .restore_settings(&snapshot)
            .map_err(|e| explain(&driver, e))?;
        let board = driver.read_settings().map_err(|e| {
            format!(
                "{file}: written, but not read back: {}",
                explain(&driver, e)
            )
        })?;
        let expected = Snapshot {
            system_mode: snapshot
                .system_mode
                .with_gyro_compensation(board.system_mode.gyro_compensation()),
            gyro_calibration: board.gyro_calibration,
            ..snapshot
        };
        if board != expected {
            return Err(format!(
                "{file}: written, but the board reads back other settings: {}",
                serde_json::to_string(&board).unwrap_or_default()
            ));
        }
        tell!("{}", restored(file, &snapshot, &board));
        return Ok(());
    }
    // A file that cannot be written fails before the board is asked anything; what was at
    // the path stays until the new settings are complete.
    let out = save.map(NewFile::create).transpose()?;
    let mut driver = open(port)?;
    let snapshot = driver.read_settings().map_err(|e| explain(&driver, e))?;
    let json = serde_json::to_string_pretty(&snapshot).map_err(|e| e.to_string())?;
    match out {
        Some(mut file) => {
            use std::io::Write as _;
            let path = file.path().to_string();
            writeln!(file, "{json}").map_err(|e| format!("cannot write {path}: {e}"))?;
            file.commit()?;
            tell!("saved to {path}");
        }
        None => say!("{json}"),
    }
    Ok(())
}

/// `chassis save`: the current settings to the board's flash.
pub fn save(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    driver
        .action(Action::Store)
        .map_err(|e| explain(&driver, e))?;
    say!("settings stored in the board's flash");
    Ok(())
}

/// Polls the driver for `ms`, or until a signal comes.
fn poll_for(driver: &mut Board, ms: u64) -> Result<(), String> {
    let until = Instant::now() + Duration::from_millis(ms);
    while Instant::now() < until && signals::caught().is_none() {
        if driver.poll().map_err(|e| explain(driver, e))?.is_none() {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    Ok(())
}

/// `chassis calibrate-gyro`: 30 s; the chassis must stay still.
pub fn calibrate_gyro(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    driver
        .action(Action::RecalibrateGyro)
        .map_err(|e| explain(&driver, e))?;
    tell!(
        "gyro calibration started (30 s): put the chassis down now; from 10 s on, do not move or touch it"
    );
    let bar = indicatif::ProgressBar::new(30);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos:>2}/{len} s  {msg}")
            .map_err(|e| e.to_string())?,
    );
    let start = Instant::now();
    let total = Duration::from_secs(30);
    while start.elapsed() < total {
        poll_for(&mut driver, 50)?;
        let s = start.elapsed().as_secs();
        bar.set_position(s);
        bar.set_message(if s < 10 {
            "settle: put it in place"
        } else {
            "keep still: do not touch"
        });
    }
    bar.finish_and_clear();
    let value = read(&mut driver, Register::GyroCalibration)?;
    say!("gyro calibration value: {value} (`chassis save` keeps it)");
    Ok(())
}

/// Stops the chassis (cancelling a turn) and says how the command ended: `ended` is what
/// happened, `Ok` a line for stdout.
fn stop_after(driver: &mut Board, ended: Result<String, String>) -> Result<String, String> {
    let stopped = driver.stop().map_err(|e| explain(driver, e));
    if let Some(signal) = signals::caught() {
        return Err(match stopped {
            Ok(()) => format!(
                "interrupted by {}: the chassis was stopped{}",
                signals::name(signal),
                ended.err().map(|e| format!(" ({e})")).unwrap_or_default()
            ),
            Err(e) => format!(
                "interrupted by {}: the stop was sent but not confirmed: {e}",
                signals::name(signal)
            ),
        });
    }
    // A turn whose cancellation was not confirmed may still run on the board.
    let pending = if driver.core().turn_state() == TurnState::Idle {
        ""
    } else {
        " (the board may still have the turn pending: run `chassis stop` once it answers again)"
    };
    match (ended, stopped) {
        (Ok(line), Ok(())) => Ok(line),
        (Err(e), Ok(())) => Err(format!("{e}; the chassis was stopped")),
        (Ok(_), Err(e)) => Err(format!("the stop was sent but not confirmed: {e}{pending}")),
        (Err(e), Err(s)) => Err(format!(
            "{e}; the stop was sent but not confirmed: {s}{pending}"
        )),
    }
}

/// A progress bar on stderr (drawn only on a terminal).
fn progress(len: u64, template: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(len),
        indicatif::ProgressDrawTarget::stderr_with_hz(10),
    );
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}

/// `chassis stop`: stops the chassis and cancels a turn the board still has pending (left by
/// a program that was killed, say).
pub fn stop(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    let pending = driver.turn_remaining();
    let stopped = driver.stop().map_err(|e| explain(&driver, e));
    match (pending, stopped) {
        (Ok(left), Ok(())) if driver.core().turn_state() == TurnState::Idle => {
            if left.unsigned_abs() > 5 {
                say!(
                    "stopped; the {:.1}° turn the board had pending was cancelled",
                    f64::from(left) / 10.0
                );
            } else {
                say!("stopped (no turn was pending)");
            }
            Ok(())
        }
        (Ok(_), Ok(())) => {
            Err("the stop was sent, but the turn pending could not be cancelled: try again".into())
        }
        (Err(e), Ok(())) => Err(format!(
            "the stop was sent, but whether a turn is pending is not known: {}",
            explain(&driver, e)
        )),
        (_, Err(e)) => Err(format!("the stop was sent but not confirmed: {e}")),
    }
}

/// `chassis drive`: a velocity for a while, re-sent every 50 ms, then stop.
pub fn drive(port: &str, velocity: Velocity, seconds: f64) -> Result<(), String> {
    if !(0.0..=600.0).contains(&seconds) {
        return Err(format!("--for: {seconds} s is out of range (0..=600)"));
    }
    // -0 is 0.
    let seconds = seconds + 0.0;
    signals::install()?;
    let mut driver = open(port)?;
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(seconds);
    let bar = progress(
        (seconds * 10.0).round() as u64,
        "driving {bar:30} {msg} (Ctrl-C stops)",
    );
    let ended = (|| -> Result<String, String> {
        let mut next = Instant::now();
        while Instant::now() < end {
            if signals::caught().is_some() {
                return Err("the drive was cut short".into());
            }
            if Instant::now() >= next {
                driver
                    .set_velocity(velocity)
                    .map_err(|e| explain(&driver, e))?;
                next += Duration::from_millis(50);
            }
            poll_for(&mut driver, 5)?;
            if driver.core().failsafe_stops() > 0 {
                return Err(if driver.core().last_heard_ms().is_none() {
                    format!(
                        "nothing came from the board on {port} (is it powered, TX wired to RX and RX to TX, at 115200 bps?): the driver's failsafe stopped it"
                    )
                } else {
                    "the board went quiet while driving: the driver's failsafe stopped it".into()
                });
            }
            let done = start.elapsed().as_secs_f64().min(seconds);
            bar.set_position((done * 10.0) as u64);
            bar.set_message(format!("{done:.1}/{seconds} s"));
        }
        Ok(format!("drove {seconds} s, stopped"))
    })();
    bar.finish_and_clear();
    say!("{}", stop_after(&mut driver, ended)?);
    Ok(())
}

/// `chassis turn DEGREES`: one turn, sent once; waits until the pending angle is done.
pub fn turn(port: &str, degrees: f64) -> Result<(), String> {
    if !(-6_553.5..=6_553.5).contains(&degrees) {
        return Err(format!("{degrees}° is out of range (±6553.5)"));
    }
    let deci = (degrees * 10.0).round() as i32;
    if deci == 0 {
        return Err(format!(
            "{degrees}° rounds to 0.0° (the board turns in steps of 0.1°): nothing sent"
        ));
    }
    let shown = f64::from(deci) / 10.0;
    signals::install()?;
    let mut driver = open(port)?;
    match driver.turn_by(deci) {
        Ok(()) => {}
        Err(Error::Core(CoreError::TurnInProgress)) => {
            let left = match driver.core().turn_state() {
                TurnState::Turning { deci_degrees } => f64::from(deci_degrees) / 10.0,
                _ => 0.0,
            };
            return Err(format!(
                "the board still has {left:.1}° of an earlier turn pending (it adds turns up): not sent; wait for it to end, or `chassis stop` cancels it"
            ));
        }
        Err(e) if driver.core().turn_state() == TurnState::Unknown => {
            return Err(format!(
                "the turn was not sent: whether the board has one pending is not known: {}",
                explain(&driver, e)
            ));
        }
        Err(e) => {
            let e = explain(&driver, e);
            return Err(
                stop_after(&mut driver, Err(format!("the turn may have gone out: {e}")))
                    .err()
                    .unwrap_or(e),
            );
        }
    }
    // At 90°/s on the simulated board; a real one may be slower: allow twice, and 5 s.
    let limit = Duration::from_secs_f64(shown.abs() / 45.0 + 5.0);
    let start = Instant::now();
    let bar = progress(
        u64::from(deci.unsigned_abs()),
        "turning {bar:30} {msg} (Ctrl-C cancels)",
    );
    let mut left = deci;
    let mut unanswered = 0u32;
    let ended = loop {
        bar.set_position(u64::from(deci.abs_diff(left)));
        bar.set_message(format!(
            "{:.1}° of {shown:.1}°",
            f64::from(deci - left) / 10.0
        ));
        if !driver.core().turning() {
            break Ok(format!(
                "turned {shown:.1}° in {:.1} s",
                start.elapsed().as_secs_f64()
            ));
        }
        if signals::caught().is_some() {
            break Err(format!(
                "the {shown:.1}° turn was sent and cancelled with {:.1}° left",
                f64::from(left) / 10.0
            ));
        }
        if driver.core().failsafe_stops() > 0 {
            break Err(format!(
                "the board went quiet during the {shown:.1}° turn (it was sent): the driver's failsafe stopped it"
            ));
        }
        if start.elapsed() > limit {
            break Err(format!(
                "the {shown:.1}° turn (sent) was not done after {:.0} s ({:.1}° left{})",
                limit.as_secs_f64(),
                f64::from(left) / 10.0,
                if unanswered > 0 {
                    format!(", {unanswered} reads of the pending angle unanswered")
                } else {
                    String::new()
                }
            ));
        }
        if let Err(e) = poll_for(&mut driver, 100) {
            break Err(format!("the {shown:.1}° turn was sent: {e}"));
        }
        match driver.turn_remaining() {
            Ok(l) => left = l,
            // One read lost is no reason to give up: the limit above bounds the wait.
            Err(_) => unanswered += 1,
        }
    };
    bar.finish_and_clear();
    say!("{}", stop_after(&mut driver, ended)?);
    Ok(())
}
