//! The package's exceptions: one class per kind of driver error, each under `ChassisError`, with
//! the `chassis` command's words.

use chassis_protocol::driver::host::{Heard, SerialError, words_heard};
use chassis_protocol::driver::{CoreError, Error};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    chassis,
    ChassisError,
    PyException,
    "Anything the chassis driver refuses or finds wrong; every one leaves the driver usable."
);
create_exception!(
    chassis,
    TimeoutError,
    ChassisError,
    "No reply in time (a read, a readback), or nothing came from the board at all."
);
create_exception!(
    chassis,
    WrongReplyError,
    ChassisError,
    "A reply that cannot be the answer: another register's, or a damaged value."
);
create_exception!(
    chassis,
    UnconfirmedError,
    ChassisError,
    "A read whose replies disagreed or went missing, or a write the board's read-back does not show."
);
create_exception!(
    chassis,
    TurnInProgressError,
    ChassisError,
    "A turn is still outstanding: the board adds turns up, so a second one is refused until the first is done or stopped."
);
create_exception!(
    chassis,
    TransportError,
    ChassisError,
    "The serial port failed (unplugged, an OS error)."
);
create_exception!(
    chassis,
    FrameError,
    ChassisError,
    "Bytes that are not a frame of the kind asked for."
);

/// A driver error as the exception of its kind, in the CLI's words, told by what came from the
/// board on `port` (`heard`): a read unanswered by a board that never said anything is a
/// `TimeoutError` whatever its kind.
pub fn driver_error(e: Error<SerialError>, heard: Heard, port: &str) -> PyErr {
    let silent = heard == Heard::Nothing;
    match e {
        Error::Transport(e) => TransportError::new_err(format!("serial port {port}: {}", e.0)),
        Error::WriteZero => {
            TransportError::new_err(format!("serial port {port}: it accepted no bytes"))
        }
        Error::Core(core) => {
            let text = words_heard(core, heard, port);
            match core {
                CoreError::Timeout(_) | CoreError::NoReadback(_) | CoreError::ClockStalled => {
                    TimeoutError::new_err(text)
                }
                CoreError::Unconfirmed(_) if silent => TimeoutError::new_err(text),
                CoreError::WrongReply { .. } | CoreError::Invalid { .. } => {
                    WrongReplyError::new_err(text)
                }
                CoreError::Unconfirmed(_) | CoreError::ReadbackDiffers(_) => {
                    UnconfirmedError::new_err(text)
                }
                CoreError::TurnInProgress | CoreError::TurnStateUnknown => {
                    TurnInProgressError::new_err(text)
                }
                _ => ChassisError::new_err(text),
            }
        }
        other => ChassisError::new_err(other.to_string()),
    }
}

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ChassisError", py.get_type::<ChassisError>())?;
    m.add("TimeoutError", py.get_type::<TimeoutError>())?;
    m.add("WrongReplyError", py.get_type::<WrongReplyError>())?;
    m.add("UnconfirmedError", py.get_type::<UnconfirmedError>())?;
    m.add("TurnInProgressError", py.get_type::<TurnInProgressError>())?;
    m.add("TransportError", py.get_type::<TransportError>())?;
    m.add("FrameError", py.get_type::<FrameError>())?;
    Ok(())
}
