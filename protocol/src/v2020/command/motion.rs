//! Motion commands, master → board: mode `0x01` (chassis velocity, or a relative turn in angle
//! mode) and modes `0x02` / `0x03` (each motor on its own).
//!
//! The wire carries unsigned 16-bit magnitudes and puts every sign in a direction byte; these
//! types hold signed `i32` values (±65 535) and do the split. Values past ±65 535 (±10 000 for
//! duty cycles built with the `*_duty` constructors) are saturated, never wrapped.
//!
//! Mode `0x01`, 10 bytes (spec 1A–1C; A2: bytes 3–8 are X/Y/Z body velocity):
//!
//! | byte | 0 | 1 | 2 | 3–4 | 5–6 | 7–8 | 9 |
//! |---|---|---|---|---|---|---|---|
//! | | FF | FE | 01 | X | Y | Z speed, or angle in 0.1° | dir |
//!
//! dir: bit 4 angle mode, bit 2 X reverse, bit 1 Y reverse, bit 0 Z reverse; 7..5 and 3 reserved.
//!
//! Modes `0x02` (closed loop) / `0x03` (open loop, duty in 0.01 %), 12 bytes (spec 1D/1E; A3:
//! the direction byte is byte 11):
//!
//! | byte | 0 | 1 | 2 | 3–4 | 5–6 | 7–8 | 9–10 | 11 |
//! |---|---|---|---|---|---|---|---|---|
//! | | FF | FE | 02/03 | MOTO1 | MOTO2 | MOTO3 | MOTO4 | dir |
//!
//! dir: **bit 3 MOTO4, bit 2 MOTO1, bit 1 MOTO2, bit 0 MOTO3** (the vendor's order); 7..4 reserved.
//!
//! Reserved direction bits, and reverse bits on an axis whose magnitude is 0 (a "negative
//! zero"), are kept by `decode` and written back by `encode`, so every frame round-trips.

use super::{HEADER, mode, mode_of};
use crate::DriveType;
use crate::error::Error;
use crate::wire;

/// Byte offsets of the motion frames.
pub(crate) mod field {
    pub const HEADER: usize = 0;
    pub const MODE: usize = 2;
    pub const X: usize = 3;
    pub const Y: usize = 5;
    pub const Z: usize = 7;
    pub const VELOCITY_DIR: usize = 9;
    /// MOTO1..MOTO4.
    pub const MOTOR: [usize; 4] = [3, 5, 7, 9];
    pub const MOTORS_DIR: usize = 11;
}

/// Bits of the direction bytes.
pub(crate) mod dir {
    pub const Z_REVERSE: u8 = 1 << 0;
    pub const Y_REVERSE: u8 = 1 << 1;
    pub const X_REVERSE: u8 = 1 << 2;
    pub const ANGLE_MODE: u8 = 1 << 4;
    /// Reverse bit of MOTO1..MOTO4: bit 2, bit 1, bit 0, bit 3.
    pub const MOTOR_REVERSE: [u8; 4] = [1 << 2, 1 << 1, 1 << 0, 1 << 3];
}

/// Full scale of a duty cycle in 0.01 % (10 000 = 100.00 %).
pub const DUTY_FULL_SCALE: u16 = 10_000;

/// Encodes a mode-`0x01` frame from signed X / Y / Z and the bits to keep.
fn encode_body(x: i32, y: i32, z: i32, flags: u8) -> [u8; Velocity::LEN] {
    let mut buf = [0u8; Velocity::LEN];
    let mut direction = flags;
    // (Written out three times: each field's offset a constant, its bytes two stores.)
    put_signed(&mut buf, field::X, x, dir::X_REVERSE, &mut direction);
    put_signed(&mut buf, field::Y, y, dir::Y_REVERSE, &mut direction);
    put_signed(&mut buf, field::Z, z, dir::Z_REVERSE, &mut direction);
    wire::put(&mut buf, field::HEADER, &HEADER);
    wire::put_u8(&mut buf, field::MODE, mode::VELOCITY);
    wire::put_u8(&mut buf, field::VELOCITY_DIR, direction);
    buf
}

/// Writes `value`'s magnitude at `at` and sets `reverse_bit` in `direction` when it is
/// negative and not zero. Inlined, so that each call's offset is a constant: two stores, not a
/// loop the compiler would make a `memcpy` call.
#[inline(always)]
fn put_signed(buf: &mut [u8], at: usize, value: i32, reverse_bit: u8, direction: &mut u8) {
    let (magnitude, reverse) = wire::split_signed(value, u16::MAX);
    wire::put_u16(buf, at, magnitude);
    if reverse && magnitude != 0 {
        *direction |= reverse_bit;
    }
}

/// Decodes a mode-`0x01` frame into signed X / Y / Z, the raw direction byte and the bits to
/// keep (reserved bits and reverse bits of zero magnitudes).
fn decode_body(bytes: &[u8]) -> Result<([i32; 3], u8, u8), Error> {
    if mode_of(bytes, Velocity::LEN)? != mode::VELOCITY {
        return Err(Error::Mode);
    }
    let direction = wire::u8_at(bytes, field::VELOCITY_DIR);
    let mut kept = direction & !(dir::X_REVERSE | dir::Y_REVERSE | dir::Z_REVERSE);
    let mut values = [0i32; 3];
    for (value, (at, reverse_bit)) in values.iter_mut().zip([
        (field::X, dir::X_REVERSE),
        (field::Y, dir::Y_REVERSE),
        (field::Z, dir::Z_REVERSE),
    ]) {
        let magnitude = wire::u16_at(bytes, at);
        let reverse = direction & reverse_bit != 0;
        *value = wire::join_signed(magnitude, reverse);
        if reverse && magnitude == 0 {
            kept |= reverse_bit;
        }
    }
    Ok((values, direction, kept))
}

/// Chassis velocity, mode `0x01` with angle mode off: safe to send again and again.
///
/// What X, Y and Z mean depends on the board's [`DriveType`]; see [`Velocity::reading`].
/// Units are not stated by the vendor (A8): the values go on the wire as they are, except for
/// open-loop differential chassis, where Y and Z are duty cycles in 0.01 %.
///
/// ```
/// use chassis_protocol::Velocity;
///
/// // Forward (Y) at 300, turning clockwise (Z reversed) at 50.
/// let frame = Velocity::new(0, 300, -50).encode();
/// assert_eq!(frame, [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x01, 0x2C, 0x00, 0x32, 0b0000_0001]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Velocity {
    /// X: sideways on omni and mecanum chassis; unused (0) on differential ones.
    pub x: i32,
    /// Y: forward (positive) or back.
    pub y: i32,
    /// Z: rotation speed; positive is the board's "forward" rotation (dir bit 0 clear).
    pub z: i32,
    /// Reserved direction bits and reverse bits of zero magnitudes, kept from `decode`. Never
    /// serialised: a value that comes through serde carries none, so no message can set a bit
    /// (such as the angle-mode bit) that the typed fields do not show.
    #[cfg_attr(feature = "serde", serde(skip))]
    kept: u8,
}

impl Velocity {
    /// Length of the frame on the wire.
    pub const LEN: usize = 10;

    /// All axes at 0: the chassis stops.
    pub const STOP: Velocity = Velocity::new(0, 0, 0);

    /// Body velocity for omni and mecanum chassis: X sideways, Y forward, Z rotation.
    #[must_use]
    pub const fn new(x: i32, y: i32, z: i32) -> Self {
        Velocity { x, y, z, kept: 0 }
    }

    /// Differential chassis with encoders: forward speed (Y) and rotation speed (Z); X is 0.
    #[must_use]
    pub const fn differential(forward: i32, rotation: i32) -> Self {
        Velocity::new(0, forward, rotation)
    }

    /// Differential chassis without encoders: forward and rotation duty cycles in 0.01 %
    /// (10 000 = 100.00 %), each clamped to ±10 000.
    #[must_use]
    pub fn differential_duty(forward_centi_percent: i32, rotation_centi_percent: i32) -> Self {
        Velocity::differential(
            wire::clamp_signed(forward_centi_percent, DUTY_FULL_SCALE),
            wire::clamp_signed(rotation_centi_percent, DUTY_FULL_SCALE),
        )
    }

    /// The 10 bytes of this frame. Each axis saturates at ±65 535.
    #[must_use]
    pub fn encode(&self) -> [u8; Self::LEN] {
        // Never the angle-mode bit, however the value was made: a `Velocity` is safe to repeat.
        encode_body(self.x, self.y, self.z, self.kept & !dir::ANGLE_MODE)
    }

    /// Decodes exactly one frame. An angle-mode frame is [`Error::Mode`]: decode it as a
    /// [`Turn`], or use [`Command::decode`](super::Command::decode) for either.
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        let ([x, y, z], direction, kept) = decode_body(bytes)?;
        if direction & dir::ANGLE_MODE != 0 {
            return Err(Error::Mode);
        }
        Ok(Velocity { x, y, z, kept })
    }

    /// What the three values mean on a chassis of drive type `drive`; `None` for a reserved
    /// drive type.
    ///
    /// ```
    /// use chassis_protocol::{DriveType, Velocity, VelocityReading};
    ///
    /// let v = Velocity::differential_duty(2_500, -12_000);
    /// assert_eq!(
    ///     v.reading(DriveType::DifferentialOpenLoop),
    ///     Some(VelocityReading::DifferentialDuty {
    ///         forward_centi_percent: 2_500,
    ///         rotation_centi_percent: -10_000,
    ///     })
    /// );
    /// ```
    #[must_use]
    pub const fn reading(&self, drive: DriveType) -> Option<VelocityReading> {
        match drive {
            DriveType::Omni | DriveType::Mecanum => Some(VelocityReading::Holonomic {
                sideways: self.x,
                forward: self.y,
                rotation: self.z,
            }),
            DriveType::Differential => Some(VelocityReading::Differential {
                forward: self.y,
                rotation: self.z,
            }),
            DriveType::DifferentialOpenLoop => Some(VelocityReading::DifferentialDuty {
                forward_centi_percent: self.y,
                rotation_centi_percent: self.z,
            }),
            DriveType::Reserved(_) => None,
        }
    }
}

/// What a [`Velocity`] means for one drive type (spec 1A–1C).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum VelocityReading {
    /// Omni or mecanum: three body velocities.
    Holonomic {
        /// X, sideways.
        sideways: i32,
        /// Y, forward.
        forward: i32,
        /// Z, rotation.
        rotation: i32,
    },
    /// Differential with encoders: X is unused.
    Differential {
        /// Y, forward speed.
        forward: i32,
        /// Z, rotation speed.
        rotation: i32,
    },
    /// Differential without encoders: duty cycles, no closed loop.
    DifferentialDuty {
        /// Y, forward duty in 0.01 %.
        forward_centi_percent: i32,
        /// Z, rotation duty in 0.01 %.
        rotation_centi_percent: i32,
    },
}

/// A relative turn: mode `0x01` with angle mode on (dir bit 4). **Not idempotent.**
///
/// # Hazard: the board accumulates angles
///
/// Every frame received with angle mode on *adds* its angle to the turn still pending. A
/// control loop that re-sends its last frame every period would spin the chassis without end.
/// Send a `Turn` once, then go back to a [`Velocity`] frame (or a turn of 0). The master-side
/// driver makes this one-shot through its API; when you write frames yourself, it is on you.
///
/// Bytes 7–8 carry the angle in 0.1° (900 = 90.0°), its sign in dir bit 0; X and Y keep their
/// meaning as velocities.
///
/// ```
/// use chassis_protocol::Turn;
///
/// // Turn by -90.0° (dir bit 0 set), standing still.
/// let frame = Turn::by_deci_degrees(-900).encode();
/// assert_eq!(frame, [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0x84, 0b0001_0001]);
/// ```
///
/// A turn is sent once: encoding consumes it, and it is not `Copy`.
///
/// ```compile_fail
/// use chassis_protocol::Turn;
///
/// let turn = Turn::by_deci_degrees(900);
/// let first = turn.encode();
/// let again = turn.encode(); // error: `turn` was consumed by the first send
/// ```
///
/// It is `Clone`, and cloning is safe: a clone is a second turn asked for in so many words, and
/// the [driver](crate)'s turn guard refuses it while the first is outstanding (test
/// `case5_a_cloned_turn_is_refused_while_the_first_runs`).
// Not `Copy`: sending a turn consumes it ([`Turn::encode`] takes `self`), so one value cannot be
// sent twice by accident; a second turn is a second value (or an explicit `clone`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Turn {
    /// X velocity while turning (see [`Velocity::x`]).
    pub x: i32,
    /// Y velocity while turning (see [`Velocity::y`]).
    pub y: i32,
    /// The angle to add to the pending turn, in 0.1° (±65 535, saturated).
    pub deci_degrees: i32,
    /// Reserved direction bits and reverse bits of zero magnitudes, kept from `decode`. Never
    /// serialised: a value that comes through serde carries none, so no message can set a bit
    /// (such as the angle-mode bit) that the typed fields do not show.
    #[cfg_attr(feature = "serde", serde(skip))]
    kept: u8,
}

impl Turn {
    /// Length of the frame on the wire.
    pub const LEN: usize = Velocity::LEN;

    /// A turn by `deci_degrees` (0.1°) while X and Y stay 0.
    #[must_use]
    pub const fn by_deci_degrees(deci_degrees: i32) -> Self {
        Turn::new(0, 0, deci_degrees)
    }

    /// A turn by `deci_degrees` (0.1°) while moving at X / Y.
    #[must_use]
    pub const fn new(x: i32, y: i32, deci_degrees: i32) -> Self {
        Turn {
            x,
            y,
            deci_degrees,
            kept: 0,
        }
    }

    /// The 10 bytes of this frame (angle-mode bit set). Consumes the turn: the board adds every
    /// angle frame it receives to the pending turn, so a `Turn` is encoded (sent) once.
    #[must_use]
    pub fn encode(self) -> [u8; Self::LEN] {
        encode_body(
            self.x,
            self.y,
            self.deci_degrees,
            self.kept | dir::ANGLE_MODE,
        )
    }

    /// Decodes exactly one frame. A frame without angle mode is [`Error::Mode`].
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        let ([x, y, deci_degrees], direction, kept) = decode_body(bytes)?;
        if direction & dir::ANGLE_MODE == 0 {
            return Err(Error::Mode);
        }
        Ok(Turn {
            x,
            y,
            deci_degrees,
            kept: kept & !dir::ANGLE_MODE,
        })
    }
}

/// Which loop drives the motors of a [`Motors`] frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum MotorLoop {
    /// Mode `0x02`: closed loop with encoders; values are speeds.
    Closed,
    /// Mode `0x03`: open loop without encoders; values are duty cycles in 0.01 %.
    Open,
}

impl MotorLoop {
    const fn mode(self) -> u8 {
        match self {
            MotorLoop::Closed => mode::MOTORS_CLOSED_LOOP,
            MotorLoop::Open => mode::MOTORS_OPEN_LOOP,
        }
    }
}

/// Each motor on its own, modes `0x02` / `0x03`, whatever the drive type. Idempotent.
///
/// `values[0]` is MOTO1 … `values[3]` is MOTO4. The direction byte uses the vendor's order
/// (bit 2 MOTO1, bit 1 MOTO2, bit 0 MOTO3, bit 3 MOTO4); this type hides it.
///
/// ```
/// use chassis_protocol::Motors;
///
/// // MOTO1 forward at 25.00 %, MOTO3 reversed at 10.00 % (dir bit 0), open loop.
/// let frame = Motors::open_loop_duty([2_500, 0, -1_000, 0]).encode();
/// assert_eq!(
///     frame,
///     [0xFF, 0xFE, 0x03, 0x09, 0xC4, 0x00, 0x00, 0x03, 0xE8, 0x00, 0x00, 0b0000_0001]
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Motors {
    /// Closed loop (`0x02`, speeds) or open loop (`0x03`, duty in 0.01 %).
    pub control: MotorLoop,
    /// MOTO1..MOTO4, signed (±65 535, saturated).
    pub values: [i32; 4],
    /// Reserved direction bits and reverse bits of zero magnitudes, kept from `decode`. Never
    /// serialised: a value that comes through serde carries none, so no message can set a bit
    /// (such as the angle-mode bit) that the typed fields do not show.
    #[cfg_attr(feature = "serde", serde(skip))]
    kept: u8,
}

impl Motors {
    /// Length of the frame on the wire.
    pub const LEN: usize = 12;

    /// Closed-loop speeds for MOTO1..MOTO4 (mode `0x02`).
    #[must_use]
    pub const fn closed_loop(speeds: [i32; 4]) -> Self {
        Motors {
            control: MotorLoop::Closed,
            values: speeds,
            kept: 0,
        }
    }

    /// Open-loop duty cycles for MOTO1..MOTO4 in 0.01 % (mode `0x03`), each clamped to ±10 000.
    #[must_use]
    pub fn open_loop_duty(centi_percent: [i32; 4]) -> Self {
        Motors {
            control: MotorLoop::Open,
            values: centi_percent.map(|v| wire::clamp_signed(v, DUTY_FULL_SCALE)),
            kept: 0,
        }
    }

    /// The 12 bytes of this frame.
    #[must_use]
    pub fn encode(&self) -> [u8; Self::LEN] {
        let mut buf = [0u8; Self::LEN];
        let mut direction = self.kept;
        // (Written out four times, as `encode_body` writes its three.)
        let [v0, v1, v2, v3] = self.values;
        let [at0, at1, at2, at3] = field::MOTOR;
        let [r0, r1, r2, r3] = dir::MOTOR_REVERSE;
        put_signed(&mut buf, at0, v0, r0, &mut direction);
        put_signed(&mut buf, at1, v1, r1, &mut direction);
        put_signed(&mut buf, at2, v2, r2, &mut direction);
        put_signed(&mut buf, at3, v3, r3, &mut direction);
        wire::put(&mut buf, field::HEADER, &HEADER);
        wire::put_u8(&mut buf, field::MODE, self.control.mode());
        wire::put_u8(&mut buf, field::MOTORS_DIR, direction);
        buf
    }

    /// Decodes exactly one mode-`0x02` or mode-`0x03` frame.
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        let control = match mode_of(bytes, Self::LEN)? {
            mode::MOTORS_CLOSED_LOOP => MotorLoop::Closed,
            mode::MOTORS_OPEN_LOOP => MotorLoop::Open,
            _ => return Err(Error::Mode),
        };
        let direction = wire::u8_at(bytes, field::MOTORS_DIR);
        let mut kept = direction & 0xF0;
        let mut values = [0i32; 4];
        for ((value, at), reverse_bit) in
            values.iter_mut().zip(field::MOTOR).zip(dir::MOTOR_REVERSE)
        {
            let magnitude = wire::u16_at(bytes, at);
            let reverse = direction & reverse_bit != 0;
            *value = wire::join_signed(magnitude, reverse);
            if reverse && magnitude == 0 {
                kept |= reverse_bit;
            }
        }
        Ok(Motors {
            control,
            values,
            kept,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Golden frames, written by hand from the spec tables (1A–1E).

    /// 1B: X = 0x0102 reversed, Y = 0x0304, Z = 0x0506 reversed: dir = bit 2 | bit 0.
    static VELOCITY_MIXED: [u8; 10] = [0xFF, 0xFE, 0x01, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x05];
    /// 1A note: angle 900 = 90.0°, forward: dir = bit 4 only.
    static TURN_90: [u8; 10] = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0x84, 0x10];
    /// 1D: MOTO1 = 1 reversed (bit 2), MOTO2 = 2, MOTO3 = 3 reversed (bit 0), MOTO4 = 4
    /// reversed (bit 3).
    static MOTORS_CLOSED: [u8; 12] = [
        0xFF,
        0xFE,
        0x02,
        0x00,
        0x01,
        0x00,
        0x02,
        0x00,
        0x03,
        0x00,
        0x04,
        0b0000_1101,
    ];
    /// 1E: all four at 100.00 % (10 000 = 0x2710), MOTO2 reversed (bit 1).
    static MOTORS_OPEN_FULL: [u8; 12] = [
        0xFF,
        0xFE,
        0x03,
        0x27,
        0x10,
        0x27,
        0x10,
        0x27,
        0x10,
        0x27,
        0x10,
        0b0000_0010,
    ];

    #[test]
    fn velocity_golden() {
        let v = Velocity::new(-0x0102, 0x0304, -0x0506);
        assert_eq!(v.encode(), VELOCITY_MIXED);
        assert_eq!(Velocity::decode(&VELOCITY_MIXED), Ok(v));
        assert_eq!(
            Velocity::STOP.encode(),
            [0xFF, 0xFE, 0x01, 0, 0, 0, 0, 0, 0, 0]
        );
    }

    #[test]
    fn differential_sends_x_as_zero() {
        let frame = Velocity::differential(-1, 2).encode();
        assert_eq!(
            frame,
            [0xFF, 0xFE, 0x01, 0, 0, 0x00, 0x01, 0x00, 0x02, 0b010]
        );
        // Duty form clamps at 100.00 %.
        let frame = Velocity::differential_duty(20_000, -10_001).encode();
        assert_eq!(
            frame,
            [0xFF, 0xFE, 0x01, 0, 0, 0x27, 0x10, 0x27, 0x10, 0b001]
        );
    }

    #[test]
    fn values_saturate_instead_of_wrapping() {
        let frame = Velocity::new(70_000, i32::MIN, 65_536).encode();
        assert_eq!(
            frame,
            [0xFF, 0xFE, 0x01, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0b010]
        );
    }

    #[test]
    fn turn_golden_and_the_two_modes_do_not_mix() {
        assert_eq!(Turn::by_deci_degrees(900).encode(), TURN_90);
        assert_eq!(Turn::decode(&TURN_90), Ok(Turn::by_deci_degrees(900)));
        assert_eq!(Velocity::decode(&TURN_90), Err(Error::Mode));
        assert_eq!(Turn::decode(&VELOCITY_MIXED), Err(Error::Mode));
    }

    #[test]
    fn motors_golden_with_the_vendor_bit_order() {
        let m = Motors::closed_loop([-1, 2, -3, -4]);
        assert_eq!(m.encode(), MOTORS_CLOSED);
        assert_eq!(Motors::decode(&MOTORS_CLOSED), Ok(m));
        let m = Motors::open_loop_duty([10_000, -10_000, 12_345, 10_000]);
        assert_eq!(m.encode(), MOTORS_OPEN_FULL);
        assert_eq!(Motors::decode(&MOTORS_OPEN_FULL), Ok(m));
    }

    #[test]
    fn each_motor_has_its_own_direction_bit() {
        for (motor, bit) in [(0, 2), (1, 1), (2, 0), (3, 3)] {
            let mut values = [5; 4];
            if let Some(v) = values.get_mut(motor) {
                *v = -5;
            }
            let frame = Motors::closed_loop(values).encode();
            assert_eq!(frame.get(11), Some(&(1u8 << bit)), "MOTO{}", motor + 1);
        }
    }

    #[test]
    fn reserved_bits_and_negative_zero_round_trip() {
        // Reserved bits 7..5 and 3 set, Y reversed with magnitude 0.
        let bytes = [
            0xFF,
            0xFE,
            0x01,
            0x00,
            0x07,
            0x00,
            0x00,
            0x00,
            0x00,
            0b1110_1010,
        ];
        let v = Velocity::decode(&bytes).unwrap();
        assert_eq!((v.x, v.y, v.z), (7, 0, 0));
        assert_eq!(v.encode(), bytes);
        let bytes = [0xFF, 0xFE, 0x02, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF];
        let m = Motors::decode(&bytes).unwrap();
        assert_eq!(m.values, [0; 4]);
        assert_eq!(m.encode(), bytes);
    }

    #[test]
    fn decode_rejects_what_is_not_this_frame() {
        assert_eq!(Velocity::decode(&VELOCITY_MIXED[..9]), Err(Error::Length));
        assert_eq!(Motors::decode(&VELOCITY_MIXED), Err(Error::Length));
        let mut bad = VELOCITY_MIXED;
        bad[1] = 0xFA;
        assert_eq!(Velocity::decode(&bad), Err(Error::Header));
        let mut bad = MOTORS_CLOSED;
        bad[2] = 0x01;
        assert_eq!(Motors::decode(&bad), Err(Error::Mode));
    }

    #[test]
    fn readings_per_drive_type() {
        let v = Velocity::new(1, 2, 3);
        assert_eq!(
            v.reading(DriveType::Mecanum),
            Some(VelocityReading::Holonomic {
                sideways: 1,
                forward: 2,
                rotation: 3
            })
        );
        assert_eq!(
            v.reading(DriveType::Differential),
            Some(VelocityReading::Differential {
                forward: 2,
                rotation: 3
            })
        );
        assert_eq!(v.reading(DriveType::Reserved(7)), None);
    }
}
