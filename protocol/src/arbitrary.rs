//! `arbitrary::Arbitrary` for the frames (feature `arbitrary`), for fuzzing.
//!
//! Each value is made by decoding arbitrary bytes laid out as the frame, so it is always one
//! that `decode` can return: reserved bits and negative zeros are where `decode` puts them, and
//! a setting that fits a typed form is never `Setting::Raw`. Hence encode → decode is exact.

use crate::{Battery, Command, Downlink, Encoders, Imu, Motors, Reply, Setting, Turn, Velocity};
use arbitrary::{Arbitrary, Result, Unstructured};

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
const VELOCITY_DIR: usize = 9;
const ANGLE_MODE: u8 = 1 << 4;

impl<'a> Arbitrary<'a> for Velocity {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let bytes = layout::<{ Velocity::LEN }>(u, &[0xFF, 0xFE, 0x01], |b| {
            if let Some(d) = b.get_mut(VELOCITY_DIR) {
                *d &= !ANGLE_MODE;
            }
        })?;
        ok(Velocity::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Turn {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let bytes = layout::<{ Turn::LEN }>(u, &[0xFF, 0xFE, 0x01], |b| {
            if let Some(d) = b.get_mut(VELOCITY_DIR) {
                *d |= ANGLE_MODE;
            }
        })?;
        ok(Turn::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Motors {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        let mode = if u.arbitrary()? { 0x02 } else { 0x03 };
        let bytes = layout::<{ Motors::LEN }>(u, &[0xFF, 0xFE, mode], |_| {})?;
        ok(Motors::decode(&bytes))
    }
}

impl<'a> Arbitrary<'a> for Setting {
    fn arbitrary(u: &mut Unstructured<'a>) -> Result<Self> {
        // Mostly typed settings: codes the spec defines, reserved byte 9 at 0.
        const CODES: [u8; 18] = [
            0x00, 0x01, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x11, 0x16, 0x17, 0x18, 0x19,
            0x1A, 0x1B, 0x1C, 0x20,
        ];
        let code = if u.ratio(7u8, 8)? {
            *u.choose(&CODES)?
        } else {
            u.arbitrary()?
        };
        let tail = if u.ratio(7u8, 8)? { 0 } else { u.arbitrary()? };
        let bytes = layout::<{ Setting::LEN }>(u, &[0xFF, 0xFE, 0x80, 0x80, code], |b| {
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
