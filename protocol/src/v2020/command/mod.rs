//! Master → board frames ("uplink"): every frame starts `FF FE`, then a mode byte.
//!
//! | mode | frame | length | module |
//! |---|---|---|---|
//! | `01` | [`Velocity`] (angle mode off) or [`Turn`] (angle mode on) | 10 | [`motion`] |
//! | `02` / `03` | [`Motors`] closed / open loop | 12 | [`motion`] |
//! | `80` | [`Setting`]: actions, writes, reads | 10 | [`settings`] |
//!
//! Each type encodes to a fixed-size array with no parser involved; [`Command`] is the sum of
//! them, for code that handles any uplink frame (the board simulator, a link sniffer).

pub mod motion;
pub mod settings;
pub mod system_mode;

pub use motion::{DUTY_FULL_SCALE, MotorLoop, Motors, Turn, Velocity, VelocityReading};
pub use settings::{Action, Register, Setting, Write};
pub use system_mode::{DriveType, SystemMode};

use crate::bytes::FrameBytes;
use crate::error::Error;

/// The two bytes every master → board frame starts with.
pub const HEADER: [u8; 2] = [0xFF, 0xFE];

/// The longest master → board frame ([`Motors`]).
pub const MAX_LEN: usize = 12;

/// The encoded bytes of a [`Command`].
pub type CommandBytes = FrameBytes<MAX_LEN>;

/// Mode bytes (byte 2).
pub(crate) mod mode {
    pub const VELOCITY: u8 = 0x01;
    pub const MOTORS_CLOSED_LOOP: u8 = 0x02;
    pub const MOTORS_OPEN_LOOP: u8 = 0x03;
    pub const SETTINGS: u8 = 0x80;
}

/// Offset of the mode byte.
const MODE_AT: usize = 2;

/// Checks a command frame's length (`len`) and header: its mode byte. (`Setting::decode` checks
/// its own: in its place this one costs the parser 24 bytes of flash.)
pub(crate) fn mode_of(bytes: &[u8], len: usize) -> Result<u8, Error> {
    if bytes.len() != len {
        return Err(Error::Length);
    }
    if bytes.get(..MODE_AT) != Some(&HEADER[..]) {
        return Err(Error::Header);
    }
    Ok(crate::wire::u8_at(bytes, MODE_AT))
}

/// The length of the frame whose mode byte is `mode`, or `None` for an unknown mode.
#[must_use]
pub const fn frame_len(mode: u8) -> Option<usize> {
    match mode {
        mode::VELOCITY => Some(Velocity::LEN),
        mode::MOTORS_CLOSED_LOOP | mode::MOTORS_OPEN_LOOP => Some(Motors::LEN),
        mode::SETTINGS => Some(Setting::LEN),
        _ => None,
    }
}

/// Any master → board frame.
///
/// ```
/// use chassis_protocol::{Command, Velocity};
///
/// let command = Command::Velocity(Velocity::new(0, 100, 0));
/// let bytes = command.clone().encode(); // encoding consumes a command (it may be a turn)
/// assert_eq!(bytes.len(), 10);
/// assert_eq!(Command::decode(bytes.as_slice()), Ok(command));
/// ```
// Not `Copy`, like the [`Turn`] it may hold.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Command {
    /// Mode `01`, angle mode off.
    Velocity(Velocity),
    /// Mode `01`, angle mode on: a relative turn that the board **accumulates** (see [`Turn`]).
    Turn(Turn),
    /// Mode `02` / `03`.
    Motors(Motors),
    /// Mode `80`.
    Setting(Setting),
}

impl Command {
    /// The frame's length on the wire (10 or 12).
    #[must_use]
    pub const fn len(&self) -> usize {
        match self {
            Command::Velocity(_) | Command::Turn(_) => Velocity::LEN,
            Command::Motors(_) => Motors::LEN,
            Command::Setting(_) => Setting::LEN,
        }
    }

    /// Always `false`: no frame is empty (here for symmetry with [`Command::len`]).
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        false
    }

    /// The frame's bytes. Consumes the command, as [`Turn::encode`] does.
    #[must_use]
    pub fn encode(self) -> CommandBytes {
        match self {
            Command::Velocity(v) => CommandBytes::new(&v.encode()),
            Command::Turn(t) => CommandBytes::new(&t.encode()),
            Command::Motors(m) => CommandBytes::new(&m.encode()),
            Command::Setting(s) => CommandBytes::new(&s.encode()),
        }
    }

    /// Decodes exactly one frame of any mode.
    pub fn decode(bytes: &[u8]) -> Result<Self, Error> {
        if bytes.get(..MODE_AT) != Some(&HEADER[..]) {
            return Err(if bytes.len() < MODE_AT {
                Error::Length
            } else {
                Error::Header
            });
        }
        let mode = bytes.get(MODE_AT).copied().ok_or(Error::Length)?;
        let len = frame_len(mode).ok_or(Error::Mode)?;
        if bytes.len() != len {
            return Err(Error::Length);
        }
        match mode {
            mode::VELOCITY => match Velocity::decode(bytes) {
                Err(Error::Mode) => Turn::decode(bytes).map(Command::Turn),
                other => other.map(Command::Velocity),
            },
            mode::SETTINGS => Setting::decode(bytes).map(Command::Setting),
            _ => Motors::decode(bytes).map(Command::Motors),
        }
    }
}

impl From<Velocity> for Command {
    fn from(v: Velocity) -> Self {
        Command::Velocity(v)
    }
}

impl From<Turn> for Command {
    fn from(t: Turn) -> Self {
        Command::Turn(t)
    }
}

impl From<Motors> for Command {
    fn from(m: Motors) -> Self {
        Command::Motors(m)
    }
}

impl From<Setting> for Command {
    fn from(s: Setting) -> Self {
        Command::Setting(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_dispatches_on_the_mode_byte() {
        let turn = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x0A, 0x10];
        assert_eq!(
            Command::decode(&turn),
            Ok(Command::Turn(Turn::by_deci_degrees(10)))
        );
        let velocity = [0xFF, 0xFE, 0x01, 0x00, 0x00, 0x00, 0x0A, 0x00, 0x00, 0x00];
        assert_eq!(
            Command::decode(&velocity),
            Ok(Command::Velocity(Velocity::new(0, 10, 0)))
        );
        let motors = [0xFF, 0xFE, 0x03, 0, 0, 0, 0, 0, 0, 0, 1, 0];
        assert_eq!(
            Command::decode(&motors),
            Ok(Command::Motors(Motors::open_loop_duty([0, 0, 0, 1])))
        );
        let setting = [0xFF, 0xFE, 0x80, 0x80, 0x00, 0x80, 0x00, 0x00, 0x03, 0x00];
        assert_eq!(
            Command::decode(&setting),
            Ok(Command::Setting(Setting::Action(Action::Store)))
        );
    }

    #[test]
    fn decode_errors() {
        assert_eq!(Command::decode(&[]), Err(Error::Length));
        assert_eq!(Command::decode(&[0xFF, 0xFE]), Err(Error::Length));
        assert_eq!(Command::decode(&[0xFF, 0xFA, 0x01]), Err(Error::Header));
        assert_eq!(Command::decode(&[0xFF, 0xFE, 0x04]), Err(Error::Mode));
        assert_eq!(
            Command::decode(&[0xFF, 0xFE, 0x02, 0, 0, 0, 0, 0, 0, 0]),
            Err(Error::Length)
        );
    }

    #[test]
    fn encoded_length_matches_the_mode() {
        for (command, len) in [
            (Command::from(Velocity::STOP), 10),
            (Command::from(Turn::by_deci_degrees(1)), 10),
            (Command::from(Motors::closed_loop([0; 4])), 12),
            (Command::from(Setting::Read(Register::SpeedKp)), 10),
        ] {
            assert_eq!(command.len(), len);
            let bytes = command.clone().encode();
            assert_eq!(bytes.len(), len);
            assert_eq!(Command::decode(&bytes), Ok(command));
        }
    }
}
