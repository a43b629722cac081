//! The frames of both generations as Python classes: fields, `==`, `repr`, `encode() -> bytes`,
//! `decode(bytes)`. Every class wraps the crate's own type: no frame is laid out twice.
//!
//! Laid out alike for both generations: [`v2020`] and [`v1`] each hold `commands` (master →
//! board) and `telemetry` (board → master, with the function that gives a received frame its
//! class); here is what they share: the checks of Python's numbers, the frame error, the
//! field-by-field conversions.

mod v1;
mod v2020;

pub use v1::{BodyVelocity, ReadbackReply, Telemetry, reply_fields, v1_downlink, v1_uplink};
pub use v2020::{
    Action, Battery, Encoders, Imu, Motors, Read, Reply, Turn, Velocity, Write, downlink, register,
    uplink, write_of,
};

use crate::args::Int;
use crate::errors::FrameError;
use pyo3::exceptions::{PyOverflowError, PyValueError};
use pyo3::prelude::*;
use std::ops::RangeInclusive;

/// A frame error from the crate as `chassis.FrameError`.
fn bad(e: impl core::fmt::Display) -> PyErr {
    FrameError::new_err(e.to_string())
}

/// The ranges of the frames' fields.
const I16: RangeInclusive<i128> = -32_768..=32_767;
const U16: RangeInclusive<i128> = 0..=65_535;
const U8: RangeInclusive<i128> = 0..=255;

/// Each of `values` in `range` (`ValueError` naming `name[i]`).
fn each<T: TryFrom<i128> + Copy + Default, const N: usize>(
    values: &[Int; N],
    name: &str,
    range: RangeInclusive<i128>,
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
            if e.is_instance_of::<PyOverflowError>(v.py()) {
                PyValueError::new_err(format!("{what}[{i}] = {v} is out of range"))
            } else {
                e
            }
        })?;
    }
    Ok(out)
}

/// A Python frame class and the crate's frame with the same fields: `From` the crate's frame
/// (`from`), and with `<=>` also `inner()`, the crate's frame back.
macro_rules! same_fields {
    ($class:ident from $frame:path { $($field:ident),* $(,)? }) => {
        impl From<$frame> for $class {
            fn from(f: $frame) -> Self {
                $class { $($field: f.$field),* }
            }
        }
    };
    ($class:ident <=> $frame:path { $($field:ident),* $(,)? }) => {
        same_fields!($class from $frame { $($field),* });

        impl $class {
            /// The crate's frame.
            pub fn inner(&self) -> $frame {
                $frame { $($field: self.$field),* }
            }
        }
    };
}
use same_fields;
