//! The commands that talk to a board over a serial port (115 200 8N1), through the driver's
//! host transport: get, set, settings, save, calibrate-gyro, stop, drive, turn.
//!
//! Every command that moves the chassis stops it on its way out, whatever ends it: done, an
//! error, a board gone quiet, SIGINT / SIGTERM / SIGHUP, its terminal or input gone
//! ([`crate::ending`]); a turn in progress is cancelled (the angle still pending is read and
//! the opposite turn sent). What it says of the chassis comes from what was sent and what came
//! back ([`crate::stopping`]).

pub mod check;
pub mod monitor;

use crate::generation::{CheckArgs, DriveArgs, Generation, SetArgs};

use crate::encode::write_of;
use crate::ending;
use crate::names::{RegisterName, register_name};
use crate::newfile::NewFile;
use crate::port::{self, Board};
use crate::stopping::{self, Stopped};
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
    stopping::explain(driver, e)
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
        let text = crate::input::read_text(file, crate::input::SETTINGS_MAX, "settings file")?;
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

/// Polls the driver for `ms`, or until the command must end.
fn poll_for(driver: &mut Board, ms: u64) -> Result<(), String> {
    let until = Instant::now() + Duration::from_millis(ms);
    while Instant::now() < until && ending::ended().is_none() {
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
        if let Some(end) = ending::ended() {
            bar.finish_and_clear();
            let left = total.saturating_sub(start.elapsed()).as_secs_f64();
            return Err(format!(
                "{}: the board goes on calibrating for {left:.0} s more: keep the chassis still, then `chassis get gyro-calibration`",
                end.words()
            ));
        }
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
/// happened (`Ok`: a line for stdout), the ending that cut it short comes first.
fn stop_after(driver: &mut Board, ended: Result<String, String>) -> Result<String, String> {
    let stopped = stopping::stop(driver);
    let words = stopped.words::<chassis_protocol::driver::DriverCore>();
    if let Some(end) = ending::ended() {
        let end = end.words();
        // A wait the ending cut short says only the ending's words: not said twice.
        return Err(match ended {
            Err(detail) if !detail.contains(&end) => format!("{end}: {detail}; {words}"),
            _ => format!("{end}: {words}"),
        });
    }
    match (ended, stopped) {
        (Ok(line), Stopped::Confirmed) => Ok(line),
        (Ok(line), _) => Err(format!("{line}, but {words}")),
        (Err(e), _) => Err(format!("{e}; {words}")),
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

/// `chassis stop`: stops the chassis at once, then reads the angle the board has pending and
/// cancels a turn it finds (left by a program that was killed, say). The read's answer is the
/// evidence that the board heard: without it, the stop is not said to have worked.
pub fn stop(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    // Nothing cuts a stop short: it is what every ending asks for.
    driver.uart_mut().uninterrupted();
    let before = driver.uart().stops_sent();
    let first = driver.stop();
    if driver.uart().stops_sent() == before {
        let why = first.err().map_or_else(
            || "nothing was written".to_string(),
            |e| explain(&driver, e),
        );
        return Err(format!(
            "the stop could not be sent ({why}): the chassis may still be moving"
        ));
    }
    let pending = match driver.turn_remaining() {
        Ok(left) => left,
        Err(e) => {
            return Err(format!(
                "the stop was sent, but the board did not answer the read after it: not confirmed, and whether a turn is pending is not known: {}",
                explain(&driver, e)
            ));
        }
    };
    if !driver.core().turning() {
        say!("stopped (the board answered; no turn was pending)");
        return Ok(());
    }
    match driver.stop() {
        Ok(()) if driver.core().turn_state() == TurnState::Idle => {
            say!(
                "stopped; the {:.1}° turn the board had pending was cancelled",
                f64::from(pending) / 10.0
            );
            Ok(())
        }
        Ok(()) => Err(format!(
            "the stop was sent, but the {:.1}° turn the board has pending could not be cancelled: try again",
            f64::from(pending) / 10.0
        )),
        Err(e) => Err(format!(
            "the stop was sent, but the {:.1}° turn the board has pending was not cancelled: {}",
            f64::from(pending) / 10.0,
            explain(&driver, e)
        )),
    }
}

/// `chassis drive`: a velocity for a while, re-sent every 50 ms, then stop.
pub fn drive(port: &str, velocity: Velocity, seconds: f64) -> Result<(), String> {
    if !(0.0..=600.0).contains(&seconds) {
        return Err(format!("--for: {seconds} s is out of range (0..=600)"));
    }
    // -0 is 0.
    let seconds = seconds + 0.0;
    let mut driver = open(port)?;
    ending::before_motion()?;
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(seconds);
    let bar = progress(
        (seconds * 10.0).round() as u64,
        "driving {bar:30} {msg} (Ctrl-C stops)",
    );
    let ended = (|| -> Result<String, String> {
        let mut next = Instant::now();
        while Instant::now() < end {
            if let Some(end) = ending::ended() {
                return Err(end.words());
            }
            if Instant::now() >= next {
                driver
                    .set_velocity(velocity)
                    .map_err(|e| explain(&driver, e))?;
                next += Duration::from_millis(50);
            }
            poll_for(&mut driver, 5)?;
            if driver.core().failsafe_stops() > 0 {
                return Err(stopping::failsafe_words(&driver, "stopped it"));
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
    let mut driver = open(port)?;
    ending::before_motion()?;
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
        // Cut short before the turn went out (reading whether one is pending).
        Err(_) if driver.core().turn_state() == TurnState::Unknown && ending::ended().is_some() => {
            ending::before_motion()?;
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
        if ending::ended().is_some() {
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

/// A 2020 register by its name on the command line.
fn register(name: &str) -> Result<RegisterName, String> {
    <RegisterName as clap::ValueEnum>::from_str(name, false).map_err(|_| {
        let names: Vec<String> = <RegisterName as clap::ValueEnum>::value_variants()
            .iter()
            .filter_map(|v| clap::ValueEnum::to_possible_value(v).map(|p| p.get_name().to_string()))
            .collect();
        format!(
            "{name:?} is not a register of the 2020 firmware: give one of {}",
            names.join(", ")
        )
    })
}

/// The 2020 firmware (`FF FE` frames): the commands as it does them.
pub struct V2020;

impl Generation for V2020 {
    fn get(&self, path: &str, name: &str) -> Result<(), String> {
        get(path, register(name)?)
    }

    fn set(&self, path: &str, set_args: &SetArgs) -> Result<(), String> {
        set(
            path,
            register(&set_args.register)?,
            &set_args.value,
            set_args.cutoff.as_deref(),
            set_args.yes,
        )
    }

    fn settings(
        &self,
        path: &str,
        save: Option<&str>,
        restore: Option<&str>,
    ) -> Result<(), String> {
        settings(path, save, restore)
    }

    fn save(&self, path: &str) -> Result<(), String> {
        save(path)
    }

    fn calibrate_gyro(&self, path: &str) -> Result<(), String> {
        calibrate_gyro(path)
    }

    fn stop(&self, path: &str) -> Result<(), String> {
        stop(path)
    }

    fn drive(&self, path: &str, args: &DriveArgs) -> Result<(), String> {
        if args.si() {
            return Err("drive: --vx/--vy/--wz are for the v1.0.0 firmware; this board runs the 2020 one: give --x --y --z (the board's raw units)".into());
        }
        let (x, y, z) = args.axes.values()?;
        drive(path, Velocity::new(x, y, z), args.seconds)
    }

    fn turn(&self, path: &str, degrees: f64) -> Result<(), String> {
        turn(path, degrees)
    }

    fn monitor(&self, path: &str, drive: bool, speed: &str) -> Result<(), String> {
        let speed = crate::value::parse_i32(speed, "speed", 1, 65_535)?;
        monitor::run(path, drive, speed)
    }

    fn check(&self, path: &str, args: &CheckArgs) -> Result<(), (String, u8)> {
        check::check(
            path,
            args.no_motion,
            args.yes,
            args.drive_type
                .map(crate::generation::DriveTypeName::drive_type),
        )
    }
}
