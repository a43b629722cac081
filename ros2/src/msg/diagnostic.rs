//! `diagnostic_msgs`: `DiagnosticArray`, `DiagnosticStatus`, `KeyValue`.

use super::Header;
use serde::{Deserialize, Serialize};

/// `diagnostic_msgs/KeyValue`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct KeyValue {
    /// What is measured.
    pub key: String,
    /// Its value, as text.
    pub value: String,
}

/// `diagnostic_msgs/DiagnosticStatus`: one component's state.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// [`DiagnosticStatus::OK`], `WARN`, `ERROR` or `STALE`.
    pub level: u8,
    /// The component's name.
    pub name: String,
    /// Its state in a few words.
    pub message: String,
    /// Which hardware.
    pub hardware_id: String,
    /// The figures behind it.
    pub values: Vec<KeyValue>,
}

impl DiagnosticStatus {
    /// All well.
    pub const OK: u8 = 0;
    /// Something to look at.
    pub const WARN: u8 = 1;
    /// Something is wrong.
    pub const ERROR: u8 = 2;
    /// Nothing new has come.
    pub const STALE: u8 = 3;
}

/// `diagnostic_msgs/DiagnosticArray`: what `/diagnostics` carries.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DiagnosticArray {
    /// When.
    pub header: Header,
    /// One per component.
    pub status: Vec<DiagnosticStatus>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::{header, wire};

    #[test]
    fn diagnostic_array_bytes() {
        let array = DiagnosticArray {
            header: header(1, 2, ""),
            status: vec![DiagnosticStatus {
                level: DiagnosticStatus::WARN,
                name: "c".into(),
                message: String::new(),
                hardware_id: "h".into(),
                values: vec![KeyValue {
                    key: "k".into(),
                    value: "vv".into(),
                }],
            }],
        };
        // 0 time, 8 length 1, 12 NUL, 13..16 pad, 16 count 1, 20 level, 21..24 pad, 24 "c"
        // (length 2), 30..32 pad, 32 "" (length 1), 37..40 pad, 40 "h", 46..48 pad, 48 count
        // 1, 52 "k", 58..60 pad, 60 "vv" (length 3).
        #[rustfmt::skip]
        let expected = [
            0x00, 0x01, 0x00, 0x00,
            1, 0, 0, 0, 2, 0, 0, 0,
            1, 0, 0, 0, 0, 0, 0, 0,
            1, 0, 0, 0,
            1, 0, 0, 0,
            2, 0, 0, 0, b'c', 0, 0, 0,
            1, 0, 0, 0, 0, 0, 0, 0,
            2, 0, 0, 0, b'h', 0, 0, 0,
            1, 0, 0, 0,
            2, 0, 0, 0, b'k', 0, 0, 0,
            3, 0, 0, 0, b'v', b'v', 0,
        ];
        assert_eq!(wire(&array), expected);
    }
}
