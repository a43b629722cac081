//! The 2020 firmware's commands (master → board, `FF FE`): the motion frames (`Velocity`,
//! `Turn`, `Motors`) and the settings frames (`Read`, `Write`, `Action`), and the class of a
//! command a parser found ([`uplink`]).

use crate::args::Int;
use crate::errors::FrameError;
use crate::frames::{U16, bad, ints, same_fields};
use chassis_protocol as p;
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::ops::RangeInclusive;

/// A 2020 speed's range: 16 bits and a direction bit.
const SPEED: RangeInclusive<i128> = -65_535..=65_535;

/// Each of `named` (a field's name, its value) in the range of a 2020 speed (`ValueError`
/// naming the field).
fn speeds<const N: usize>(named: [(&str, Int); N]) -> PyResult<[i32; N]> {
    let mut out = [0; N];
    for (o, (name, v)) in out.iter_mut().zip(named) {
        *o = v.within(name, SPEED)?;
    }
    Ok(out)
}

/// A body velocity (2020 firmware, mode 01): X sideways, Y forward, Z rotation, each ±65535 in
/// the board's raw units.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Velocity {
    /// Sideways.
    #[pyo3(get)]
    pub x: i32,
    /// Forward.
    #[pyo3(get)]
    pub y: i32,
    /// Rotation.
    #[pyo3(get)]
    pub z: i32,
}

#[pymethods]
impl Velocity {
    #[new]
    #[pyo3(
        signature = (x = Int::ZERO, y = Int::ZERO, z = Int::ZERO),
        text_signature = "(x=0, y=0, z=0)"
    )]
    fn new(x: Int, y: Int, z: Int) -> PyResult<Self> {
        let [x, y, z] = speeds([("x", x), ("y", y), ("z", z)])?;
        Ok(Velocity { x, y, z })
    }

    /// The frame's 10 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner().encode())
    }

    /// A velocity frame's fields (`FrameError` if the bytes are not one).
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        p::Velocity::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!("Velocity(x={}, y={}, z={})", self.x, self.y, self.z)
    }
}

impl Velocity {
    /// The crate's velocity of `x`, `y`, `z`, range-checked (`ValueError`).
    pub fn new_checked(x: Int, y: Int, z: Int) -> PyResult<p::Velocity> {
        Velocity::new(x, y, z).map(|v| v.inner())
    }

    /// The crate's velocity.
    pub fn inner(&self) -> p::Velocity {
        p::Velocity::new(self.x, self.y, self.z)
    }
}

same_fields!(Velocity from p::Velocity { x, y, z });

/// A relative turn (2020 firmware, mode 01 with the angle bit): the board **adds** it to the
/// angle it still has to turn. Encoding one is sending it: `Chassis.turn` sends it once.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Turn {
    /// The angle, in 0.1°.
    #[pyo3(get)]
    pub deci_degrees: i32,
    /// Sideways velocity while turning.
    #[pyo3(get)]
    pub x: i32,
    /// Forward velocity while turning.
    #[pyo3(get)]
    pub y: i32,
}

#[pymethods]
impl Turn {
    /// The angle in 0.1° (±65535: 16 bits and a direction bit) and the velocity while
    /// turning (±65535 each); out of range is a `ValueError`, not clamped.
    #[new]
    #[pyo3(
        signature = (deci_degrees, x = Int::ZERO, y = Int::ZERO),
        text_signature = "(deci_degrees, x=0, y=0)"
    )]
    fn new(deci_degrees: Int, x: Int, y: Int) -> PyResult<Self> {
        let [deci_degrees, x, y] = speeds([("deci_degrees", deci_degrees), ("x", x), ("y", y)])?;
        Ok(Turn { deci_degrees, x, y })
    }

    /// The frame's 10 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(
            py,
            &p::Turn::new(self.x, self.y, self.deci_degrees).encode(),
        )
    }

    /// A turn frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        p::Turn::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!(
            "Turn(deci_degrees={}, x={}, y={})",
            self.deci_degrees, self.x, self.y
        )
    }
}

same_fields!(Turn from p::Turn { deci_degrees, x, y });

/// Each motor on its own (2020 firmware, modes 02 / 03): closed loop (speeds ±65535) or open
/// loop (duty in 0.01 %, ±10000).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Motors {
    /// MOTO1..MOTO4.
    #[pyo3(get)]
    pub values: [i32; 4],
    /// Duty cycles (mode 03) instead of speeds (mode 02).
    #[pyo3(get)]
    pub open_loop: bool,
}

#[pymethods]
impl Motors {
    #[new]
    #[pyo3(signature = (values, open_loop = false))]
    fn new(values: [Bound<'_, PyAny>; 4], open_loop: bool) -> PyResult<Self> {
        Self::new_checked(ints(values, "values")?, open_loop)
    }

    /// The frame's 12 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner().encode())
    }

    /// A motors frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        p::Motors::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!(
            "Motors(values={:?}, open_loop={})",
            self.values,
            if self.open_loop { "True" } else { "False" }
        )
    }
}

impl Motors {
    /// Each value range-checked (`ValueError`): speeds ±65535, duty ±10000 (0.01 %).
    pub fn new_checked(values: [i64; 4], open_loop: bool) -> PyResult<Self> {
        let limit: i64 = if open_loop { 10_000 } else { 65_535 };
        let mut checked = [0i32; 4];
        for (i, (out, v)) in checked.iter_mut().zip(values).enumerate() {
            if !(-limit..=limit).contains(&v) {
                return Err(PyValueError::new_err(format!(
                    "values[{i}] = {v} is out of range (±{limit}{})",
                    if open_loop { ", duty in 0.01 %" } else { "" }
                )));
            }
            *out = v as i32;
        }
        Ok(Motors {
            values: checked,
            open_loop,
        })
    }

    /// The crate's motors frame.
    pub fn inner(&self) -> p::Motors {
        if self.open_loop {
            p::Motors::open_loop_duty(self.values)
        } else {
            p::Motors::closed_loop(self.values)
        }
    }
}

impl From<p::Motors> for Motors {
    fn from(m: p::Motors) -> Self {
        Motors {
            values: m.values,
            open_loop: m.control == p::MotorLoop::Open,
        }
    }
}

/// A register read (2020 firmware, 2C / 2D).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Read {
    /// The register, as the `chassis` command spells it (`max-speed`, …).
    #[pyo3(get)]
    pub register: String,
}

/// The register of a name, or a `ValueError` listing the names.
pub fn register(name: &str) -> PyResult<p::Register> {
    p::Register::from_name(name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{name:?} is not a register of the 2020 firmware: give one of {}",
            p::Register::ALL.map(p::Register::name).join(", ")
        ))
    })
}

#[pymethods]
impl Read {
    #[new]
    fn new(register: &str) -> PyResult<Self> {
        self::register(register)?;
        Ok(Read {
            register: register.to_string(),
        })
    }

    /// The frame's 10 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        Ok(PyBytes::new(
            py,
            &p::Setting::Read(register(&self.register)?).encode(),
        ))
    }

    /// A read frame's register.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        match p::Setting::decode(data).map_err(bad)? {
            p::Setting::Read(r) => Ok(r.into()),
            _ => Err(FrameError::new_err("a settings frame, not a read")),
        }
    }

    fn __repr__(&self) -> String {
        format!("Read({:?})", self.register)
    }
}

impl From<p::Register> for Read {
    fn from(r: p::Register) -> Self {
        Read {
            register: r.name().to_string(),
        }
    }
}

/// A register write (2020 firmware, 2B). The board does not answer writes.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Write {
    /// The register.
    #[pyo3(get)]
    pub register: String,
    /// The raw value (battery-range: full << 16 | cut-off).
    #[pyo3(get)]
    pub value: u32,
}

/// The crate's write of `register` = `value`, or a `ValueError`.
pub fn write_of(name: &str, value: u32) -> PyResult<p::Write> {
    let r = register(name)?;
    p::Write::from_value(r, value).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{name} = {value} cannot be written (read-only, or out of its range)"
        ))
    })
}

#[pymethods]
impl Write {
    #[new]
    fn new(register: &str, value: Int) -> PyResult<Self> {
        let value = value.within(register, 0..=i128::from(u32::MAX))?;
        write_of(register, value)?;
        Ok(Write {
            register: register.to_string(),
            value,
        })
    }

    /// The frame's 10 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let w = write_of(&self.register, self.value)?;
        Ok(PyBytes::new(py, &p::Setting::Write(w).encode()))
    }

    /// A write frame's register and value.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        match p::Setting::decode(data).map_err(bad)? {
            p::Setting::Write(w) => Ok(w.into()),
            _ => Err(FrameError::new_err("a settings frame, not a write")),
        }
    }

    fn __repr__(&self) -> String {
        format!("Write({:?}, {})", self.register, self.value)
    }
}

impl From<p::Write> for Write {
    fn from(w: p::Write) -> Self {
        Write {
            register: w.register().name().to_string(),
            value: w.value(),
        }
    }
}

/// An action (2020 firmware, 2A): 1 load stored, 2 load defaults, 3 store in flash, 4 gyro
/// compensation off, 5 on, 6 calibrate the gyro again (30 s).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Action {
    /// The action's number.
    #[pyo3(get)]
    pub number: u16,
}

#[pymethods]
impl Action {
    #[new]
    fn new(number: Int) -> PyResult<Self> {
        Ok(Action {
            number: number.within("number", U16)?,
        })
    }

    /// The frame's 10 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(
            py,
            &p::Setting::Action(p::Action::from_number(self.number)).encode(),
        )
    }

    /// An action frame's number.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        match p::Setting::decode(data).map_err(bad)? {
            p::Setting::Action(a) => Ok(a.into()),
            _ => Err(FrameError::new_err("a settings frame, not an action")),
        }
    }

    fn __repr__(&self) -> String {
        format!("Action({})", self.number)
    }
}

impl From<p::Action> for Action {
    fn from(a: p::Action) -> Self {
        Action { number: a.number() }
    }
}

/// A 2020 master → board frame as its Python class.
pub fn uplink(py: Python<'_>, frame: p::Command) -> PyResult<Py<PyAny>> {
    match frame {
        p::Command::Velocity(v) => Velocity::from(v).into_py_any(py),
        p::Command::Turn(t) => Turn::from(t).into_py_any(py),
        p::Command::Motors(m) => Motors::from(m).into_py_any(py),
        p::Command::Setting(p::Setting::Read(r)) => Read::from(r).into_py_any(py),
        p::Command::Setting(p::Setting::Write(w)) => Write::from(w).into_py_any(py),
        p::Command::Setting(p::Setting::Action(a)) => Action::from(a).into_py_any(py),
        p::Command::Setting(p::Setting::Raw { code, value, tail }) => {
            let d = PyDict::new(py);
            d.set_item("frame", "setting-raw")?;
            d.set_item("code", code)?;
            d.set_item("value", value)?;
            d.set_item("tail", tail)?;
            d.into_py_any(py)
        }
    }
}
