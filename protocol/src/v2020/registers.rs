//! [`Snapshot`]: a snapshot of every readable register — what the driver reads in one call and
//! writes back in one call, and what the board simulator keeps (live and stored copies).

use crate::command::{Register, SystemMode, Write};
use crate::telemetry::Reply;

/// A snapshot of the board's registers (2C): every readable setting (named `Snapshot`, not
/// `Settings`, so that it is never mistaken for a [`Setting`](crate::Setting) frame). Serialises with `serde` (feature `serde`), e.g.
/// with postcard's `to_slice` / `to_slice_cobs`, to keep a bring-up's settings in flash.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
// A settings file with a misspelt key is refused, not half applied.
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Snapshot {
    /// `0x01`, unit not stated.
    pub max_speed: u16,
    /// `0x06`, raw.
    pub speed_kp: u32,
    /// `0x07`, raw.
    pub speed_ki: u32,
    /// `0x08`, in 0.00001.
    pub gyro_gain: u32,
    /// `0x09`.
    pub system_mode: SystemMode,
    /// `0x0A`.
    pub gyro_calibration: u16,
    /// `0x0B`, 0.01 V.
    pub motor_centivolts: u16,
    /// `0x0C` high half, 0.01 V (0x7FFF: the built-in table).
    pub battery_full_centivolts: u16,
    /// `0x0C` low half, 0.01 V (0x7FFF: the built-in table).
    pub battery_cutoff_centivolts: u16,
}

impl Snapshot {
    /// The eight registers a snapshot holds. [`Snapshot::writes`] gives seven of them back, in
    /// this order, leaving out the gyro calibration value.
    pub const REGISTERS: [Register; 8] = [
        Register::MaxSpeed,
        Register::SpeedKp,
        Register::SpeedKi,
        Register::GyroGain,
        Register::SystemMode,
        Register::GyroCalibration,
        Register::MotorVoltage,
        Register::BatteryRange,
    ];

    /// Takes in the reply to one of [`Snapshot::REGISTERS`]; `false` for any other reply, or a
    /// value that does not fit its register.
    pub fn apply(&mut self, reply: &Reply) -> bool {
        match reply.as_write() {
            Some(write) => {
                self.set(write);
                true
            }
            None => false,
        }
    }

    /// The value a read of `register` returns: as its reply carries it (`None` for the pending
    /// angle, which is no setting).
    #[must_use]
    pub fn value(&self, register: Register) -> Option<u32> {
        Some(match register {
            Register::MaxSpeed => u32::from(self.max_speed),
            Register::SpeedKp => self.speed_kp,
            Register::SpeedKi => self.speed_ki,
            Register::GyroGain => self.gyro_gain,
            Register::SystemMode => self.system_mode.bits(),
            Register::GyroCalibration => u32::from(self.gyro_calibration),
            Register::MotorVoltage => u32::from(self.motor_centivolts),
            Register::BatteryRange => {
                (u32::from(self.battery_full_centivolts) << 16)
                    | u32::from(self.battery_cutoff_centivolts)
            }
            Register::PendingAngle => return None,
        })
    }

    /// Applies a register write.
    pub fn set(&mut self, write: Write) {
        match write {
            Write::MaxSpeed(v) => self.max_speed = v,
            Write::SpeedKp(v) => self.speed_kp = v,
            Write::SpeedKi(v) => self.speed_ki = v,
            Write::GyroGain(v) => self.gyro_gain = v,
            Write::SystemMode(m) => self.system_mode = m,
            Write::GyroCalibration(v) => self.gyro_calibration = v,
            Write::MotorVoltage { centivolts } => self.motor_centivolts = centivolts,
            Write::BatteryRange {
                full_centivolts,
                cutoff_centivolts,
            } => {
                self.battery_full_centivolts = full_centivolts;
                self.battery_cutoff_centivolts = cutoff_centivolts;
            }
        }
    }

    /// The writes that put these settings back on a board. The gyro calibration value is left
    /// out: writing it back would not recalibrate, and 0xFFFF would start a 30 s calibration.
    #[must_use]
    pub const fn writes(&self) -> [Write; 7] {
        [
            Write::MaxSpeed(self.max_speed),
            Write::SpeedKp(self.speed_kp),
            Write::SpeedKi(self.speed_ki),
            Write::GyroGain(self.gyro_gain),
            Write::SystemMode(self.system_mode),
            Write::MotorVoltage {
                centivolts: self.motor_centivolts,
            },
            Write::BatteryRange {
                full_centivolts: self.battery_full_centivolts,
                cutoff_centivolts: self.battery_cutoff_centivolts,
            },
        ]
    }
}

/// The battery voltage range register (`0x0C`): two values in 0.01 V; `0x7FFF` in either means
/// the board's built-in table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BatteryRange {
    /// A full battery, in 0.01 V (the reply's high half).
    pub full_centivolts: u16,
    /// The cut-off, in 0.01 V (the reply's low half).
    pub cutoff_centivolts: u16,
}

/// A register whose reply has a type of its own: what [`reg`]'s marker types implement, so that
/// reading a register gives its value typed (max speed a `u16`, the system mode a
/// [`SystemMode`], the pending angle signed 0.1°), and a reply whose value does not fit the
/// register is an error instead of a wrong value.
pub trait Readable {
    /// The register read.
    const REGISTER: Register;
    /// Its value's type.
    type Value: Copy + core::fmt::Debug + PartialEq;
    /// The value a reply carries, `None` if it does not fit this register (a 16-bit register
    /// with bits in its high half: a damaged reply).
    fn from_raw(raw: u32) -> Option<Self::Value>;
}

/// Marker types of the readable registers, for typed reads (`driver.read(reg::MaxSpeed)`).
pub mod reg {
    use super::Readable;
    use crate::command::Register;

    macro_rules! readable {
        ($(#[$doc:meta])* $name:ident, $value:ty, |$raw:ident| $convert:expr) => {
            $(#[$doc])*
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub struct $name;

            impl Readable for $name {
                const REGISTER: Register = Register::$name;
                type Value = $value;
                fn from_raw($raw: u32) -> Option<$value> {
                    $convert
                }
            }
        };
    }

    readable!(
        /// `0x01`: maximum speed limit, `u16` (unit not stated, A8).
        MaxSpeed, u16, |raw| u16::try_from(raw).ok()
    );
    readable!(
        /// `0x06`: speed-loop KP, raw `u32`.
        SpeedKp, u32, |raw| Some(raw)
    );
    readable!(
        /// `0x07`: speed-loop KI, raw `u32`.
        SpeedKi, u32, |raw| Some(raw)
    );
    readable!(
        /// `0x08`: gyro compensation gain, `u32` in 0.00001.
        GyroGain, u32, |raw| Some(raw)
    );
    readable!(
        /// `0x09`: the system mode bit field (every bit kept).
        SystemMode, crate::command::SystemMode, |raw| Some(
            crate::command::SystemMode::from_bits(raw)
        )
    );
    readable!(
        /// `0x0A`: gyro calibration value, `u16` (0xFFFF while a calibration runs).
        GyroCalibration, u16, |raw| u16::try_from(raw).ok()
    );
    readable!(
        /// `0x0B`: motor output voltage, `u16` in 0.01 V.
        MotorVoltage, u16, |raw| u16::try_from(raw).ok()
    );
    readable!(
        /// `0x0C`: the battery voltage range.
        BatteryRange, super::BatteryRange, |raw| Some(super::BatteryRange {
            full_centivolts: (raw >> 16) as u16,
            cutoff_centivolts: (raw & 0xFFFF) as u16,
        })
    );
    readable!(
        /// `0x20`: the angle still to turn, signed, in 0.1° (the reply's `u32` read as `i32`).
        PendingAngle, i32, |raw| Some(raw as i32)
    );
}

/// Whether `raw` fits `register` (16-bit registers need their high half at 0).
#[must_use]
pub const fn fits(register: Register, raw: u32) -> bool {
    match register {
        Register::MaxSpeed | Register::GyroCalibration | Register::MotorVoltage => raw >> 16 == 0,
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_registers_refuse_a_high_half() {
        assert_eq!(
            <reg::MaxSpeed as Readable>::from_raw(0x0000_03E8),
            Some(1_000)
        );
        assert_eq!(<reg::MaxSpeed as Readable>::from_raw(0x0001_0000), None);
        assert_eq!(<reg::MotorVoltage as Readable>::from_raw(0x0100_04B0), None);
        assert!(!fits(Register::GyroCalibration, 0x0001_FFFF));
        assert!(fits(Register::SpeedKp, u32::MAX));
    }

    #[test]
    fn the_pending_angle_is_signed_and_the_battery_range_split() {
        assert_eq!(
            <reg::PendingAngle as Readable>::from_raw(0xFFFF_FC7C),
            Some(-900)
        );
        assert_eq!(
            <reg::BatteryRange as Readable>::from_raw(0x04EC_041A),
            Some(BatteryRange {
                full_centivolts: 1_260,
                cutoff_centivolts: 1_050
            })
        );
    }

    #[test]
    fn the_snapshot_lists_its_eight_registers_and_writes_seven() {
        assert_eq!(Snapshot::REGISTERS.len(), 8);
        assert_eq!(Snapshot::default().writes().len(), 7);
    }
}
