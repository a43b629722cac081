//! `chassis.decode_capture`: what `chassis decode` prints, as Python dicts with the same field
//! names (the decoder is the CLI's own crate, `chassis-capture`).

use crate::json;
use chassis_capture as decode;
use chassis_protocol::detect::Firmware;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A decoded capture: `frames` (dicts, in stream order; iterate over it directly) and the
/// `summary` line `chassis decode` prints.
#[pyclass(module = "chassis")]
pub struct Decoded {
    frames: Vec<Py<PyDict>>,
    summary: String,
}

#[pymethods]
impl Decoded {
    /// The frames, in stream order.
    #[getter]
    fn frames(&self, py: Python<'_>) -> Vec<Py<PyDict>> {
        self.frames.iter().map(|f| f.clone_ref(py)).collect()
    }

    /// The summary line (generation, counters).
    #[getter]
    fn summary(&self) -> &str {
        &self.summary
    }

    fn __len__(&self) -> usize {
        self.frames.len()
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let list = pyo3::types::PyList::new(py, self.frames(py))?;
        Ok(list.try_iter()?.into_any().unbind())
    }

    fn __repr__(&self) -> String {
        format!("Decoded({} frames: {})", self.frames.len(), self.summary)
    }
}

fn input_of(name: &str) -> PyResult<decode::Input> {
    match name {
        "raw" => Ok(decode::Input::Raw),
        "hex" => Ok(decode::Input::Hex),
        "saleae-csv" => Ok(decode::Input::SaleaeCsv),
        other => Err(PyValueError::new_err(format!(
            "input={other:?}: give \"raw\", \"hex\" or \"saleae-csv\""
        ))),
    }
}

/// Decodes a capture as `chassis decode` does. `data`: the capture's bytes; `input`: "raw",
/// "hex" or "saleae-csv"; `uplink`: the master → board direction; `master`: the master →
/// board side of the same capture (both sides then come in time order, each with "from");
/// `firmware`: "2020" or "v1.0.0" (`None`: found from the capture); `quiet_ms`: a gap in the
/// time stamps longer than this is a quiet line (2; 40 for a `chassis record` capture).
#[pyfunction]
#[pyo3(signature = (data, *, input = "raw", uplink = false, master = None, firmware = None, quiet_ms = None))]
pub fn decode_capture(
    py: Python<'_>,
    data: pyo3::pybacked::PyBackedBytes,
    input: &str,
    uplink: bool,
    master: Option<pyo3::pybacked::PyBackedBytes>,
    firmware: Option<&str>,
    quiet_ms: Option<crate::args::Real>,
) -> PyResult<Decoded> {
    let input = input_of(input)?;
    let firmware = firmware
        .map(|name| {
            Firmware::from_name(name).ok_or_else(|| {
                PyValueError::new_err(format!("firmware={name:?}: give \"2020\" or \"v1.0.0\""))
            })
        })
        .transpose()?;
    if let Some(q) = &quiet_ms {
        if !(q.value > 0.0 && q.value <= 60_000.0) {
            return Err(PyValueError::new_err(format!(
                "quiet_ms = {q} is out of range (above 0, up to 60000)"
            )));
        }
    }
    let quiet_s = quiet_ms.map(|q| q.value / 1000.0);
    let decoded = crate::detach(py, || -> Result<decode::Decoded, String> {
        let mut capture = decode::read_capture(&data, input)?;
        capture.quiet_s = quiet_s;
        match master.as_deref() {
            Some(m) => {
                let mut master = decode::read_capture(m, input)?;
                master.quiet_s = quiet_s;
                decode::decode_both(&capture, &master, firmware)
            }
            None => Ok(decode::decode(&capture, uplink, firmware)),
        }
    });
    let decoded = decoded.map_err(PyValueError::new_err)?;
    let frames = decoded
        .frames
        .iter()
        .map(|f| json::to_dict(py, &f.json).map(Bound::unbind))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(Decoded {
        frames,
        summary: decoded.summary,
    })
}
