//! Numbers from Python as they were given, checked against their field's range in the call
//! itself: a value out of range, however large, is a `ValueError` that names the field (PyO3's
//! own conversions raise `OverflowError`, without the name, for an int too large for the Rust
//! type).

use pyo3::exceptions::{PyOverflowError, PyValueError};
use pyo3::prelude::*;
use std::ops::RangeInclusive;

/// A Python int, however large: its value, or (too large even for 128 bits) its digits.
pub struct Int(Result<i128, String>);

impl Int {
    /// 0, for a default.
    pub const ZERO: Int = Int(Ok(0));
}

impl<'a, 'py> FromPyObject<'a, 'py> for Int {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match obj.extract::<i128>() {
            Ok(v) => Ok(Int(Ok(v))),
            Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => {
                Ok(Int(Err(shorten(obj.repr()?.to_string()))))
            }
            Err(e) => Err(e),
        }
    }
}

impl From<i128> for Int {
    fn from(v: i128) -> Self {
        Int(Ok(v))
    }
}

/// The digits of a huge int as a message says them: the first ones and how many.
fn shorten(digits: String) -> String {
    if digits.len() <= 40 {
        return digits;
    }
    let head: String = digits.chars().take(20).collect();
    format!("{head}… ({} digits)", digits.trim_start_matches('-').len())
}

/// A range as the messages say it: `±N`, or `lo..=hi`.
fn words(range: &RangeInclusive<i128>) -> String {
    if *range.start() == -*range.end() {
        format!("±{}", range.end())
    } else {
        format!("{}..={}", range.start(), range.end())
    }
}

impl Int {
    /// The value as `T` if it lies in `range`; else `ValueError`: "`name` = value is out of
    /// range (the range)".
    pub fn within<T: TryFrom<i128>>(&self, name: &str, range: RangeInclusive<i128>) -> PyResult<T> {
        let out = |shown: &dyn std::fmt::Display| {
            PyValueError::new_err(format!(
                "{name} = {shown} is out of range ({})",
                words(&range)
            ))
        };
        match &self.0 {
            Ok(v) if range.contains(v) => T::try_from(*v).map_err(|_| out(v)),
            Ok(v) => Err(out(v)),
            Err(digits) => Err(out(digits)),
        }
    }
}

/// A Python number as a float; an int too large even for a float is infinite (with its sign),
/// its digits kept for the message.
pub struct Real {
    /// The value (infinite for an int too large for a float).
    pub value: f64,
    /// The digits of an int too large for a float.
    digits: Option<String>,
}

impl<'a, 'py> FromPyObject<'a, 'py> for Real {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match obj.extract::<f64>() {
            Ok(value) => Ok(Real {
                value,
                digits: None,
            }),
            Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => {
                let negative = obj.lt(0)?;
                Ok(Real {
                    value: if negative {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    },
                    digits: Some(shorten(obj.repr()?.to_string())),
                })
            }
            Err(e) => Err(e),
        }
    }
}

impl From<f64> for Real {
    fn from(value: f64) -> Self {
        Real {
            value,
            digits: None,
        }
    }
}

impl std::fmt::Display for Real {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.digits {
            Some(d) => f.write_str(d),
            None => write!(f, "{}", self.value),
        }
    }
}
