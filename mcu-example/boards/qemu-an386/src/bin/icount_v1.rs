//! Instructions per byte of the v1.0.0 board → master parser (`chassis_protocol::v1::DownlinkParser`)
//! on the Cortex-M itself, measured as `icount` measures the 2020 parser (its own binary, so
//! that the 2020 figures stay those of a binary with nothing else in it): the run of
//! [`board_qemu_an386::icount`] under QEMU with `-icount shift=0`, on the v1.0.0 board's
//! stream, through the parser's [`Parser`](chassis_protocol::stream::Parser) implementation
//! alone.
//!
//! It prints one line per figure over semihosting (plain text, each starting with `v1`) and
//! exits 0. `cargo xtask icount` runs it on both machines beside `icount` and prints the table.

#![no_std]
#![no_main]

use board_qemu_an386::icount::{self, Generation, Lcg, MAX_FRAMES, MIX_LEN, Prefix};
use chassis_protocol::v1;

/// The v1.0.0 board → master parser.
struct V1;

impl Generation for V1 {
    type Parser = v1::DownlinkParser;
    const PREFIX: Prefix = Prefix::V1;
    // A byte completes at most one frame; one found inside a damaged frame may follow it.
    const POLL: bool = true;

    fn parser() -> v1::DownlinkParser {
        v1::DownlinkParser::new()
    }

    fn mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; MAX_FRAMES]) -> (usize, usize) {
        v1_mix(buf, ends)
    }
}

/// The v1.0.0 board's stream: 32-byte telemetry at 22 Hz (a chassis driving and turning: the
/// velocity steps about, the quaternion × 1000 turns about z, the battery near 12 V) with a
/// readback reply every second, back to back; the frame ends are recorded.
fn v1_mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; MAX_FRAMES]) -> (usize, usize) {
    let mut rng = Lcg(2026);
    let mut len = 0;
    let mut frames = 0;
    // The heading as (cos, sin) of half the angle, Q14.
    let (mut c, mut s) = (16_384i32, 0i32);
    let mut velocity = [0i16; 3];
    for tick in 0u32.. {
        for (v, limit) in velocity.iter_mut().zip([600, 1_000, 2_500]) {
            *v = (*v + rng.small(60)).clamp(-limit, limit);
        }
        // Half of wz × 45 ms, in Q14 radians: wz (mrad/s) × 0.0225 × 16.384.
        let half = i32::from(velocity[2]) * 369 / 1_000;
        let (c2, s2) = (c - ((s * half) >> 14), s + ((c * half) >> 14));
        // Back onto the unit circle (one Newton step).
        let n2 = (c2 * c2 + s2 * s2) >> 14;
        let k = (3 * 16_384 - n2) / 2;
        (c, s) = ((c2 * k) >> 14, (s2 * k) >> 14);
        let t = v1::Telemetry {
            velocity: [
                velocity[0] + rng.small(4),
                velocity[1] + rng.small(4),
                velocity[2] + rng.small(4),
            ],
            accel: [rng.small(120), rng.small(120), 16_384 + rng.small(120)],
            gyro: [rng.small(6), rng.small(6), velocity[2] + rng.small(8)],
            quaternion: [
                ((c * 1_000) >> 14) as i16,
                rng.small(2),
                rng.small(2),
                ((s * 1_000) >> 14) as i16,
            ],
            battery_mv: 12_000 + rng.small(200),
        };
        let frame = t.encode();
        if len + frame.len() > MIX_LEN || frames >= ends.len() {
            break;
        }
        buf[len..len + frame.len()].copy_from_slice(&frame);
        len += frame.len();
        ends[frames] = len as u16;
        frames += 1;
        if tick % 22 == 11 {
            let request = v1::Readback::ALL[rng.next_value() as usize % v1::Readback::ALL.len()];
            let mut payload = [0u8; 10];
            for b in payload.iter_mut().skip(2) {
                *b = rng.next_value() as u8;
            }
            let frame = v1::Reply { request, payload }.encode();
            if len + frame.len() > MIX_LEN || frames >= ends.len() {
                break;
            }
            buf[len..len + frame.len()].copy_from_slice(&frame);
            len += frame.len();
            ends[frames] = len as u16;
            frames += 1;
        }
    }
    (len, frames)
}

#[cortex_m_rt::entry]
fn main() -> ! {
    icount::run::<V1>()
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    semihosting::println!("panic: {}", info);
    semihosting::process::exit(101)
}
