//! The velocity commands: `0x25` (the body velocity; the forced stop) and `0x26` (each
//! motor's), and the readback replies laid out as them (`0x35`, `0x36`).

use super::super::PAYLOAD_LEN;
use crate::wire;

/// Byte offsets in the ten payload bytes (the frame's bytes 2..12).
mod field {
    /// The control byte.
    pub const CTL: usize = 0;
    /// The vehicle type.
    pub const KIND: usize = 1;
    /// `0x25`: vx, vy (mm/s), wz (mrad/s), big-endian `i16`; bytes 8 and 9 are `00`.
    pub mod body {
        pub const VX: usize = 2;
        pub const VY: usize = 4;
        pub const WZ: usize = 6;
    }
    /// `0x26`: M1..M4, big-endian `i16`.
    pub mod motors {
        pub const SPEEDS: [usize; 4] = [2, 4, 6, 8];
    }
}

/// `0x25`: the body velocity, SI units × 1000.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyVelocity {
    /// `0x02` drives; `0x00` with everything else 0 is the forced stop. Other values: unknown,
    /// kept.
    pub ctl: u8,
    /// The vehicle type ("divisor mode"): 4 in the vendor's mecanum example; other values
    /// unknown. Kept raw. `"type"` in JSON, as the vendor calls it.
    #[cfg_attr(feature = "serde", serde(rename = "type", alias = "kind"))]
    pub kind: u8,
    /// Sideways, mm/s.
    pub vx_mm_s: i16,
    /// Forward, mm/s.
    pub vy_mm_s: i16,
    /// Rotation, mrad/s.
    pub wz_mrad_s: i16,
}

impl BodyVelocity {
    /// `ctl` that drives.
    pub const DRIVE: u8 = 0x02;
    /// The vendor's mecanum vehicle type.
    pub const MECANUM: u8 = 4;
    /// The forced stop: `ctl = 0`, everything 0. What the driver's failsafe sends to a v1.0.0
    /// board (it has no documented watchdog).
    pub const FORCED_STOP: BodyVelocity = BodyVelocity {
        ctl: 0,
        kind: 0,
        vx_mm_s: 0,
        vy_mm_s: 0,
        wz_mrad_s: 0,
    };

    /// Drive at vx, vy (mm/s) and wz (mrad/s), vehicle type 4.
    #[must_use]
    pub const fn new(vx_mm_s: i16, vy_mm_s: i16, wz_mrad_s: i16) -> Self {
        BodyVelocity {
            ctl: Self::DRIVE,
            kind: Self::MECANUM,
            vx_mm_s,
            vy_mm_s,
            wz_mrad_s,
        }
    }

    /// Whether this is the forced stop.
    #[must_use]
    pub fn is_forced_stop(&self) -> bool {
        *self == Self::FORCED_STOP
    }

    pub(in crate::v1) fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u8(&mut p, field::CTL, self.ctl);
        wire::put_u8(&mut p, field::KIND, self.kind);
        wire::put_i16(&mut p, field::body::VX, self.vx_mm_s);
        wire::put_i16(&mut p, field::body::VY, self.vy_mm_s);
        wire::put_i16(&mut p, field::body::WZ, self.wz_mrad_s);
        p
    }

    pub(in crate::v1) fn from_payload(p: &[u8]) -> Self {
        BodyVelocity {
            ctl: wire::u8_at(p, field::CTL),
            kind: wire::u8_at(p, field::KIND),
            vx_mm_s: wire::i16_at(p, field::body::VX),
            vy_mm_s: wire::i16_at(p, field::body::VY),
            wz_mrad_s: wire::i16_at(p, field::body::WZ),
        }
    }
}

/// `0x26`: each motor's velocity (`ctl` 2), in the board's own unit × 1000 ("mm/s or
/// 1000·r": not established, kept raw).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MotorVelocity {
    /// The control byte (2 in a command; in a `0x36` reply, the board's control mode).
    pub ctl: u8,
    /// The vehicle type, as [`BodyVelocity::kind`] (`"type"` in JSON).
    #[cfg_attr(feature = "serde", serde(rename = "type", alias = "kind"))]
    pub kind: u8,
    /// M1..M4, raw (`"speeds_raw"` in JSON: the unit is the board's own).
    #[cfg_attr(feature = "serde", serde(rename = "speeds_raw", alias = "speeds"))]
    pub speeds: [i16; 4],
}

impl MotorVelocity {
    /// Each motor at `speeds` (raw), `ctl` 2, vehicle type 4.
    #[must_use]
    pub const fn new(speeds: [i16; 4]) -> Self {
        MotorVelocity {
            ctl: BodyVelocity::DRIVE,
            kind: BodyVelocity::MECANUM,
            speeds,
        }
    }

    pub(in crate::v1) fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u8(&mut p, field::CTL, self.ctl);
        wire::put_u8(&mut p, field::KIND, self.kind);
        for (at, s) in field::motors::SPEEDS.into_iter().zip(self.speeds) {
            wire::put_i16(&mut p, at, s);
        }
        p
    }

    pub(in crate::v1) fn from_payload(p: &[u8]) -> Self {
        MotorVelocity {
            ctl: wire::u8_at(p, field::CTL),
            kind: wire::u8_at(p, field::KIND),
            speeds: field::motors::SPEEDS.map(|at| wire::i16_at(p, at)),
        }
    }
}
