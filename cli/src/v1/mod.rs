//! The commands on a board running the v1.0.0 firmware (`7B … BCC 7D` frames): `drive --vx
//! --vy --wz`, `stop` (the forced stop), `get` / `set` over the five readbacks and the three
//! settings frames, `settings` (save / restore the three). The driver is the same as the 2020
//! board's, its core the v1.0.0 one: the same failsafe (it sends the forced stop), the same
//! whole-frame guarantee. What v1.0.0 has no frame for (a turn by an angle, storing in flash, a
//! gyro calibration) is refused in one line.

pub mod check;
pub mod monitor;

use crate::generation::{CheckArgs, DriveArgs, Generation, SetArgs};

use crate::ending;
use crate::port::{self, BoardV1};
use crate::stopping::{self, Stopped};
use chassis_protocol::driver::Error;
use chassis_protocol::driver::host::SerialError;
use chassis_protocol::driver::v1::DriverCore;
use chassis_protocol::driver::v1::Settings;
use chassis_protocol::v1::{
    BodyVelocity, FIELDS, FieldError, Geometry, Pid, Readback, Reply, SystemSettings,
};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

/// The names `get` takes on v1.0.0, for messages.
pub fn names() -> String {
    let frames = Readback::ALL.map(Readback::name).join(", ");
    let fields: Vec<&str> = FIELDS.iter().map(|(n, _)| *n).collect();
    format!("{frames}, or one field: {}", fields.join(", "))
}

/// A driver error as one line, in the CLI's words.
fn explain(driver: &BoardV1, e: Error<SerialError>) -> String {
    stopping::explain(driver, e)
}

/// One readback.
fn readback(driver: &mut BoardV1, r: Readback) -> Result<Reply, String> {
    driver.readback(r).map_err(|e| explain(driver, e))
}

/// A reply's fields as JSON.
fn reply_json(reply: &Reply) -> serde_json::Value {
    let value = match reply.request {
        Readback::System => reply.system().map(|s| serde_json::to_value(s).ok()),
        Readback::Geometry => reply.geometry().map(|g| serde_json::to_value(g).ok()),
        Readback::BodyVelocity => reply.body_velocity().map(|v| serde_json::to_value(v).ok()),
        Readback::MotorSpeeds => reply.motor_speeds().map(|m| serde_json::to_value(m).ok()),
        Readback::Pid => reply.pid().map(|p| serde_json::to_value(p).ok()),
    };
    value.flatten().unwrap_or(serde_json::Value::Null)
}

/// `chassis get NAME` on v1.0.0: a whole readback as JSON, or one field.
pub fn get(path: &str, name: &str) -> Result<(), String> {
    let frame = Readback::from_name(name);
    let field = FIELDS.iter().find(|(n, _)| *n == name);
    let request = match (frame, field) {
        (Some(r), _) => r,
        (None, Some((_, r))) => *r,
        (None, None) => {
            return Err(format!(
                "{name:?} is not a v1.0.0 setting: give {}",
                names()
            ));
        }
    };
    let mut driver = port::open_v1(path, None)?;
    let reply = readback(&mut driver, request)?;
    match field {
        Some((n, _)) => {
            let value = reply
                .field(n)
                .ok_or_else(|| format!("no {n} in the reply"))?;
            say!("{n}: {value}");
        }
        None => say!("{}", reply_json(&reply)),
    }
    Ok(())
}

/// `chassis set FIELD VALUE` on v1.0.0: reads the settings frame that holds FIELD, writes it
/// back with FIELD changed, and confirms it by a readback.
pub fn set(path: &str, name: &str, value: &str) -> Result<(), String> {
    let Some((field, request)) = FIELDS.iter().find(|(n, _)| *n == name).copied() else {
        return Err(format!(
            "{name:?} is not a v1.0.0 setting that can be written: give one of {}",
            FIELDS.map(|(n, _)| n).join(", ")
        ));
    };
    let value = i64::from(crate::value::parse_i32(
        value,
        field,
        0,
        i64::from(u16::MAX),
    )?);
    let value = u16::try_from(value).map_err(|_| format!("{field}: {value} is out of range"))?;
    let mut driver = port::open_v1(path, None)?;
    let reply = readback(&mut driver, request)?;
    let settings = reply.with_field(field, value).map_err(|e| match e {
        FieldError::OutOfRange => {
            format!("{field}: {value} is out of range (0..=255, a bit field)")
        }
        FieldError::NotHere => format!("{field}: the board's readback does not hold it"),
    })?;
    driver
        .write_settings(settings)
        .map_err(|e| explain(&driver, e))?;
    say!("{field}: {value} (written and read back)");
    Ok(())
}

/// The three settings frames of a v1.0.0 board, as `settings --save` writes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Saved {
    /// Always "v1.0.0": a file of the other generation is refused.
    firmware: Mark,
    system: SystemSettings,
    geometry: Geometry,
    pid: Pid,
}

/// The firmware mark of a settings file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
enum Mark {
    /// v1.0.0.
    #[serde(rename = "v1.0.0")]
    V1,
}

/// `chassis settings [--save FILE | --restore FILE]` on v1.0.0.
pub fn settings(path: &str, save: Option<&str>, restore: Option<&str>) -> Result<(), String> {
    if let Some(file) = restore {
        let text = crate::input::read_text(file, crate::input::SETTINGS_MAX, "settings file")?;
        let saved: Saved = serde_json::from_str(&text).map_err(|e| {
            format!("{file} is not a v1.0.0 settings file (`chassis settings --save` on a v1.0.0 board writes one): {e}")
        })?;
        let mut driver = port::open_v1(path, None)?;
        for settings in [
            Settings::System(saved.system),
            Settings::Geometry(saved.geometry),
            Settings::Pid(saved.pid),
        ] {
            driver.write_settings(settings).map_err(|e| {
                format!(
                    "{} (the frames before it were written and confirmed)",
                    explain(&driver, e)
                )
            })?;
        }
        say!(
            "restored from {file}: system, geometry and PID written, each confirmed by its readback (v1.0.0 stores nothing in flash: they last until power-off)"
        );
        return Ok(());
    }
    // A file that cannot be written fails before the board is asked anything.
    let out = save.map(crate::newfile::NewFile::create).transpose()?;
    let mut driver = port::open_v1(path, None)?;
    let system = readback(&mut driver, Readback::System)?.system();
    let geometry = readback(&mut driver, Readback::Geometry)?.geometry();
    let pid = readback(&mut driver, Readback::Pid)?.pid();
    let (Some(system), Some(geometry), Some(pid)) = (system, geometry, pid) else {
        return Err("a readback came back as another frame".into());
    };
    let saved = Saved {
        firmware: Mark::V1,
        system,
        geometry,
        pid,
    };
    let json = serde_json::to_string_pretty(&saved).map_err(|e| e.to_string())?;
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

/// How long `chassis stop` waits for the board's telemetry after the forced stop (it sends a
/// frame every 39-47 ms).
const STOP_EVIDENCE: Duration = Duration::from_millis(300);

/// `chassis stop` on v1.0.0: the forced stop, then the board's next telemetry frame as the
/// evidence that it is there (its velocity said); without one, the stop is not said to have
/// worked.
pub fn stop(path: &str) -> Result<(), String> {
    let mut driver = port::open_v1(path, None)?;
    let stopped = stopping::stop(&mut driver);
    if let Stopped::NotSent(_) = stopped {
        return Err(stopped.words::<DriverCore>());
    }
    let sent_at = driver.uart().now_ms();
    let until = Instant::now() + STOP_EVIDENCE;
    while Instant::now() < until {
        if let Err(e) = driver.poll() {
            return Err(format!(
                "the forced stop was sent, but not confirmed: {}",
                explain(&driver, e)
            ));
        }
        if let Some(t) = driver.core().telemetry().filter(|t| t.at_ms > sent_at) {
            let [vx, vy, wz] = t.value.velocity;
            if [vx, vy, wz] == [0; 3] {
                say!(
                    "stopped (the forced stop was sent; the board's next frame reports it standing still)"
                );
            } else {
                say!(
                    "the forced stop was sent; the board's next frame still reports vx {} m/s, vy {} m/s, wz {} rad/s (slowing down?)",
                    f64::from(vx) / 1000.0,
                    f64::from(vy) / 1000.0,
                    f64::from(wz) / 1000.0
                );
            }
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    Err(format!(
        "the forced stop was sent but not confirmed: {}",
        stopping::unheard(&driver).unwrap_or_else(|| format!(
            "no frame came from the board within {} ms after it",
            STOP_EVIDENCE.as_millis()
        ))
    ))
}

/// A speed in m/s (or rad/s) as the board's thousandths, range-checked.
pub fn milli(value: f64, name: &str, unit: &str) -> Result<i16, String> {
    let m = (value * 1000.0).round();
    if !m.is_finite() || !(f64::from(i16::MIN)..=f64::from(i16::MAX)).contains(&m) {
        // A huge value in exponent form, not 300 digits.
        let shown = if value.abs() < 1e6 {
            format!("{value}")
        } else {
            format!("{value:e}")
        };
        return Err(format!(
            "--{name}: {shown} {unit} is out of range (±32.767, the frame's 16 bits in thousandths)"
        ));
    }
    Ok(m as i16)
}

/// `chassis drive --vx --vy --wz --for S` on v1.0.0: the velocity re-sent every 50 ms, then
/// the forced stop; on a signal, the forced stop at once.
pub fn drive(path: &str, velocity: BodyVelocity, seconds: f64) -> Result<(), String> {
    if !(0.0..=600.0).contains(&seconds) {
        return Err(format!("--for: {seconds} s is out of range (0..=600)"));
    }
    let seconds = seconds + 0.0;
    let mut driver = port::open_v1(path, None)?;
    crate::ending::before_motion()?;
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(seconds);
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
            if driver.poll().map_err(|e| explain(&driver, e))?.is_none() {
                std::thread::sleep(Duration::from_millis(2));
            }
            if driver.core().failsafe_stops() > 0 {
                return Err(crate::stopping::failsafe_words(
                    &driver,
                    "sent the forced stop",
                ));
            }
        }
        Ok(format!("drove {seconds} s, stopped (forced stop)"))
    })();
    let stopped = stopping::stop(&mut driver);
    let words = stopped.words::<DriverCore>();
    if let Some(end) = ending::ended() {
        return Err(format!("{}: {words}", end.words()));
    }
    match (ended, stopped) {
        (Ok(line), Stopped::Confirmed) => {
            say!("{line}");
            Ok(())
        }
        (Ok(line), _) => Err(format!("{line}, but {words}")),
        (Err(e), _) => Err(format!("{e}; {words}")),
    }
}

/// The line for a command v1.0.0 has no frame for: nothing was sent.
fn not_here(command: &str, why: &str) -> String {
    format!("{command}: this board runs the v1.0.0 firmware, and {why}")
}

/// The v1.0.0 firmware (`7B … BCC 7D` frames): the commands as it does them.
pub struct V1;

impl Generation for V1 {
    fn get(&self, path: &str, name: &str) -> Result<(), String> {
        get(path, name)
    }

    fn set(&self, path: &str, args: &SetArgs) -> Result<(), String> {
        if args.cutoff.is_some() {
            return Err(format!(
                "set {}: one value on v1.0.0 (the cut-off is battery-range's, a 2020 register)",
                args.register
            ));
        }
        set(path, &args.register, &args.value)
    }

    fn settings(
        &self,
        path: &str,
        save: Option<&str>,
        restore: Option<&str>,
    ) -> Result<(), String> {
        settings(path, save, restore)
    }

    fn save(&self, _path: &str) -> Result<(), String> {
        Err(not_here(
            "save",
            "v1.0.0 has no frame that stores settings in flash (settings last until power-off: `chassis settings --save FILE` keeps them in a file)",
        ))
    }

    fn calibrate_gyro(&self, _path: &str) -> Result<(), String> {
        Err(not_here(
            "calibrate-gyro",
            "v1.0.0 has no gyro calibration frame",
        ))
    }

    fn stop(&self, path: &str) -> Result<(), String> {
        stop(path)
    }

    fn drive(&self, path: &str, args: &DriveArgs) -> Result<(), String> {
        if args.raw() {
            return Err("drive: --x/--y/--z are the 2020 firmware's raw units; this board runs v1.0.0: give --vx --vy (m/s) --wz (rad/s)".into());
        }
        let velocity = BodyVelocity::new(
            milli(args.vx.unwrap_or(0.0), "vx", "m/s")?,
            milli(args.vy.unwrap_or(0.0), "vy", "m/s")?,
            milli(args.wz.unwrap_or(0.0), "wz", "rad/s")?,
        );
        drive(path, velocity, args.seconds)
    }

    fn turn(&self, _path: &str, _degrees: f64) -> Result<(), String> {
        Err(not_here(
            "turn",
            "v1.0.0 has no turn by an angle (its protocol has none): `chassis drive --wz RAD/S --for SECONDS` turns at a rate",
        ))
    }

    fn monitor(&self, path: &str, drive: bool, speed: &str) -> Result<(), String> {
        let speed = crate::value::parse_i32(speed, "speed", 1, 2_000)
            .map_err(|e| format!("{e}: on v1.0.0 the speed is in mm/s"))?;
        monitor::run(path, drive, speed)
    }

    fn check(&self, path: &str, args: &CheckArgs) -> Result<(), (String, u8)> {
        if args.drive_type.is_some() {
            return Err((
                not_here(
                    "check --drive-type",
                    "it has no drive-type register (each velocity frame carries the vendor's type byte): run `chassis check` without it",
                ),
                1,
            ));
        }
        check::check(path, args.no_motion, args.yes)
    }
}
