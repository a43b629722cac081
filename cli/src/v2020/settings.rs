//! A 2020 board's registers and settings: `get`, `set` (a write read back; one that starts a
//! gyro calibration needs `--yes`), `settings` (all of them as JSON, saved to a file or restored
//! from one), `save` (into the board's flash) and `calibrate-gyro`.

use super::{explain, open};
use crate::driving::poll_for;
use crate::encode::write_of;
use crate::ending;
use crate::names::{RegisterName, register_name};
use crate::newfile::NewFile;
use crate::port::Board;
use chassis_protocol::driver::{Outcome, Request};
use chassis_protocol::{Action, Register, Snapshot, SystemMode, Write};
use std::time::{Duration, Instant};

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
    crate::newfile::put_json(out, &json)
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
