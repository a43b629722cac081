//! The v1.0.0 chassis's readbacks and settings frames: a readback or one of its fields read by
//! name, one field written (its frame read, written with the field changed, read back), the
//! three settings frames read as the `chassis settings` JSON and written back from it.

use super::ChassisV1;
use crate::args::Int;
use crate::driver::unconfirmed;
use crate::errors::ChassisError;
use crate::frames;
use chassis_protocol::driver::v1;
use chassis_protocol::v1 as frame;
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};
use serde_json::Value;

/// The keys of the dict `ChassisV1.settings()` gives.
const KEYS: [&str; 4] = ["firmware", "system", "geometry", "pid"];

/// One part of a v1.0.0 settings dict (`parse`d), every key a field of it: a key that is none
/// (a typo) is a `ValueError`, and nothing is written. `show` gives the fields back, for the
/// message.
fn section<T>(
    value: &Value,
    name: &str,
    parse: impl Fn(Value) -> Result<T, serde_json::Error>,
    show: impl Fn(&T) -> Result<Value, serde_json::Error>,
) -> PyResult<T> {
    let part = value.get(name).cloned().unwrap_or(Value::Null);
    let bad = |e: &dyn std::fmt::Display| {
        PyValueError::new_err(format!(
            "not v1.0.0 settings: {name}: {e}; nothing was written"
        ))
    };
    let parsed = parse(part.clone()).map_err(|e| bad(&e))?;
    // Every field is needed: a key the fields do without is none of them.
    if let Some(map) = part.as_object() {
        for key in map.keys() {
            let mut without = map.clone();
            without.remove(key);
            if parse(Value::Object(without)).is_ok() {
                let fields = show(&parsed)
                    .ok()
                    .and_then(|v| v.as_object().map(|m| m.keys().cloned().collect::<Vec<_>>()))
                    .unwrap_or_default();
                return Err(bad(&format!(
                    "{key:?} is not one of its fields ({})",
                    fields.join(", ")
                )));
            }
        }
    }
    Ok(parsed)
}

/// The three settings frames of a dict as `ChassisV1.settings()` gives: its firmware and keys
/// checked, each part parsed; a `ValueError` for anything else, nothing written.
fn settings_of(value: &Value) -> PyResult<[frame::Settings; 3]> {
    if value.get("firmware").and_then(|f| f.as_str()) != Some("v1.0.0") {
        return Err(PyValueError::new_err(
            "not v1.0.0 settings: the dict must have \"firmware\": \"v1.0.0\" (as settings() gives)",
        ));
    }
    if let Some(key) = value
        .as_object()
        .and_then(|m| m.keys().find(|k| !KEYS.contains(&k.as_str())))
    {
        return Err(PyValueError::new_err(format!(
            "not v1.0.0 settings: no key {key:?} in them (they are {}, as settings() gives); nothing was written",
            KEYS.join(", ")
        )));
    }
    Ok([
        frame::Settings::System(section(value, "system", serde_json::from_value, |t| {
            serde_json::to_value(t)
        })?),
        frame::Settings::Geometry(section(value, "geometry", serde_json::from_value, |t| {
            serde_json::to_value(t)
        })?),
        frame::Settings::Pid(section(value, "pid", serde_json::from_value, |t| {
            serde_json::to_value(t)
        })?),
    ])
}

/// `ValueError`: `name` is no settings field (`readbacks`: nor a readback).
fn not_a_field(name: &str, readbacks: bool) -> PyErr {
    let fields = frame::FIELDS.map(|(n, _)| n).join(", ");
    PyValueError::new_err(if readbacks {
        format!(
            "{name:?} is not a v1.0.0 readback or settings field: give one of {}, or {fields}",
            frame::Readback::ALL.map(frame::Readback::name).join(", "),
        )
    } else {
        format!("{name:?} is not a v1.0.0 settings field: give one of {fields}")
    })
}

impl ChassisV1 {
    /// One readback: the board's reply.
    fn readback(&self, py: Python<'_>, r: frame::Readback) -> PyResult<frame::Reply> {
        match self.link.request(py, v1::Request::Read(r))? {
            v1::Outcome::Reply(reply) => Ok(reply),
            v1::Outcome::Done => Err(ChassisError::new_err("the readback ended with no reply")),
        }
    }

    /// A settings frame written, 100 ms after the previous one, and confirmed by its readback.
    fn write_settings(&self, py: Python<'_>, s: frame::Settings) -> PyResult<()> {
        self.link.request(py, v1::Request::Write(s)).map(|_| ())
    }

    /// `ChassisV1.read`: a readback's fields (a dict), or one field's value.
    pub(super) fn read_name<'py>(
        &self,
        py: Python<'py>,
        name: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let Some(r) = frame::Readback::from_name(name) {
            let reply = self.readback(py, r)?;
            return Ok(frames::reply_fields(py, &reply)?.into_any());
        }
        let r = frame::field_readback(name).ok_or_else(|| not_a_field(name, true))?;
        let reply = self.readback(py, r)?;
        let value = reply
            .field(name)
            .ok_or_else(|| ChassisError::new_err(format!("no {name} in the board's reply")))?;
        value.into_bound_py_any(py)
    }

    /// `ChassisV1.write`: the field's frame read back, written with it changed, confirmed.
    pub(super) fn write_field(
        &self,
        py: Python<'_>,
        name: &str,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        if value.is_instance_of::<PyBool>() {
            return Err(PyTypeError::new_err(format!(
                "{name}: {value} is a bool, not a value: give an int"
            )));
        }
        let value: u16 = value.extract::<Int>()?.within(name, 0..=65_535)?;
        let r = frame::field_readback(name).ok_or_else(|| not_a_field(name, false))?;
        let reply = self.readback(py, r)?;
        let settings = reply.with_field(name, value).map_err(|e| match e {
            frame::FieldError::OutOfRange => {
                PyValueError::new_err(format!("{name} = {value} is out of range (0..=255)"))
            }
            frame::FieldError::NotHere => {
                ChassisError::new_err(format!("the board's readback does not hold {name}"))
            }
        })?;
        self.write_settings(py, settings).map_err(|e| {
            unconfirmed(
                py,
                &format!("{name}: {value} was written (the frame went out), but not confirmed"),
                e,
            )
        })
    }

    /// `ChassisV1.settings`: the three settings frames read back, as the `chassis settings`
    /// JSON.
    pub(super) fn settings_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut got = Vec::new();
        for r in [
            frame::Readback::System,
            frame::Readback::Geometry,
            frame::Readback::Pid,
        ] {
            got.push(self.readback(py, r)?);
        }
        let (Some(system), Some(geometry), Some(pid)) = (
            got.first().and_then(frame::Reply::system),
            got.get(1).and_then(frame::Reply::geometry),
            got.get(2).and_then(frame::Reply::pid),
        ) else {
            return Err(ChassisError::new_err(
                "a readback came back as another frame",
            ));
        };
        let value = serde_json::json!({
            "firmware": "v1.0.0",
            "system": system,
            "geometry": geometry,
            "pid": pid,
        });
        crate::json::to_dict(py, &value)
    }

    /// `ChassisV1.restore`: the dict checked (nothing written if anything is wrong), then each
    /// settings frame written and confirmed.
    pub(super) fn restore_settings(
        &self,
        py: Python<'_>,
        settings: &Bound<'_, PyDict>,
    ) -> PyResult<()> {
        let value = crate::json::from_py(settings.as_any())?;
        for (i, s) in settings_of(&value)?.into_iter().enumerate() {
            self.write_settings(py, s).map_err(|e| {
                let before = if i == 0 {
                    String::new()
                } else {
                    " (the frames before it were written and confirmed)".into()
                };
                unconfirmed(
                    py,
                    &format!(
                        "the {} settings were written (the frame went out), but not confirmed{before}",
                        s.readback().name()
                    ),
                    e,
                )
            })?;
        }
        Ok(())
    }
}
