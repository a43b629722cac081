//! The settings the v1.0.0 board keeps: the system, geometry and PID frames last written (not
//! across power-ups), the vendor example's at power-up.

use super::Board;
use crate::v1::{Geometry, Pid, SystemSettings};

/// The system settings at power-up: the vendor example's 0, 10, 3600, 2100, 165.
pub const FACTORY_SYSTEM: SystemSettings = SystemSettings {
    motor_directions: 0,
    encoder_directions: 10,
    pwm_max: 3_600,
    pwm_min: 2_100,
    encoder_ppr: 165,
};

/// The geometry at power-up: the vendor example's 110, 110, 55, 60.
pub const FACTORY_GEOMETRY: Geometry = Geometry {
    wheel_spacing_mm: 110,
    axle_spacing_mm: 110,
    gear_ratio: 55,
    wheel_diameter_mm: 60,
};

/// The PID gains at power-up: the vendor example's 3000, 1050, 0, 3000, 1050.
pub const FACTORY_PID: Pid = Pid {
    position_kp: 3_000,
    position_ki: 1_050,
    position_kd: 0,
    velocity_kp: 3_000,
    velocity_ki: 1_050,
};

/// The settings frames last written (or the factory's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Registers {
    pub(super) system: SystemSettings,
    pub(super) geometry: Geometry,
    pub(super) pid: Pid,
}

impl Registers {
    /// The factory's.
    pub(super) const fn new() -> Self {
        Registers {
            system: FACTORY_SYSTEM,
            geometry: FACTORY_GEOMETRY,
            pid: FACTORY_PID,
        }
    }
}

impl Board {
    /// The system settings (last written, or the factory's).
    #[must_use]
    pub const fn system(&self) -> SystemSettings {
        self.registers.system
    }

    /// The geometry (last written, or the factory's).
    #[must_use]
    pub const fn geometry(&self) -> Geometry {
        self.registers.geometry
    }

    /// The PID gains (last written, or the factory's).
    #[must_use]
    pub const fn pid(&self) -> Pid {
        self.registers.pid
    }
}
