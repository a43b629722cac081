//! The settings frames: `0x23` (system), `0x24` (geometry), `0x40` (PID), and the readback
//! replies laid out as them (`0x33`, `0x34`, `0x50`). Every value is big-endian; in `0x23` and
//! `0x24`, bytes 8 and 9 of the payload are `00`.

use super::super::PAYLOAD_LEN;
use crate::wire;

/// Byte offsets in the ten payload bytes (the frame's bytes 2..12).
mod field {
    /// `0x23`.
    pub mod system {
        pub const MOTOR_DIRECTIONS: usize = 0;
        pub const ENCODER_DIRECTIONS: usize = 1;
        pub const PWM_MAX: usize = 2;
        pub const PWM_MIN: usize = 4;
        pub const ENCODER_PPR: usize = 6;
    }
    /// `0x24`.
    pub mod geometry {
        pub const WHEEL_SPACING: usize = 0;
        pub const AXLE_SPACING: usize = 2;
        pub const GEAR_RATIO: usize = 4;
        pub const WHEEL_DIAMETER: usize = 6;
    }
    /// `0x40`.
    pub mod pid {
        pub const POSITION_KP: usize = 0;
        pub const POSITION_KI: usize = 2;
        pub const POSITION_KD: usize = 4;
        pub const VELOCITY_KP: usize = 6;
        pub const VELOCITY_KI: usize = 8;
    }
}

/// `0x23`: the system settings (the bits' meanings are not known: kept raw). The vendor's
/// example writes 0, 10, 3600, 2100, 165. Writing them overwrites what the owner tuned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SystemSettings {
    /// Motor direction bits (meaning unknown; `"motor_direction_bits"` in JSON).
    #[cfg_attr(
        feature = "serde",
        serde(rename = "motor_direction_bits", alias = "motor_directions")
    )]
    pub motor_directions: u8,
    /// Encoder direction bits (meaning unknown; `"encoder_direction_bits"` in JSON).
    #[cfg_attr(
        feature = "serde",
        serde(rename = "encoder_direction_bits", alias = "encoder_directions")
    )]
    pub encoder_directions: u8,
    /// PWM maximum.
    pub pwm_max: u16,
    /// PWM minimum.
    pub pwm_min: u16,
    /// Encoder pulses per revolution.
    pub encoder_ppr: u16,
}

impl SystemSettings {
    pub(in crate::v1) fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u8(
            &mut p,
            field::system::MOTOR_DIRECTIONS,
            self.motor_directions,
        );
        wire::put_u8(
            &mut p,
            field::system::ENCODER_DIRECTIONS,
            self.encoder_directions,
        );
        wire::put_u16(&mut p, field::system::PWM_MAX, self.pwm_max);
        wire::put_u16(&mut p, field::system::PWM_MIN, self.pwm_min);
        wire::put_u16(&mut p, field::system::ENCODER_PPR, self.encoder_ppr);
        p
    }

    pub(in crate::v1) fn from_payload(p: &[u8]) -> Self {
        SystemSettings {
            motor_directions: wire::u8_at(p, field::system::MOTOR_DIRECTIONS),
            encoder_directions: wire::u8_at(p, field::system::ENCODER_DIRECTIONS),
            pwm_max: wire::u16_at(p, field::system::PWM_MAX),
            pwm_min: wire::u16_at(p, field::system::PWM_MIN),
            encoder_ppr: wire::u16_at(p, field::system::ENCODER_PPR),
        }
    }
}

/// `0x24`: the chassis geometry. The vendor's example: 110, 110, 55, 60.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Geometry {
    /// Wheel spacing, mm.
    pub wheel_spacing_mm: u16,
    /// Axle spacing, mm.
    pub axle_spacing_mm: u16,
    /// Gear ratio.
    pub gear_ratio: u16,
    /// Wheel diameter, mm.
    pub wheel_diameter_mm: u16,
}

impl Geometry {
    pub(in crate::v1) fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u16(
            &mut p,
            field::geometry::WHEEL_SPACING,
            self.wheel_spacing_mm,
        );
        wire::put_u16(&mut p, field::geometry::AXLE_SPACING, self.axle_spacing_mm);
        wire::put_u16(&mut p, field::geometry::GEAR_RATIO, self.gear_ratio);
        wire::put_u16(
            &mut p,
            field::geometry::WHEEL_DIAMETER,
            self.wheel_diameter_mm,
        );
        p
    }

    pub(in crate::v1) fn from_payload(p: &[u8]) -> Self {
        Geometry {
            wheel_spacing_mm: wire::u16_at(p, field::geometry::WHEEL_SPACING),
            axle_spacing_mm: wire::u16_at(p, field::geometry::AXLE_SPACING),
            gear_ratio: wire::u16_at(p, field::geometry::GEAR_RATIO),
            wheel_diameter_mm: wire::u16_at(p, field::geometry::WHEEL_DIAMETER),
        }
    }
}

/// `0x40`: the PID gains, raw. The vendor's example: 3000, 1050, 0, 3000, 1050.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pid {
    /// Position loop KP.
    pub position_kp: u16,
    /// Position loop KI.
    pub position_ki: u16,
    /// Position loop KD.
    pub position_kd: u16,
    /// Velocity loop KP.
    pub velocity_kp: u16,
    /// Velocity loop KI.
    pub velocity_ki: u16,
}

impl Pid {
    pub(in crate::v1) fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u16(&mut p, field::pid::POSITION_KP, self.position_kp);
        wire::put_u16(&mut p, field::pid::POSITION_KI, self.position_ki);
        wire::put_u16(&mut p, field::pid::POSITION_KD, self.position_kd);
        wire::put_u16(&mut p, field::pid::VELOCITY_KP, self.velocity_kp);
        wire::put_u16(&mut p, field::pid::VELOCITY_KI, self.velocity_ki);
        p
    }

    pub(in crate::v1) fn from_payload(p: &[u8]) -> Self {
        Pid {
            position_kp: wire::u16_at(p, field::pid::POSITION_KP),
            position_ki: wire::u16_at(p, field::pid::POSITION_KI),
            position_kd: wire::u16_at(p, field::pid::POSITION_KD),
            velocity_kp: wire::u16_at(p, field::pid::VELOCITY_KP),
            velocity_ki: wire::u16_at(p, field::pid::VELOCITY_KI),
        }
    }
}
