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
        let found: Vec<p::Downlink> = crate::detach(py, || self.inner.frames(&data).collect());
        found.into_iter().map(|f| frames::downlink(py, f)).collect()
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
        let found: Vec<p::Command> = crate::detach(py, || self.inner.frames(&data).collect());
        found.into_iter().map(|f| frames::uplink(py, f)).collect()
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
        let d = PyDict::new(py);
        d.set_item("frames", s.frames)?;
        d.set_item("discarded", s.discarded)?;
        d.set_item("resyncs", s.resyncs)?;
        Ok(d)
    }
}

/// v1.0.0 parser counters as a dict.
fn v1_stats<'py>(py: Python<'py>, s: v1::Stats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("frames", s.frames)?;
    d.set_item("bad_checksum", s.bad_checksum)?;
    d.set_item("bad_end", s.bad_end)?;
    d.set_item("refused", s.refused)?;
    d.set_item("discarded", s.discarded)?;
    Ok(d)
}

/// The v1.0.0 board → master parser (32-byte `Telemetry`, 14-byte `ReadbackReply`): BCC and end
/// byte checked, resynchronising on the next `7B` inside what it holds.
#[pyclass(module = "chassis")]
pub struct V1DownlinkParser {
    inner: v1::DownlinkParser,
}

#[pymethods]
impl V1DownlinkParser {
    #[new]
    fn new() -> Self {
        V1DownlinkParser {
            inner: v1::DownlinkParser::new(),
        }
    }

    /// Takes bytes; the frames they complete.
    fn feed(&mut self, py: Python<'_>, data: PyBackedBytes) -> PyResult<Vec<Py<PyAny>>> {
        use v1::Parser as _;
        let found: Vec<v1::Downlink> = crate::detach(py, || self.inner.frames(&data).collect());
        found
            .into_iter()
            .map(|f| frames::v1_downlink(py, f))
            .collect()
    }

    /// The line has been quiet (2 ms on a UART, 25 ms behind a USB-UART): the start of a
    /// frame cut short is thrown away; no frame spans a quiet line.
    fn quiet(&mut self) {
        self.inner.quiet();
    }

    /// Counters: frames, bad_checksum, bad_end, refused, discarded.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        v1_stats(py, self.inner.stats())
    }
}

/// The v1.0.0 master → board parser (commands), for captures: a body velocity as
/// `BodyVelocity`, other commands as dicts with the frame's fields.
#[pyclass(module = "chassis")]
pub struct V1UplinkParser {
    inner: v1::UplinkParser,
}

#[pymethods]
impl V1UplinkParser {
    #[new]
    fn new() -> Self {
        V1UplinkParser {
            inner: v1::UplinkParser::new(),
        }
    }

    /// Takes bytes; the commands they complete.
    fn feed(&mut self, py: Python<'_>, data: PyBackedBytes) -> PyResult<Vec<Py<PyAny>>> {
        use v1::Parser as _;
        let found: Vec<v1::Command> = crate::detach(py, || self.inner.frames(&data).collect());
        found
            .into_iter()
            .map(|f| frames::v1_uplink(py, f))
            .collect()
    }

    /// The line has been quiet (2 ms on a UART, 25 ms behind a USB-UART): the start of a
    /// frame cut short is thrown away; no frame spans a quiet line.
    fn quiet(&mut self) {
        self.inner.quiet();
    }

    /// Counters: frames, bad_checksum, bad_end, refused, discarded.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        v1_stats(py, self.inner.stats())
    }
}
