//! Settings, master → board: mode `0x80`, always 10 bytes (spec 2A–2D).
//!
//! | byte | 0 | 1 | 2 | 3 | 4 | 5–8 | 9 |
//! |---|---|---|---|---|---|---|---|
//! | | FF | FE | 80 | 80 (fixed) | code | value (u32, big-endian) | 00 (reserved) |
//!
//! * **Actions** (2A): code `00`, value `0x8000_0000 | action`.
//! * **Writes** (2B): the register's code (`01`, `06`..`0C`); 16-bit registers send `00 00` in
//!   bytes 5–6; the battery range sends full (bytes 5–6) and cut-off (bytes 7–8).
//! * **Reads** (2C / 2D): code `0x10 +` the register's code (`0x20` for the pending angle),
//!   value 0. The board answers with a [`Reply`](crate::Reply).
//!
//! The board stops its telemetry while settings are being made.
//!
//! Anything that fits the layout but not one of these typed forms (an unknown code, a
//! non-zero reserved byte) decodes as [`Setting::Raw`] and re-encodes to the same bytes.

use super::{HEADER, SystemMode, mode};
use crate::codes::code_enum;
use crate::error::Error;
use crate::wire;

/// Byte offsets of a settings frame.
mod field {
    pub const HEADER: usize = 0;
    pub const MODE: usize = 2;
    /// Always `0x80`.
    pub const FIXED: usize = 3;
    pub const CODE: usize = 4;
    /// b5..b8, a big-endian u32.
    pub const VALUE: usize = 5;
    /// Reserved, `0x00`.
    pub const TAIL: usize = 9;
}

/// The byte after the settings mode byte.
pub(crate) const FIXED: u8 = 0x80;
/// Where it stands (the master → board parser checks it early).
pub(crate) const FIXED_AT: usize = field::FIXED;
/// Code of the actions (2A).
pub(crate) const ACTION_CODE: u8 = 0x00;
/// Bytes 5–6 of an action: `80 00`.
const ACTION_MARK: u32 = 0x8000_0000;

code_enum! {
    /// A register of the board: what a [`Write`] sets, a [`Setting::Read`] asks for and a
    /// [`Reply`](crate::Reply) answers. [`Register::code`] is its write code and the code its
    /// reply carries.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub enum Register (code, from_code): u8 {
        /// `0x01`: maximum speed limit, u16 (unit not stated, A8).
        MaxSpeed = 0x01,
        /// `0x06`: speed-loop KP, raw u32.
        SpeedKp = 0x06,
        /// `0x07`: speed-loop KI, raw u32.
        SpeedKi = 0x07,
        /// `0x08`: gyro compensation gain, u32 in 0.00001 (too large makes the chassis
        /// oscillate).
        GyroGain = 0x08,
        /// `0x09`: the [`SystemMode`] bit field.
        SystemMode = 0x09,
        /// `0x0A`: gyro calibration value, u16; writing 0xFFFF calibrates again.
        GyroCalibration = 0x0A,
        /// `0x0B`: motor output voltage, u16 in 0.01 V.
        MotorVoltage = 0x0B,
        /// `0x0C`: battery voltage range: full (high u16) and cut-off (low u16), 0.01 V;
        /// 0x7FFF = the built-in table.
        BatteryRange = 0x0C,
        /// `0x20` (read only, 2D): the rotation still to turn, i32 in 0.1°.
        PendingAngle = 0x20,
    }
}

impl Register {
    /// Its name as the `chassis` command and the Python package spell it (`max-speed`, `kp`,
    /// `ki`, `gyro-gain`, `system-mode`, `gyro-calibration`, `motor-voltage`, `battery-range`,
    /// `pending-angle`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Register::MaxSpeed => "max-speed",
            Register::SpeedKp => "kp",
            Register::SpeedKi => "ki",
            Register::GyroGain => "gyro-gain",
            Register::SystemMode => "system-mode",
            Register::GyroCalibration => "gyro-calibration",
            Register::MotorVoltage => "motor-voltage",
            Register::BatteryRange => "battery-range",
            Register::PendingAngle => "pending-angle",
        }
    }

    /// The register of a [`name`](Register::name).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Register::ALL.into_iter().find(|r| r.name() == name)
    }

    /// The code that reads it: `0x10 +` its code (2C), `0x20` for the pending angle (2D).
    #[must_use]
    pub const fn read_code(self) -> u8 {
        match self {
            Register::PendingAngle => 0x20,
            other => other.code() | 0x10,
        }
    }

    /// The code a reply to it carries (the same as [`Register::code`]).
    #[must_use]
    pub const fn reply_code(self) -> u8 {
        self.code()
    }

    /// The register whose reply carries `code`.
    #[must_use]
    pub const fn from_reply_code(code: u8) -> Option<Self> {
        Register::from_code(code)
    }

    /// The register that `code` reads.
    #[must_use]
    pub const fn from_read_code(code: u8) -> Option<Self> {
        match code {
            0x20 => Some(Register::PendingAngle),
            0x11..=0x1C => match Register::from_reply_code(code & 0x0F) {
                Some(Register::PendingAngle) | None => None,
                found => found,
            },
            _ => None,
        }
    }
}

code_enum! {
    /// A 2A action: code `00`, bytes 5–6 `80 00`, bytes 7–8 the action number
    /// ([`Action::number`]).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    pub enum Action (number, from_number): u16 {
        /// `0x0001`: load the stored settings.
        LoadStored = 1,
        /// `0x0002`: load the factory defaults.
        LoadDefaults = 2,
        /// `0x0003`: store the current settings (system-mode bit 3 is not stored).
        Store = 3,
        /// `0x0004`: gyro compensation off (system-mode bit 3 = 0; A4).
        GyroCompensationOff = 4,
        /// `0x0005`: gyro compensation on (system-mode bit 3 = 1; A4).
        GyroCompensationOn = 5,
        /// `0x0006`: calibrate the gyro again, compensation on. Takes 30 s: 10 s to put the
        /// chassis in place, then 20 s without moving or touching it.
        RecalibrateGyro = 6,
    }
    /// Any other action number, kept as received.
    unknown Unknown
}

/// A 2B register write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Write {
    /// `0x01`: maximum speed limit (unit not stated).
    MaxSpeed(u16),
    /// `0x06`: speed-loop KP, raw.
    SpeedKp(u32),
    /// `0x07`: speed-loop KI, raw.
    SpeedKi(u32),
    /// `0x08`: gyro compensation gain in 0.00001 (100 000 = 1.0).
    GyroGain(u32),
    /// `0x09`: system mode.
    SystemMode(SystemMode),
    /// `0x0A`: gyro calibration value; 0xFFFF calibrates again (30 s).
    GyroCalibration(u16),
    /// `0x0B`: motor output voltage.
    MotorVoltage {
        /// In 0.01 V.
        centivolts: u16,
    },
    /// `0x0C`: battery voltage range; 0x7FFF in either field = the built-in table (default).
    BatteryRange {
        /// Full-charge voltage in 0.01 V (bytes 5–6).
        full_centivolts: u16,
        /// Cut-off voltage in 0.01 V (bytes 7–8).
        cutoff_centivolts: u16,
    },
}

impl Write {
    /// The register this writes.
    #[must_use]
    pub const fn register(&self) -> Register {
        match self {
            Write::MaxSpeed(_) => Register::MaxSpeed,
            Write::SpeedKp(_) => Register::SpeedKp,
            Write::SpeedKi(_) => Register::SpeedKi,
            Write::GyroGain(_) => Register::GyroGain,
            Write::SystemMode(_) => Register::SystemMode,
            Write::GyroCalibration(_) => Register::GyroCalibration,
            Write::MotorVoltage { .. } => Register::MotorVoltage,
            Write::BatteryRange { .. } => Register::BatteryRange,
        }
    }

    /// The 32-bit value of bytes 5–8: the same value the register's [`Reply`](crate::Reply)
    /// carries.
    #[must_use]
    pub const fn value(&self) -> u32 {
        match *self {
            Write::MaxSpeed(v) | Write::GyroCalibration(v) => v as u32,
            Write::MotorVoltage { centivolts } => centivolts as u32,
            Write::SpeedKp(v) | Write::SpeedKi(v) | Write::GyroGain(v) => v,
            Write::SystemMode(mode) => mode.bits(),
            Write::BatteryRange {
                full_centivolts,
                cutoff_centivolts,
            } => ((full_centivolts as u32) << 16) | cutoff_centivolts as u32,
        }
    }

    /// The write of `value` to `register`, if `register` is writable and `value` fits it
    /// (16-bit registers need bytes 5–6 at 0).
    #[must_use]
    pub const fn from_value(register: Register, value: u32) -> Option<Self> {
        let narrow = if value >> 16 == 0 {
            Some(value as u16)
        } else {
            None
        };
        match (register, narrow) {
            (Register::MaxSpeed, Some(v)) => Some(Write::MaxSpeed(v)),
            (Register::GyroCalibration, Some(v)) => Some(Write::GyroCalibration(v)),
            (Register::MotorVoltage, Some(v)) => Some(Write::MotorVoltage { centivolts: v }),
            (Register::SpeedKp, _) => Some(Write::SpeedKp(value)),
            (Register::SpeedKi, _) => Some(Write::SpeedKi(value)),
            (Register::GyroGain, _) => Some(Write::GyroGain(value)),
            (Register::SystemMode, _) => Some(Write::SystemMode(SystemMode::from_bits(value))),
            (Register::BatteryRange, _) => Some(Write::BatteryRange {
                full_centivolts: (value >> 16) as u16,
                cutoff_centivolts: value as u16,
            }),
            _ => None,
        }
    }
}

/// A settings frame (mode `0x80`).
///
/// ```
/// use chassis_protocol::{Register, Setting, Write};
///
/// let frame = Setting::Write(Write::MotorVoltage { centivolts: 1_200 }).encode();
/// assert_eq!(frame, [0xFF, 0xFE, 0x80, 0x80, 0x0B, 0x00, 0x00, 0x04, 0xB0, 0x00]);
/// let frame = Setting::Read(Register::SystemMode).encode();
/// assert_eq!(frame, [0xFF, 0xFE, 0x80, 0x80, 0x19, 0x00, 0x00, 0x00, 0x00, 0x00]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Setting {
    /// 2A: an action.
    Action(Action),
    /// 2B: a register write.
    Write(Write),
    /// 2C / 2D: a register read; the board answers with a [`Reply`](crate::Reply).
    Read(Register),
    /// A frame of the settings layout that is none of the above, kept byte for byte.
    Raw {
        /// Byte 4.
        code: u8,
        /// Bytes 5–8.
        value: u32,
        /// Byte 9 (reserved, 0 in every typed form).
        tail: u8,
    },
}

impl Setting {
    /// Length of the frame on the wire.
    pub const LEN: usize = 10;

    /// Code, value and tail bytes of this setting.
    const fn parts(&self) -> (u8, u32, u8) {
        match *self {
            Setting::Action(action) => (ACTION_CODE, ACTION_MARK | action.number() as u32, 0),
            Setting::Write(write) => (write.register().code(), write.value(), 0),
            Setting::Read(register) => (register.read_code(), 0, 0),
            Setting::Raw { code, value, tail } => (code, value, tail),
        }
    }

    /// The setting of these code, value and tail bytes: typed where one fits exactly.
    const fn from_parts(code: u8, value: u32, tail: u8) -> Self {
        let raw = Setting::Raw { code, value, tail };
        if tail != 0 {
            return raw;
        }
        if code == ACTION_CODE {
            return if value & 0xFFFF_0000 == ACTION_MARK {
                Setting::Action(Action::from_number(value as u16))
            } else {
                raw
            };
        }
        if let Some(register) = Register::from_read_code(code) {
            return if value == 0 {
                Setting::Read(register)
            } else {
                raw
            };
        }
        match Register::from_reply_code(code) {
            Some(register) => match Write::from_value(register, value) {
                Some(write) => Setting::Write(write),
                None => raw,
            },
            None => raw,
        }
    }

    /// The 10 bytes of this frame.
    #[must_use]
    pub fn encode(&self) -> [u8; Self::LEN] {
        let (code, value, tail) = self.parts();
        let mut buf = [0u8; Self::LEN];
        wire::put(&mut buf, field::HEADER, &HEADER);
        wire::put_u8(&mut buf, field::MODE, mode::SETTINGS);
        wire::put_u8(&mut buf, field::FIXED, FIXED);
        wire::put_u8(&mut buf, field::CODE, code);
        wire::put_u32(&mut buf, field::VALUE, value);
        wire::put_u8(&mut buf, field::TAIL, tail);
        buf
    }

    /// Decodes exactly one settings frame. Byte 3 must be `80` ([`Error::Fixed`] otherwise).
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        if bytes.len() != Self::LEN {
            return Err(Error::Length);
        }
        if bytes.get(field::HEADER..field::MODE) != Some(&HEADER[..]) {
            return Err(Error::Header);
        }
        if wire::u8_at(bytes, field::MODE) != mode::SETTINGS {
            return Err(Error::Mode);
        }
        if wire::u8_at(bytes, field::FIXED) != FIXED {
            return Err(Error::Fixed);
        }
        Ok(Setting::from_parts(
            wire::u8_at(bytes, field::CODE),
            wire::u32_at(bytes, field::VALUE),
            wire::u8_at(bytes, field::TAIL),
        ))
    }
}

impl From<Action> for Setting {
    fn from(action: Action) -> Self {
        Setting::Action(action)
    }
}

impl From<Write> for Setting {
    fn from(write: Write) -> Self {
        Setting::Write(write)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DriveType;

    /// Golden frames, byte for byte from the tables of 2A, 2B, 2C and 2D.
    #[test]
    fn register_names_are_the_cli_spellings_and_round_trip() {
        let names = Register::ALL.map(Register::name);
        assert_eq!(
            names,
            [
                "max-speed",
                "kp",
                "ki",
                "gyro-gain",
                "system-mode",
                "gyro-calibration",
                "motor-voltage",
                "battery-range",
                "pending-angle",
            ]
        );
        for r in Register::ALL {
            assert_eq!(Register::from_name(r.name()), Some(r));
        }
        assert_eq!(Register::from_name("max_speed"), None);
    }

    #[test]
    fn actions_golden() {
        let cases = [
            (Action::LoadStored, 0x01),
            (Action::LoadDefaults, 0x02),
            (Action::Store, 0x03),
            (Action::GyroCompensationOff, 0x04),
            (Action::GyroCompensationOn, 0x05),
            (Action::RecalibrateGyro, 0x06),
        ];
        for (action, n) in cases {
            let golden = [0xFF, 0xFE, 0x80, 0x80, 0x00, 0x80, 0x00, 0x00, n, 0x00];
            assert_eq!(Setting::Action(action).encode(), golden, "{action:?}");
            assert_eq!(Setting::decode(&golden), Ok(Setting::Action(action)));
        }
    }

    #[test]
    fn writes_golden() {
        let cases: [(Write, [u8; 10]); 8] = [
            (
                Write::MaxSpeed(0x1234),
                [0xFF, 0xFE, 0x80, 0x80, 0x01, 0x00, 0x00, 0x12, 0x34, 0x00],
            ),
            (
                Write::SpeedKp(0x0102_0304),
                [0xFF, 0xFE, 0x80, 0x80, 0x06, 0x01, 0x02, 0x03, 0x04, 0x00],
            ),
            (
                Write::SpeedKi(0xA0B0_C0D0),
                [0xFF, 0xFE, 0x80, 0x80, 0x07, 0xA0, 0xB0, 0xC0, 0xD0, 0x00],
            ),
            (
                Write::GyroGain(100_000),
                [0xFF, 0xFE, 0x80, 0x80, 0x08, 0x00, 0x01, 0x86, 0xA0, 0x00],
            ),
            (
                Write::SystemMode(SystemMode::new(DriveType::Mecanum).with_gyro_reversed(true)),
                [0xFF, 0xFE, 0x80, 0x80, 0x09, 0x00, 0x00, 0x08, 0x01, 0x00],
            ),
            (
                Write::GyroCalibration(0xFFFF),
                [0xFF, 0xFE, 0x80, 0x80, 0x0A, 0x00, 0x00, 0xFF, 0xFF, 0x00],
            ),
            (
                Write::MotorVoltage { centivolts: 1_200 },
                [0xFF, 0xFE, 0x80, 0x80, 0x0B, 0x00, 0x00, 0x04, 0xB0, 0x00],
            ),
            (
                Write::BatteryRange {
                    full_centivolts: 1_260,
                    cutoff_centivolts: 0x7FFF,
                },
                [0xFF, 0xFE, 0x80, 0x80, 0x0C, 0x04, 0xEC, 0x7F, 0xFF, 0x00],
            ),
        ];
        for (write, golden) in cases {
            assert_eq!(Setting::Write(write).encode(), golden, "{write:?}");
            assert_eq!(Setting::decode(&golden), Ok(Setting::Write(write)));
        }
    }

    #[test]
    fn reads_golden() {
        let cases = [
            (Register::MaxSpeed, 0x11),
            (Register::SpeedKp, 0x16),
            (Register::SpeedKi, 0x17),
            (Register::GyroGain, 0x18),
            (Register::SystemMode, 0x19),
            (Register::GyroCalibration, 0x1A),
            (Register::MotorVoltage, 0x1B),
            (Register::BatteryRange, 0x1C),
            (Register::PendingAngle, 0x20),
        ];
        for (register, code) in cases {
            let golden = [0xFF, 0xFE, 0x80, 0x80, code, 0, 0, 0, 0, 0];
            assert_eq!(Setting::Read(register).encode(), golden, "{register:?}");
            assert_eq!(Setting::decode(&golden), Ok(Setting::Read(register)));
        }
    }

    #[test]
    fn register_codes() {
        assert_eq!(
            Register::ALL.map(Register::code),
            [1, 6, 7, 8, 9, 10, 11, 12, 0x20]
        );
        for register in Register::ALL {
            assert_eq!(
                Register::from_reply_code(register.reply_code()),
                Some(register)
            );
            assert_eq!(
                Register::from_read_code(register.read_code()),
                Some(register)
            );
        }
        for code in [0x10, 0x12, 0x15, 0x1D, 0x1F, 0x21, 0x30, 0x01] {
            assert_eq!(Register::from_read_code(code), None, "{code:#x}");
        }
    }

    #[test]
    fn irregular_frames_are_kept_raw() {
        let cases: [[u8; 10]; 6] = [
            // Unknown code.
            [0xFF, 0xFE, 0x80, 0x80, 0x42, 1, 2, 3, 4, 0],
            // Non-zero reserved byte 9 on an otherwise valid write.
            [0xFF, 0xFE, 0x80, 0x80, 0x06, 0, 0, 0, 1, 0x55],
            // A 16-bit write with bytes 5-6 set.
            [0xFF, 0xFE, 0x80, 0x80, 0x01, 0x00, 0x01, 0x00, 0x00, 0],
            // An action without the 80 00 mark.
            [0xFF, 0xFE, 0x80, 0x80, 0x00, 0x00, 0x00, 0x00, 0x01, 0],
            // A read with a value.
            [0xFF, 0xFE, 0x80, 0x80, 0x19, 0, 0, 0, 9, 0],
            // Code 0x10 reads nothing.
            [0xFF, 0xFE, 0x80, 0x80, 0x10, 0, 0, 0, 0, 0],
        ];
        for bytes in cases {
            let setting = Setting::decode(&bytes).unwrap();
            assert!(
                matches!(setting, Setting::Raw { .. }),
                "{bytes:02x?} -> {setting:?}"
            );
            assert_eq!(setting.encode(), bytes);
        }
        let unknown_action = [0xFF, 0xFE, 0x80, 0x80, 0x00, 0x80, 0x00, 0x12, 0x34, 0];
        let setting = Setting::decode(&unknown_action).unwrap();
        assert_eq!(setting, Setting::Action(Action::Unknown(0x1234)));
        assert_eq!(setting.encode(), unknown_action);
    }

    #[test]
    fn decode_errors() {
        let good = Setting::Read(Register::MaxSpeed).encode();
        assert_eq!(Setting::decode(&good[..9]), Err(Error::Length));
        let mut bad = good;
        bad[3] = 0x00;
        assert_eq!(Setting::decode(&bad), Err(Error::Fixed));
        let mut bad = good;
        bad[2] = 0x01;
        assert_eq!(Setting::decode(&bad), Err(Error::Mode));
        let mut bad = good;
        bad[0] = 0x23;
        assert_eq!(Setting::decode(&bad), Err(Error::Header));
    }
}
