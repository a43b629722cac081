//! Instructions per byte of the 2020 board → master parser (`chassis_protocol::DownlinkParser`)
//! on the Cortex-M itself: the run of [`board_qemu_an386::icount`] under QEMU with
//! `-icount shift=0`, on the 2020 board's telemetry, through the parser's own `push` and slice
//! path.
//!
//! It prints one line per figure over semihosting (plain text) and exits 0. `cargo xtask icount`
//! runs it on both machines and prints the table.

#![no_std]
#![no_main]

use board_qemu_an386::icount::{self, Generation, Lcg, MAX_FRAMES, MIX_LEN, Prefix};
use chassis_protocol::{Battery, Downlink, DownlinkParser, Encoders, Imu, Register, Reply};

/// The 2020 board → master parser.
struct V2020;

impl Generation for V2020 {
    type Parser = DownlinkParser;
    const PREFIX: Prefix = Prefix::None;
    // Each byte is only pushed, as an interrupt handler does: a frame held back comes out of
    // the next `push`.
    const POLL: bool = false;

    fn parser() -> DownlinkParser {
        DownlinkParser::new()
    }

    fn mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; MAX_FRAMES]) -> (usize, usize) {
        telemetry_mix(buf, ends)
    }

    /// The parser's own `push`, its fast path inlined into the loop (the trait's, not marked
    /// `#[inline]`, stays a call).
    #[inline(always)]
    fn push(parser: &mut DownlinkParser, byte: u8) -> Option<Downlink> {
        parser.push(byte)
    }

    /// The parser's own `frames()`, with its fast path over a slice (the trait's calls
    /// `push_slice` for each frame).
    fn frames<'a>(
        parser: &'a mut DownlinkParser,
        bytes: &'a [u8],
    ) -> impl Iterator<Item = Downlink> {
        parser.frames(bytes)
    }
}

/// The board's telemetry at its rates (IMU every 10 ms, encoders every 40, battery every
/// 1 000), with a reply every 100 ms; the frame ends are recorded.
fn telemetry_mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; MAX_FRAMES]) -> (usize, usize) {
    let mut rng = Lcg(2026);
    let (mut len, mut frames) = (0, 0);
    let mut seq = [0u8; 3];
    let mut push = |bytes: &[u8], len: &mut usize, frames: &mut usize| -> bool {
        if *len + bytes.len() > MIX_LEN || *frames >= ends.len() {
            return false;
        }
        buf[*len..*len + bytes.len()].copy_from_slice(bytes);
        *len += bytes.len();
        ends[*frames] = *len as u16;
        *frames += 1;
        true
    };
    for tick in 0u32.. {
        seq[0] = seq[0].wrapping_add(1);
        let imu = Imu {
            accel: [rng.small(40), rng.small(40), 16_384 + rng.small(40)],
            gyro: [rng.small(8), rng.small(8), rng.small(8)],
            seq: seq[0],
        };
        if !push(&imu.encode(), &mut len, &mut frames) {
            break;
        }
        if tick % 4 == 0 {
            seq[1] = seq[1].wrapping_add(1);
            let mut ticks = || rng.small(300);
            let e = Encoders {
                ticks: [ticks(), ticks(), ticks(), ticks()],
                seq: seq[1],
            };
            if !push(&e.encode(), &mut len, &mut frames) {
                break;
            }
        }
        if tick % 10 == 5 {
            let register = Register::ALL[rng.next_value() as usize % Register::ALL.len()];
            let r = Reply {
                code: register.reply_code(),
                value: rng.next_value() % 2_000,
            };
            if !push(&r.encode(), &mut len, &mut frames) {
                break;
            }
        }
        if tick % 100 == 0 {
            seq[2] = seq[2].wrapping_add(1);
            let b = Battery {
                centivolts: 1_200,
                percent: 90,
                seq: seq[2],
            };
            if !push(&b.encode(), &mut len, &mut frames) {
                break;
            }
        }
    }
    (len, frames)
}

#[cortex_m_rt::entry]
fn main() -> ! {
    icount::run::<V2020>()
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    semihosting::println!("panic: {}", info);
    semihosting::process::exit(101)
}
