//! The 2020 firmware's board → master frames: the telemetry (`Imu`, `Encoders`, `Battery`) and
//! the replies to register reads (`Reply`), and the class of a frame a parser or the driver
//! took in ([`downlink`]).

use crate::args::Int;
use crate::frames::{I16, U8, U16, bad, each, same_fields};
use chassis_protocol as p;
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

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

/// The `#[pymethods]` of a telemetry or reply class: its constructor (given), `encode`, `decode`
/// and `__repr__` (by the function given).
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

same_fields!(Imu <=> p::Imu { accel, gyro, seq });
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

same_fields!(Encoders <=> p::Encoders { ticks, seq });
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

same_fields!(Battery <=> p::Battery { centivolts, percent, seq });
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
            let r = super::commands::register(register)?;
            let value = value.within("value", 0..=i128::from(u32::MAX))?;
            Ok(p::Reply::new(r, value).into())
        }
    }
);

/// A 2020 board → master frame as its Python class.
pub fn downlink(py: Python<'_>, frame: p::Downlink) -> PyResult<Py<PyAny>> {
    match frame {
        p::Downlink::Imu(f) => Imu::from(f).into_py_any(py),
        p::Downlink::Encoders(f) => Encoders::from(f).into_py_any(py),
        p::Downlink::Battery(f) => Battery::from(f).into_py_any(py),
        p::Downlink::Reply(f) => Reply::from(f).into_py_any(py),
    }
}
