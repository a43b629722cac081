//! Instructions per byte of the downlink parser, on the Cortex-M itself: run under QEMU with
//! `-icount shift=0` (virtual time then advances one nanosecond per instruction), so SysTick,
//! counting the core clock, counts instructions: one tick is 40 instructions on mps2-an386
//! (25 MHz, Cortex-M4) and 62.5 on the micro:bit (16 MHz, Cortex-M0). The same code is built
//! for thumbv7em and thumbv6m; the core's CPUID tells which machine it runs on.
//!
//! It prints one line per figure over semihosting (plain text) and exits 0. `cargo xtask icount`
//! runs it on both machines and prints the table.

#![no_std]
#![no_main]

use board_qemu_an386::time;
use chassis_protocol::{Battery, Downlink, DownlinkParser, Encoders, Imu, Reply};
use core::hint::black_box;

/// Telemetry mix: about two seconds of the board's output.
const MIX_LEN: usize = 4_096;
/// Random bytes.
const RANDOM_LEN: usize = 4_096;

/// A small deterministic generator (the same stream on both machines).
struct Lcg(u32);

impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        self.0 >> 8
    }
    /// A sensor value near 0 (±`range`): at rest a gyro reads small numbers, and -6..-4 are
    /// `FF FA`..`FF FC`: false headers are ordinary traffic.
    fn small(&mut self, range: u32) -> i16 {
        (self.next() % (2 * range + 1)) as i16 - range as i16
    }
}

/// The board's telemetry at its rates (IMU every 10 ms, encoders every 40, battery every
/// 1 000), with a reply every 100 ms; the frame ends are recorded.
fn telemetry_mix(buf: &mut [u8; MIX_LEN], ends: &mut [u16; 512]) -> (usize, usize) {
    let mut rng = Lcg(2026);
    let mut len = 0;
    let mut frames = 0;
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
            let e = Encoders {
                ticks: [
                    rng.small(300),
                    rng.small(300),
                    rng.small(300),
                    rng.small(300),
                ],
                seq: seq[1],
            };
            if !push(&e.encode(), &mut len, &mut frames) {
                break;
            }
        }
        if tick % 10 == 5 {
            let registers = chassis_protocol::Register::ALL;
            let register = registers[rng.next() as usize % registers.len()];
            let r = Reply {
                code: register.reply_code(),
                value: rng.next() % 2_000,
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

/// SysTick ticks for `f`, less the cost of the measurement itself (`overhead`).
fn measure(overhead: u64, f: impl FnOnce()) -> u64 {
    let start = time::cycles();
    f();
    time::cycles()
        .saturating_sub(start)
        .saturating_sub(overhead)
}

/// Runs the parser's slice path over `bytes`; the frames it gave.
fn parse_slices(bytes: &[u8]) -> u32 {
    let mut parser = DownlinkParser::new();
    let mut frames = 0u32;
    for frame in parser.frames(bytes) {
        black_box(&frame);
        frames += 1;
    }
    frames
}

/// Runs the parser over `bytes`, one byte at a time (`push`: what an interrupt handler does);
/// the frames it gave.
fn parse_all(bytes: &[u8]) -> u32 {
    let mut parser = DownlinkParser::new();
    let mut frames = 0u32;
    for &byte in bytes {
        if let Some(frame) = parser.push(byte) {
            black_box(&frame);
            frames += 1;
        }
    }
    frames
}

#[cortex_m_rt::entry]
fn main() -> ! {
    // SAFETY: taken once, before anything else runs.
    let mut core = unsafe { cortex_m::Peripherals::steal() };
    // Cortex-M4 (part number 0xC24): mps2-an386 at 25 MHz; otherwise the micro:bit at 16 MHz.
    let m4 = (core.CPUID.base.read() >> 4) & 0xFFF == 0xC24;
    let (machine, clock_hz) = if m4 {
        ("mps2-an386 Cortex-M4 thumbv7em", 25_000_000u32)
    } else {
        ("microbit Cortex-M0 thumbv6m", 16_000_000u32)
    };
    time::start_cycles(&mut core.SYST);
    // Instructions per 1 000 ticks (1e9 ns per s / clock, ×1 000).
    let milli_instr_per_tick = 1_000_000_000_000u64 / u64::from(clock_hz);
    let instr = |ticks: u64| ticks * milli_instr_per_tick / 1_000;

    let overhead = (0..16).map(|_| measure(0, || {})).min().unwrap_or(0);

    let mut mix = [0u8; MIX_LEN];
    let mut ends = [0u16; 512];
    let (mix_len, mix_frames) = telemetry_mix(&mut mix, &mut ends);
    let mix = &mix[..mix_len];
    let mut random = [0u8; RANDOM_LEN];
    let mut rng = Lcg(7);
    for b in random.iter_mut() {
        *b = rng.next() as u8;
    }

    let mut got = 0;
    let ticks_mix = measure(overhead, || got = parse_all(black_box(mix)));
    let mut got_slices = 0;
    let ticks_slices = measure(overhead, || got_slices = parse_slices(black_box(mix)));
    let mut got_random = 0;
    let ticks_random = measure(overhead, || got_random = parse_all(black_box(&random)));

    // The byte that completes a frame: everything before it untimed.
    let mut parser = DownlinkParser::new();
    let mut start = 0usize;
    let mut completing = 0u64;
    let mut timed = 0u64;
    for &end in &ends[..mix_frames] {
        let end = usize::from(end);
        for &byte in &mix[start..end - 1] {
            black_box(parser.push(byte));
        }
        let last = mix[end - 1];
        completing += measure(overhead, || {
            black_box(parser.push(black_box(last)));
        });
        timed += 1;
        start = end;
    }
    let _: Option<Downlink> = None;

    // The tick-to-instruction factor, checked on a loop of known length: 2 instructions (subs,
    // bne) per turn.
    let turns = 100_000u32;
    let ticks_loop = measure(overhead, || {
        // SAFETY: a register-only loop: no memory, no stack.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, #1",
                "bne 2b",
                n = inout(reg) turns => _,
                options(nomem, nostack),
            );
        }
    });
    semihosting::println!("machine: {}", machine);
    semihosting::println!(
        "calibration: a loop of {} instructions measured as {}",
        2 * turns,
        instr(ticks_loop)
    );
    semihosting::println!(
        "telemetry mix, push: {} bytes, {} frames sent, {} parsed, {} instructions, {} milli-instructions per byte",
        mix_len,
        mix_frames,
        got,
        instr(ticks_mix),
        instr(ticks_mix) * 1_000 / mix_len as u64
    );
    semihosting::println!(
        "telemetry mix, slices: {} frames parsed, {} instructions, {} milli-instructions per byte",
        got_slices,
        instr(ticks_slices),
        instr(ticks_slices) * 1_000 / mix_len as u64
    );
    semihosting::println!(
        "random bytes, push: {} bytes, {} frames parsed, {} instructions, {} milli-instructions per byte",
        RANDOM_LEN,
        got_random,
        instr(ticks_random),
        instr(ticks_random) * 1_000 / RANDOM_LEN as u64
    );
    semihosting::println!(
        "frame-completing byte: {} frames, {} milli-instructions each on average",
        timed,
        instr(completing) * 1_000 / timed.max(1)
    );
    semihosting::process::exit(0)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    semihosting::println!("panic: {}", info);
    semihosting::process::exit(101)
}
