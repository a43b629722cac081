//! A v1.0.0 board's settings: `get` (a whole readback as JSON, or one field), `set` (the frame
//! that holds the field read, written back with it changed, confirmed by a readback) and
//! `settings` (the system, geometry and PID frames saved to a file or restored from one).

use super::explain;
use crate::port::{self, BoardV1};
use chassis_protocol::driver::v1::Settings;
use chassis_protocol::v1::{FIELDS, FieldError, Geometry, Pid, Readback, Reply, SystemSettings};
use serde::{Deserialize, Serialize};

/// The names `get` takes on v1.0.0, for messages.
pub fn names() -> String {
    let frames = Readback::ALL.map(Readback::name).join(", ");
    let fields: Vec<&str> = FIELDS.iter().map(|(n, _)| *n).collect();
    format!("{frames}, or one field: {}", fields.join(", "))
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
    crate::newfile::put_json(out, &json)
}
