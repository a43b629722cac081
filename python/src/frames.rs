//! The frames of both generations as Python classes: fields, `==`, `repr`, `encode() -> bytes`,
//! `decode(bytes)`. Every class wraps the crate's own type: no frame is laid out twice.

use crate::args::Int;
use crate::errors::FrameError;
use chassis_protocol as p;
use chassis_protocol::v1;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

/// A frame error from the crate as `chassis.FrameError`.
fn bad(e: impl core::fmt::Display) -> PyErr {
    FrameError::new_err(e.to_string())
}

// ----- 2020: master → board -----

/// A 2020 speed's range: 16 bits and a direction bit.
const SPEED: std::ops::RangeInclusive<i128> = -65_535..=65_535;

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
        Ok(Velocity {
            x: x.within("x", SPEED)?,
            y: y.within("y", SPEED)?,
            z: z.within("z", SPEED)?,
        })
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

impl From<p::Velocity> for Velocity {
    fn from(v: p::Velocity) -> Self {
        Velocity {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

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
        Ok(Turn {
            deci_degrees: deci_degrees.within("deci_degrees", SPEED)?,
            x: x.within("x", SPEED)?,
            y: y.within("y", SPEED)?,
        })
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
        let t = p::Turn::decode(data).map_err(bad)?;
        Ok(Turn {
            deci_degrees: t.deci_degrees,
            x: t.x,
            y: t.y,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Turn(deci_degrees={}, x={}, y={})",
            self.deci_degrees, self.x, self.y
        )
    }
}

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
        let m = p::Motors::decode(data).map_err(bad)?;
        Ok(Motors {
            values: m.values,
            open_loop: m.control == p::MotorLoop::Open,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Motors(values={:?}, open_loop={})",
            self.values,
            if self.open_loop { "True" } else { "False" }
        )
    }
}

/// The ranges of the frames' fields.
const I16: std::ops::RangeInclusive<i128> = -32_768..=32_767;
const U16: std::ops::RangeInclusive<i128> = 0..=65_535;
const U8: std::ops::RangeInclusive<i128> = 0..=255;

/// Each of `values` in `range` (`ValueError` naming `name[i]`).
fn each<T: TryFrom<i128> + Copy + Default, const N: usize>(
    values: &[Int; N],
    name: &str,
    range: std::ops::RangeInclusive<i128>,
) -> PyResult<[T; N]> {
    let mut out = [T::default(); N];
    for (i, (o, v)) in out.iter_mut().zip(values).enumerate() {
        *o = v.within(&format!("{name}[{i}]"), range.clone())?;
    }
    Ok(out)
}

/// Python ints as `i64`, one too large for it a `ValueError` (out of range), not an
/// `OverflowError`; anything but an int a `TypeError`.
pub fn ints<const N: usize>(values: [Bound<'_, PyAny>; N], what: &str) -> PyResult<[i64; N]> {
    let mut out = [0i64; N];
    for (i, (o, v)) in out.iter_mut().zip(values).enumerate() {
        *o = v.extract::<i64>().map_err(|e| {
            if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(v.py()) {
                pyo3::exceptions::PyValueError::new_err(format!(
                    "{what}[{i}] = {v} is out of range"
                ))
            } else {
                e
            }
        })?;
    }
    Ok(out)
}

impl Motors {
    /// Each value range-checked (`ValueError`): speeds ±65535, duty ±10000 (0.01 %).
    pub fn new_checked(values: [i64; 4], open_loop: bool) -> PyResult<Self> {
        let limit: i64 = if open_loop { 10_000 } else { 65_535 };
        let mut checked = [0i32; 4];
        for (i, (out, v)) in checked.iter_mut().zip(values).enumerate() {
            if !(-limit..=limit).contains(&v) {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
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
        pyo3::exceptions::PyValueError::new_err(format!(
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
            p::Setting::Read(r) => Ok(Read {
                register: r.name().to_string(),
            }),
            _ => Err(FrameError::new_err("a settings frame, not a read")),
        }
    }

    fn __repr__(&self) -> String {
        format!("Read({:?})", self.register)
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
        pyo3::exceptions::PyValueError::new_err(format!(
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
            p::Setting::Write(w) => Ok(Write {
                register: w.register().name().to_string(),
                value: w.value(),
            }),
            _ => Err(FrameError::new_err("a settings frame, not a write")),
        }
    }

    fn __repr__(&self) -> String {
        format!("Write({:?}, {})", self.register, self.value)
    }
}

// ----- 2020: board → master -----

/// An IMU frame (2020 firmware, `FF FA`, 100 Hz): raw accelerometer and gyro, rolling count.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Imu {
    /// Accelerometer x, y, z (raw).
    #[pyo3(get)]
    pub accel: [i16; 3],
    /// Gyro x, y, z (raw).
    #[pyo3(get)]
    pub gyro: [i16; 3],
    /// Rolling count.
    #[pyo3(get)]
    pub seq: u8,
}

/// An encoder frame (2020 firmware, `FF FB`, 25 Hz).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Encoders {
    /// MOTO1..MOTO4 as the board sends them (whether a count per period or a running total
    /// is not stated: spec A5).
    #[pyo3(get)]
    pub ticks: [i16; 4],
    /// Rolling count.
    #[pyo3(get)]
    pub seq: u8,
}

/// A battery frame (2020 firmware, `FF FC`, 1 Hz).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Battery {
    /// Voltage in 0.01 V.
    #[pyo3(get)]
    pub centivolts: u16,
    /// Charge in percent.
    #[pyo3(get)]
    pub percent: u16,
    /// Rolling count.
    #[pyo3(get)]
    pub seq: u8,
}

/// A reply to a register read (2020 firmware, `#`).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Reply {
    /// The register it answers (`None`: a code of no register).
    #[pyo3(get)]
    pub register: Option<String>,
    /// Its code byte.
    #[pyo3(get)]
    pub code: u8,
    /// The raw value.
    #[pyo3(get)]
    pub value: u32,
}

macro_rules! downlink_methods {
    ($ty:ident, $inner:path, $repr:expr, { $($new:tt)* }) => {
        #[pymethods]
        impl $ty {
            $($new)*

            /// The frame's bytes.
            fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
                PyBytes::new(py, &self.inner().encode())
            }

            /// The fields of a frame of this kind (`FrameError` if the bytes are not one).
            #[staticmethod]
            fn decode(data: &[u8]) -> PyResult<Self> {
                <$inner>::decode(data).map(Self::from).map_err(bad)
            }

            fn __repr__(&self) -> String {
                let f: fn(&$ty) -> String = $repr;
                f(self)
            }
        }
    };
}

impl Imu {
    fn inner(&self) -> p::Imu {
        p::Imu {
            accel: self.accel,
            gyro: self.gyro,
            seq: self.seq,
        }
    }
}
impl From<p::Imu> for Imu {
    fn from(v: p::Imu) -> Self {
        Imu {
            accel: v.accel,
            gyro: v.gyro,
            seq: v.seq,
        }
    }
}
downlink_methods!(
    Imu,
    p::Imu,
    |f| format!("Imu(accel={:?}, gyro={:?}, seq={})", f.accel, f.gyro, f.seq),
    {
        #[new]
        #[pyo3(signature = (accel, gyro, seq))]
        fn new(accel: [Int; 3], gyro: [Int; 3], seq: Int) -> PyResult<Self> {
            Ok(Imu {
                accel: each(&accel, "accel", I16)?,
                gyro: each(&gyro, "gyro", I16)?,
                seq: seq.within("seq", U8)?,
            })
        }
    }
);

impl Encoders {
    fn inner(&self) -> p::Encoders {
        p::Encoders {
            ticks: self.ticks,
            seq: self.seq,
        }
    }
}
impl From<p::Encoders> for Encoders {
    fn from(v: p::Encoders) -> Self {
        Encoders {
            ticks: v.ticks,
            seq: v.seq,
        }
    }
}
downlink_methods!(
    Encoders,
    p::Encoders,
    |f| format!("Encoders(ticks={:?}, seq={})", f.ticks, f.seq),
    {
        #[new]
        fn new(ticks: [Int; 4], seq: Int) -> PyResult<Self> {
            Ok(Encoders {
                ticks: each(&ticks, "ticks", I16)?,
                seq: seq.within("seq", U8)?,
            })
        }
    }
);

impl Battery {
    fn inner(&self) -> p::Battery {
        p::Battery {
            centivolts: self.centivolts,
            percent: self.percent,
            seq: self.seq,
        }
    }
}
impl From<p::Battery> for Battery {
    fn from(v: p::Battery) -> Self {
        Battery {
            centivolts: v.centivolts,
            percent: v.percent,
            seq: v.seq,
        }
    }
}
downlink_methods!(
    Battery,
    p::Battery,
    |f| format!(
        "Battery(centivolts={}, percent={}, seq={})",
        f.centivolts, f.percent, f.seq
    ),
    {
        #[new]
        fn new(centivolts: Int, percent: Int, seq: Int) -> PyResult<Self> {
            Ok(Battery {
                centivolts: centivolts.within("centivolts", U16)?,
                percent: percent.within("percent", U16)?,
                seq: seq.within("seq", U8)?,
            })
        }
    }
);

impl Reply {
    fn inner(&self) -> p::Reply {
        p::Reply {
            code: self.code,
            value: self.value,
        }
    }
}
impl From<p::Reply> for Reply {
    fn from(v: p::Reply) -> Self {
        Reply {
            register: v.register().map(|r| r.name().to_string()),
            code: v.code,
            value: v.value,
        }
    }
}
downlink_methods!(
    Reply,
    p::Reply,
    |f| format!(
        "Reply(register={}, value={})",
        f.register
            .as_deref()
            .map_or_else(|| format!("{:#04x}", f.code), |r| format!("{r:?}")),
        f.value
    ),
    {
        /// The reply to a read of `register` carrying `value`.
        #[new]
        fn new(register: &str, value: Int) -> PyResult<Self> {
            let r = self::register(register)?;
            let value = value.within("value", 0..=i128::from(u32::MAX))?;
            Ok(p::Reply::new(r, value).into())
        }
    }
);

/// A 2020 board → master frame as its Python class.
pub fn downlink(py: Python<'_>, frame: p::Downlink) -> PyResult<Py<PyAny>> {
    Ok(match frame {
        p::Downlink::Imu(f) => Imu::from(f).into_pyobject(py)?.into_any().unbind(),
        p::Downlink::Encoders(f) => Encoders::from(f).into_pyobject(py)?.into_any().unbind(),
        p::Downlink::Battery(f) => Battery::from(f).into_pyobject(py)?.into_any().unbind(),
        p::Downlink::Reply(f) => Reply::from(f).into_pyobject(py)?.into_any().unbind(),
    })
}

/// A 2020 master → board frame as its Python class.
pub fn uplink(py: Python<'_>, frame: p::Command) -> PyResult<Py<PyAny>> {
    Ok(match frame {
        p::Command::Velocity(v) => Velocity::from(v).into_pyobject(py)?.into_any().unbind(),
        p::Command::Turn(t) => Turn {
            deci_degrees: t.deci_degrees,
            x: t.x,
            y: t.y,
        }
        .into_pyobject(py)?
        .into_any()
        .unbind(),
        p::Command::Motors(m) => Motors {
            values: m.values,
            open_loop: m.control == p::MotorLoop::Open,
        }
        .into_pyobject(py)?
        .into_any()
        .unbind(),
        p::Command::Setting(p::Setting::Read(r)) => Read {
            register: r.name().to_string(),
        }
        .into_pyobject(py)?
        .into_any()
        .unbind(),
        p::Command::Setting(p::Setting::Write(w)) => Write {
            register: w.register().name().to_string(),
            value: w.value(),
        }
        .into_pyobject(py)?
        .into_any()
        .unbind(),
        p::Command::Setting(p::Setting::Action(a)) => Action { number: a.number() }
            .into_pyobject(py)?
            .into_any()
            .unbind(),
        p::Command::Setting(p::Setting::Raw { code, value, tail }) => {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("frame", "setting-raw")?;
            d.set_item("code", code)?;
            d.set_item("value", value)?;
            d.set_item("tail", tail)?;
            d.into_any().unbind()
        }
    })
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
            p::Setting::Action(a) => Ok(Action { number: a.number() }),
            _ => Err(FrameError::new_err("a settings frame, not an action")),
        }
    }

    fn __repr__(&self) -> String {
        format!("Action({})", self.number)
    }
}

// ----- v1.0.0 -----

/// A v1.0.0 body velocity (`0x25`): vx, vy in mm/s, wz in mrad/s; `ctl` 2 drives, the forced
/// stop is `ctl` 0 with everything 0; `kind` is the vehicle type (4: the vendor's mecanum).
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyVelocity {
    /// Sideways, mm/s.
    #[pyo3(get)]
    pub vx_mm_s: i16,
    /// Forward, mm/s.
    #[pyo3(get)]
    pub vy_mm_s: i16,
    /// Rotation, mrad/s.
    #[pyo3(get)]
    pub wz_mrad_s: i16,
    /// Control byte.
    #[pyo3(get)]
    pub ctl: u8,
    /// Vehicle type.
    #[pyo3(get)]
    pub kind: u8,
}

impl BodyVelocity {
    /// The crate's frame.
    pub fn inner(&self) -> v1::BodyVelocity {
        v1::BodyVelocity {
            ctl: self.ctl,
            kind: self.kind,
            vx_mm_s: self.vx_mm_s,
            vy_mm_s: self.vy_mm_s,
            wz_mrad_s: self.wz_mrad_s,
        }
    }
}

impl From<v1::BodyVelocity> for BodyVelocity {
    fn from(v: v1::BodyVelocity) -> Self {
        BodyVelocity {
            vx_mm_s: v.vx_mm_s,
            vy_mm_s: v.vy_mm_s,
            wz_mrad_s: v.wz_mrad_s,
            ctl: v.ctl,
            kind: v.kind,
        }
    }
}

#[pymethods]
impl BodyVelocity {
    #[new]
    #[pyo3(
        signature = (vx_mm_s = Int::ZERO, vy_mm_s = Int::ZERO, wz_mrad_s = Int::ZERO, ctl = Int::from(2), kind = Int::from(4)),
        text_signature = "(vx_mm_s=0, vy_mm_s=0, wz_mrad_s=0, ctl=2, kind=4)"
    )]
    fn new(vx_mm_s: Int, vy_mm_s: Int, wz_mrad_s: Int, ctl: Int, kind: Int) -> PyResult<Self> {
        Ok(BodyVelocity {
            vx_mm_s: vx_mm_s.within("vx_mm_s", I16)?,
            vy_mm_s: vy_mm_s.within("vy_mm_s", I16)?,
            wz_mrad_s: wz_mrad_s.within("wz_mrad_s", I16)?,
            ctl: ctl.within("ctl", U8)?,
            kind: kind.within("kind", U8)?,
        })
    }

    /// The forced stop.
    #[staticmethod]
    fn forced_stop() -> Self {
        v1::BodyVelocity::FORCED_STOP.into()
    }

    /// Whether this is the forced stop.
    #[getter]
    fn is_forced_stop(&self) -> bool {
        self.inner().is_forced_stop()
    }

    /// The frame's 14 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &v1::Command::BodyVelocity(self.inner()).encode())
    }

    /// A `0x25` frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        match v1::Command::decode(data).map_err(bad)? {
            v1::Command::BodyVelocity(v) => Ok(v.into()),
            _ => Err(FrameError::new_err("a v1.0.0 frame, not a body velocity")),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "BodyVelocity(vx_mm_s={}, vy_mm_s={}, wz_mrad_s={}, ctl={}, kind={})",
            self.vx_mm_s, self.vy_mm_s, self.wz_mrad_s, self.ctl, self.kind
        )
    }
}

/// A v1.0.0 telemetry frame (32 bytes, ~22 Hz): measured velocity (mm/s, mrad/s), raw
/// accelerometer and gyro, the IMU's quaternion × 1000, battery in mV.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Telemetry {
    /// vx, vy (mm/s), wz (mrad/s).
    #[pyo3(get)]
    pub velocity: [i16; 3],
    /// Accelerometer x, y, z: raw (scale unknown).
    #[pyo3(get)]
    pub accel: [i16; 3],
    /// Gyro x, y, z: raw.
    #[pyo3(get)]
    pub gyro: [i16; 3],
    /// w, x, y, z × 1000.
    #[pyo3(get)]
    pub quaternion: [i16; 4],
    /// Battery, mV.
    #[pyo3(get)]
    pub battery_mv: i16,
}

impl From<v1::Telemetry> for Telemetry {
    fn from(t: v1::Telemetry) -> Self {
        Telemetry {
            velocity: t.velocity,
            accel: t.accel,
            gyro: t.gyro,
            quaternion: t.quaternion,
            battery_mv: t.battery_mv,
        }
    }
}

#[pymethods]
impl Telemetry {
    #[new]
    #[pyo3(
        signature = (velocity = [Int::ZERO; 3], accel = [Int::ZERO; 3], gyro = [Int::ZERO; 3], quaternion = [Int::from(1000), Int::ZERO, Int::ZERO, Int::ZERO], battery_mv = Int::ZERO),
        text_signature = "(velocity=(0, 0, 0), accel=(0, 0, 0), gyro=(0, 0, 0), quaternion=(1000, 0, 0, 0), battery_mv=0)"
    )]
    fn new(
        velocity: [Int; 3],
        accel: [Int; 3],
        gyro: [Int; 3],
        quaternion: [Int; 4],
        battery_mv: Int,
    ) -> PyResult<Self> {
        Ok(Telemetry {
            velocity: each(&velocity, "velocity", I16)?,
            accel: each(&accel, "accel", I16)?,
            gyro: each(&gyro, "gyro", I16)?,
            quaternion: each(&quaternion, "quaternion", I16)?,
            battery_mv: battery_mv.within("battery_mv", I16)?,
        })
    }

    /// The heading from the quaternion, in degrees (−180…180].
    #[getter]
    fn yaw_degrees(&self) -> f64 {
        let [w, x, y, z] = self.quaternion.map(|v| f64::from(v) / 1000.0);
        let siny = 2.0 * (w * z + x * y);
        let cosy = 1.0 - 2.0 * (y * y + z * z);
        siny.atan2(cosy).to_degrees()
    }

    /// The frame's 32 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let t = v1::Telemetry {
            velocity: self.velocity,
            accel: self.accel,
            gyro: self.gyro,
            quaternion: self.quaternion,
            battery_mv: self.battery_mv,
        };
        PyBytes::new(py, &t.encode())
    }

    /// A telemetry frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        v1::Telemetry::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!(
            "Telemetry(velocity={:?}, accel={:?}, gyro={:?}, quaternion={:?}, battery_mv={})",
            self.velocity, self.accel, self.gyro, self.quaternion, self.battery_mv
        )
    }
}

/// A v1.0.0 reply to a readback (14 bytes): its request's name and the ten payload bytes,
/// typed by `fields()`.
#[pyclass(module = "chassis", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct ReadbackReply {
    inner: v1::Reply,
}

impl From<v1::Reply> for ReadbackReply {
    fn from(inner: v1::Reply) -> Self {
        ReadbackReply { inner }
    }
}

/// A v1 reply's fields as a dict (the names the `chassis` command's JSON uses).
pub fn reply_fields<'py>(
    py: Python<'py>,
    reply: &v1::Reply,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let value = match reply.request {
        v1::Readback::System => reply.system().map(serde_json::to_value),
        v1::Readback::Geometry => reply.geometry().map(serde_json::to_value),
        v1::Readback::BodyVelocity => reply.body_velocity().map(serde_json::to_value),
        v1::Readback::MotorSpeeds => reply.motor_speeds().map(serde_json::to_value),
        v1::Readback::Pid => reply.pid().map(serde_json::to_value),
    };
    let value = value
        .transpose()
        .map_err(|e| FrameError::new_err(e.to_string()))?
        .unwrap_or(serde_json::Value::Null);
    crate::json::to_dict(py, &value)
}

#[pymethods]
impl ReadbackReply {
    /// The reply to the readback `request` (`system`, `geometry`, …) with its ten payload
    /// bytes.
    #[new]
    fn new(request: &str, payload: [Int; 10]) -> PyResult<Self> {
        let payload = each(&payload, "payload", U8)?;
        let request = v1::Readback::from_name(request).ok_or_else(|| {
            pyo3::exceptions::PyValueError::new_err(format!(
                "{request:?} is not a readback: give one of {}",
                v1::Readback::ALL.map(v1::Readback::name).join(", ")
            ))
        })?;
        Ok(v1::Reply { request, payload }.into())
    }

    /// The readback it answers: `system`, `geometry`, `body-velocity`, `motor-speeds`, `pid`.
    #[getter]
    fn request(&self) -> &'static str {
        self.inner.request.name()
    }

    /// Its code byte.
    #[getter]
    fn code(&self) -> u8 {
        self.inner.request.code()
    }

    /// The ten payload bytes.
    #[getter]
    fn payload<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.payload)
    }

    /// Its fields by name, typed (a dict).
    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        reply_fields(py, &self.inner)
    }

    /// The frame's 14 bytes.
    fn encode<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.encode())
    }

    /// A reply frame's fields.
    #[staticmethod]
    fn decode(data: &[u8]) -> PyResult<Self> {
        v1::Reply::decode(data).map(Self::from).map_err(bad)
    }

    fn __repr__(&self) -> String {
        format!(
            "ReadbackReply(request={:?}, payload={:02X?})",
            self.inner.request.name(),
            self.inner.payload
        )
    }
}

/// A v1.0.0 board → master frame as its Python class.
pub fn v1_downlink(py: Python<'_>, frame: v1::Downlink) -> PyResult<Py<PyAny>> {
    Ok(match frame {
        v1::Downlink::Telemetry(t) => Telemetry::from(t).into_pyobject(py)?.into_any().unbind(),
        v1::Downlink::Reply(r) => ReadbackReply::from(r)
            .into_pyobject(py)?
            .into_any()
            .unbind(),
    })
}

/// A v1.0.0 master → board frame: a `BodyVelocity`, or a dict as `decode_capture` gives it
/// (`{"frame": "v1-readback", "request": "system", "code": 51}`).
pub fn v1_uplink(py: Python<'_>, frame: v1::Command) -> PyResult<Py<PyAny>> {
    if let v1::Command::BodyVelocity(v) = frame {
        return Ok(BodyVelocity::from(v).into_pyobject(py)?.into_any().unbind());
    }
    let (value, _) = chassis_capture::describe_v1_uplink(&frame);
    Ok(crate::json::to_py(py, &value)?.unbind())
}
