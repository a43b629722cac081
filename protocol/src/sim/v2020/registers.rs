//! The board's registers: live and stored copies, factory defaults, actions, and the gyro
//! calibration that switching compensation on starts.

use super::Board;
use crate::command::{Action, DriveType, Register, Setting, SystemMode, Write};
use crate::registers::Snapshot;
use crate::telemetry::Reply;

/// The factory defaults of the model (the vendor does not publish them; these are chosen).
pub const FACTORY: Snapshot = Snapshot {
    max_speed: 1_000,
    speed_kp: 300,
    speed_ki: 20,
    gyro_gain: 50_000,
    system_mode: SystemMode::new(DriveType::Mecanum),
    gyro_calibration: 0x0200,
    motor_centivolts: 1_200,
    battery_full_centivolts: 0x7FFF,
    battery_cutoff_centivolts: 0x7FFF,
};

/// The registers: the live copy, the stored one, and a gyro calibration running.
#[derive(Clone, Debug)]
pub(super) struct Registers {
    /// What the board works with.
    pub(super) live: Snapshot,
    /// What it would load back (its flash).
    pub(super) stored: Snapshot,
    /// A gyro calibration ends then, ms.
    pub(super) calibrating_until_ms: Option<u64>,
}

impl Registers {
    /// The factory defaults, live and stored.
    pub(super) const fn new() -> Self {
        Registers {
            live: FACTORY,
            stored: FACTORY,
            calibrating_until_ms: None,
        }
    }
}

/// Gyro calibration time: 10 s settle + 20 s still.
const CALIBRATION_MS: u64 = 30_000;
impl Board {
    pub(super) fn setting(&mut self, setting: Setting) {
        self.streams.quiet_until_ms = self
            .port
            .now_ms
            .saturating_add(u64::from(self.config.resume_after_ms));
        match setting {
            Setting::Action(action) => self.action(action),
            Setting::Write(write) => {
                let compensation_was = self.registers.live.system_mode.gyro_compensation();
                self.registers.live.set(write);
                match write {
                    Write::GyroCalibration(0xFFFF) => self.start_calibration(),
                    Write::SystemMode(mode) if mode.gyro_compensation() && !compensation_was => {
                        self.start_calibration();
                    }
                    _ => {}
                }
            }
            Setting::Read(register) => {
                let value = match register {
                    Register::PendingAngle => self.pending_deci_degrees() as u32,
                    Register::GyroCalibration if self.calibrating() => 0xFFFF,
                    other => self.registers.live.value(other).unwrap_or(0),
                };
                let due = self
                    .port
                    .now_ms
                    .saturating_add(u64::from(self.config.reply_delay_ms));
                let _ = self.replies.push_back((due, Reply::new(register, value)));
            }
            Setting::Raw { .. } => {}
        }
    }

    pub(super) fn action(&mut self, action: Action) {
        match action {
            Action::LoadStored => self.registers.live = self.registers.stored,
            Action::LoadDefaults => self.registers.live = FACTORY,
            Action::Store => {
                // System-mode bit 3 is not stored.
                let compensation = self.registers.stored.system_mode.gyro_compensation();
                self.registers.stored = self.registers.live;
                self.registers.stored.system_mode = self
                    .registers
                    .stored
                    .system_mode
                    .with_gyro_compensation(compensation);
            }
            Action::GyroCompensationOff => {
                self.registers.live.system_mode = self
                    .registers
                    .live
                    .system_mode
                    .with_gyro_compensation(false);
            }
            Action::GyroCompensationOn | Action::RecalibrateGyro => {
                self.registers.live.system_mode =
                    self.registers.live.system_mode.with_gyro_compensation(true);
                self.start_calibration();
            }
            Action::Unknown(_) => {}
        }
    }

    pub(super) fn start_calibration(&mut self) {
        self.registers.calibrating_until_ms = Some(self.port.now_ms.saturating_add(CALIBRATION_MS));
    }
}
