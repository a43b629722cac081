//! The commands that talk to a board over a serial port (115 200 8N1), through the driver's
//! host transport: get, set, settings, save, calibrate-gyro, drive, turn.

use crate::encode::write_of;
use crate::names::RegisterName;
use chassis_protocol::driver::host::{HostDriver, SerialError, open as open_port};
use chassis_protocol::driver::{CoreError, Error, Outcome, Request};
use chassis_protocol::{Action, Register, Snapshot, SystemMode, Velocity};
use std::time::{Duration, Instant};

/// Opens the board's serial port with the host defaults.
pub fn open(port: &str) -> Result<HostDriver, String> {
    open_port(port).map_err(|e| format!("cannot open {port}: {}", e.0))
}

/// A driver error as one line.
pub fn explain(e: Error<SerialError>) -> String {
    match e {
        Error::Core(CoreError::Timeout(register))
        | Error::Core(CoreError::Unconfirmed(register)) => {
            format!(
                "the board did not answer the read of {register:?} (is it powered, on this port, at 115200 bps?)"
            )
        }
        Error::Transport(e) => format!("serial port: {}", e.0),
        other => other.to_string(),
    }
}

/// Reads `register` until two replies agree; its raw value.
pub fn read(driver: &mut HostDriver, register: Register) -> Result<u32, String> {
    match driver
        .run(Request::ReadVerified(register))
        .map_err(explain)?
    {
        Outcome::Value(v) => Ok(v),
        _ => Err(format!("no value for {register:?}")),
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
    println!("{}: {}", register.name(), show(register.register(), raw));
    Ok(())
}

/// `chassis set REGISTER VALUE [CUTOFF]`: writes, then reads back.
pub fn set(
    port: &str,
    register: RegisterName,
    value: &str,
    cutoff: Option<&str>,
) -> Result<(), String> {
    let write = write_of(register, value, cutoff)?;
    let mut driver = open(port)?;
    driver.write(write).map_err(explain)?;
    let back = read(&mut driver, register.register())?;
    if back != write.value() {
        return Err(format!(
            "{} reads back {} after writing {}",
            register.name(),
            back,
            write.value()
        ));
    }
    println!(
        "{}: {} (read back; `chassis save` keeps it over a power cycle)",
        register.name(),
        show(register.register(), back)
    );
    Ok(())
}

/// `chassis settings [--save FILE | --restore FILE]`.
pub fn settings(port: &str, save: Option<&str>, restore: Option<&str>) -> Result<(), String> {
    if let Some(file) = restore {
        let text = std::fs::read_to_string(file).map_err(|e| format!("cannot read {file}: {e}"))?;
        let snapshot: Snapshot =
            serde_json::from_str(&text).map_err(|e| format!("{file}: not a settings file: {e}"))?;
        let mut driver = open(port)?;
        driver.restore_settings(&snapshot).map_err(explain)?;
        eprintln!("restored from {file} (not saved to the board's flash: `chassis save`)");
        return Ok(());
    }
    let mut driver = open(port)?;
    let snapshot = driver.read_settings().map_err(explain)?;
    let json = serde_json::to_string_pretty(&snapshot).map_err(|e| e.to_string())?;
    match save {
        Some(file) => {
            std::fs::write(file, format!("{json}\n"))
                .map_err(|e| format!("cannot write {file}: {e}"))?;
            eprintln!("saved to {file}");
        }
        None => println!("{json}"),
    }
    Ok(())
}

/// `chassis save`: the current settings to the board's flash.
pub fn save(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    driver.action(Action::Store).map_err(explain)?;
    println!("settings stored in the board's flash");
    Ok(())
}

/// `chassis calibrate-gyro`: 30 s; the chassis must stay still.
pub fn calibrate_gyro(port: &str) -> Result<(), String> {
    let mut driver = open(port)?;
    driver.action(Action::RecalibrateGyro).map_err(explain)?;
    eprintln!(
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
        let _ = driver.poll().map_err(explain)?;
        let s = start.elapsed().as_secs();
        bar.set_position(s);
        bar.set_message(if s < 10 {
            "settle: put it in place"
        } else {
            "keep still: do not touch"
        });
        std::thread::sleep(Duration::from_millis(5));
    }
    bar.finish_and_clear();
    let value = read(&mut driver, Register::GyroCalibration)?;
    println!("gyro calibration value: {value} (`chassis save` keeps it)");
    Ok(())
}

/// `chassis drive`: a velocity for a while, re-sent every 50 ms, then stop.
pub fn drive(port: &str, velocity: Velocity, seconds: f64) -> Result<(), String> {
    if !(0.0..=600.0).contains(&seconds) {
        return Err(format!("--for: {seconds} s is out of range (0..=600)"));
    }
    let mut driver = open(port)?;
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    let mut next = Instant::now();
    let result = (|| -> Result<(), String> {
        while Instant::now() < end {
            if Instant::now() >= next {
                driver.set_velocity(velocity).map_err(explain)?;
                next += Duration::from_millis(50);
            }
            let _ = driver.poll().map_err(explain)?;
            if driver.core().failsafe_stops() > 0 {
                return Err("the board went quiet: the driver stopped the chassis".into());
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        Ok(())
    })();
    // Stop whatever happened.
    let stopped = driver.stop().map_err(explain);
    result?;
    stopped?;
    println!("drove {seconds} s, stopped");
    Ok(())
}

/// `chassis turn DEGREES`: one turn, sent once; waits until the pending angle is done.
pub fn turn(port: &str, degrees: f64) -> Result<(), String> {
    if !(-6_553.5..=6_553.5).contains(&degrees) {
        return Err(format!("{degrees}° is out of range (±6553.5)"));
    }
    let deci = (degrees * 10.0).round() as i32;
    let mut driver = open(port)?;
    driver.turn_by(deci).map_err(explain)?;
    // At 90°/s on the simulated board; a real one may be slower: allow twice, and 5 s.
    let limit = Duration::from_secs_f64(degrees.abs() / 45.0 + 5.0);
    let start = Instant::now();
    while driver.core().turning() {
        if start.elapsed() > limit {
            let left = driver.turn_remaining().map_err(explain)?;
            let _ = driver.stop();
            return Err(format!(
                "the turn was not done after {:.0} s ({:.1}° left); stopped",
                limit.as_secs_f64(),
                f64::from(left) / 10.0
            ));
        }
        let until = Instant::now() + Duration::from_millis(100);
        while Instant::now() < until {
            let _ = driver.poll().map_err(explain)?;
            std::thread::sleep(Duration::from_millis(2));
        }
        let _ = driver.turn_remaining().map_err(explain)?;
    }
    println!(
        "turned {degrees}° in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
