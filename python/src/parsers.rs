//! The streaming parsers of both generations, for captures and for code that owns its own
//! serial port: `feed(bytes) -> list` of frames, `quiet(ms)`, `expect_reply(register)`, `stats`.

use crate::args::Int;
use crate::frames;
use chassis_protocol as p;
use chassis_protocol::v1;
use pyo3::prelude::*;
use pyo3::pybacked::PyBackedBytes;
use pyo3::types::PyDict;

/// The 2020 board → master parser (`FF FA/FB/FC` telemetry, `#` replies), resynchronising on a
/// line with no checksum. Call `quiet(ms)` when the line has been quiet that long: a frame
/// that waits for what follows it is judged then.
#[pyclass(module = "chassis")]
pub struct DownlinkParser {
    inner: p::DownlinkParser,
}

#[pymethods]
impl DownlinkParser {
    #[new]
    fn new() -> Self {
        DownlinkParser {
            inner: p::DownlinkParser::new(),
        }
    }

    /// Takes bytes; the frames they complete, in order (`Imu`, `Encoders`, `Battery`, `Reply`).
    fn feed(&mut self, py: Python<'_>, data: PyBackedBytes) -> PyResult<Vec<Py<PyAny>>> {
        found(py, || self.inner.frames(&data).collect(), frames::downlink)
    }

    /// The line has been quiet for `ms`: the frames that waited for it.
    fn quiet(&mut self, py: Python<'_>, ms: Int) -> PyResult<Vec<Py<PyAny>>> {
        let ms: u32 = ms.within("ms", 0..=i128::from(u32::MAX))?;
        let mut out = Vec::new();
        while let Some(f) = self.inner.quiet(ms) {
            out.push(frames::downlink(py, f)?);
        }
        Ok(out)
    }

    /// A reply to a read of `register` is awaited (`None`: none is): it is taken on less
    /// evidence.
    #[pyo3(signature = (register))]
    fn expect_reply(&mut self, register: Option<&str>) -> PyResult<()> {
        let r = register.map(frames::register).transpose()?;
        self.inner.expect_reply(r);
        Ok(())
    }

    /// Counters: frames per kind, bytes discarded, lock losses, resyncs, gaps and missed frames
    /// per stream (a dict).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.stats();
        let d = PyDict::new(py);
        for stream in [p::Stream::Imu, p::Stream::Encoders, p::Stream::Battery] {
            let name = format!("{stream:?}").to_lowercase();
            d.set_item(name, s.frames_of(p::Kind::Telemetry(stream)))?;
        }
        d.set_item("reply", s.frames_of(p::Kind::Reply))?;
        d.set_item("frames", s.total_frames())?;
        d.set_item("discarded", s.discarded)?;
        d.set_item("lock_losses", s.lock_losses)?;
        d.set_item("resyncs", s.resyncs)?;
        for stream in [p::Stream::Imu, p::Stream::Encoders, p::Stream::Battery] {
            let name = format!("{stream:?}").to_lowercase();
            d.set_item(format!("{name}_gaps"), s.gaps_of(stream))?;
            d.set_item(format!("{name}_missed"), s.missed_of(stream))?;
        }
        Ok(d)
    }
}

/// The 2020 master → board parser (commands), for captures.
#[pyclass(module = "chassis")]
pub struct UplinkParser {
    inner: p::UplinkParser,
}

#[pymethods]
impl UplinkParser {
    #[new]
    fn new() -> Self {
        UplinkParser {
            inner: p::UplinkParser::new(),
        }
    }

    /// Takes bytes; the commands they complete (`Velocity`, `Turn`, `Motors`, `Read`, `Write`,
    /// `Action`).
    fn feed(&mut self, py: Python<'_>, data: PyBackedBytes) -> PyResult<Vec<Py<PyAny>>> {
        found(py, || self.inner.frames(&data).collect(), frames::uplink)
    }

    /// The line has been quiet: a frame cut short is thrown away.
    fn quiet(&mut self, ms: Int) -> PyResult<()> {
        let _: u32 = ms.within("ms", 0..=i128::from(u32::MAX))?;
        self.inner.idle();
        Ok(())
    }

    /// Counters: frames, bytes discarded, resyncs.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.stats();
        counts(
            py,
            &[
                ("frames", s.frames),
                ("discarded", s.discarded),
                ("resyncs", s.resyncs),
            ],
        )
    }
}

/// Counters by name as a dict (in their order).
pub fn counts<'py>(py: Python<'py>, counters: &[(&str, u32)]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, n) in counters {
        d.set_item(*name, n)?;
    }
    Ok(d)
}

/// A v1.0.0 parser's counters by name.
pub fn v1_counts(s: v1::Stats) -> [(&'static str, u32); 5] {
    [
        ("frames", s.frames),
        ("bad_checksum", s.bad_checksum),
        ("bad_end", s.bad_end),
        ("refused", s.refused),
        ("discarded", s.discarded),
    ]
}

/// The frames `parse` finds in what it was fed (the GIL released meanwhile), each as its
/// Python class (`class`).
fn found<F: Send>(
    py: Python<'_>,
    parse: impl FnOnce() -> Vec<F> + Send,
    class: fn(Python<'_>, F) -> PyResult<Py<PyAny>>,
) -> PyResult<Vec<Py<PyAny>>> {
    let found = crate::detach(py, parse);
    found.into_iter().map(|f| class(py, f)).collect()
}

/// A v1.0.0 parser class (both directions are alike): `feed`, `quiet()`, `stats`.
macro_rules! v1_parser {
    ($(#[$doc:meta])* $class:ident($inner:ty) -> $frame:ty, $to_py:path) => {
        $(#[$doc])*
        #[pyclass(module = "chassis")]
        pub struct $class {
            inner: $inner,
        }

        #[pymethods]
        impl $class {
            #[new]
            fn new() -> Self {
                $class {
                    inner: <$inner>::new(),
                }
            }

            /// Takes bytes; the frames they complete.
            fn feed(&mut self, py: Python<'_>, data: PyBackedBytes) -> PyResult<Vec<Py<PyAny>>> {
                use v1::Parser as _;
                found(py, || self.inner.frames(&data).collect::<Vec<$frame>>(), $to_py)
            }

            /// The line has been quiet (2 ms on a UART, 25 ms behind a USB-UART): the frames
            /// whole among the bytes held; the start of a frame cut short is thrown away; no
            /// frame spans a quiet line.
            fn quiet(&mut self, py: Python<'_>) -> PyResult<Vec<Py<PyAny>>> {
                let inner = &mut self.inner;
                found(
                    py,
                    || core::iter::from_fn(|| inner.quiet()).collect::<Vec<$frame>>(),
                    $to_py,
                )
            }

            /// Counters: frames, bad_checksum, bad_end, refused, discarded.
            #[getter]
            fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                counts(py, &v1_counts(self.inner.stats()))
            }
        }
    };
}

v1_parser!(
    /// The v1.0.0 board → master parser (32-byte `Telemetry`, 14-byte `ReadbackReply`): BCC and end
    /// byte checked, resynchronising on the next `7B` inside what it holds.
    V1DownlinkParser(v1::DownlinkParser) -> v1::Downlink,
    frames::v1_downlink
);

v1_parser!(
    /// The v1.0.0 master → board parser (commands), for captures: a body velocity as
    /// `BodyVelocity`, other commands as dicts with the frame's fields.
    V1UplinkParser(v1::UplinkParser) -> v1::Command,
    frames::v1_uplink
);
