//! The system-mode register (setting code `0x09`, spec 2B-5): a 32-bit field of which the low
//! 12 bits are defined.
//!
//! | bits | meaning |
//! |---|---|
//! | 2..0 | [`DriveType`] |
//! | 3 | gyro compensation (not stored by [`Action::Store`](super::Action::Store)) |
//! | 4 | gyro correction also while X and Y are 0 |
//! | 7..5 | reserved |
//! | 8 | motor direction reversed |
//! | 9 | encoder direction reversed |
//! | 10 | steering reversed |
//! | 11 | gyro reversed |
//! | 31..12 | reserved |
//!
//! [`SystemMode`] keeps all 32 bits as received, reserved ones included, so a value read from the
//! board writes back unchanged.

/// Bit positions of the system-mode register.
mod bit {
    pub const DRIVE_TYPE_MASK: u32 = 0b111;
    pub const GYRO_COMPENSATION: u32 = 1 << 3;
    pub const GYRO_CORRECTION_AT_REST: u32 = 1 << 4;
    pub const MOTOR_REVERSED: u32 = 1 << 8;
    pub const ENCODER_REVERSED: u32 = 1 << 9;
    pub const STEERING_REVERSED: u32 = 1 << 10;
    pub const GYRO_REVERSED: u32 = 1 << 11;
}

/// The chassis's drive type: system-mode bits 2..0. It decides what the X / Y / Z fields of a
/// velocity frame mean (see [`Velocity::reading`](super::Velocity::reading)).
///
/// **Ambiguity A1**: the original's section 1C says open-loop differential is 4, its register
/// table (2B-5) says 3. [`DriveType::DifferentialOpenLoop`] encodes as 3 (the register table);
/// decoding accepts both 3 and 4. [`SystemMode`] keeps the raw three bits either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum DriveType {
    /// 0: omni wheels. X sideways, Y forward, Z rotation.
    Omni,
    /// 1: mecanum wheels (MOTO1 left-front, MOTO2 right-front, MOTO3 right-rear, MOTO4
    /// left-rear). X sideways, Y forward, Z rotation.
    Mecanum,
    /// 2: differential ("ordinary") wheels with encoders: Y forward speed, Z rotation speed,
    /// X unused. Left side MOTO1 + MOTO4, right side MOTO2 + MOTO3.
    Differential,
    /// 3 (or 4, see A1): differential wheels without encoders: Y and Z are duty cycles in
    /// 0.01 % (0..=10 000); no PID, no position control, no gyro correction.
    DifferentialOpenLoop,
    /// 5..=7: not defined by the spec; the raw value is kept.
    Reserved(u8),
}

impl DriveType {
    /// The drive type of the raw three bits (only the low three bits of `bits` are read).
    #[must_use]
    pub const fn from_bits(bits: u8) -> Self {
        match bits & 0b111 {
            0 => DriveType::Omni,
            1 => DriveType::Mecanum,
            2 => DriveType::Differential,
            3 | 4 => DriveType::DifferentialOpenLoop,
            other => DriveType::Reserved(other),
        }
    }

    /// The three bits this drive type is written as (`DifferentialOpenLoop` as 3, A1).
    #[must_use]
    pub const fn bits(self) -> u8 {
        match self {
            DriveType::Omni => 0,
            DriveType::Mecanum => 1,
            DriveType::Differential => 2,
            DriveType::DifferentialOpenLoop => 3,
            DriveType::Reserved(bits) => bits & 0b111,
        }
    }
}

/// The system-mode register value, lossless: every one of the 32 bits is kept.
///
/// ```
/// use chassis_protocol::{DriveType, SystemMode};
///
/// let mode = SystemMode::new(DriveType::Mecanum).with_gyro_compensation(true);
/// assert_eq!(mode.bits(), 0b1001);
/// assert_eq!(mode.drive_type(), DriveType::Mecanum);
/// // A1: the vendor's section 1C calls open-loop differential "4"; it is still understood.
/// assert_eq!(SystemMode::from_bits(4).drive_type(), DriveType::DifferentialOpenLoop);
/// assert_eq!(SystemMode::from_bits(4).bits(), 4);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SystemMode(u32);

impl SystemMode {
    /// A mode with the given drive type and every flag off.
    #[must_use]
    pub const fn new(drive: DriveType) -> Self {
        SystemMode(drive.bits() as u32)
    }

    /// The mode exactly as the raw register value.
    #[must_use]
    pub const fn from_bits(bits: u32) -> Self {
        SystemMode(bits)
    }

    /// The raw register value, reserved bits included.
    #[must_use]
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The drive type (bits 2..0).
    #[must_use]
    pub const fn drive_type(self) -> DriveType {
        DriveType::from_bits(self.drive_type_bits())
    }

    /// The raw drive-type bits 2..0, as received (3 and 4 both mean open-loop differential).
    #[must_use]
    pub const fn drive_type_bits(self) -> u8 {
        (self.0 & bit::DRIVE_TYPE_MASK) as u8
    }

    /// This mode with another drive type; every other bit is kept.
    #[must_use]
    pub const fn with_drive_type(self, drive: DriveType) -> Self {
        SystemMode((self.0 & !bit::DRIVE_TYPE_MASK) | drive.bits() as u32)
    }

    const fn flag(self, mask: u32) -> bool {
        self.0 & mask != 0
    }

    const fn with_flag(self, mask: u32, on: bool) -> Self {
        SystemMode(if on { self.0 | mask } else { self.0 & !mask })
    }

    /// Bit 3: gyro compensation on. The board does **not** store this bit with
    /// [`Action::Store`](super::Action::Store). Switching it on starts a 30 s gyro calibration:
    /// put the chassis in place during the first 10 s, then do not move or touch it for 20 s.
    #[must_use]
    pub const fn gyro_compensation(self) -> bool {
        self.flag(bit::GYRO_COMPENSATION)
    }

    /// This mode with bit 3 (gyro compensation) set or cleared.
    #[must_use]
    pub const fn with_gyro_compensation(self, on: bool) -> Self {
        self.with_flag(bit::GYRO_COMPENSATION, on)
    }

    /// Bit 4: gyro correction also while X and Y are both 0.
    #[must_use]
    pub const fn gyro_correction_at_rest(self) -> bool {
        self.flag(bit::GYRO_CORRECTION_AT_REST)
    }

    /// This mode with bit 4 set or cleared.
    #[must_use]
    pub const fn with_gyro_correction_at_rest(self, on: bool) -> Self {
        self.with_flag(bit::GYRO_CORRECTION_AT_REST, on)
    }

    /// Bit 8: motor direction reversed.
    #[must_use]
    pub const fn motor_reversed(self) -> bool {
        self.flag(bit::MOTOR_REVERSED)
    }

    /// This mode with bit 8 set or cleared.
    #[must_use]
    pub const fn with_motor_reversed(self, on: bool) -> Self {
        self.with_flag(bit::MOTOR_REVERSED, on)
    }

    /// Bit 9: encoder direction reversed.
    #[must_use]
    pub const fn encoder_reversed(self) -> bool {
        self.flag(bit::ENCODER_REVERSED)
    }

    /// This mode with bit 9 set or cleared.
    #[must_use]
    pub const fn with_encoder_reversed(self, on: bool) -> Self {
        self.with_flag(bit::ENCODER_REVERSED, on)
    }

    /// Bit 10: steering reversed.
    #[must_use]
    pub const fn steering_reversed(self) -> bool {
        self.flag(bit::STEERING_REVERSED)
    }

    /// This mode with bit 10 set or cleared.
    #[must_use]
    pub const fn with_steering_reversed(self, on: bool) -> Self {
        self.with_flag(bit::STEERING_REVERSED, on)
    }

    /// Bit 11: gyro reversed. The vendor's advice: if gyro compensation is on and the chassis
    /// keeps spinning in place, flip this bit.
    #[must_use]
    pub const fn gyro_reversed(self) -> bool {
        self.flag(bit::GYRO_REVERSED)
    }

    /// This mode with bit 11 set or cleared.
    #[must_use]
    pub const fn with_gyro_reversed(self, on: bool) -> Self {
        self.with_flag(bit::GYRO_REVERSED, on)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_flag_is_its_own_bit() {
        let base = SystemMode::new(DriveType::Omni);
        assert_eq!(base.with_gyro_compensation(true).bits(), 1 << 3);
        assert_eq!(base.with_gyro_correction_at_rest(true).bits(), 1 << 4);
        assert_eq!(base.with_motor_reversed(true).bits(), 1 << 8);
        assert_eq!(base.with_encoder_reversed(true).bits(), 1 << 9);
        assert_eq!(base.with_steering_reversed(true).bits(), 1 << 10);
        assert_eq!(base.with_gyro_reversed(true).bits(), 1 << 11);
        let all = SystemMode::from_bits(0xFFFF_FFFF);
        assert!(all.gyro_compensation() && all.gyro_correction_at_rest());
        assert!(all.motor_reversed() && all.encoder_reversed());
        assert!(all.steering_reversed() && all.gyro_reversed());
        assert_eq!(all.with_gyro_reversed(false).bits(), 0xFFFF_F7FF);
    }

    #[test]
    fn drive_types_follow_the_register_table_and_a1() {
        assert_eq!(SystemMode::new(DriveType::Omni).bits(), 0);
        assert_eq!(SystemMode::new(DriveType::Mecanum).bits(), 1);
        assert_eq!(SystemMode::new(DriveType::Differential).bits(), 2);
        assert_eq!(SystemMode::new(DriveType::DifferentialOpenLoop).bits(), 3);
        assert_eq!(DriveType::from_bits(4), DriveType::DifferentialOpenLoop);
        assert_eq!(DriveType::from_bits(3), DriveType::DifferentialOpenLoop);
        assert_eq!(DriveType::from_bits(6), DriveType::Reserved(6));
        assert_eq!(DriveType::Reserved(6).bits(), 6);
    }

    #[test]
    fn changing_the_drive_type_keeps_every_other_bit() {
        let mode = SystemMode::from_bits(0xABCD_E004);
        let changed = mode.with_drive_type(DriveType::Mecanum);
        assert_eq!(changed.bits(), 0xABCD_E001);
        assert_eq!(mode.drive_type_bits(), 4);
    }
}
