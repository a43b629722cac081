//! Register and action names on the command line.

use chassis_protocol::{Action, Register};
use clap::ValueEnum;

/// A register, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RegisterName {
    /// 0x01, u16.
    MaxSpeed,
    /// 0x06, speed-loop KP, u32.
    Kp,
    /// 0x07, speed-loop KI, u32.
    Ki,
    /// 0x08, gyro compensation gain in 0.00001, u32.
    GyroGain,
    /// 0x09, the system-mode bit field, u32.
    SystemMode,
    /// 0x0A, gyro calibration value, u16 (0xFFFF: calibrate again, 30 s).
    GyroCalibration,
    /// 0x0B, motor output voltage in 0.01 V, u16.
    MotorVoltage,
    /// 0x0C, battery range: full and cut-off, 0.01 V each (0x7FFF: built-in table).
    BatteryRange,
    /// 0x20 (2D, read only): the angle still to turn, 0.1°.
    PendingAngle,
}

impl RegisterName {
    /// The protocol's register.
    pub const fn register(self) -> Register {
        match self {
            RegisterName::MaxSpeed => Register::MaxSpeed,
            RegisterName::Kp => Register::SpeedKp,
            RegisterName::Ki => Register::SpeedKi,
            RegisterName::GyroGain => Register::GyroGain,
            RegisterName::SystemMode => Register::SystemMode,
            RegisterName::GyroCalibration => Register::GyroCalibration,
            RegisterName::MotorVoltage => Register::MotorVoltage,
            RegisterName::BatteryRange => Register::BatteryRange,
            RegisterName::PendingAngle => Register::PendingAngle,
        }
    }

    /// Its name on the command line.
    pub const fn name(self) -> &'static str {
        self.register().name()
    }
}

/// A 2A action, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ActionName {
    /// 1: load the stored settings.
    Load,
    /// 2: load the factory defaults.
    Defaults,
    /// 3: store the current settings in the board's flash.
    Save,
    /// 4: gyro compensation off.
    GyroOff,
    /// 5: gyro compensation on.
    GyroOn,
    /// 6: calibrate the gyro again (30 s: keep the chassis still).
    GyroRecalibrate,
}

impl ActionName {
    /// The protocol's action.
    pub const fn action(self) -> Action {
        match self {
            ActionName::Load => Action::LoadStored,
            ActionName::Defaults => Action::LoadDefaults,
            ActionName::Save => Action::Store,
            ActionName::GyroOff => Action::GyroCompensationOff,
            ActionName::GyroOn => Action::GyroCompensationOn,
            ActionName::GyroRecalibrate => Action::RecalibrateGyro,
        }
    }
}

/// `register`'s name on the command line ("max-speed").
pub fn register_name(register: Register) -> String {
    register.name().to_string()
}
