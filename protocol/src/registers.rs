//! [`Settings`]: a snapshot of every readable register — what the driver reads in one call and
//! writes back in one call, and what the board simulator keeps (live and stored copies).

use crate::command::{Register, SystemMode, Write};
use crate::telemetry::Reply;

/// A snapshot of the board's registers (2C). Serialises with `serde` (feature `serde`), e.g.
/// with postcard's `to_slice` / `to_slice_cobs`, to keep a bring-up's settings in flash.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Settings {
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

impl Settings {
    /// The registers a snapshot holds, in the order [`Settings::writes`] gives them.
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

    /// Takes in the reply to one of [`Settings::REGISTERS`]; `false` for any other reply, or a
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
