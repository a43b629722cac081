//! `arbitrary::Arbitrary` for the frames (feature `arbitrary`), for fuzzing.
//!
//! Each value is made by decoding arbitrary bytes laid out as the frame, so it is always one
//! that `decode` can return: reserved bits and negative zeros are where `decode` puts them, and
//! a setting that fits a typed form is never `Setting::Raw`. Hence encode → decode is exact.

use crate::command::motion::{dir::ANGLE_MODE, field::VELOCITY_DIR};
use crate::command::{HEADER, mode, settings};
use crate::{
    Battery, Command, Downlink, Encoders, Imu, Motors, Register, Reply, Setting, Turn, Velocity,
};
use arbitrary::{Arbitrary, Result, Unstructured};

/// A master → board frame's first three bytes: the header and `mode` (from the frame modules'
/// own constants).
const fn head(mode: u8) -> [u8; 3] {
    let [a, b] = HEADER;
    [a, b, mode]
}

/// `N` bytes: `head`, then arbitrary bytes, then `fix` applied.
fn layout<const N: usize>(
    u: &mut Unstructured<'_>,
    head: &[u8],
    fix: impl Fn(&mut [u8; N]),
) -> Result<[u8; N]> {
    let mut bytes: [u8; N] = u.arbitrary()?;
    for (b, h) in bytes.iter_mut().zip(head) {
        *b = *h;
    }
    fix(&mut bytes);
    Ok(bytes)
}

/// Turns a decode error (impossible for a well-laid-out frame) into an arbitrary error.
fn ok<T>(decoded: core::result::Result<T, crate::Error>) -> Result<T> {
    decoded.map_err(|_| arbitrary::Error::IncorrectFormat)
}

/// Direction byte of a mode-`0x01` frame, and its angle-mode bit.
impl<'a> Arbitrary<'a> for Velocity {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let bytes = layout::<{ Velocity::LEN }>(u, &head(mode::VELOCITY), |b| {
            if let Some(d) = b.get_mut(VELOCITY_DIR) {
                *d &= !ANGLE_MODE;
            }
        })?;
        ok(Velocity::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Turn {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let bytes = layout::<{ Turn::LEN }>(u, &head(mode::VELOCITY), |b| {
            if let Some(d) = b.get_mut(VELOCITY_DIR) {
                *d |= ANGLE_MODE;
            }
        })?;
        ok(Turn::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Motors {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let mode = if u.arbitrary()? {
            mode::MOTORS_CLOSED_LOOP
        } else {
            mode::MOTORS_OPEN_LOOP
        };
        let bytes = layout::<{ Motors::LEN }>(u, &head(mode), |_| {})?;
        ok(Motors::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Setting {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        // Mostly typed settings: codes the spec defines (the actions', each register's write
        // and read codes, from the register table), reserved byte 9 at 0.
        let code = if u.ratio(7u8, 8)? {
            match u.int_in_range(0u8..=2)? {
                0 => settings::ACTION_CODE,
                1 => u.choose(&Register::ALL)?.code(),
                _ => u.choose(&Register::ALL)?.read_code(),
            }
        } else {
            u.arbitrary()?
        };
        let tail = if u.ratio(7u8, 8)? { 0 } else { u.arbitrary()? };
        let [a, b, m] = head(mode::SETTINGS);
        let bytes = layout::<{ Setting::LEN }>(u, &[a, b, m, settings::FIXED, code], |b| {
            if let Some(t) = b.last_mut() {
                *t = tail;
            }
        })?;
        ok(Setting::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Command {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        Ok(match u.int_in_range(0u8..=3)? {
            0 => Command::Velocity(u.arbitrary()?),
            1 => Command::Turn(u.arbitrary()?),
            2 => Command::Motors(u.arbitrary()?),
            _ => Command::Setting(u.arbitrary()?),
        })
    }
}

impl<'a> Arbitrary<'a> for Imu {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        Ok(Imu {
            accel: u.arbitrary()?,
            gyro: u.arbitrary()?,
            seq: u.arbitrary()?,
        })
    }
}

impl<'a> Arbitrary<'a> for Encoders {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        Ok(Encoders {
            ticks: u.arbitrary()?,
            seq: u.arbitrary()?,
        })
    }
}

impl<'a> Arbitrary<'a> for Battery {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        Ok(Battery {
            centivolts: u.arbitrary()?,
            percent: u.arbitrary()?,
            seq: u.arbitrary()?,
        })
    }
}

impl<'a> Arbitrary<'a> for Reply {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        Ok(Reply {
            code: u.arbitrary()?,
            value: u.arbitrary()?,
        })
    }
}

impl<'a> Arbitrary<'a> for Downlink {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        Ok(match u.int_in_range(0u8..=3)? {
            0 => Downlink::Imu(u.arbitrary()?),
            1 => Downlink::Encoders(u.arbitrary()?),
            2 => Downlink::Battery(u.arbitrary()?),
            _ => Downlink::Reply(u.arbitrary()?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_arbitrary_frame_round_trips() {
        let data: Vec<u8> = (0..4096u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        let mut u = Unstructured::new(&data);
        let mut made = 0;
        while !u.is_empty() {
            let (Ok(c), Ok(t)) = (Command::arbitrary(&mut u), Downlink::arbitrary(&mut u)) else {
                break;
            };
            assert_eq!(Command::decode(&c.clone().encode()), Ok(c));
            assert_eq!(Downlink::decode(&t.encode()), Ok(t));
            made += 1;
        }
        assert!(made > 50, "{made}");
    }
}
