//! The board's newer firmware, **v1.0.0** (2023): `7B … BCC 7D` frames, a different protocol
//! on the same 115 200 bps UART (`PROTOCOL-V1.md` beside the spec: every fact, with how sure
//! it is).
//!
//! * Master → board: always 14 bytes, `7B`, a code, ten payload bytes, BCC, `7D`
//!   ([`Command`]).
//! * Board → master: a 32-byte [`Telemetry`] frame (code `00`) streamed at about 20–24 Hz,
//!   and 14-byte [`Reply`] frames to the five readback requests ([`Readback`]).
//! * BCC is the XOR of every byte from the `7B` to the byte before it ([`bcc`]); multi-byte
//!   values are big-endian.
//!
//! Velocities are SI units × 1000 (mm/s, mrad/s). Values whose scale nobody has established
//! (the accelerometer, the per-motor "mm/s or 1000·r") stay raw, and their docs say so. There is
//! no turn by angle in this generation: nothing here can send one.
//!
//! [`DownlinkParser`] and [`UplinkParser`] take bytes one at a time (or a slice), check the
//! start, end and BCC of every frame, and resynchronise on the next `7B` inside what they hold.
//!
//! ```
//! use chassis_protocol::v1::{BodyVelocity, Command, Readback};
//!
//! // 0.3 m/s forward (Y), the vendor's mecanum type 4.
//! let frame = Command::BodyVelocity(BodyVelocity::new(0, 300, 0)).encode();
//! assert_eq!(frame, [0x7B, 0x25, 0x02, 0x04, 0, 0, 0x01, 0x2C, 0, 0, 0, 0, 0x75, 0x7D]);
//! // The vendor's readback request of the system settings.
//! let read = Command::Readback(Readback::System).encode();
//! assert_eq!(read[12], 0x48);
//! ```

mod fields;
mod parse;

pub use fields::{FIELDS, FieldError, Settings, field_readback};
pub use parse::{DownlinkParser, Frames, Parser, Stats, UplinkParser};

use crate::wire;

/// First byte of every frame.
pub const START: u8 = 0x7B;
/// Last byte of every frame.
pub const END: u8 = 0x7D;
/// A master → board frame, and a reply: 14 bytes.
pub const COMMAND_LEN: usize = 14;
/// A telemetry frame: 32 bytes.
pub const TELEMETRY_LEN: usize = 32;
/// Byte 1 of a telemetry frame.
pub const TELEMETRY_CODE: u8 = 0x00;
/// The payload of a 14-byte frame: bytes 2..12.
pub const PAYLOAD_LEN: usize = 10;

/// The XOR of `bytes`: a frame's BCC is that of every byte before it.
#[must_use]
pub fn bcc(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0, |acc, b| acc ^ b)
}

/// Why bytes are not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FrameError {
    /// Not the frame's length (14, or 32 for telemetry).
    Length,
    /// The first byte is not `7B`.
    Start,
    /// The last byte is not `7D`.
    End,
    /// The BCC does not match.
    Checksum {
        /// The BCC of the bytes.
        computed: u8,
        /// The BCC the frame carries.
        carried: u8,
    },
    /// A code this direction does not have.
    UnknownCode(u8),
    /// Payload bytes the layout gives as `00` are not: a readback request's ten, the last two
    /// of `0x23`, `0x24`, `0x25` (anything else is not known to be harmless).
    Payload,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FrameError::Length => f.write_str("not a frame's length"),
            FrameError::Start => f.write_str("does not start with 7B"),
            FrameError::End => f.write_str("does not end with 7D"),
            FrameError::Checksum { computed, carried } => {
                write!(f, "BCC {carried:#04x}, the bytes give {computed:#04x}")
            }
            FrameError::UnknownCode(c) => write!(f, "unknown code {c:#04x}"),
            FrameError::Payload => f.write_str("payload bytes that must be 00 are not"),
        }
    }
}

impl core::error::Error for FrameError {}

/// Checks start, end and BCC of `bytes` as a frame of `len` bytes.
fn check(bytes: &[u8], len: usize) -> Result<(), FrameError> {
    if bytes.len() != len {
        return Err(FrameError::Length);
    }
    let last = len.saturating_sub(1);
    if wire::u8_at(bytes, 0) != START {
        return Err(FrameError::Start);
    }
    if wire::u8_at(bytes, last) != END {
        return Err(FrameError::End);
    }
    let body = last.saturating_sub(1);
    let computed = bcc(bytes.get(..body).unwrap_or(&[]));
    let carried = wire::u8_at(bytes, body);
    if computed != carried {
        return Err(FrameError::Checksum { computed, carried });
    }
    Ok(())
}

/// A 14-byte frame: `7B`, `code`, `payload`, BCC, `7D`.
fn frame14(code: u8, payload: &[u8; PAYLOAD_LEN]) -> [u8; COMMAND_LEN] {
    let mut out = [0u8; COMMAND_LEN];
    wire::put_u8(&mut out, 0, START);
    wire::put_u8(&mut out, 1, code);
    wire::put(&mut out, 2, payload);
    let sum = bcc(out.get(..12).unwrap_or(&[]));
    wire::put_u8(&mut out, 12, sum);
    wire::put_u8(&mut out, 13, END);
    out
}

/// The payload of a checked 14-byte frame.
fn payload_of(bytes: &[u8]) -> [u8; PAYLOAD_LEN] {
    let mut p = [0u8; PAYLOAD_LEN];
    wire::put(&mut p, 0, bytes.get(2..12).unwrap_or(&[]));
    p
}

/// The five readback requests (their reply carries the same code).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Readback {
    /// `0x33`: the system settings ([`SystemSettings`]).
    System,
    /// `0x34`: the geometry ([`Geometry`]).
    Geometry,
    /// `0x35`: the body-velocity state (documented, unverified).
    BodyVelocity,
    /// `0x36`: the per-motor speeds from the encoders (documented, unverified).
    MotorSpeeds,
    /// `0x50`: the PID gains ([`Pid`]).
    Pid,
}

impl Readback {
    /// All five.
    pub const ALL: [Readback; 5] = [
        Readback::System,
        Readback::Geometry,
        Readback::BodyVelocity,
        Readback::MotorSpeeds,
        Readback::Pid,
    ];

    /// Its code byte.
    #[must_use]
    pub const fn code(self) -> u8 {
        match self {
            Readback::System => 0x33,
            Readback::Geometry => 0x34,
            Readback::BodyVelocity => 0x35,
            Readback::MotorSpeeds => 0x36,
            Readback::Pid => 0x50,
        }
    }

    /// The request of a code byte.
    #[must_use]
    pub const fn from_code(code: u8) -> Option<Readback> {
        match code {
            0x33 => Some(Readback::System),
            0x34 => Some(Readback::Geometry),
            0x35 => Some(Readback::BodyVelocity),
            0x36 => Some(Readback::MotorSpeeds),
            0x50 => Some(Readback::Pid),
            _ => None,
        }
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

    fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u8(&mut p, 0, self.ctl);
        wire::put_u8(&mut p, 1, self.kind);
        wire::put_i16(&mut p, 2, self.vx_mm_s);
        wire::put_i16(&mut p, 4, self.vy_mm_s);
        wire::put_i16(&mut p, 6, self.wz_mrad_s);
        p
    }

    fn from_payload(p: &[u8]) -> Self {
        BodyVelocity {
            ctl: wire::u8_at(p, 0),
            kind: wire::u8_at(p, 1),
            vx_mm_s: wire::i16_at(p, 2),
            vy_mm_s: wire::i16_at(p, 4),
            wz_mrad_s: wire::i16_at(p, 6),
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

    fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u8(&mut p, 0, self.ctl);
        wire::put_u8(&mut p, 1, self.kind);
        for (i, s) in self.speeds.iter().enumerate() {
            wire::put_i16(&mut p, i.saturating_mul(2).saturating_add(2), *s);
        }
        p
    }

    fn from_payload(p: &[u8]) -> Self {
        MotorVelocity {
            ctl: wire::u8_at(p, 0),
            kind: wire::u8_at(p, 1),
            speeds: [
                wire::i16_at(p, 2),
                wire::i16_at(p, 4),
                wire::i16_at(p, 6),
                wire::i16_at(p, 8),
            ],
        }
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
    fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u8(&mut p, 0, self.motor_directions);
        wire::put_u8(&mut p, 1, self.encoder_directions);
        wire::put_u16(&mut p, 2, self.pwm_max);
        wire::put_u16(&mut p, 4, self.pwm_min);
        wire::put_u16(&mut p, 6, self.encoder_ppr);
        p
    }

    fn from_payload(p: &[u8]) -> Self {
        SystemSettings {
            motor_directions: wire::u8_at(p, 0),
            encoder_directions: wire::u8_at(p, 1),
            pwm_max: wire::u16_at(p, 2),
            pwm_min: wire::u16_at(p, 4),
            encoder_ppr: wire::u16_at(p, 6),
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
    fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u16(&mut p, 0, self.wheel_spacing_mm);
        wire::put_u16(&mut p, 2, self.axle_spacing_mm);
        wire::put_u16(&mut p, 4, self.gear_ratio);
        wire::put_u16(&mut p, 6, self.wheel_diameter_mm);
        p
    }

    fn from_payload(p: &[u8]) -> Self {
        Geometry {
            wheel_spacing_mm: wire::u16_at(p, 0),
            axle_spacing_mm: wire::u16_at(p, 2),
            gear_ratio: wire::u16_at(p, 4),
            wheel_diameter_mm: wire::u16_at(p, 6),
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
    fn payload(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0u8; PAYLOAD_LEN];
        wire::put_u16(&mut p, 0, self.position_kp);
        wire::put_u16(&mut p, 2, self.position_ki);
        wire::put_u16(&mut p, 4, self.position_kd);
        wire::put_u16(&mut p, 6, self.velocity_kp);
        wire::put_u16(&mut p, 8, self.velocity_ki);
        p
    }

    fn from_payload(p: &[u8]) -> Self {
        Pid {
            position_kp: wire::u16_at(p, 0),
            position_ki: wire::u16_at(p, 2),
            position_kd: wire::u16_at(p, 4),
            velocity_kp: wire::u16_at(p, 6),
            velocity_ki: wire::u16_at(p, 8),
        }
    }
}

/// A master → board frame (14 bytes). There is no turn by angle in v1.0.0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Command {
    /// `0x25`.
    BodyVelocity(BodyVelocity),
    /// `0x26`.
    MotorVelocity(MotorVelocity),
    /// `0x23`.
    System(SystemSettings),
    /// `0x24`.
    Geometry(Geometry),
    /// `0x40`.
    Pid(Pid),
    /// `0x33` `0x34` `0x35` `0x36` `0x50`: ten `00`.
    Readback(Readback),
}

impl Command {
    /// Its code byte.
    #[must_use]
    pub const fn code(&self) -> u8 {
        match self {
            Command::BodyVelocity(_) => 0x25,
            Command::MotorVelocity(_) => 0x26,
            Command::System(_) => 0x23,
            Command::Geometry(_) => 0x24,
            Command::Pid(_) => 0x40,
            Command::Readback(r) => r.code(),
        }
    }

    /// Whether `code` is a master → board code.
    #[must_use]
    pub const fn is_code(code: u8) -> bool {
        matches!(code, 0x23..=0x26 | 0x40) || Readback::from_code(code).is_some()
    }

    /// The frame's 14 bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; COMMAND_LEN] {
        let payload = match self {
            Command::BodyVelocity(v) => v.payload(),
            Command::MotorVelocity(m) => m.payload(),
            Command::System(s) => s.payload(),
            Command::Geometry(g) => g.payload(),
            Command::Pid(p) => p.payload(),
            Command::Readback(_) => [0; PAYLOAD_LEN],
        };
        frame14(self.code(), &payload)
    }

    /// A frame's command: start, end and BCC checked; a readback request's payload must be
    /// ten `00`, as the vendor sends it ([`FrameError::Payload`]).
    pub fn decode(bytes: &[u8]) -> Result<Command, FrameError> {
        check(bytes, COMMAND_LEN)?;
        let p = payload_of(bytes);
        let code = wire::u8_at(bytes, 1);
        // Bytes the layout gives as `00 00` (the last two of 0x23, 0x24, 0x25) must be.
        if matches!(code, 0x23..=0x25) && wire::u16_at(&p, 8) != 0 {
            return Err(FrameError::Payload);
        }
        Ok(match code {
            0x25 => Command::BodyVelocity(BodyVelocity::from_payload(&p)),
            0x26 => Command::MotorVelocity(MotorVelocity::from_payload(&p)),
            0x23 => Command::System(SystemSettings::from_payload(&p)),
            0x24 => Command::Geometry(Geometry::from_payload(&p)),
            0x40 => Command::Pid(Pid::from_payload(&p)),
            code => {
                let request = Readback::from_code(code).ok_or(FrameError::UnknownCode(code))?;
                if p != [0; PAYLOAD_LEN] {
                    return Err(FrameError::Payload);
                }
                Command::Readback(request)
            }
        })
    }
}

/// The 32-byte telemetry frame, streamed at about 20–24 Hz.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Telemetry {
    /// Measured body velocity: vx, vy (mm/s), wz (mrad/s).
    pub velocity: [i16; 3],
    /// Accelerometer x, y, z: raw (scale unknown).
    pub accel: [i16; 3],
    /// Gyro x, y, z: raw (read by one user as mrad/s; not established).
    pub gyro: [i16; 3],
    /// The IMU's quaternion w, x, y, z, × 1000.
    pub quaternion: [i16; 4],
    /// Battery voltage, mV.
    pub battery_mv: i16,
}

impl Telemetry {
    /// The frame's 32 bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; TELEMETRY_LEN] {
        let mut out = [0u8; TELEMETRY_LEN];
        wire::put_u8(&mut out, 0, START);
        wire::put_u8(&mut out, 1, TELEMETRY_CODE);
        let values = self
            .velocity
            .iter()
            .chain(self.accel.iter())
            .chain(self.gyro.iter())
            .chain(self.quaternion.iter())
            .chain(core::iter::once(&self.battery_mv));
        for (i, v) in values.enumerate() {
            wire::put_i16(&mut out, i.saturating_mul(2).saturating_add(2), *v);
        }
        let sum = bcc(out.get(..30).unwrap_or(&[]));
        wire::put_u8(&mut out, 30, sum);
        wire::put_u8(&mut out, 31, END);
        out
    }

    /// A telemetry frame: start, code `00`, end and BCC checked.
    pub fn decode(bytes: &[u8]) -> Result<Telemetry, FrameError> {
        check(bytes, TELEMETRY_LEN)?;
        let code = wire::u8_at(bytes, 1);
        if code != TELEMETRY_CODE {
            return Err(FrameError::UnknownCode(code));
        }
        let at = |i: usize| wire::i16_at(bytes, i.saturating_mul(2).saturating_add(2));
        Ok(Telemetry {
            velocity: [at(0), at(1), at(2)],
            accel: [at(3), at(4), at(5)],
            gyro: [at(6), at(7), at(8)],
            quaternion: [at(9), at(10), at(11), at(12)],
            battery_mv: at(13),
        })
    }
}

/// A 14-byte reply to a readback request: its code, and ten bytes laid out as the matching
/// write (typed by [`Reply::system`], [`Reply::geometry`], …).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Reply {
    /// The request it answers.
    pub request: Readback,
    /// The ten payload bytes.
    pub payload: [u8; PAYLOAD_LEN],
}

impl Reply {
    /// The frame's 14 bytes.
    #[must_use]
    pub fn encode(&self) -> [u8; COMMAND_LEN] {
        frame14(self.request.code(), &self.payload)
    }

    /// A reply frame: start, a readback code, end and BCC checked.
    pub fn decode(bytes: &[u8]) -> Result<Reply, FrameError> {
        check(bytes, COMMAND_LEN)?;
        let code = wire::u8_at(bytes, 1);
        let request = Readback::from_code(code).ok_or(FrameError::UnknownCode(code))?;
        Ok(Reply {
            request,
            payload: payload_of(bytes),
        })
    }

    /// The reply of `0x33`.
    #[must_use]
    pub fn system(&self) -> Option<SystemSettings> {
        (self.request == Readback::System).then(|| SystemSettings::from_payload(&self.payload))
    }

    /// The reply of `0x34`.
    #[must_use]
    pub fn geometry(&self) -> Option<Geometry> {
        (self.request == Readback::Geometry).then(|| Geometry::from_payload(&self.payload))
    }

    /// The reply of `0x35`, laid out as a body-velocity command.
    #[must_use]
    pub fn body_velocity(&self) -> Option<BodyVelocity> {
        (self.request == Readback::BodyVelocity).then(|| BodyVelocity::from_payload(&self.payload))
    }

    /// The reply of `0x36`: control mode, type, M1..M4.
    #[must_use]
    pub fn motor_speeds(&self) -> Option<MotorVelocity> {
        (self.request == Readback::MotorSpeeds).then(|| MotorVelocity::from_payload(&self.payload))
    }

    /// The reply of `0x50`.
    #[must_use]
    pub fn pid(&self) -> Option<Pid> {
        (self.request == Readback::Pid).then(|| Pid::from_payload(&self.payload))
    }
}

/// A board → master frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Downlink {
    /// 32 bytes, code `00`.
    Telemetry(Telemetry),
    /// 14 bytes, a readback code.
    Reply(Reply),
}

impl Downlink {
    /// The frame's length on the wire for the code in its byte 1, if the code is one of this
    /// direction's.
    #[must_use]
    pub const fn len_of(code: u8) -> Option<usize> {
        if code == TELEMETRY_CODE {
            Some(TELEMETRY_LEN)
        } else if Readback::from_code(code).is_some() {
            Some(COMMAND_LEN)
        } else {
            None
        }
    }

    /// A board → master frame (telemetry or a reply, told apart by byte 1).
    pub fn decode(bytes: &[u8]) -> Result<Downlink, FrameError> {
        match wire::u8_at(bytes, 1) {
            TELEMETRY_CODE => Telemetry::decode(bytes).map(Downlink::Telemetry),
            _ => Reply::decode(bytes).map(Downlink::Reply),
        }
    }

    /// The frame's bytes.
    #[must_use]
    pub fn encode(&self) -> crate::FrameBytes<TELEMETRY_LEN> {
        match self {
            Downlink::Telemetry(t) => crate::FrameBytes::new(&t.encode()),
            Downlink::Reply(r) => crate::FrameBytes::new(&r.encode()),
        }
    }
}

#[cfg(test)]
mod tests;
